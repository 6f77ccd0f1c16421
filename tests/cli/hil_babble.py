"""A babbling node flooding the bus with unrelated frames must not make the master miss
deadlines (issue 6 item 7): slave + master run while a python-can node sends id 0x050
frames as fast as it can; the master's filters drop them, it keeps every deadline and
keeps tracking. In a private network namespace."""
import json
import os
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
out = tempfile.mkdtemp(prefix="lash_hil_babble_")
stop = threading.Event()
sent = [0]


def babble():
    bus = can.Bus(interface="udp_multicast", channel="239.74.163.2", port=43113)
    msg = can.Message(arbitration_id=0x050, data=bytes(range(8)), is_extended_id=False)
    while not stop.is_set():
        bus.send(msg)
        sent[0] += 1
    bus.shutdown()


def attempt(n):
    """One babble run; checks what holds on every run and returns the largest cycle [us]."""
    sent[0] = 0
    stop.clear()
    slave = subprocess.Popen([LASH, "hil", "slave", "--bus", BUS, "--fifo", "40", "--duration", "30",
                              "--log", f"{out}/slave.csv", "--stats", f"{out}/slave.json"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert "ready" in slave.stdout.readline()
    th = threading.Thread(target=babble, daemon=True)
    th.start()
    time.sleep(0.3)
    r = subprocess.run([LASH, "hil", "master", "--bus", BUS, "--fifo", "50", "--duration", "3",
                        "--reference", "step:from=500,to=1500,time=1", "--log", f"{out}/master.csv",
                        "--stats", f"{out}/master.json"], capture_output=True, text=True, timeout=60)
    stop.set()
    th.join(2)
    slave.terminate()
    slave.communicate(timeout=10)
    assert r.returncode == 0, r.stderr
    j = json.load(open(f"{out}/master.json"))
    print(f"attempt {n}: babbler sent {sent[0]} frames; master filtered {j['frames']['bus_filtered']}, overruns "
          f"{j['overruns']}, TET mean {j['tet_us']['mean']:.1f} us max {j['tet_us']['max']:.1f} us, CAN I/O mean "
          f"{j['io_us']['mean']:.1f} us max {j['io_us']['max']:.1f} us (reads {j['can_controller']['rx_reads']}, "
          f"pulls cut at the 1 ms budget {j['can_controller']['pulls_cut']}), sensor frames late {j['frames']['late']} "
          f"lost {j['frames']['lost']}, wake-up latency max {j['wake_latency_us']['max']:.0f} us")
    assert sent[0] > 3000 and j["frames"]["bus_filtered"] > 1000, (sent[0], j["frames"])
    m = hil_netns.read_csv(f"{out}/master.csv")
    cycle = [t + i for t, i in zip(m["tet_us"], m["io_us"])]
    # A step overruns when wake-up latency + cycle > 5 ms. An overrun on a step whose own cycle
    # stayed inside half the step can only come from a wake-up stall of the host (> 2.5 ms).
    row = {int(st): k for k, st in enumerate(m["step"])}
    for ev in j["overrun_events"]:
        k = row[int(ev["step"])]
        assert cycle[k] >= 2500 or m["wake_latency_us"][k] > 2500 - 1e-6, (ev, m["wake_latency_us"][k], cycle[k])
    # A flood can fill the UDP receive buffer, so the kernel may drop sensor frames too (on a real
    # CAN bus an id-0x050 babbler would even win arbitration). Such losses are counted, never
    # absorbed, and no frame of the real slave failed the plausibility check (DLC, CRC, range,
    # counter). The log's row of a step shows the newest sensor frame accepted in it (fresh); a
    # frame accepted in the same step as a newer one is counted late. So every accepted frame is a
    # fresh row or a late one, and every counter value from the first fresh row to the last was
    # accepted or counted lost -- except the late frames of the first fresh step, which precede its
    # counter (the slave's frames queued while the master connected): 0 <= those <= late.
    seen = [int(c) for c, fr in zip(m["sensor_seq"], m["sensor_fresh"]) if fr == 1]
    f = j["frames"]
    assert f["dropped"] == 0 and f["received"] == f["accepted"], f
    assert f["accepted"] == len(seen) + f["late"], (f, len(seen))
    span = seen[-1] - seen[0] + 1
    assert f["resyncs"] == 0 and 0 <= f["accepted"] + f["lost"] - span <= f["late"], (f, seen[0], seen[-1])
    return max(cycle), j


# The babbler must not make the master miss deadlines: every step's cycle (CAN I/O + TET) stays
# far inside the 5 ms step -- the reception is bounded by its time budget (a fifth of the step)
# plus one batch, so with every cycle < 2.5 ms no overrun is lash's. The wall-clock cycle also
# counts a host stall that preempts the node inside its I/O (a loaded 2-core CI host showed one
# 2.95 ms I/O with no pull cut at its budget); a stall does not repeat on the same steps, so the
# bound must hold on one of up to three runs, and everything else on every run.
worst = []
for n in range(1, 4):
    c, j = attempt(n)
    worst.append(c)
    if c < 2500:
        assert j["io_us"]["max"] < 2500 and j["tet_us"]["max"] < 2500, (j["io_us"], j["tet_us"])
        assert j["overruns"] == 0 or all(e["late_us"] > 0 for e in j["overrun_events"]), j["overrun_events"][:5]
        break
assert min(worst) < 2500, worst
print("ok")
