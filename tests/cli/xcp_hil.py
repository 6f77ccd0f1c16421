"""Must-show of issue 26 (XCP on CAN in the emulated master ECU), in a private network namespace:

1. `lash hil a2l` writes an A2L that passes a checker written here from the ASAP2 (ASAM MCD-2 MC)
   keyword structure: balanced /begin../end, the positional fields of every block used, the
   IF_DATA XCP parts (PROTOCOL_LAYER, DAQ, EVENT, XCP_ON_CAN).
2. During `lash hil run`, XCP at the byte level through python-can (frames written by hand from
   the ASAM MCD-1 XCP tables, not lash's client): commands before CONNECT get no answer, the
   CONNECT response, ERR_CMD_UNKNOWN, ERR_CMD_SYNTAX on a short frame, ERR_OUT_OF_RANGE for kp =
   200 (A2L limit 100) in a DOWNLOAD/DOWNLOAD_NEXT block, SYNCH → ERR_CMD_SYNCH.
3. `lash xcp set kp 0.7` mid-run: master.csv's kp column changes once, to 0.7, at the step
   master.events.csv logs; `get kp` reads 0.7; `hil simulate --schedule` equals the run (0 kPa).
4. `lash xcp daq` of 5 measurements: consecutive control steps (no sample missing) whose values
   equal master.csv's at the same control step.
5. Under `hil run --scenario valve_deadzone_drift.toml`: `lash xcp set compensation 0` (adaptive ->
   none) mid-run; 1.5 and 3 are refused (ERR_OUT_OF_RANGE); master.csv's compensation column
   changes once, at the step master.events.csv logs (2 -> 0); the run ends in mode none; and
   `hil simulate --schedule` with the scenario equals the run (0 kPa)."""
import csv
import json
import os
import re
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(__file__))
import hil_netns  # noqa: E402

hil_netns.enter_private_netns()
import can  # noqa: E402  (python3-can, after the re-exec)

LASH = hil_netns.lash()
GROUP, PORT = "239.74.163.2", 43113
BUS = f"udp:{GROUP}:{PORT}"
out = tempfile.mkdtemp(prefix="lash_xcp_")
a2l = os.path.join(out, "master.a2l")


def lash(*args, check=True):
    r = subprocess.run([LASH, *args], capture_output=True, text=True, timeout=60)
    if check:
        assert r.returncode == 0, (args, r.stdout, r.stderr)
    return r


# ----------------------------------------------------------------------------- 1. A2L grammar
lash("hil", "a2l", "-o", a2l)
text = open(a2l).read()
tokens = re.findall(r'"(?:[^"\\]|\\.)*"|\S+', re.sub(r"/\*.*?\*/", " ", text, flags=re.S))
IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_.\[\]]*$")
NUM = re.compile(r"^-?(0x[0-9A-Fa-f]+|\d+(\.\d*)?([eE][-+]?\d+)?)$")


def is_str(t): return t.startswith('"') and t.endswith('"')


def ident(t): return bool(IDENT.match(t))


def num(t): return bool(NUM.match(t))


def enum(*vals): return lambda t: t in vals


