"""The master runs unchanged against another implementation of the slave (docs/method.md §B5,
thesis §2.7.4): a python-can (Debian python3-can, udp_multicast interface) node that
speaks config/hydraulic_bench.dbc through canmatrix — it answers the CCP CONNECT with the
recorded DTO read by python-can's CanutilsLogReader and sends sensor frames from its own
simple plant — while `lash hil master` holds a step reference on it. Runs in a private
network namespace (unshare -n).

The bench's frames are E2E-protected (CRC-8 SAE J1850 over the identifier and payload,
alive counters): this slave computes the CRC with its own bit-by-bit implementation
(checked against python3-crcmod and the catalogue check value), and checks the CRC and
counter of every command frame lash's master sends."""
import json
import math
import os
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "cli"))
import hil_netns  # noqa: E402

hil_netns.enter_private_netns()

import can  # noqa: E402
import canmatrix.formats  # noqa: E402

SRC = hil_netns.source_dir()
db = canmatrix.formats.loadp_flat(os.path.join(SRC, "config", "hydraulic_bench.dbc"))
CMD = db.frame_by_name("BenchCommand")
SEN = db.frame_by_name("BenchSensors")
CRO = db.frame_by_name("CCP_CRO")
DTO = db.frame_by_name("CCP_DTO")
recorded = [m for m in can.CanutilsLogReader(os.path.join(SRC, "config", "hil", "ccp_connect.log"))
            if m.arbitration_id == DTO.arbitration_id.id]
assert recorded, "no DTO in the recorded log"

T = 0.005


hil_netns.check_crc8_j1850()
e2e_crc = hil_netns.e2e_crc
CMD_CRC_BYTE = CMD.signal_by_name("Command_CRC").start_bit // 8
SEN_CRC_BYTE = SEN.signal_by_name("Sensor_CRC").start_bit // 8


class Plant:
    """Its own simple pilot-valve model: deadzone 288 mA, 2.15 kPa/mA, first-order 0.07 s
    (exact exponential discretisation), 90.1 kPa bias, no noise."""

    def __init__(self):
        self.w = 0.0
        self.a = math.exp(-T / 0.07)

    def step(self, current_mA):
        z = max(current_mA - 288.0, 0.0)
        self.w = self.a * self.w + (1 - self.a) * 2.15 * z
        return 90.1 + self.w


stop = threading.Event()
stats = {"dto": 0, "sensors": 0, "commands": 0, "bad_crc": 0, "bad_counter": 0, "bad_dlc": 0}


def slave():
    try:  # a real-time slave where permitted (root): python's sleep jitter would look like lost frames
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(40))
    except (PermissionError, OSError):
        pass
    bus = can.Bus(interface="udp_multicast", channel="239.74.163.2", port=43113, receive_own_messages=False)
    plant = Plant()
    current = 0.0
    try:
        # Wait for the CONNECT (CRO command byte 0x01), answer with the recorded DTO.
        while not stop.is_set():
            msg = bus.recv(0.1)
            if msg is None or msg.arbitration_id != CRO.arbitration_id.id:
                continue
            if CRO.decode(msg.data)["CRO_CMD"].raw_value == 1:
                for d in recorded:
                    bus.send(can.Message(arbitration_id=d.arbitration_id, data=d.data, is_extended_id=False))
                stats["dto"] += 1
                break
        t_next = time.monotonic() + T / 2
        counter = 0
        last_ctr = None
        while not stop.is_set():
            delay = t_next - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            t_next += T
            while True:
                msg = bus.recv(0)
                if msg is None:
                    break
                if msg.arbitration_id == CMD.arbitration_id.id:
                    if len(msg.data) != CMD.size:
                        stats["bad_dlc"] += 1
                        continue
                    if e2e_crc(msg.arbitration_id, msg.data, CMD_CRC_BYTE) != msg.data[CMD_CRC_BYTE]:
                        stats["bad_crc"] += 1
                        continue
                    sig = CMD.decode(msg.data)
                    ctr = int(sig["Command_Counter"].raw_value)
                    if last_ctr is not None and ctr != (last_ctr + 1) % 256:
                        stats["bad_counter"] += 1
                    last_ctr = ctr
                    current = float(sig["SolenoidA_Current"].phys_value)
                    stats["commands"] += 1
            p = plant.step(current)
            duty = p / 48.82 + 5.98
            raw = min(max(round(duty * 65535 / 100), 0), 65535)  # sensor code, docs/method.md §B1
            # canmatrix's Frame.encode takes raw signal values and does the bit packing.
            data = bytearray(SEN.encode({"PilotPressure_Duty": raw, "SupplyPressure_Duty": 0,
                                         "Sensor_Counter": counter % 65536, "Sensor_CRC": 0}))
            data[SEN_CRC_BYTE] = e2e_crc(SEN.arbitration_id.id, data, SEN_CRC_BYTE)
            bus.send(can.Message(arbitration_id=SEN.arbitration_id.id, data=data, is_extended_id=False))
            counter += 1
            stats["sensors"] += 1
    finally:
        bus.shutdown()


