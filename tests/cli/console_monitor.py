"""Issue 27, `lash monitor --console` in a real browser (chromium + chromium-driver, python3-selenium).
The test writes a candump -L log of a plant with an input deadzone (v = SolenoidA - SolenoidB
[mA], y = PilotPressure_kPa; frames every 5 ms, hydraulic_bench_kpa.dbc) with a 1.5-s silence at
t = 12 s, and runs `lash monitor LOG --realtime --console 0` on it. Then:

1. the page loads with no console errors; it is read-only (no tuning form);
2. scopes v and y and one estimate panel per parameter (data-scope "est:NAME", value with its
   95 % band, green when identified, grey when not) appear;
3. samples/s in the status panel is the log's rate, 200/s (+-15 %), computed here from the log;
4. the stale status reads "ok" while frames flow and "stale..." during the silence the test made;
5. the v scope's envelope over the whole run so far spans the commands written to the log up to
   the page's t_end (within 1 mA: the 0.1-mA quantisation and float32);
6. a change (POST /api/tune) is refused with 403 (read-only).
Skips (77) when chromium, its driver or selenium is missing. LASH_CONSOLE_SHOT=FILE saves a screenshot."""
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

LASH = os.environ.get("LASH", "lash")
SRC = os.environ.get("LASH_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import browser  # noqa: E402  (the shared headless chromium; exits 77 when it is missing)
from browser import By  # noqa: E402
DBC = os.path.join(SRC, "config", "monitor", "hydraulic_bench_kpa.dbc")
DT, DURATION, GAP_AT, GAP = 0.005, 26.0, 12.0, 1.5


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def write_log(path):
    """The plant: u = deadzone(v) with c_r = 200, c_l = -150 mA; y(k) = 0.9 y(k-1) + 0.1 * 1.5 u(k-1)."""
    y, u, t0 = 0.0, 0.0, 1795000000.0
    cmds = []  # (t since the first frame, v as encoded)
    with open(path, "w") as f:
        k, t = 0, 0.0
        while t < DURATION:
            if GAP_AT <= t < GAP_AT + GAP:
                k += 1
                t = k * DT
                continue
            v = 700 * math.sin(2 * math.pi * 0.4 * t) + 250 * math.sin(2 * math.pi * 1.7 * t)
            a, b = round(max(v, 0) / 0.1), round(max(-v, 0) / 0.1)
            cmd = struct.pack("<HHHBB", a, b, 0, k & 255, 0)
            cmds.append((t, (a - b) * 0.1))
            y = 0.9 * y + 0.1 * 1.5 * u
            u = v - 200 if v > 200 else (v + 150 if v < -150 else 0.0)
            raw = round((y + 2291.9436) / 0.07449454489967193)
            sen = struct.pack("<HHHBB", raw, 0, k & 0xFFFF, 0, 0)
            f.write(f"({t0 + t:.6f}) can0 100#{cmd.hex().upper()}\n")
            f.write(f"({t0 + t + 0.001:.6f}) can0 200#{sen.hex().upper()}\n")
            k += 1
            t = k * DT
    return cmds


def get(url, token):
    with urllib.request.urlopen(urllib.request.Request(url, headers={"X-Lash-Token": token}), timeout=5) as r:
        return r.read()


with tempfile.TemporaryDirectory() as tmp:
    log = os.path.join(tmp, "bench.log")
    cmds = write_log(log)
    run = subprocess.Popen([LASH, "monitor", log, "--dbc", DBC, "--v",
                            "BenchCommand.SolenoidA_Current-BenchCommand.SolenoidB_Current",
                            "--y", "BenchSensors.PilotPressure_kPa", "--model", "input-deadzone", "--realtime",
                            "--quiet", "--console", "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    m = None
    while m is None:
        line = run.stderr.readline()
        if not line:
            fail("no console URL printed: " + run.stderr.read()[-500:])
        m = browser.lash_url(line)
    url, port, token = m
    t_start = time.time()
    base = f"http://127.0.0.1:{port}"
    d = browser.chrome(os.path.join(tmp, "profile"))
    status = lambda: d.execute_script("const o = {}; document.querySelectorAll('[data-status]').forEach("
                                      "(e) => o[e.getAttribute('data-status')] = e.textContent); return o;")
    try:
        d.get(url)
        stale_seen, ok_seen, rate = [], [], None
        while time.time() - t_start < GAP_AT + GAP + 4:
            st = status()
            (stale_seen if (st.get("stale") or "").startswith("stale") else ok_seen).append(st.get("stale"))
            if time.time() - t_start > 8 and rate is None and st.get("samples_per_s"):
                rate = float(st["samples_per_s"])
            time.sleep(0.25)
        scopes = [e.get_attribute("data-scope") for e in d.find_elements(By.CSS_SELECTOR, "[data-scope]")]
        print("scopes:", scopes)
        est = [s[4:] for s in scopes if s.startswith("est:")]
        if "v" not in scopes or "y" not in scopes or not est:
            fail("want scopes v, y and estimate panels")
        if not set(est) <= {"c_r", "c_l", "d_r", "d_l", "K_r", "K_l", "tau_s_r", "tau_s_l", "K", "tau_s", "d"}:
            fail(f"unknown estimate panels {est}")
        if d.find_elements(By.CSS_SELECTOR, "form[data-tune]"):
            fail("the monitor's page has a tuning form")
        print(f"samples/s in the page: {rate} (the log: {1 / DT:.0f}/s)")
        if rate is None or abs(rate - 1 / DT) > 0.15 / DT:
            fail("samples/s is not the log's rate")
        print(f"stale status: 'ok' {ok_seen.count('ok')} times, stale {len(stale_seen)} times "
              f"(the log is silent {GAP} s at {GAP_AT} s): {stale_seen[:1]}")
        if not stale_seen or ok_seen.count("ok") < 5:
            fail("the stale status did not follow the log's silence")
        b = get(base + "/api/frame?window=3600&columns=400&sig=0", token)
        ncol = struct.unpack_from("<I", b, 4)[0]
        t_end = struct.unpack_from("<d", b, 16)[0]
        vals = [x for x in struct.unpack_from(f"<{2 * ncol}f", b, 64) if x == x]
        vs = [v for t, v in cmds if t <= t_end]
        print(f"v envelope [{min(vals):.2f}, {max(vals):.2f}] mA up to t = {t_end:.2f} s; the log's commands "
              f"[{min(vs):.2f}, {max(vs):.2f}] mA")
        if abs(min(vals) - min(vs)) > 1.0 or abs(max(vals) - max(vs)) > 1.0:
            fail("the v scope is not the log's v")
        req = urllib.request.Request(base + "/api/tune", data=b'{"name":"x","value":1}', method="POST",
                                     headers={"X-Lash-Token": token, "Origin": base, "Content-Type": "application/json"})
        try:
            urllib.request.urlopen(req, timeout=5)
            fail("a change was accepted by the monitor's (read-only) console")
        except urllib.error.HTTPError as e:
            print("POST /api/tune with the token:", e.code)
            if e.code != 403:
                fail("want 403")
        if os.environ.get("LASH_CONSOLE_SHOT"):
            d.save_screenshot(os.environ["LASH_CONSOLE_SHOT"])
        errors = browser.severe_errors(d)
        if errors:
            fail(f"console errors in the page: {errors[:3]}")
        print("no console errors")
    finally:
        d.quit()
    out, err = run.communicate(timeout=60)
    if run.returncode != 0:
        fail(f"lash monitor exited {run.returncode}: {err[-1000:]}")
print("PASS")