DATATYPES = ("UBYTE", "SBYTE", "UWORD", "SWORD", "ULONG", "SLONG", "A_UINT64", "A_INT64", "FLOAT32_IEEE", "FLOAT64_IEEE")
# The positional fields of each block (ASAP2 1.7 keyword reference; IF_DATA XCP from the XCP A2ML).
BLOCKS = {
    "PROJECT": [ident, is_str],
    "HEADER": [is_str],
    "MODULE": [ident, is_str],
    "MOD_PAR": [is_str],
    "MOD_COMMON": [is_str],
    "MEMORY_SEGMENT": [ident, is_str, enum("CODE", "DATA", "OFFLINE_DATA", "VARIABLES", "SERAM", "RESERVED",
                                           "CALIBRATION_VARIABLES", "EXCLUDE_FROM_FLASH"),
                       enum("EEPROM", "EPROM", "FLASH", "RAM", "ROM", "REGISTER", "NOT_IN_ECU"),
                       enum("INTERN", "EXTERN"), num, num, num, num, num, num, num],
    "COMPU_METHOD": [ident, is_str, enum("IDENTICAL", "FORM", "LINEAR", "RAT_FUNC", "TAB_INTP", "TAB_NOINTP",
                                         "TAB_VERB"), is_str, is_str],
    "COMPU_VTAB": [ident, is_str, enum("TAB_VERB"), num],
    "RECORD_LAYOUT": [ident],
    "MEASUREMENT": [ident, is_str, enum(*DATATYPES), ident, num, num, num, num],
    "CHARACTERISTIC": [ident, is_str, enum("VALUE", "CURVE", "MAP", "CUBOID", "VAL_BLK", "ASCII"), num, ident, num,
                       ident, num, num],
    "IF_DATA": [enum("XCP")],
    "PROTOCOL_LAYER": [num] * 8 + [num, num, enum("BYTE_ORDER_MSB_LAST", "BYTE_ORDER_MSB_FIRST"),
                                    enum("ADDRESS_GRANULARITY_BYTE", "ADDRESS_GRANULARITY_WORD",
                                         "ADDRESS_GRANULARITY_DWORD")],
    "DAQ": [enum("STATIC", "DYNAMIC"), num, num, num, enum("OPTIMISATION_TYPE_DEFAULT"),
            enum("ADDRESS_EXTENSION_FREE", "ADDRESS_EXTENSION_ODT", "ADDRESS_EXTENSION_DAQ"),
            enum("IDENTIFICATION_FIELD_TYPE_ABSOLUTE", "IDENTIFICATION_FIELD_TYPE_RELATIVE_BYTE",
                 "IDENTIFICATION_FIELD_TYPE_RELATIVE_WORD", "IDENTIFICATION_FIELD_TYPE_RELATIVE_WORD_ALIGNED"),
            enum("GRANULARITY_ODT_ENTRY_SIZE_DAQ_BYTE", "GRANULARITY_ODT_ENTRY_SIZE_DAQ_WORD"), num,
            enum("NO_OVERLOAD_INDICATION", "OVERLOAD_INDICATION_PID", "OVERLOAD_INDICATION_EVENT")],
    "TIMESTAMP_SUPPORTED": [num, enum("NO_TIME_STAMP", "SIZE_BYTE", "SIZE_WORD", "SIZE_DWORD"),
                            enum("UNIT_1NS", "UNIT_10NS", "UNIT_100NS", "UNIT_1US", "UNIT_10US", "UNIT_100US",
                                 "UNIT_1MS", "UNIT_10MS", "UNIT_100MS", "UNIT_1S")],
    "EVENT": [is_str, is_str, num, enum("DAQ", "STIM", "DAQ_STIM"), num, num, num, num],
    "XCP_ON_CAN": [num],
}
# Blocks allowed inside each block (the standard's nesting).
PARENT = {"PROJECT": None, "HEADER": "PROJECT", "MODULE": "PROJECT", "MOD_PAR": "MODULE", "MOD_COMMON": "MODULE",
          "MEMORY_SEGMENT": "MOD_PAR", "COMPU_METHOD": "MODULE", "COMPU_VTAB": "MODULE", "RECORD_LAYOUT": "MODULE",
          "MEASUREMENT": "MODULE", "CHARACTERISTIC": "MODULE", "IF_DATA": "MODULE", "PROTOCOL_LAYER": "IF_DATA",
          "DAQ": "IF_DATA", "TIMESTAMP_SUPPORTED": "DAQ", "EVENT": "DAQ", "XCP_ON_CAN": "IF_DATA"}
assert tokens[:3] == ["ASAP2_VERSION", "1", "71"], tokens[:3]
stack, seen, i = [], {}, 3
names = {"MEASUREMENT": [], "CHARACTERISTIC": [], "COMPU_METHOD": [], "RECORD_LAYOUT": []}
refs = []
while i < len(tokens):
    t = tokens[i]
    if t == "/begin":
        b = tokens[i + 1]
        assert b in BLOCKS, f"unknown block {b}"
        assert PARENT[b] == (stack[-1] if stack else None), f"{b} inside {stack}"
        fields = tokens[i + 2:i + 2 + len(BLOCKS[b])]
        for k, (f, check) in enumerate(zip(fields, BLOCKS[b])):
            assert check(f), f"{b} field {k}: '{f}'"
        if b in names:
            names[b].append(fields[0])
        if b == "MEASUREMENT":
            refs.append(("COMPU_METHOD", fields[3]))
        if b == "CHARACTERISTIC":
            refs += [("RECORD_LAYOUT", fields[4]), ("COMPU_METHOD", fields[6])]
            assert float(fields[7]) <= float(fields[8])
        seen[b] = seen.get(b, 0) + 1
        stack.append(b)
        i += 2 + len(BLOCKS[b])
    elif t == "/end":
        assert stack and tokens[i + 1] == stack[-1], f"/end {tokens[i + 1]} closes {stack}"
        stack.pop()
        i += 2
    else:
        i += 1
