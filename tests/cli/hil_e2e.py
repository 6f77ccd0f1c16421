"""Plausibility checks and the safe-state machine under fault injection (issue 15, items 1-2),
in a private network namespace. A python-can node on the bench's bus:

A. forges command frames (id 0x100) for 1.5 s while slave and master run: values outside the
   DBC range (6143 mA, as in the issue) with a right CRC and the next counter, right CRCs with a
   repeated or jumped counter, wrong CRCs -- one right after each real command frame. The slave's current stays within 0-2000 mA at every
   step of slave.csv, the drops are counted per reason, and the slave degrades (ramps to 0 mA),
   reaches the safe state and resumes after the forging ends; its events say so.
B. floods the sensor id (0x200) for 3 s with garbage payloads and wrong DLCs. The master drops
   and counts them, its integrator does not move (frozen) while degraded or safe, the
   degraded/safe/resumed events are logged, and 0.5 s after the flood ends the measured
   pressure is within 10 % of the 1500 kPa reference again.

The CRC the forger computes is its own bit-by-bit CRC-8 SAE J1850 (checked against
python3-crcmod), never lash's."""
import json
import os
import random
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(__file__))
import hil_netns  # noqa: E402

hil_netns.enter_private_netns()
import can  # noqa: E402

LASH = hil_netns.lash()
BUS = "udp:239.74.163.2:43113"
T = 0.005
RUNNING, DEGRADED, SAFE = 2, 3, 4  # the state column (nodes.hpp, docs/hil.md)
out = tempfile.mkdtemp(prefix="lash_hil_e2e_")


hil_netns.check_crc8_j1850()


def command(mA_raw, counter, crc_ok=True):
    """BenchCommand by hand (config/hydraulic_bench.dbc): SolenoidA 0|16 (0.1 mA), B 16|16,
    restrictor 32|16, counter 48|8, CRC 56|8 over 00 01 + bytes 0-6."""
    body = bytes([mA_raw & 0xFF, mA_raw >> 8, 0, 0, 0, 0, counter & 0xFF])
    crc = hil_netns.e2e_crc(0x100, body + b"\x00", 7)
    return body + bytes([crc if crc_ok else crc ^ 0xA5])