def run_once(attempt):
    """One master run against the python-can slave; returns (master stats, settling [s], tail, before)."""
    stop.clear()
    for k in stats:
        stats[k] = 0
    th = threading.Thread(target=slave, daemon=True)
    th.start()
    time.sleep(0.5)
    r = subprocess.run([hil_netns.lash(), "hil", "master", "--bus", "udp:239.74.163.2:43113", "--duration", "3",
                        "--fifo", "50", "--reference", "step:from=500,to=1500,time=1", "--log", f"{out}/master.csv",
                        "--stats", f"{out}/master.json", "--bus-log", f"{out}/master_bus.log"],
                       capture_output=True, text=True, timeout=60)
    stop.set()
    th.join(2)
    print(r.stderr)
    assert r.returncode == 0, r.stderr
    assert stats["dto"] == 1 and stats["commands"] > 500, stats
    # Every command frame lash sent had the DBC's length and a CRC this independent
    # implementation agrees with, and its alive counter advanced by one each time.
    assert stats["bad_crc"] == 0 and stats["bad_dlc"] == 0 and stats["bad_counter"] == 0, stats
    with open(f"{out}/master.json") as f:
        ms = json.load(f)
    # ... and the master accepted this slave's frames (CRC, counter, range): no drop.
    print("master frames:", ms["frames"])
    assert ms["frames"]["dropped"] == 0 and ms["frames"]["accepted"] > 500, ms["frames"]
    assert [e["event"] for e in ms["events"]][:3] == ["ccp_connect_sent", "ccp_connected", "input_valid_running"], \
        ms["events"]
    m = hil_netns.read_csv(f"{out}/master.csv")
    rows = [i for i, cs in enumerate(m["control_step"]) if cs >= 0]
    t = [m["control_step"][i] * T for i in rows]
    y = [m["measured_kPa"][i] for i in rows]
    i_mA = [m["current_mA"][i] for i in rows]
    assert max(i_mA) <= 2000 and min(i_mA) >= 0
    # Settling into the 10 % band of the 500 -> 1500 kPa step (thesis simulation: 0.25 s).
    after = [(tt, yy) for tt, yy in zip(t, y) if tt >= 1.0]
    outside = [tt for tt, yy in after if abs(yy - 1500) > 100]
    settling = (max(outside) - 1.0) if outside else 0.0
    tail = [yy for tt, yy in after if tt >= 2.5]
    before = [yy for tt, yy in zip(t, y) if 0.7 <= tt < 1.0]
    late = ms["frames"]["late"] + ms["frames"]["lost"]
    # A stall of the python slave long enough for the master's staleness or sensor timeout puts the
    # master in its degraded or safe state (PI frozen or reset, current ramped or 0 mA): correct,
    # but the step response is then not the loop's own.
    safe = [e["event"] for e in ms["events"] if "safe_state" in e["event"] or "degraded" in e["event"]]
    print(f"attempt {attempt}: python-can slave: settling {settling:.3f} s, final mean {sum(tail) / len(tail):.1f} kPa, "
          f"{stats['sensors']} sensor frames sent, {late} late or lost at the master, degraded/safe episodes {safe}")
    return late, safe, settling, tail, before


out = tempfile.mkdtemp(prefix="lash_hil_py_")
# The loop's dynamics are lash's only while the python slave keeps its schedule: a sensor frame
# late at the master is a delay in the loop, and with the thesis's aggressive gains a few dozen
# of them (a python thread on a loaded host) stretch the settling. So the step-response figures
# are asserted on a run whose frames were on time (at most 1 % late, no degraded or safe-state episode);
# every run must pass the interoperability checks above. A host too busy for any such run is a
# skip, not a pass.
clean = None
for attempt in range(1, 4):
    late, safe, settling, tail, before = run_once(attempt)
    if late <= 6 and not safe:
        clean = (settling, tail, before)
        break
if clean is None:
    print("skip: every attempt had late sensor frames (python slave too slow on this host)")
    sys.exit(hil_netns.SKIP)
settling, tail, before = clean
# Settling within 0.5 s of the step and then staying in the band; steady state within 1 %.
assert settling <= 0.5, settling
assert abs(sum(tail) / len(tail) - 1500) < 15
assert abs(sum(before) / len(before) - 500) < 10
# The bus log is a candump -L log python-can can read, and it holds the handshake.
msgs = list(can.CanutilsLogReader(f"{out}/master_bus.log"))
assert msgs[0].arbitration_id == CRO.arbitration_id.id
assert any(mm.arbitration_id == DTO.arbitration_id.id for mm in msgs)
print("ok")