assert not stack, stack
for b in ("PROJECT", "MODULE", "MOD_PAR", "MEMORY_SEGMENT", "MOD_COMMON", "IF_DATA", "PROTOCOL_LAYER", "DAQ", "EVENT",
          "XCP_ON_CAN", "MEASUREMENT", "CHARACTERISTIC", "COMPU_METHOD", "RECORD_LAYOUT"):
    assert seen.get(b), f"no {b}"
for kind, name in refs:
    assert name in names[kind], f"{kind} {name} is referenced but not defined"
for kind in names:
    assert len(set(names[kind])) == len(names[kind]), f"duplicate {kind}"
for key, val in (("BYTE_ORDER", "MSB_LAST"), ("CAN_ID_MASTER", "0x7F0"), ("CAN_ID_SLAVE", "0x7F1")):
    assert f"{key} {val}" in text, key
master_csv_cols = ["reference_kPa", "measured_kPa", "current_mA", "integrator_mA", "control_step"]
assert all(c in names["MEASUREMENT"] for c in master_csv_cols), names["MEASUREMENT"]
assert "kp" in names["CHARACTERISTIC"]
epk = re.search(r'^\s*EPK "([^"]*)"', text, re.M).group(1)
print(f"a2l: {seen['MEASUREMENT']} MEASUREMENTs, {seen['CHARACTERISTIC']} CHARACTERISTICs, EPK {epk}: grammar ok")

