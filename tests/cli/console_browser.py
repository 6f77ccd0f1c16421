"""Issue 27, the live console, tested in a real browser (Debian's chromium + chromium-driver,
python3-selenium): `lash hil run --duration 50 --console 0` (long enough for every step below on a loaded
machine: the browser must go away while the run goes on), then

1. the page loads from the printed URL with no console errors (and nothing from elsewhere:
   the server's Content-Security-Policy is default-src 'self');
2. a scope's canvas (inside [data-scope]) changes between two screenshots 1 s apart;
3. kp set in the page's form (<form data-tune>, <input data-param="kp">): the readback
   ([data-readback="kp"]) shows the ECU's confirmed value, master.csv's kp column takes it and
   master.events.csv logs the calibration write; kp = 200 shows the ECU's refusal in [data-error];
4. a POST without the token, or with it but from another origin, gets 403;
5. frames per second in the page (requestAnimationFrame count over 10 s) and data redraws are
   printed; the status panel shows the master's TET (mean, max, p99), wake-up latency, overruns,
   late/lost frames (XCP measurements of the loop's figures) and its state: checked against
   master.csv's tet_us column written by the master (the console's mean = the file's mean over
   the control steps the page says it covers, to the 4 digits shown; its max <= the file's max);
5b. the slave's scope ([data-scope=slave], slave_measured_kPa from its sensor frames on the bus)
   changes, and its envelope lies within slave.csv's measured_kPa range;
6. the browser is closed mid-run: the run goes on and ends with exit 0.
Skips (77) when chromium, its driver or selenium is missing. LASH_CONSOLE_SHOT=FILE saves a
screenshot of the page (docs/console.md)."""
import csv
import json
import os
import re
import struct
import sys
import tempfile
import time
import urllib.error
import urllib.request

LASH = os.environ.get("LASH", "lash")
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import console_run  # noqa: E402  (the lash command with its console)
import browser  # noqa: E402  (the shared headless chromium; exits 77 when it is missing)
from browser import By  # noqa: E402


T0 = time.time()


def fail(msg):
    print(f"FAIL at {time.time() - T0:.1f} s:", msg)
    sys.exit(1)


def post(url, body, headers):
    req = urllib.request.Request(url, data=json.dumps(body).encode(), headers=headers, method="POST")
    try:
        with urllib.request.urlopen(req, timeout=5) as r:
            return r.status
    except urllib.error.HTTPError as e:
        return e.code


def canvas_png(driver):
    c = driver.find_element(By.CSS_SELECTOR, '[data-scope="pressure"] canvas')
    return c.screenshot_as_png


