"""Bounded memory of the HIL nodes and of `lash hil simulate` (issue 29 item 1): the nodes stream
their logs to disk (docs/hil.md, "Logs that survive the node"), so their peak resident set does
not grow with the duration.
- `lash hil run --step-ms 1`: each node's peak RSS (getrusage ru_maxrss of the node process,
  handed over in report.json) at --duration 60 within 2x of --duration 2 (before the logs were
  streamed, 60 000 steps added about 40 MB per node: 2.8x); and the session's own
  (report.json session_peak_rss_kB, its getrusage after the report) within 1.5x: the report is
  computed by streaming over the logs (before, reading them back took ~0.5 kB a control step);
- `lash hil simulate --duration 10000` (2e6 steps, a 120 MB CSV) vs --duration 10: the peak RSS
  of the simulate process (resource.getrusage of the waited child) within 1.5x and under 64 MB,
  and the CSV has every row; the same for `hil simulate --scenario` at 4000 s against 40 s."""
import json
import os
import resource
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(__file__))
import hil_netns  # noqa: E402

LASH = hil_netns.lash()


def child_peak_kB(cmd):
    """Runs cmd in a fresh child of a fresh python (so that RUSAGE_CHILDREN is this child alone)."""
    code = ("import resource, subprocess, sys; r = subprocess.run(sys.argv[1:], capture_output=True, text=True); "
            "sys.stderr.write(r.stderr); sys.stdout.write(r.stdout); "
            "print('PEAK_KB', resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss); sys.exit(r.returncode)")
    r = subprocess.run([sys.executable, "-c", code, *cmd], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    peak = int(r.stdout.strip().splitlines()[-1].split()[1])
    return peak, r.stdout


# --- hil simulate: memory independent of the duration.
d = tempfile.mkdtemp(prefix="lash_hil_memory_")
sims = {}
for dur in (10, 10000):
    out = os.path.join(d, f"sim{dur}.csv")
    peak, _ = child_peak_kB([LASH, "hil", "simulate", "--duration", str(dur), "-o", out])
    with open(out, "rb") as f:
        n = sum(1 for _ in f) - 1
    assert n == round(dur / 0.005), (dur, n)
    sims[dur] = peak
    print(f"hil simulate --duration {dur}: {n} rows, peak RSS {peak} kB")
    os.remove(out)
assert sims[10000] <= 1.5 * sims[10], sims
assert sims[10000] < 64 * 1024, sims

# --- hil simulate --scenario: the tracking figures are accumulated as the rows come (before, the
# runner kept every row for them: 279 MB at 4000 s against 19 MB at 40 s).
scen = os.path.join(os.environ.get("LASH_SOURCE_DIR", "."), "config", "scenarios", "closed_loop",
                    "valve_deadzone_drift.toml")
speaks = {}
for dur in (40, 4000):
    out = os.path.join(d, f"scen{dur}.csv")
    peak, text = child_peak_kB([LASH, "hil", "simulate", "--scenario", scen, "--duration", str(dur), "-o", out])
    assert "rms" in text.lower(), text
    speaks[dur] = peak
    print(f"hil simulate --scenario valve_deadzone_drift --duration {dur}: peak RSS {peak} kB")
    os.remove(out)
assert speaks[4000] <= 1.5 * speaks[40], speaks

# --- hil run: each node's peak RSS at 60 s within 2x of 2 s.
if os.geteuid() != 0 and subprocess.run(["unshare", "-rn", "true"], capture_output=True).returncode != 0:
    print("skip (hil run part): no root and no user namespaces: lash hil run cannot isolate its bus")
    sys.exit(0)
peaks = {}
for dur in (2, 60):
    out = os.path.join(d, f"run{dur}")
    r = subprocess.run([LASH, "hil", "run", "--json", "--step-ms", "1", "--duration", str(dur), "--out-dir", out],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    rep = json.loads(r.stdout)
    peaks[dur] = {n: rep[n]["peak_rss_kB"] for n in ("master", "slave")}
    peaks[dur]["session"] = rep["session_peak_rss_kB"]
    rows = {n: rep[n]["logs"]["rows"] for n in ("master", "slave")}
    print(f"hil run --step-ms 1 --duration {dur}: peak RSS [kB] {peaks[dur]}, log rows {rows}, "
          f"ring full {[rep[n]['logs']['ring_full'] for n in ('master', 'slave')]}")
    assert rows["master"] >= dur * 1000, rows
for n in ("master", "slave"):
    assert 0 < peaks[60][n] <= 2 * peaks[2][n], (n, peaks)
assert 0 < peaks[60]["session"] <= 1.5 * peaks[2]["session"], peaks
print("ok")