# ----------------------------------------------------------------------------- 2.-4. live
run_dir = os.path.join(out, "run")
run = subprocess.Popen([LASH, "hil", "run", "--no-isolate", "--duration", "10", "--json", "--out-dir", run_dir],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
time.sleep(1.5)

bus = can.Bus(interface="udp_multicast", channel=GROUP, port=PORT, hop_limit=0)


def xcp(data, expect=True, timeout=0.5):
    """Sends one CTO on 0x7F0 and returns the first frame on 0x7F1 that is a response or an error
    packet (PID 0xFF / 0xFE), or None."""
    bus.send(can.Message(arbitration_id=0x7F0, is_extended_id=False, data=bytes(data)))
    end = time.time() + timeout
    while time.time() < end:
        m = bus.recv(timeout=max(0.0, end - time.time()))
        if m is not None and m.arbitration_id == 0x7F1 and len(m.data) and m.data[0] in (0xFF, 0xFE):
            return bytes(m.data)
    assert not expect, f"no response to {bytes(data).hex()}"
    return None


assert xcp([0xFD], expect=False, timeout=0.3) is None                              # GET_STATUS before CONNECT
assert xcp([0xF6, 0, 0, 0, 0x00, 0x01, 0x01, 0x00], expect=False, timeout=0.3) is None  # SET_MTA before CONNECT
# CONNECT: FF, RESOURCE CAL/PAG|DAQ, COMM_MODE_BASIC OPTIONAL|SLAVE_BLOCK (Intel), MAX_CTO 8, MAX_DTO 8 (LE), 1, 1.
assert xcp([0xFF, 0x00]) == bytes([0xFF, 0x05, 0xC0, 0x08, 0x08, 0x00, 0x01, 0x01])
assert xcp([0xC9]) == bytes([0xFE, 0x20])                                         # ERR_CMD_UNKNOWN
assert xcp([0xF6, 0x00]) == bytes([0xFE, 0x21])                                   # SET_MTA, DLC 2: ERR_CMD_SYNTAX
assert xcp([0xFC]) == bytes([0xFE, 0x00])                                         # SYNCH: ERR_CMD_SYNCH
# kp sits at the A2L's address; 200.0 = 0x4069000000000000 (IEEE 754, little-endian bytes).
kp_addr = int(re.search(r"/begin CHARACTERISTIC kp \"[^\"]*\" VALUE (0x[0-9A-F]+)", text).group(1), 16)
assert xcp([0xF6, 0, 0, 0, *kp_addr.to_bytes(4, "little")]) == b"\xff"
v200 = (0x4069000000000000).to_bytes(8, "little")
assert xcp([0xF0, 0x08, *v200[:6]], expect=False, timeout=0.2) is None             # master block mode: no answer yet
assert xcp([0xEF, 0x02, *v200[6:]]) == bytes([0xFE, 0x22])                        # ERR_OUT_OF_RANGE
assert xcp([0xFE]) == b"\xff"                                                      # DISCONNECT
bus.shutdown()

r = lash("xcp", "--bus", BUS, "--a2l", a2l, "set", "kp", "200", check=False)
assert r.returncode == 1 and "ERR_OUT_OF_RANGE (0x22)" in r.stderr, r.stderr
r = lash("xcp", "--bus", BUS, "--a2l", a2l, "get", "no_such_object", check=False)
assert r.returncode == 2 and "no_such_object" in r.stderr, r.stderr
info = lash("xcp", "--bus", BUS, "--a2l", a2l, "info").stdout
assert f"EPK {epk} (matches" in info, info
assert lash("xcp", "--bus", BUS, "--a2l", a2l, "set", "kp", "0.7").stdout.strip() == "kp = 0.7 mA/kPa"
daq_csv = os.path.join(out, "daq.csv")
d = lash("xcp", "--bus", BUS, "--a2l", a2l, "daq", *master_csv_cols, "--duration", "2", "--csv", daq_csv)
print(d.stdout.strip())
assert lash("xcp", "--bus", BUS, "--a2l", a2l, "get", "kp").stdout.strip() == "kp = 0.7 mA/kPa"
# The same from Python (lash.xcp.Client over the same library), when the package is built.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(LASH)), "python"))
try:
    import lash.xcp as lxcp
except ImportError as e:
    lxcp = None
    print(f"python: lash.xcp not importable ({e}); skipped")
if lxcp is not None:
    with lxcp.Client(a2l, bus=BUS) as c:
        assert c.get("kp") == 0.7 and c.epk() == epk
        try:
            c.set("kp", 200.0)
            raise AssertionError("kp = 200 must be refused")
        except RuntimeError as e:
            assert "ERR_OUT_OF_RANGE" in str(e), e
        d = c.daq(["control_step", "current_mA"], 0.5)
        cs = list(d["control_step"])
        assert len(cs) >= 80 and all(b - a == 1 for a, b in zip(cs, cs[1:])), cs[:5]
    print(f"python: lash.xcp.Client get/set/daq ok ({len(cs)} samples)")
stdout, stderr = run.communicate(timeout=60)
assert run.returncode == 0, stderr

m = list(csv.DictReader(open(os.path.join(run_dir, "master.csv"))))
kp = [float(r["kp"]) for r in m]
changes = [i for i in range(1, len(kp)) if kp[i] != kp[i - 1]]
assert len(changes) == 1 and kp[changes[0]] == 0.7, [(i, kp[i]) for i in changes]
step_changed = int(m[changes[0]]["step"])
ev = list(csv.DictReader(open(os.path.join(run_dir, "master.events.csv"))))
cal = [e for e in ev if e["event"] == "calibration"]
assert len(cal) == 1 and cal[0]["name"] == "kp" and float(cal[0]["new"]) == 0.7 and \
    float(cal[0]["old"]) == kp[0] and int(cal[0]["step"]) == step_changed, cal
print(f"kp {kp[0]} -> 0.7 at step {step_changed}; logged in master.events.csv")

sim = lash("hil", "simulate", "--schedule", os.path.join(run_dir, "master.csv"), "-o", os.path.join(out, "sim.csv"))
assert "max |log - simulation| 0 kPa, 0 mA" in sim.stdout, sim.stdout
print(sim.stdout.splitlines()[0])

by_m = {int(float(r["control_step"])): r for r in m}
rows = list(csv.DictReader(open(daq_csv)))
assert len(rows) > 300, len(rows)  # 2 s at 5 ms
steps = [int(float(r["control_step"])) for r in rows]
assert all(b - a == 1 for a, b in zip(steps, steps[1:])), "a DAQ sample is missing"
ts = [int(float(r["timestamp_us"])) for r in rows]
assert all(b - a > 0 for a, b in zip(ts, ts[1:])), "timestamps must increase"
for r in rows:
    ref = by_m[int(float(r["control_step"]))]
    for c in master_csv_cols[:4]:
        assert float(r[c]) == float(ref[c]), (c, r, ref)
print(f"daq: {len(rows)} consecutive samples (control steps {steps[0]}..{steps[-1]}) equal master.csv")
assert any(e["event"] == "ccp_connected" for e in ev), "the CCP handshake must still work"

# ----------------------------------------------------------------------------- 5. --scenario
# The scenario law's compensation mode calibrated mid-run (docs/xcp.md): adaptive (2) -> none (0).
drift = os.path.join(hil_netns.source_dir(), "config", "scenarios", "closed_loop", "valve_deadzone_drift.toml")
sdir = os.path.join(out, "scenario")
srun = subprocess.Popen([LASH, "hil", "run", "--no-isolate", "--scenario", drift, "--compensation", "adaptive",
                         "--duration", "10", "--json", "--out-dir", sdir],
                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
time.sleep(2.0)
assert float(lash("xcp", "--bus", BUS, "--a2l", a2l, "get", "compensation").stdout.split("=")[1].split()[0]) == 2
r = lash("xcp", "--bus", BUS, "--a2l", a2l, "set", "compensation", "1.5", check=False)  # a mode is an integer
assert r.returncode == 1 and "ERR_OUT_OF_RANGE (0x22)" in r.stderr, r.stderr
r = lash("xcp", "--bus", BUS, "--a2l", a2l, "set", "compensation", "3", check=False)    # A2L limits 0..2
assert r.returncode == 1 and "ERR_OUT_OF_RANGE (0x22)" in r.stderr, r.stderr
lash("xcp", "--bus", BUS, "--a2l", a2l, "set", "compensation", "0")
assert float(lash("xcp", "--bus", BUS, "--a2l", a2l, "get", "compensation").stdout.split("=")[1].split()[0]) == 0
stdout, stderr = srun.communicate(timeout=90)
assert srun.returncode == 0, stderr
rep = json.loads(stdout)
m = list(csv.DictReader(open(os.path.join(sdir, "master.csv"))))
mode = [float(r["compensation"]) for r in m]
changes = [i for i in range(1, len(mode)) if mode[i] != mode[i - 1]]
assert mode[0] == 2 and len(changes) == 1 and mode[changes[0]] == 0, [(i, mode[i]) for i in changes]
step_changed = int(m[changes[0]]["step"])
cal = [e for e in csv.DictReader(open(os.path.join(sdir, "master.events.csv"))) if e["event"] == "calibration"]
assert len(cal) == 1 and cal[0]["name"] == "compensation" and float(cal[0]["old"]) == 2 and \
    float(cal[0]["new"]) == 0 and int(cal[0]["step"]) == step_changed, cal
# The compensator at the end of the run: mode none, no inverse (edges 0).
fin = rep["compensation"]["final"]
assert rep["compensation_mode"] == "adaptive" and rep["compensation"]["final_mode"] == "none" and \
    fin == {"right": 0.0, "left": 0.0}, rep["compensation"]
sim = lash("hil", "simulate", "--schedule", os.path.join(sdir, "master.csv"), "--scenario", drift, "--compensation",
           "adaptive", "-o", os.path.join(out, "sim_scenario.csv"))
assert "max |log - simulation| 0 kPa, 0 mA" in sim.stdout, sim.stdout
print(f"--scenario: compensation 2 -> 0 at step {step_changed}; logged; final {rep['compensation']}; "
      f"{sim.stdout.splitlines()[0]}")

# --xcp off: no slave on the bus (the tool times out), the run itself is unaffected.
off = subprocess.Popen([LASH, "hil", "run", "--no-isolate", "--duration", "3", "--xcp", "off", "--out-dir",
                        os.path.join(out, "off")], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
time.sleep(1.2)
r = lash("xcp", "--bus", BUS, "--a2l", a2l, "--timeout-ms", "300", "info", check=False)
assert r.returncode == 1 and "no response to CONNECT" in r.stderr, r.stderr
_, err = off.communicate(timeout=60)
assert off.returncode == 0, err
print("--xcp off: CONNECT unanswered, run ok")
print("ok")