def start_slave():
    p = subprocess.Popen([LASH, "hil", "slave", "--bus", BUS, "--fifo", "40", "--duration", "30",
                          "--log", f"{out}/slave.csv", "--stats", f"{out}/slave.json"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert "ready" in p.stdout.readline()
    return p


def run_master(duration, reference, tag):
    return subprocess.Popen([LASH, "hil", "master", "--bus", BUS, "--fifo", "50", "--duration", str(duration),
                             "--reference", reference, "--log", f"{out}/master_{tag}.csv",
                             "--events", f"{out}/events_{tag}.csv", "--stats", f"{out}/master_{tag}.json"],
                            stderr=subprocess.PIPE, text=True)


def stop_slave(p):
    p.terminate()
    _, err = p.communicate(timeout=10)
    assert p.returncode == 0, err


# ------------------------------------------------------------------------------- A: forged commands
slave = start_slave()
master = run_master(4, "constant:amplitude=1000", "a")
bus = can.Bus(interface="udp_multicast", channel="239.74.163.2", port=43113, receive_own_messages=False)
time.sleep(1.0)
last = [None]
forged = {}
kinds = {"range": 0, "crc": 0, "repeated": 0, "jump": 0}
t_end = time.monotonic() + 1.5
rng = random.Random(15)
while time.monotonic() < t_end:
    msg = bus.recv(0.01)  # sniff the master's counter; one forged frame after each real one
    if msg is None or msg.arbitration_id != 0x100 or len(msg.data) != 8:
        continue
    if bytes(msg.data) in forged:  # our own frame, looped back on the namespace's lo
        forged[bytes(msg.data)] -= 1
        if forged[bytes(msg.data)] == 0:
            del forged[bytes(msg.data)]
        continue
    last[0] = msg.data[6]
    k = rng.choice(list(kinds))
    if k == "range":
        data = command(61430, last[0] + 1)                  # 6143 mA, right CRC, next counter
    elif k == "crc":
        data = command(15000, last[0] + 1, crc_ok=False)    # 1500 mA, CRC wrong
    elif k == "repeated":
        data = command(19990, last[0])                      # in range, counter already used
    else:
        data = command(19990, last[0] + 100)                # in range, counter far ahead
    kinds[k] += 1
    forged[data] = forged.get(data, 0) + 1
    bus.send(can.Message(arbitration_id=0x100, data=data, is_extended_id=False))
forge_end = time.monotonic()
_, err = master.communicate(timeout=30)
assert master.returncode == 0, err
bus.shutdown()
stop_slave(slave)

s = hil_netns.read_csv(f"{out}/slave.csv")
sj = json.load(open(f"{out}/slave.json"))
f = sj["frames"]
print("forged:", kinds, "slave frames:", f)
assert all(0.0 <= i <= 2000.0 for i in s["current_mA"]), (min(s["current_mA"]), max(s["current_mA"]))
by = f["dropped_by_reason"]
assert by["range"] >= 0.8 * kinds["range"] and by["crc"] >= 0.8 * kinds["crc"], (by, kinds)
assert by["wrong_sequence"] >= 0.8 * kinds["jump"] and by["repeated_counter"] >= 1, (by, kinds)
assert f["dropped"] == sum(by.values()) and f["dropped"] == sum(s["dropped"]), f
ev = [e["event"] for e in sj["events"]]
print("slave events:", ev[:8], "...")
assert ev[:2] == ["ccp_connected", "input_valid_running"] and "input_implausible_degraded" in ev, ev
i_deg = ev.index("input_implausible_degraded")
assert "input_resumed" in ev[i_deg:] or "input_recovered" in ev[i_deg:], ev
# The ramp: from the step the slave degraded, the current falls by 20 mA per step (4000 mA/s) at most.
row = {int(st): k for k, st in enumerate(s["step"])}
k0 = row[sj["events"][i_deg]["step"]]
for k in range(k0, len(s["step"])):
    if s["state"][k] not in (DEGRADED, SAFE):
        break
    assert s["current_mA"][k] >= s["current_mA"][k - 1] - 20.0 - 1e-9, k
    assert s["current_mA"][k] <= s["current_mA"][k - 1] + 1e-9, k
    if s["state"][k] == SAFE:
        assert s["current_mA"][k] == 0.0, k
# The forged values never reached the valve: while running the slave applied exactly what the
# master commanded one step earlier (quantised to 0.1 mA): ~1000 mA here, never 1999 or 6143 mA.
m = hil_netns.read_csv(f"{out}/master_a.csv")
assert max(i for i, st in zip(s["current_mA"], s["state"]) if st == RUNNING) <= max(m["current_mA"]) + 0.05
assert s["state"][-1] == RUNNING or "input_stale_degraded" in ev  # back to running, or stale after the master ended

# ------------------------------------------------------------------------------- B: garbage sensors


def flood(attempt):
    """One run of B. Every check of the master's handling of the flood holds on every run; returns
    the rows of the recovery window and the degraded/safe events after the resume (a host stall that
    starves the master of sensor frames for 5 periods is a fault the test did not cause)."""
    slave = start_slave()
    master = run_master(7, "step:from=500,to=1500,time=0.5", "b")
    bus = can.Bus(interface="udp_multicast", channel="239.74.163.2", port=43113, receive_own_messages=False)
    time.sleep(2.0)
    n_flood = 0
    t_end = time.monotonic() + 3.0
    while time.monotonic() < t_end:
        dlc = rng.choice([8, 8, 8, 3, 6, 7, 0, 1])
        bus.send(can.Message(arbitration_id=0x200, data=bytes(rng.randrange(256) for _ in range(dlc)),
                             is_extended_id=False))
        n_flood += 1
        time.sleep(0.001)
    bus.shutdown()
    _, err = master.communicate(timeout=30)
    assert master.returncode == 0, err
    stop_slave(slave)

    m = hil_netns.read_csv(f"{out}/master_b.csv")
    mj = json.load(open(f"{out}/master_b.json"))
    f = mj["frames"]
    print(f"attempt {attempt}: flood: {n_flood} garbage frames; master frames: {f}")
    by = f["dropped_by_reason"]
    assert by["dlc"] > 0.5 * n_flood * 5 / 8 and by["crc"] > 0.5 * n_flood * 3 / 8, (by, n_flood)
    assert f["dropped"] == sum(m["dropped"]), f
    ev = [(e["step"], e["event"]) for e in mj["events"]]
    print("master events:", ev)
    names = [e for _, e in ev]
    assert "input_implausible_degraded" in names, names
    i_deg = names.index("input_implausible_degraded")
    assert "ramp_done_safe_state" in names[i_deg:] or "sensor_timeout_safe_state" in names[i_deg:], names
    rec = [k for k, (_, e) in enumerate(ev) if k > i_deg and e in ("input_resumed", "input_recovered")]
    assert rec, names
    steps = [int(v) for v in m["step"]]
    row = {st: k for k, st in enumerate(steps)}
    flood_rows = [k for k, d in enumerate(m["dropped"]) if d > 0]
    first_bad, last_bad = flood_rows[0], flood_rows[-1]
    print(f"garbage seen from step {steps[first_bad]} to {steps[last_bad]} ({(last_bad - first_bad) * T:.2f} s)")
    assert (last_bad - first_bad) * T > 2.5
    # No windup: in every degraded or safe step the integrator keeps the value it had (frozen), and
    # the master spends the flood in those states (a host stall of the python node longer than
    # 5 good periods may let it recover for a moment: then it runs on plausible frames, legitimately).
    held = [k for k in range(first_bad, last_bad + 1) if m["state"][k] in (DEGRADED, SAFE)]
    assert len(held) >= 0.9 * (last_bad - first_bad + 1), (len(held), last_bad - first_bad + 1)
    for k in held:
        assert m["integrator_mA"][k] == m["integrator_mA"][k - 1], (k, m["integrator_mA"][k - 1], m["integrator_mA"][k])
    after = [k for k in rec if ev[k][0] > steps[last_bad]]  # the first resume after the flood (a later
    assert after, (ev, steps[last_bad])                       # host stall may add another fault + resume)
    resume_row = row[ev[after[0]][0]]
    print(f"resumed at step {steps[resume_row]}, {resume_row - last_bad} steps after the last garbage frame")
    assert 0 < resume_row - last_bad <= 20, (resume_row, last_bad)  # 5 good frames (+ a few late ones)
    window = range(last_bad + 100, min(last_bad + 200, len(steps)))
    assert len(window) >= 90, len(window)
    late_faults = [(st, e) for st, e in ev[after[0] + 1:]
                   if ("degraded" in e or "safe_state" in e) and st <= steps[window[-1]]]
    return m, window, late_faults


# Tracking is back 0.5 s after the flood ends: within 10 % of the reference over the next 0.5 s.
# That figure is lash's only on a run where nothing but the flood faulted the loop: a host stall
# after the resume (sensor timeout -> safe state -> PI reset) is a second fault, not a slow
# recovery. So the figure is asserted on a run without a degraded or safe-state episode after the
# resume (up to three runs); a host too busy for any such run is a skip, not a pass.
for attempt in range(1, 4):
    m, window, late_faults = flood(attempt)
    if not late_faults:
        break
    print(f"attempt {attempt}: a fault the test did not cause after the resume: {late_faults}")
else:
    print("skip: every run had a fault from a host stall between the resume and the end of the window")
    sys.exit(hil_netns.SKIP)
worst = max(abs(m["measured_kPa"][k] - m["reference_kPa"][k]) / m["reference_kPa"][k] for k in window)
print(f"0.5-1.0 s after the flood: max |y - r| / r = {100 * worst:.1f} %")
assert worst <= 0.10, worst
assert all(m["state"][k] == RUNNING for k in window)
print("ok")
