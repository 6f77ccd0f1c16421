"""`lash hil run` as a supervisor (issue 15 items 3, 4):
- SIGTERM to the parent: both nodes stop, report.json is written whole and marked
  "interrupted": true, no lash process is left and the private network namespace is gone;
  stale files of an earlier run never sit beside the new logs;
- master_bus.log holds wall-clock timestamps (sent and received frames) inside the run's
  wall-clock interval (received frames used to get the epoch twice, about 3.5e9 s);
- kill -9 of the slave: without --restart-slave the run ends at once with exit 1 and a report
  naming the signal; with --restart-slave the watchdog starts a new slave, control resumes,
  the report gives the gap and the run exits 0."""
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


def procs():
    """pid -> (ppid, argv, net namespace) of every process we can see."""
    out = {}
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            argv = open(f"/proc/{d}/cmdline", "rb").read().split(b"\0")
            ppid = int(open(f"/proc/{d}/stat").read().rsplit(")", 1)[1].split()[1])
            ns = os.readlink(f"/proc/{d}/ns/net")
        except OSError:
            continue
        out[int(d)] = (ppid, [a.decode(errors="replace") for a in argv if a], ns)
    return out


def nodes_of(parent):
    return {pid: argv for pid, (ppid, argv, _) in procs().items() if ppid == parent}


def wait_nodes(parent, n, timeout=10):
    end = time.time() + timeout
    while time.time() < end:
        kids = nodes_of(parent)
        if len(kids) >= n:
            return kids
        time.sleep(0.05)
    raise AssertionError(f"expected {n} node processes, saw {nodes_of(parent)}")