with tempfile.TemporaryDirectory() as tmp:
    out = os.path.join(tmp, "run")
    run, m = console_run.start([LASH, "hil", "run", "--duration", "50", "--console", "0", "--out-dir", out])
    if m is None:
        fail("no console URL printed")
    url, port, token = m
    print("URL printed:", re.sub(r"token=\w+", "token=...", url))
    base = f"http://127.0.0.1:{port}"
    d = browser.chrome(os.path.join(tmp, "profile"))
    try:
        d.get(url)
        time.sleep(3)
        scopes = [e.get_attribute("data-scope") for e in d.find_elements(By.CSS_SELECTOR, "[data-scope]")]
        print("scopes:", scopes)
        if "pressure" not in scopes:
            fail("no [data-scope=pressure]")
        a = canvas_png(d)
        time.sleep(1)
        b = canvas_png(d)
        if a == b:
            fail("the pressure scope did not change in 1 s")
        print("scope canvas changed between two screenshots 1 s apart")

        inp = d.find_element(By.CSS_SELECTOR, 'form[data-tune] input[data-param="kp"]')
        inp.clear()
        inp.send_keys("0.7")
        inp.submit()
        rb = d.find_element(By.CSS_SELECTOR, '[data-readback="kp"]')
        t = time.time() + 5
        while time.time() < t and rb.text != "0.7000":
            time.sleep(0.1)
        if rb.text not in ("0.7000", "0.7"):
            fail(f"readback of kp shows {rb.text!r}, want 0.7")
        print("kp = 0.7 set in the page, readback", rb.text)
        t_set = time.time()

        inp.clear()
        inp.send_keys("200")
        d.execute_script("arguments[0].min = ''; arguments[0].max = '';", inp)  # let the ECU refuse it
        inp.submit()
        err = d.find_element(By.CSS_SELECTOR, '[data-error="kp"]')
        t = time.time() + 5
        while time.time() < t and not err.text:
            time.sleep(0.1)
        if "ERR_OUT_OF_RANGE" not in err.text:
            fail(f"kp = 200: data-error shows {err.text!r}")
        print("kp = 200 refused:", err.text)

        hdr = {"Content-Type": "application/json"}
        s1 = post(base + "/api/tune", {"name": "kp", "value": 0.5}, hdr)
        s2 = post(base + "/api/tune", {"name": "kp", "value": 0.5},
                  dict(hdr, **{"X-Lash-Token": token, "Origin": "http://evil.example"}))
        s3 = post(base + "/api/tune", {"name": "kp", "value": 0.5},
                  dict(hdr, **{"X-Lash-Token": "0" * 32, "Origin": base}))
        print(f"POST without token: {s1}; with token, other Origin: {s2}; wrong token: {s3}")
        if (s1, s2, s3) != (403, 403, 403):
            fail("a change without the token / from another origin was not refused with 403")

        a = d.find_element(By.CSS_SELECTOR, '[data-scope="slave"] canvas').screenshot_as_png
        time.sleep(1)
        if a == d.find_element(By.CSS_SELECTOR, '[data-scope="slave"] canvas').screenshot_as_png:
            fail("the slave scope did not change in 1 s")
        print("slave scope canvas changed between two screenshots 1 s apart")
        s0 = d.execute_script("return Object.assign({}, window.lashStats)")
        time.sleep(10)
        s1 = d.execute_script("return Object.assign({}, window.lashStats)")
        fps = (s1["frames"] - s0["frames"]) / 10.0
        print(f"page: {(s1['draws'] - s0['draws']) / 10.0:.1f} data redraws/s over 10 s")
        st = d.execute_script("const o = {}; document.querySelectorAll('[data-status]').forEach("
                              "(e) => o[e.getAttribute('data-status')] = e.textContent); return o;")
        print("status:", {k: st.get(k) for k in ("state", "tet_mean_us", "tet_max_us", "tet_p99_us",
                                                  "wake_latency_mean_us", "wake_latency_p99_us", "overruns",
                                                  "frames_late", "frames_lost", "slave_frames")})
        for k in ("tet_mean_us", "tet_max_us", "tet_p99_us", "wake_latency_mean_us", "wake_latency_max_us",
                  "wake_latency_p99_us", "overruns", "frames_late", "frames_lost"):
            try:
                float(st.get(k))
            except (TypeError, ValueError):
                fail(f"status {k} shows {st.get(k)!r}")
        # the safe-state machine's state by name (a loaded machine may drive it to degraded or safe)
        if st.get("state") not in ("startup", "connected", "running", "degraded", "safe", "failed"):
            fail(f"status state shows {st.get('state')!r}")
        seen_tet = (float(st["tet_mean_us"]), float(st["tet_max_us"]), float(st["tet_p99_us"]))
        tet_span = (float(st["tet_from_step"]), float(st["tet_to_step"]), int(st["tet_steps"]), int(st["daq_gaps"]))
        frame = urllib.request.urlopen(urllib.request.Request(
            base + "/api/frame?window=30&columns=300", headers={"X-Lash-Token": token}), timeout=5).read()
        names = json.loads(urllib.request.urlopen(urllib.request.Request(
            base + "/api/meta", headers={"X-Lash-Token": token}), timeout=5).read())["signals"]
        ncol, nsig = struct.unpack_from("<II", frame, 4)
        vals = struct.unpack_from(f"<{nsig * 2 * ncol}f", frame, 64)
        k = names.index("slave_measured_kPa")
        env = [x for x in vals[2 * k * ncol:(2 * k + 2) * ncol] if x == x]
        # read in one script call: the status panel is redrawn as it updates, so a found element
        # can be replaced before its text is asked for (StaleElementReferenceException)
        drops = d.execute_script("const e = document.querySelector('[data-status=\"drops\"]');"
                                 " return e ? e.textContent : null;")
        if drops is None or not drops.strip().isdigit():
            fail(f"the status panel's drop counter shows {drops!r}")
        print(f"page: {fps:.1f} frames/s (requestAnimationFrame over 10 s); drops {drops}")
        if os.environ.get("LASH_CONSOLE_SHOT"):
            d.save_screenshot(os.environ["LASH_CONSOLE_SHOT"])
        errors = browser.severe_errors(d)
        if errors:
            fail(f"console errors in the page: {errors}")
        print("no console errors")
    finally:
        mid_run = run.poll() is None
        d.quit()  # the browser goes away mid-run
    print("browser closed at t_run ~", round(time.time() - t_set, 1), "s after the change")
    if not mid_run:
        fail("the run had ended before the browser was closed (not a mid-run close)")
    rest_out = console_run.finish(run, fail)
    print("run ended with exit 0")
    tet = re.search(r"master\s+TET \[us\] mean\s+([\d.]+)", rest_out)
    print("master TET mean", tet.group(1) if tet else "?", "us (with the console attached)")

    with open(os.path.join(out, "master.csv")) as f:
        kps = [float(r["kp"]) for r in csv.DictReader(f)]
    changes = [(a, b) for a, b in zip(kps, kps[1:]) if a != b]
    if 0.7 not in kps or changes[0][1] != 0.7:
        fail(f"master.csv kp changes {changes}")
    with open(os.path.join(out, "master.events.csv")) as f:
        cal = [l.strip() for l in f if ",calibration," in l]
    if not cal or not cal[0].endswith(",kp,1.1207208729396014,0.7"):
        fail(f"master.events.csv calibration lines {cal}")
    print("master.csv kp:", changes, "; master.events.csv:", cal)
    with open(os.path.join(out, "master.csv")) as f:
        rows = list(csv.DictReader(f))
    tets = [float(r["tet_us"]) for r in rows]
    # the page's figures: the DAQ sample of loop step k carries step k-1's TET; they cover the
    # samples whose control_step lies in [tet_from_step, tet_to_step] (shown beside them)
    c0, c1, n_page, gaps = tet_span
    span = [tets[i - 1] for i in range(1, len(rows)) if c0 <= float(rows[i]["control_step"]) <= c1 and tets[i - 1] > 0]
    span_mean = sum(span) / len(span)
    print(f"the page's TET covers control steps {c0:.0f}..{c1:.0f}: {n_page} samples (master.csv: {len(span)}, "
          f"DAQ gaps {gaps}); master.csv's mean over them {span_mean:.4f} us")
    tol = 0.001 * span_mean + 0.01 if gaps == 0 and n_page == len(span) else 0.05 * span_mean
    if abs(seen_tet[0] - span_mean) > tol:
        fail(f"the page's TET mean {seen_tet[0]} is not master.csv's {span_mean:.4f} over the same steps")
    file_mean = sum(tets) / len(tets)
    print(f"TET [us] in the page: mean {seen_tet[0]} max {seen_tet[1]} p99 {seen_tet[2]}; master.csv: mean "
          f"{file_mean:.3f} max {max(tets):.3f}")
    shown = lambda x: 0.51 if x >= 1000 else 0.0006 * x + 1e-9  # the panel shows 4 digits (>= 1000: integers)
    if not (seen_tet[1] <= max(tets) + shown(max(tets)) and seen_tet[2] <= max(tets) + 0.05 + shown(max(tets)) and
            seen_tet[2] <= seen_tet[1] + shown(seen_tet[1])):
        fail("the page's TET is not master.csv's")
    with open(os.path.join(out, "slave.csv")) as f:
        meas = [float(r["measured_kPa"]) for r in csv.DictReader(f)]
    print(f"slave_measured_kPa envelope in the page [{min(env):.2f}, {max(env):.2f}] kPa; slave.csv measured_kPa "
          f"[{min(meas):.2f}, {max(meas):.2f}]")
    if not env or min(env) < min(meas) - 0.01 or max(env) > max(meas) + 0.01:
        fail("the slave scope's values are not slave.csv's")
print("PASS")
