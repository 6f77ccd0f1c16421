"""A lash command with its live console (`--console 0`) for the console tests (console_browser.py,
console_slave_log.py; browser.py re-exports lash_url): start it, wait for the console's URL and
token on its stderr, and wait for its end. No browser needed (console_slave_log.py uses the HTTP API).

    import console_run                   # from tests/cli (or with tests/cli on sys.path)
    run, m = console_run.start([LASH, "hil", "run", ..., "--console", "0"])
    if m is None: fail("no console URL printed")
    url, port, token = m
    ...
    out = console_run.finish(run, fail)  # its stdout; fail(msg) unless it exited 0
"""
import re
import subprocess
import time

URL_RE = re.compile(r"lash console: (http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]{32}))$")


def lash_url(line):
    """(url, port, token) of lash's "lash console: URL" line, or None."""
    m = URL_RE.search(line.strip())
    return (m.group(1), m.group(2), m.group(3)) if m else None


def start(cmd, wait_s=15):
    """Starts `cmd` (stdout and stderr piped, text) and reads its stderr up to the console's URL
    line, for at most wait_s seconds. Returns (process, (url, port, token)); (process, None), the
    process killed, when no URL came."""
    run = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t_end = time.time() + wait_s
    while time.time() < t_end:
        line = run.stderr.readline()
        if not line:
            break
        m = lash_url(line)
        if m:
            return run, m
    run.kill()
    return run, None


def finish(run, fail, timeout=60):
    """Waits for the command's end (at most `timeout` s); fail(message) unless it exited 0.
    Returns its stdout."""
    out, err = run.communicate(timeout=timeout)
    if run.returncode != 0:
        fail(f"lash {' '.join(run.args[1:3])} exited {run.returncode}: {err[-2000:]}")  # "lash hil run exited …"
    return out
