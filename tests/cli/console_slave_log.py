"""The console's slave_log_* signals (docs/console.md): `lash hil run --console 0` follows
<out-dir>/slave.csv as the slave writes it. During the run, over the HTTP API (no browser):
/api/frame at one column per control step (5 ms) for slave_log_step, slave_log_state and
slave_log_pressure_kPa must hold finite values, and after the run each column must agree with
slave.csv, read independently with the csv module: the column's state min/max and pressure
min/max equal those of slave.csv's rows over the column's step range (exactly when the column
holds one step; float32 rounding allowed for the pressure); the status panel names the slave's
state; the log's step lies within a few steps of the bus tap's Sensor_Counter at the same time."""
import csv
import json
import os
import statistics
import struct
import sys
import tempfile
import time
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import console_run  # noqa: E402  (the lash command with its console)

LASH = os.environ.get("LASH", "lash")
STATES = ("startup", "connected", "running", "degraded", "safe", "failed")


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def get(base, token, path):
    return urllib.request.urlopen(urllib.request.Request(base + path, headers={"X-Lash-Token": token}),
                                  timeout=5).read()


with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "run")
    run, m = console_run.start([LASH, "hil", "run", "--duration", "8", "--console", "0", "--out-dir", out])
    if m is None:
        fail("no console URL printed")
    base, token = f"http://127.0.0.1:{m[1]}", m[2]
    names = json.loads(get(base, token, "/api/meta"))["signals"]
    want = ["slave_step", "slave_log_step", "slave_log_state", "slave_log_pressure_kPa"]  # in /api/meta's order
    for n in want + ["slave_log_tet_us", "slave_log_io_us", "slave_log_wake_latency_us", "slave_log_dropped"]:
        if n not in names:
            fail(f"/api/meta lists no {n}: {names}")
    idx = [names.index(n) for n in want]
    if idx != sorted(idx):
        fail(f"unexpected signal order {idx}")  # /api/frame returns the signals asked for in index order
    frames, st = [], None
    time.sleep(4)
    for _ in range(3):  # 2 s windows, one column per control step (the decimator's base bucket = step_s)
        frames.append(get(base, token, "/api/frame?window=2&columns=4000&sig=" + ",".join(map(str, idx))))
        st = json.loads(get(base, token, "/api/status"))
        time.sleep(0.7)
    console_run.finish(run, fail)

    with open(os.path.join(out, "slave.csv")) as f:
        rows = {int(float(r["step"])): (float(r["state"]), float(r["pressure_kPa"])) for r in csv.DictReader(f)}
    checked = exact = 0
    lag = []
    for fr in frames:
        ncol, nsig = struct.unpack_from("<II", fr, 4)
        col_s = struct.unpack_from("<d", fr, 32)[0]
        v = struct.unpack_from(f"<{nsig * 2 * ncol}f", fr, 64)
        lo = lambda s, c: v[2 * s * ncol + c]
        hi = lambda s, c: v[(2 * s + 1) * ncol + c]
        for c in range(ncol):
            if lo(1, c) != lo(1, c):
                continue  # no log row in this column
            k0, k1 = int(lo(1, c)), int(hi(1, c))
            states = [rows[k][0] for k in range(k0, k1 + 1) if k in rows]
            press = [rows[k][1] for k in range(k0, k1 + 1) if k in rows]
            if not states:
                fail(f"steps {k0}..{k1} shown in the page are not in slave.csv")
            for s in (2, 3):
                if not (lo(s, c) == lo(s, c) and hi(s, c) == hi(s, c)):
                    fail(f"column {c}: {want[s]} is not finite beside step {k0}")
            if k0 == k1:
                exact += 1
                if lo(2, c) != states[0] or hi(2, c) != states[0]:
                    fail(f"step {k0}: slave_log_state {lo(2, c)} but slave.csv's state {states[0]}")
            if not (min(states) <= lo(2, c) and hi(2, c) <= max(states)):
                fail(f"steps {k0}..{k1}: state [{lo(2, c)}, {hi(2, c)}] not within slave.csv's {states}")
            tol = 1e-6 * max(abs(x) for x in press) + 1e-9  # float32 in the frame
            if not (min(press) - tol <= lo(3, c) and hi(3, c) <= max(press) + tol):
                fail(f"steps {k0}..{k1}: pressure [{lo(3, c)}, {hi(3, c)}] not within slave.csv's "
                     f"[{min(press)}, {max(press)}]")
            checked += 1
            if lo(0, c) == lo(0, c):  # the bus tap's Sensor_Counter (16 bits) in the same column
                lag.append(((k0 - int(lo(0, c))) + 32768) % 65536 - 32768)
    print(f"{checked} columns checked against slave.csv ({exact} holding one step: state exact, "
          f"pressure to float32), column width {col_s * 1e3:.3f} ms")
    if checked < 300:
        fail(f"only {checked} columns held slave_log rows")
    if not lag:
        fail("no column held both the log's step and the bus tap's")
    med = statistics.median(lag)
    print(f"log step - bus Sensor_Counter in the same column: median {med}, min {min(lag)}, max {max(lag)} "
          f"steps over {len(lag)} columns")
    if abs(med) > 2:
        fail("the log's rows are not on the bus tap's clock")
    shown = st["status_text"].get("slave_state")
    print("status slave_state:", shown, "; slave_log:", st["status_text"].get("slave_log"),
          "; rows:", st["status"].get("slave_log_rows"))
    if shown not in STATES:
        fail(f"status slave_state shows {shown!r}")
print("PASS")
