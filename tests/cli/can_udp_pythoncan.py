"""UDP multicast interop with python-can (Debian python3-can), run inside `unshare -n`
by can_udp_pythoncan.sh. Checks:
  1. frames sent by `lash can send` arrive at a python-can udp_multicast bus, identical id/flags/data;
  2. frames sent by python-can arrive at `lash can dump`, identical, and the candump log lash
     wrote is read back by python-can's CanutilsLogReader frame for frame;
  3. malformed, unknown-key and oversized datagrams are dropped and counted by lash.
"""
import os
import socket
import subprocess
import sys
import tempfile
import time
import logging

logging.disable(logging.CRITICAL)
import can  # noqa: E402
import msgpack  # noqa: E402

LASH = os.environ["LASH"]
GROUP, PORT = "239.74.163.2", 43113

FRAMES = [
    can.Message(arbitration_id=0x123, is_extended_id=False, data=bytes.fromhex("DEADBEEF")),
    can.Message(arbitration_id=0x7FF, is_extended_id=False, data=b""),
    can.Message(arbitration_id=0x1ABCDEF0, is_extended_id=True, data=bytes(range(8))),
    can.Message(arbitration_id=0x001, is_extended_id=False, is_remote_frame=True, dlc=3),
    can.Message(arbitration_id=0x18FF0001, is_extended_id=True, data=bytes.fromhex("00FF7F80")),
]


def text(m):
    idt = ("%08X" if m.is_extended_id else "%03X") % m.arbitration_id
    if m.is_remote_frame:
        return idt + "#R" + (str(m.dlc) if m.dlc else "")
    return idt + "#" + bytes(m.data).hex().upper()


def same(a, b):
    return (a.arbitration_id == b.arbitration_id and a.is_extended_id == b.is_extended_id
            and a.is_remote_frame == b.is_remote_frame and a.dlc == b.dlc
            and (a.is_remote_frame or bytes(a.data) == bytes(b.data)))


def main():
    failures = []
    # 1. lash -> python-can
    bus = can.Bus(interface="udp_multicast", channel=GROUP, port=PORT, hop_limit=0)
    subprocess.run([LASH, "can", "send", "--bus", "udp:%s:%d" % (GROUP, PORT)] + [text(m) for m in FRAMES], check=True)
    got = []
    deadline = time.time() + 5
    while len(got) < len(FRAMES) and time.time() < deadline:
        m = bus.recv(timeout=0.5)
        if m is not None:
            got.append(m)
    if len(got) != len(FRAMES):
        failures.append("python-can received %d of %d frames from lash" % (len(got), len(FRAMES)))
    for a, b in zip(FRAMES, got):
        if not same(a, b):
            failures.append("lash->python-can: sent %s got %s" % (text(a), text(b)))
    print("lash -> python-can: %d/%d frames identical" % (sum(same(a, b) for a, b in zip(FRAMES, got)), len(FRAMES)))

    # 2. python-can -> lash dump (+ 3. bad datagrams)
    with tempfile.TemporaryDirectory() as tmp:
        log = os.path.join(tmp, "dump.log")
        dump = subprocess.Popen([LASH, "can", "dump", "--bus", "udp:", "--count", str(len(FRAMES)), "--timeout", "10",
                                 "--log", log], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        time.sleep(1.0)
        raw = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        raw.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
        good = dict(timestamp=0.0, arbitration_id=1, is_extended_id=False, is_remote_frame=False,
                    is_error_frame=False, channel=None, dlc=1, data=b"\x01", is_fd=False,
                    bitrate_switch=False, error_state_indicator=False)
        bad = [b"\x8b\xff garbage", msgpack.packb(dict(good, colour="red"), use_bin_type=True), b"\x80" * 2000]
        for d in bad:
            raw.sendto(d, (GROUP, PORT))
        for m in FRAMES:
            bus.send(m)
            time.sleep(0.01)
        out, err = dump.communicate(timeout=15)
        lines = out.strip().split("\n") if out.strip() else []
        texts = [ln.split()[2] for ln in lines]
        want = [text(m) for m in FRAMES]
        if texts != want:
            failures.append("lash dump printed %s, python-can sent %s" % (texts, want))
        if "%d dropped" % len(bad) not in err:
            failures.append("lash should count %d dropped datagrams: %s" % (len(bad), err.strip()))
        print("python-can -> lash dump: %d/%d frames identical; %s" % (
            sum(a == b for a, b in zip(texts, want)), len(want), err.strip()))
        back = list(can.CanutilsLogReader(log))
        if len(back) != len(FRAMES) or not all(same(a, b) for a, b in zip(FRAMES, back)):
            failures.append("CanutilsLogReader read %s" % [text(m) for m in back])
        else:
            print("CanutilsLogReader read lash's log frame for frame (%d frames)" % len(back))
    bus.shutdown()
    for f in failures:
        print("FAIL", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
