"""Shared helpers of the lash hil script tests: run inside a private network
namespace (``unshare -n``, loopback up, 224.0.0.0/4 routed on lo) so that no
multicast leaves the machine; skip (exit 77) where namespaces are not permitted."""
import os
import shutil
import subprocess
import sys

SKIP = 77


def enter_private_netns():
    """Re-executes this script under `unshare -n` unless already done."""
    if os.environ.get("LASH_HIL_NETNS") == "1":
        for cmd in (["ip", "link", "set", "lo", "up"], ["ip", "route", "add", "224.0.0.0/4", "dev", "lo"]):
            r = subprocess.run(cmd, capture_output=True, text=True)
            if r.returncode != 0 and "File exists" not in r.stderr:
                print(f"skip: {' '.join(cmd)} failed: {r.stderr.strip()}")
                sys.exit(SKIP)
        return
    unshare = shutil.which("unshare")
    if unshare is None or shutil.which("ip") is None:
        print("skip: unshare or ip (iproute2) not available")
        sys.exit(SKIP)
    probe = subprocess.run([unshare, "-n", "true"], capture_output=True)
    if probe.returncode != 0:
        probe = subprocess.run([unshare, "-rn", "true"], capture_output=True)
        if probe.returncode != 0:
            print("skip: cannot create a network namespace here")
            sys.exit(SKIP)
        flags = ["-rn"]
    else:
        flags = ["-n"]
    env = dict(os.environ, LASH_HIL_NETNS="1")
    sys.exit(subprocess.run([unshare, *flags, sys.executable, *sys.argv], env=env).returncode)


def crc8_j1850(data):
    """CRC-8 SAE J1850, bit by bit: poly 0x1D, init 0xFF, xorout 0xFF, MSB first (independent of
    lash's table-driven code; the tests check it against python3-crcmod and the check value)."""
    reg = 0xFF
    for b in data:
        reg ^= b
        for _ in range(8):
            reg = ((reg << 1) ^ 0x1D) & 0xFF if reg & 0x80 else (reg << 1) & 0xFF
    return reg ^ 0xFF


def check_crc8_j1850():
    """The catalogue check value, and python3-crcmod (whose initCrc is init XOR xorout) agreeing."""
    import crcmod
    assert crc8_j1850(b"123456789") == 0x4B
    ref = crcmod.mkCrcFun(0x11D, initCrc=0x00, rev=False, xorOut=0xFF)
    for probe in (b"123456789", bytes(range(9)), bytes([0xFF] * 8), b"\x00\x01\x02"):
        assert ref(probe) == crc8_j1850(probe), probe


def e2e_crc(arbitration_id, data, crc_byte):
    """The bench DBC's E2E CRC: data ID (identifier low byte, high byte) + payload without the CRC byte."""
    body = bytes([arbitration_id & 0xFF, (arbitration_id >> 8) & 0xFF]) + bytes(
        b for i, b in enumerate(data) if i != crc_byte)
    return crc8_j1850(body)


def node_role(argv):
    """'slave' / 'master' for a node process of `lash hil run` (`lash hil node DIR/slave.launch.json`,
    the launch file named after the node) or of `lash hil slave|master`; None otherwise."""
    if len(argv) > 3 and argv[1] == "hil" and argv[2] == "node":
        return os.path.basename(argv[3]).split(".")[0]
    if len(argv) > 2 and argv[1] == "hil" and argv[2] in ("slave", "master"):
        return argv[2]
    return None


def lash():
    return os.environ["LASH"]


def source_dir():
    return os.environ.get("LASH_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def read_csv(path):
    import csv
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) if k != "event" else r[k] for r in rows] for k in (rows[0].keys() if rows else [])}
