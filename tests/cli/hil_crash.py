"""kill -9 of a node during `lash hil run` (issue 29 item 2): the nodes stream their logs to disk
while they run (a writer thread fed by a lock-free ring, written out every 0.2 s), so a node
killed outright loses at most the last second:
- kill -9 of the master, and separately of the slave, about 3 s into a 10 s run;
- the run exits 1, its report names the signal and says what it recovered from the node's log
  (rows kept, last t), instead of "no master log";
- the killed node's CSV holds every step 0, 1, 2, … without a gap, up to at least 1 s before the
  kill (the node's wall-clock epoch is read from master_bus.log: the master's first sent frame
  for the master, the first sensor frame it received for the slave);
- `lash hil simulate --schedule` of what was kept reproduces the kept master rows exactly
  (measured pressure and current, compared here row by row with master.csv)."""
import csv
import json
import os
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(__file__))
import hil_netns  # noqa: E402

if os.geteuid() != 0 and subprocess.run(["unshare", "-rn", "true"], capture_output=True).returncode != 0:
    print("skip: no root and no user namespaces: lash hil run cannot isolate its bus")
    sys.exit(hil_netns.SKIP)

LASH = hil_netns.lash()


def children(parent):
    out = {}
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            argv = [a.decode() for a in open(f"/proc/{d}/cmdline", "rb").read().split(b"\0") if a]
            ppid = int(open(f"/proc/{d}/stat").read().rsplit(")", 1)[1].split()[1])
        except OSError:
            continue
        if ppid == parent:
            out[int(d)] = argv
    return out


def node_pid(parent, role, timeout=10):
    end = time.time() + timeout
    while time.time() < end:
        for pid, argv in children(parent).items():
            if hil_netns.node_role(argv) == role:
                return pid
        time.sleep(0.02)
    raise AssertionError(f"no {role} node under pid {parent}: {children(parent)}")


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def bus_log_times(path, frame_id, sent_only=None):
    """Wall-clock times of candump -L lines with this id."""
    out = []
    for line in open(path):
        parts = line.split()
        if len(parts) == 3 and parts[2].split("#")[0].upper() == frame_id:
            out.append(float(parts[0].strip("()")))
    return out


def check(victim):
    out = tempfile.mkdtemp(prefix=f"lash_hil_crash_{victim}_")
    p = subprocess.Popen([LASH, "hil", "run", "--json", "--duration", "10", "--out-dir", out],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    pid = node_pid(p.pid, victim)
    node_pid(p.pid, "master")
    time.sleep(3.0)
    t_kill = time.time()
    os.kill(pid, signal.SIGKILL)
    stdout, stderr = p.communicate(timeout=60)
    print(stderr)
    assert p.returncode == 1, (p.returncode, stderr)
    assert "handed nothing over" in stderr and "recovered" in stderr, stderr
    rep = json.loads(stdout)
    exit_ = rep["master_exit"] if victim == "master" else rep["slave_exits"][0]
    assert exit_["signal"] == 9 and exit_["status"] == 137, exit_

    csv_rows = rows(os.path.join(out, f"{victim}.csv"))
    rec = rep[victim]["recovered_from_log"]
    assert rec is not None and rec["rows"] == len(csv_rows) > 0, (rec, len(csv_rows))
    steps = [int(float(r["step"])) for r in csv_rows]
    assert steps == list(range(len(steps))), "the kept log has a gap"
    last_t = float(csv_rows[-1]["t_s"])
    assert abs(rec["last_t_s"] - last_t) < 1e-9, (rec, last_t)

    bus = os.path.join(out, "master_bus.log")
    if victim == "master":
        epoch = bus_log_times(bus, "7E0")[0]  # the first CRO: sent at step 0 (epoch + wake-up latency)
    else:
        epoch = bus_log_times(bus, "200")[0]  # the first sensor frame: sent at slave step 0
    lost_s = t_kill - (epoch + last_t)
    print(f"{victim}: killed at {t_kill - epoch:.3f} s of its loop; log kept {len(csv_rows)} rows up to "
          f"t = {last_t:.3f} s: lost the last {lost_s:.3f} s")
    assert last_t > 1.5, last_t
    assert lost_s <= 1.0, f"the log lost {lost_s:.3f} s before the kill (at most 1 s allowed)"

    # The session replayed the observed schedule of what was kept: 0 difference.
    assert rep["max_abs_diff_vs_observed_schedule_kPa"] == 0, rep.get("observed_schedule_note")
    assert rep["max_abs_diff_vs_observed_schedule_mA"] == 0

    # hil simulate --schedule of the kept logs reproduces the kept master rows.
    sim = os.path.join(out, "sim.csv")
    r = subprocess.run([LASH, "hil", "simulate", "--schedule", os.path.join(out, "master.csv"), "-o", sim],
                       capture_output=True, text=True, timeout=120)
    print(r.stdout, r.stderr)
    assert r.returncode == 0, r.stderr
    assert " 0 kPa, 0 mA over " in r.stdout, r.stdout
    master = [m for m in rows(os.path.join(out, "master.csv")) if int(float(m["control_step"])) >= 0]
    simulated = rows(sim)
    n = len(simulated)
    assert n > 300 and n >= min(len(master), 1) and n <= len(master), (n, len(master))
    if victim == "master":
        assert n == len(master), (n, len(master))  # every kept control step replayed
    for m, s in zip(master[:n], simulated):
        assert int(float(m["control_step"])) == int(float(s["control_step"]))
        assert float(m["measured_kPa"]) == float(s["measured_kPa"]), (m, s)
        assert float(m["current_mA"]) == float(s["current_mA"]), (m, s)
    print(f"{victim}: hil simulate --schedule reproduced {n} of {len(master)} kept control steps exactly")


check("master")
check("slave")
print("ok")
