"""Faults (issue 6 item 7), in a private network namespace:
- the slave is killed (SIGKILL) mid-run: the master enters its safe state (0 mA) within 3
  periods of the last sensor frame and logs the fault with its time; the slave is restarted: the master
  reconnects (CCP CONNECT answered again) and control resumes; the events log shows both;
- SIGINT/SIGTERM stop both nodes at a step boundary with complete logs and exit 0."""
import os
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(__file__))
import hil_netns  # noqa: E402

hil_netns.enter_private_netns()

LASH = hil_netns.lash()
BUS = "udp:239.74.163.2:43113"
out = tempfile.mkdtemp(prefix="lash_hil_fault_")


def start_slave(tag):
    p = subprocess.Popen([LASH, "hil", "slave", "--bus", BUS, "--fifo", "40", "--duration", "30",
                          "--log", f"{out}/slave_{tag}.csv", "--stats", f"{out}/slave_{tag}.json"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert "ready" in p.stdout.readline()
    return p


s1 = start_slave("a")
master = subprocess.Popen([LASH, "hil", "master", "--bus", BUS, "--fifo", "50", "--duration", "5",
                           "--reference", "step:from=500,to=1500,time=0.5", "--log", f"{out}/master.csv",
                           "--events", f"{out}/events.csv", "--stats", f"{out}/master.json"],
                          stderr=subprocess.PIPE, text=True)
time.sleep(1.5)
s1.send_signal(signal.SIGKILL)
s1.wait()
time.sleep(0.7)
s2 = start_slave("b")
_, err = master.communicate(timeout=30)
print(err)
assert master.returncode == 0, err
s2.send_signal(signal.SIGTERM)
_, s2err = s2.communicate(timeout=10)
assert s2.returncode == 0, s2err

m = hil_netns.read_csv(f"{out}/master.csv")
with open(f"{out}/events.csv") as f:
    events = [line.strip().split(",") for line in f.readlines()[1:]]
kinds = [e[2] for e in events]
print(events)
assert kinds[:2] == ["ccp_connect_sent", "ccp_connected"], kinds
assert "sensor_timeout_safe_state" in kinds and "input_resumed" in kinds, kinds
# The kill is the longest fault (a busy machine may add short ones: each is logged too).
steps = [int(v) for v in m["step"]]
# A fault never resumed lasts to the end of the run.
faults = [(int(e[0]), next((int(r[0]) for r in events[i:] if r[2] == "input_resumed"), steps[-1] + 1))
          for i, e in enumerate(events) if e[2] == "sensor_timeout_safe_state"]
fault_step, resume_step = max(faults, key=lambda f: f[1] - f[0])
row = {s: i for i, s in enumerate(steps)}
# The property (issue 17): the master enters the safe state within 3 periods of the last fresh
# sensor frame, logs the fault at that very step, and commands 0 mA from that step until the
# sensor resumes -- whatever the controller commanded before (a saturated PID may already sit at 0 mA).
# States (nodes.hpp, docs/hil.md): 0 startup, 1 connected, 2 running, 3 degraded, 4 safe, 5 failed.
RUNNING, SAFE = 2, 4
last_fresh = max(s for s in steps if s < fault_step and m["sensor_fresh"][row[s]] == 1)
safe_from = min(s for s in steps if s > last_fresh and m["state"][row[s]] == SAFE)
print(f"last sensor frame at step {last_fresh}, safe state from step {safe_from}, fault logged at step "
      f"{fault_step}, resumed at step {resume_step}")
assert safe_from - last_fresh <= 3, (last_fresh, safe_from)
assert fault_step == safe_from, (fault_step, safe_from)
assert all(m["state"][row[s]] == RUNNING for s in steps if last_fresh <= s < safe_from), "running until the timeout"
# Safe state held until the restarted slave answers (its counter restarts at 0: re-synchronised,
# then 5 good frames in a row); then control resumes and tracks again.
for s in range(safe_from, resume_step):
    assert m["current_mA"][row[s]] == 0.0 and m["state"][row[s]] == SAFE, s
assert m["state"][row[resume_step]] == RUNNING
assert (resume_step - fault_step) * 0.005 >= 0.6  # the slave was down for 0.7 s
# Tracking is scored on the steps that lie 200 steps (1 s) or more after the latest resume and
# before any later fault: a short fault a host stall adds (logged, above) drops the valve to 0 mA
# too, and its own recovery is left out the same way the kill's is, not averaged in.


def settled(s):
    return s >= resume_step + 200 and not any(f <= s < r + 200 for f, r in faults)


tail = [m["measured_kPa"][i] for i, s in enumerate(steps) if settled(s)]
print(f"{len(faults)} fault(s) {faults}; tail of {len(tail)} settled steps")
assert len(tail) > 50 and abs(sum(tail) / len(tail) - 1500) < 15, sum(tail) / len(tail)

# SIGINT to both nodes: they stop at a step boundary, write whole logs and exit 0.
s3 = start_slave("c")
m2 = subprocess.Popen([LASH, "hil", "master", "--bus", BUS, "--duration", "60", "--log", f"{out}/m2.csv",
                       "--bus-log", f"{out}/m2.log", "--stats", f"{out}/m2.json"], stderr=subprocess.PIPE, text=True)
time.sleep(1.0)
m2.send_signal(signal.SIGINT)
s3.send_signal(signal.SIGINT)
_, e2 = m2.communicate(timeout=10)
_, e3 = s3.communicate(timeout=10)
assert m2.returncode == 0 and s3.returncode == 0, (e2, e3)
for path in (f"{out}/m2.csv", f"{out}/slave_c.csv", f"{out}/m2.log"):
    text = open(path).read()
    assert text.endswith("\n"), path
    lines = text.splitlines()
    width = len(lines[0].split(",")) if path.endswith(".csv") else 3
    assert all(len(line.split(",") if path.endswith(".csv") else line.split(" ")) == width for line in lines), path
    print(path, len(lines), "lines, complete")
assert 100 < len(open(f"{out}/m2.csv").read().splitlines()) < 400
print("ok")
