#!/usr/bin/python3
"""The console's server memory over a long run (issue 27, "server memory flat over a 10-minute
run"; docs/console.md): `lash console demo` (32 synthetic signals at 1 kHz) with a headless
chromium (tests/cli/browser.py) showing the page the whole time, its window switched every minute
through 10 s, 1 min and 10 min (so every level of the decimator is read). Every --every seconds it
samples the server's VmRSS (/proc/PID/status) and the page's frames/s and data redraws/s
(window.lashStats).

Printed: one line per sample, then VmRSS first / after the warm-up / last / max [kB], the
least-squares slope after the warm-up [kB/min], the growth from the end of the warm-up to the end
[kB] against --max-growth-kb (exit 1 above it), the page's mean frames/s and redraws/s, and the
demo's own summary (samples, drops, requests).

usage: bench/console_memory.py [--lash build/bin/lash] [--minutes 10] [--every 10] [--warmup 60]
                               [--max-growth-kb 2048]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.path.join(HERE, "..")
sys.path.insert(0, os.path.join(SRC, "tests", "cli"))
ap = argparse.ArgumentParser()
ap.add_argument("--lash", default=os.path.join(SRC, "build", "bin", "lash"))
ap.add_argument("--minutes", type=float, default=10.0, help="length of the run [min]")
ap.add_argument("--every", type=float, default=10.0, help="sampling period of VmRSS [s]")
ap.add_argument("--warmup", type=float, default=60.0, help="samples before this are the warm-up [s]")
ap.add_argument("--max-growth-kb", type=int, default=2048, help="bound on VmRSS growth after the warm-up [kB]")
a = ap.parse_args()
import browser  # noqa: E402  (exits 77 without chromium / chromium-driver / python3-selenium)


def slope_per_min(ts, ys):
    n = len(ts)
    if n < 2:
        return 0.0
    mt, my = sum(ts) / n, sum(ys) / n
    sxx = sum((t - mt) ** 2 for t in ts)
    return 60.0 * sum((t - mt) * (y - my) for t, y in zip(ts, ys)) / sxx if sxx else 0.0


duration = a.minutes * 60.0
with tempfile.TemporaryDirectory() as tmp:
    run = subprocess.Popen([a.lash, "console", "demo", "--signals", "32", "--rate", "1000", "--duration",
                            str(duration + 15), "--console", "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           text=True)
    m = None
    while m is None:
        line = run.stderr.readline()
        if not line:
            sys.exit("no console URL printed")
        m = browser.lash_url(line)
    url = m[0]
    d = browser.chrome(os.path.join(tmp, "profile"))
    samples = []  # (t [s], VmRSS [kB], frames/s, redraws/s)
    try:
        d.get(url)
        t0 = time.time()
        windows = ["10", "60", "600"]
        last = d.execute_script("return Object.assign({}, window.lashStats)")
        t_last = time.time()
        k = 1
        while True:
            t_next = t0 + k * a.every
            if t_next > t0 + duration:
                break
            time.sleep(max(0.0, t_next - time.time()))
            el = time.time() - t0
            w = windows[int(el // 60) % len(windows)]
            s = d.execute_script("const w = document.getElementById('window');"
                                 f"if (w.value !== '{w}') {{ w.value = '{w}'; w.dispatchEvent(new Event('change')); }}"
                                 "return Object.assign({}, window.lashStats)")
            now = time.time()
            fps = (s["frames"] - last["frames"]) / (now - t_last)
            rdr = (s["draws"] - last["draws"]) / (now - t_last)
            last, t_last = s, now
            r = browser.rss_kb(run.pid)
            samples.append((el, r, fps, rdr))
            print(f"{el:6.0f} s  VmRSS {r:7d} kB  window {w:>3} s  page {fps:5.1f} frames/s {rdr:5.1f} redraws/s",
                  flush=True)
            k += 1
        errors = browser.severe_errors(d)
    finally:
        d.quit()
    run.terminate()
    out, _ = run.communicate(timeout=30)

ts = [s[0] for s in samples]
rs = [s[1] for s in samples]
warm = [s for s in samples if s[0] >= a.warmup] or samples
growth = warm[-1][1] - warm[0][1]
print(f"VmRSS [kB]: first {rs[0]} (at {ts[0]:.0f} s), after the warm-up {warm[0][1]} (at {warm[0][0]:.0f} s), "
      f"last {rs[-1]} (at {ts[-1]:.0f} s), max {max(rs)}")
print(f"slope after the warm-up: {slope_per_min([s[0] for s in warm], [s[1] for s in warm]):+.1f} kB/min; "
      f"growth after the warm-up {growth:+d} kB (bound {a.max_growth_kb} kB)")
print(f"page: mean {sum(s[2] for s in samples) / len(samples):.1f} frames/s, "
      f"{sum(s[3] for s in samples) / len(samples):.1f} data redraws/s; console errors: {len(errors)}")
print(out.strip())
print(json.dumps({"rss_first_kB": rs[0], "rss_warm_kB": warm[0][1], "rss_last_kB": rs[-1], "rss_max_kB": max(rs),
                  "growth_kB": growth}))
sys.exit(1 if growth > a.max_growth_kb or errors else 0)
