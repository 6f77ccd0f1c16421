"""Must-show of `lash monitor` (issue 25), live: the hil run's master_bus.log replayed on the UDP
bus with `lash can replay` into `lash monitor udp:... --record`, at the bench's rate (--speed 1)
and at 10x (--speed 10), inside a private network namespace (no multicast leaves the machine).

Checks, against independent sources:
 - the monitor received every frame of the log (its count_frames in the SQLite meta, read with
   Python's sqlite3, equals the frames python-can reads from the log; count_bus_dropped = 0);
 - the recorded v,y sequences equal those of the file mode (`lash monitor master_bus.log --record`)
   value for value, in the same order: no frame lost, none reordered;
 - their number equals the y frames python-can counts in the log (one sample per y frame).
Timestamps differ (the live record's are receive times), so only v and y are compared.
"""
import os
import signal
import sqlite3
import subprocess
import sys
import tempfile
import time

import can

sys.path.insert(0, os.path.dirname(__file__))
import hil_netns  # noqa: E402

hil_netns.enter_private_netns()

LASH = hil_netns.lash()
SRC = hil_netns.source_dir()
DBC = os.path.join(SRC, "config", "monitor", "hydraulic_bench_kpa.dbc")
SCN = os.path.join(SRC, "config", "scenarios", "closed_loop", "valve_deadzone_drift.toml")
MON = ["--dbc", DBC, "--v", "BenchCommand.SolenoidA_Current-BenchCommand.SolenoidB_Current",
       "--y", "BenchSensors.PilotPressure_kPa", "--model", "input-deadzone", "--method", "iv", "--lambda", "0.995",
       "--quiet"]
BUS = "udp:239.74.163.9:43119"
tmp = tempfile.mkdtemp(prefix="lash_monitor_udp_")

r = subprocess.run([LASH, "hil", "run", "--scenario", SCN, "--out-dir", os.path.join(tmp, "hil")],
                   capture_output=True, text=True, timeout=180)
assert r.returncode == 0, r.stderr
log = os.path.join(tmp, "hil", "master_bus.log")

frames = list(can.CanutilsLogReader(log))
n_y = sum(1 for m in frames if m.arbitration_id == 0x200)
print(f"log: {len(frames)} frames, {n_y} of BenchSensors (python-can)")


def vy(path):
    with open(path) as f:
        assert f.readline().strip() == "t,v,y"
        return [tuple(line.rstrip("\n").split(",")[1:]) for line in f]


file_rec = os.path.join(tmp, "file.csv")
r = subprocess.run([LASH, "monitor", log, *MON, "--record", file_rec], capture_output=True, text=True, timeout=300)
assert r.returncode == 0, r.stderr
file_vy = vy(file_rec)
assert len(file_vy) == n_y, (len(file_vy), n_y)

for speed in ("1", "10"):
    rec, db = os.path.join(tmp, f"live{speed}.csv"), os.path.join(tmp, f"live{speed}.sqlite")
    mon = subprocess.Popen([LASH, "monitor", BUS, *MON, "--record", rec, "--db", db],
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    time.sleep(1.0)  # the monitor joins the group before the first frame goes out
    rp = subprocess.run([LASH, "can", "replay", "--bus", BUS, "--speed", speed, log],
                        capture_output=True, text=True, timeout=120)
    assert rp.returncode == 0, rp.stderr
    time.sleep(1.0)  # the last datagrams are read
    mon.send_signal(signal.SIGINT)
    _, err = mon.communicate(timeout=60)
    assert mon.returncode == 0, err
    con = sqlite3.connect(db)
    assert con.execute("PRAGMA integrity_check").fetchone()[0] == "ok"
    meta = dict(con.execute("SELECT key, value FROM meta WHERE key LIKE 'count_%'"))
    con.close()
    assert int(meta["count_frames"]) == len(frames), (meta["count_frames"], len(frames))
    assert int(meta["count_bus_dropped"]) == 0 and int(meta["count_garbage"]) == 0, meta
    live_vy = vy(rec)
    assert len(live_vy) == len(file_vy), (speed, len(live_vy), len(file_vy))
    diff = [i for i, (a, b) in enumerate(zip(live_vy, file_vy)) if a != b]
    assert not diff, (speed, diff[:5], [(live_vy[i], file_vy[i]) for i in diff[:3]])
    print(f"speed {speed}: {meta['count_frames']} frames received, {len(live_vy)} samples, "
          f"v,y equal to the file mode's")
