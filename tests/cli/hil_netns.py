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


def lash():
    return os.environ["LASH"]


def source_dir():
    return os.environ.get("LASH_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def read_csv(path):
    import csv
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) if k != "event" else r[k] for r in rows] for k in (rows[0].keys() if rows else [])}