def run(args, out):
    return subprocess.Popen([LASH, "hil", "run", "--json", "--fifo", "50", "--out-dir", out, *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


# --- SIGTERM to the parent, with stale files of an "earlier run" in the output directory.
out = tempfile.mkdtemp(prefix="lash_hil_session_")
for name in ("report.json", "master.csv", "slave.2.csv"):
    with open(os.path.join(out, name), "w") as f:
        f.write('{"stale": true}\n')
wall0 = time.time()
p = run(["--duration", "8"], out)
kids = wait_nodes(p.pid, 2)
ns = procs()[p.pid][2]
time.sleep(1.0)
# The run's own files only: the stale ones are gone before any node writes (the nodes stream
# master.csv and slave.csv from their first step: what is there now is this run's).
for n in ("report.json", "master.csv", "slave.2.csv"):
    path = os.path.join(out, n)
    assert not os.path.exists(path) or "stale" not in open(path).read(), (n, os.listdir(out))
assert not os.path.exists(os.path.join(out, "report.json")) and not os.path.exists(os.path.join(out, "slave.2.csv"))
t_kill = time.time()
p.send_signal(signal.SIGTERM)
stdout, stderr = p.communicate(timeout=15)
wall1 = time.time()
print(stderr)
assert p.returncode == 128 + signal.SIGTERM, (p.returncode, stderr)
assert wall1 - t_kill < 5, wall1 - t_kill
rep = json.load(open(os.path.join(out, "report.json")))
assert rep == json.loads(stdout), "stdout and report.json differ"
assert rep["interrupted"] is True and rep["interrupt_signal"] == signal.SIGTERM, rep
assert "stale" not in rep
# Both nodes stopped at a step boundary and handed complete logs over: about 1.3 s of control.
m = hil_netns.read_csv(os.path.join(out, "master.csv"))
assert 100 < rep["master"]["control_steps"] < 1600, rep["master"]["control_steps"]
assert len(m["step"]) == rep["master"]["steps"], (len(m["step"]), rep["master"]["steps"])
assert rep["master_exit"]["status"] == 0 and all(e["status"] == 0 for e in rep["slave_exits"]), rep
left = [pid for pid in kids if pid in procs()]
assert not left, f"node processes left: {left}"
in_ns = [pid for pid, (_, _, n) in procs().items() if n == ns]
assert not in_ns, f"processes still in the run's network namespace: {in_ns}"
print(f"SIGTERM: interrupted report after {rep['master']['control_steps']} control steps, "
      f"stopped in {wall1 - t_kill:.2f} s, no process or namespace left")

# --- Bus log timestamps: wall clock, inside the run.
stamps = []
for line in open(os.path.join(out, "master_bus.log")):
    stamps.append((float(line.split()[0].strip("()")), "#" in line))
assert len(stamps) > 200, len(stamps)
lo_, hi_ = min(s for s, _ in stamps), max(s for s, _ in stamps)
print(f"master_bus.log: {len(stamps)} frames from {lo_:.3f} to {hi_:.3f} s; run {wall0:.3f} .. {wall1:.3f} s")
assert wall0 - 0.5 <= lo_ and hi_ <= wall1 + 0.5, (lo_, hi_, wall0, wall1)

# --- kill -9 of the slave, no watchdog: the run ends now, exit 1, the report names the signal.
out2 = tempfile.mkdtemp(prefix="lash_hil_session_")
p = run(["--duration", "8"], out2)
kids = wait_nodes(p.pid, 2)
time.sleep(1.0)
slave = next(pid for pid, argv in kids.items() if hil_netns.node_role(argv) == "slave")
t_kill = time.time()
os.kill(slave, signal.SIGKILL)
stdout, stderr = p.communicate(timeout=15)
print(stderr)
assert p.returncode == 1, (p.returncode, stderr)
assert time.time() - t_kill < 5
rep = json.loads(stdout)
assert rep["slave_exits"][0]["signal"] == signal.SIGKILL and rep["slave_exits"][0]["status"] == 128 + 9, rep
assert rep["slave_restarts"][0]["restarted_s"] == -1, rep["slave_restarts"]
assert rep["master"]["control_steps"] < 1600
print("kill -9 without watchdog: exit 1, slave death reported at t =", rep["slave_exits"][0]["t_s"], "s")

# --- kill -9 of the slave with the watchdog: a new slave, control resumes, the gap is reported.
out3 = tempfile.mkdtemp(prefix="lash_hil_session_")
p = run(["--duration", "4", "--restart-slave", "--reference", "step:from=500,to=1500,time=0.5"], out3)
kids = wait_nodes(p.pid, 2)
time.sleep(1.5)
slave = next(pid for pid, argv in kids.items() if hil_netns.node_role(argv) == "slave")
os.kill(slave, signal.SIGKILL)
stdout, stderr = p.communicate(timeout=30)
print(stderr)
assert p.returncode == 0, (p.returncode, stderr)
rep = json.loads(stdout)
gap = rep["slave_restarts"][0]
assert gap["died"]["signal"] == signal.SIGKILL and 0 < gap["gap_s"] < 2, gap
assert len(rep["slave_exits"]) == 2 and rep["slave_exits"][1]["status"] == 0, rep["slave_exits"]
events = [e["event"] for e in rep["master"]["events"]]
assert "sensor_timeout_safe_state" in events and events[-1] == "input_resumed", events
last = rep["master"]["events"][-1]
assert (last["from"], last["to"]) == ("safe", "running") and rep["master"]["state"] == "running", (last, rep["master"])
assert rep["master"]["control_steps"] == 800
m = hil_netns.read_csv(os.path.join(out3, "master.csv"))
resumed = max(e["step"] for e in rep["master"]["events"] if e["event"] == "input_resumed")
tail = [y for s, y in zip(m["step"], m["measured_kPa"]) if s >= resumed + 200]
assert len(tail) > 50 and abs(sum(tail) / len(tail) - 1500) < 15, sum(tail) / len(tail)
assert os.path.exists(os.path.join(out3, "slave.2.csv"))
# The restarted slave writes its safe-state events next to its log.
with open(os.path.join(out3, "slave.2.events.csv")) as f:
    assert f.readline().strip() == "step,t_s,event,from,to"
print(f"watchdog: slave restarted after {gap['gap_s']:.3f} s; tracking 1500 kPa again "
      f"(mean {sum(tail) / len(tail):.1f} kPa)")
print("ok")
