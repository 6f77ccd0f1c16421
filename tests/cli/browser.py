"""The headless Chromium of the console's browser tests (console_browser.py, console_load.py,
console_monitor.py) and of bench/console_memory.py: Debian's chromium + chromium-driver driven by
python3-selenium. Importing this module exits with 77 (ctest's skip) when one of them is missing.

    import browser                       # from tests/cli (or with tests/cli on sys.path)
    d = browser.chrome(profile_dir)      # a new headless chromium, its own profile
    browser.severe_errors(d)             # the page's console errors (level SEVERE)
    browser.lash_url(line)               # (url, port, token) from lash's "lash console: URL" line
"""
import os
import shutil
import sys

from console_run import URL_RE, lash_url  # noqa: F401  (re-exported for the tests)

CHROMIUM = shutil.which("chromium")
DRIVER = shutil.which("chromedriver") or "/usr/bin/chromedriver"
try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By  # noqa: F401  (re-exported for the tests)
except ImportError:
    print("SKIP: python3-selenium is not installed")
    sys.exit(77)
if not CHROMIUM or not os.path.exists(DRIVER):
    print("SKIP: chromium or chromium-driver is not installed")
    sys.exit(77)

# No network but loopback is needed: no updates, sync, QUIC, background requests.
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--disable-dev-shm-usage", "--window-size=1400,1100"]


def chrome(profile):
    """A headless chromium with its own profile directory (made by the caller, e.g. in a temp dir),
    the browser's console log kept (severe_errors)."""
    o = webdriver.ChromeOptions()
    o.binary_location = CHROMIUM
    for a in ARGS + [f"--user-data-dir={profile}"]:
        o.add_argument(a)
    o.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(DRIVER), options=o)


def severe_errors(driver):
    """The page's console messages of level SEVERE (errors) since the last call."""
    return [e for e in driver.get_log("browser") if e.get("level") == "SEVERE"]


def rss_kb(pid):
    """The resident set [kB] of process `pid` (VmRSS of /proc/PID/status); -1 if absent."""
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return -1
