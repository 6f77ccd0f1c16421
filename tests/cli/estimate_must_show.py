#!/usr/bin/env python3
"""Issue 12 must-show (docs/identification.md, "Defaults chosen from the data"): `lash estimate
DATA --model M` with nothing else.

Truth comes from outside the estimator: the plant file's parameters (thesis eq. 34, written by
hand), the same file scaled here, and a coupled-carts model written here in numpy; EMPS is the
authors' published Coulomb force. Outliers are injected here with numpy.
 - E2 (noise variance 200, seeds 1-5, 200 s): a1 <= 1 %, b1 <= 3 %, c <= 3 %, d <= 10 % per side;
 - the same records with 0.2 % of the samples moved by +-100 sigma: same bounds, outliers counted;
 - deadzone edges and deadband widths scaled by 0.3 and by 2 (amplitude 600 and 1200): same bounds;
 - coupled carts, ideal model, position through a 0.1 um scale, deadband 2-8 mm, sine and triangle
   at 2, 3, 4 and 5 rad/s: d within 5 %;
 - EMPS with only the column mapping: Coulomb force within 5 % of 20.14 / 20.63 N (skipped without data);
 - sweep of E3 and E4 with no [estimator] table: at least 100 % and 97.0 % good runs, E3 with at
   least 65 % of its identified sides within 5 % of the rig (a regression floor);
 - --print-config -> --config gives the same result; options a model does not use exit 2;
   given guesses inside the deadzone are reported (reason wrong_guess, per side).
"""
import csv, json, math, os, re, subprocess, sys, tempfile

import numpy as np

LASH = os.environ["LASH"]
SRC = os.environ["LASH_SOURCE_DIR"]
fail = 0


def check(cond, what):
    global fail
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        fail = 1


def lash(*args, ok=True):
    r = subprocess.run([LASH, *args], capture_output=True, text=True)
    if ok and r.returncode != 0:
        raise SystemExit(f"lash {' '.join(args)} failed ({r.returncode}): {r.stderr}")
    return r


TRUTH = {"right": dict(a1=-0.96, b1=0.1, c=200.0, d=30.0), "left": dict(a1=-0.94, b1=0.15, c=-300.0, d=50.0)}
BOUND = dict(a1=0.01, b1=0.03, c=0.03, d=0.10)


def within(j, scale, label):
    worst = {}
    for side in ("right", "left"):
        for p, t in TRUTH[side].items():
            t = t * scale if p in ("c", "d") else t
            e = j[side][p]
            err = math.inf if e is None else abs(e / t - 1)
            worst[f"{p}_{side[0]}"] = err
            check(err <= BOUND[p], f"{label} {side} {p} = {e} (truth {t}, error {100 * err:.2f} %, bound {100 * BOUND[p]:.0f} %)")
    return worst


def estimate(path, model="deadzone-deadband", *extra):
    return json.loads(lash("estimate", path, "--model", model, "--json", *extra).stdout)


def scaled_plant(d, k):
    text = open(f"{SRC}/config/plants/thesis_eq34.toml").read()
    text = text.replace("left = -300.0", f"left = {-300 * k}").replace("right = 200.0", f"right = {200 * k}")
    text = text.replace("half_width = { left = 50.0, right = 30.0 }",
                        f"half_width = {{ left = {50 * k}, right = {30 * k} }}")
    path = os.path.join(d, f"plant_{k}.toml")
    open(path, "w").write(text)
    return path


def simulate(d, plant, amplitude, seed, name):
    out = os.path.join(d, name)
    lash("simulate", plant, "--input", "sine", "--amplitude", str(amplitude), "--frequency", "1", "--duration", "200",
         "--noise-variance", "200", "--seed", str(seed), "-o", out)
    return out


def coupled_carts(path, d, wave, w, q=1e-7, dt=0.001, n=30000, amp=6.0):
    """Motor-cart velocity x = G(u), G = 0.0007/(z - 0.98) [m/s per V]; w' = DZ(x; -0.03, 0.02);
    w = sum T w'; free cart y = DB(w; d), read through a linear scale of resolution q [m]."""
    a1, b1, cl, cr = -0.98, 0.0007, -0.03, 0.02
    t = np.arange(n) * dt
    if wave == "sine":
        u = amp * np.sin(w * t)
    else:
        ph = (w * t / (2 * np.pi)) % 1.0
        u = amp * np.where(ph < 0.25, 4 * ph, np.where(ph < 0.75, 2 - 4 * ph, 4 * ph - 4))
    x = pos = wpos = u1 = 0.0
    y = np.zeros(n)
    for k in range(n):
        x = -a1 * x + b1 * u1
        wd = x - cr if x > cr else (x - cl if x < cl else 0.0)
        wpos += dt * wd
        if wpos > pos + d:
            pos = wpos - d
        elif wpos < pos - d:
            pos = wpos + d
        y[k] = np.round(pos / q) * q
        u1 = u[k]
    np.savetxt(path, np.c_[t, u, y], delimiter=",", header="t,v,y", comments="", fmt="%.10g")


with tempfile.TemporaryDirectory() as d:
    plant = f"{SRC}/config/plants/thesis_eq34.toml"
    sigma = math.sqrt(200.0)
    for seed in range(1, 6):
        rec = simulate(d, plant, 600, seed, f"e2_{seed}.csv")
        j = estimate(rec)
        within(j, 1.0, f"E2 seed {seed}")
        # the dy/dt switching runs on searched guesses; model switching checks its result and is
        # kept when it departs from it by more than its interval's width or its free run fits the
        # record better (docs/method.md §A4.4b): then the final run used no guesses
        ms = j["model_switching"]
        if ms["used"]:
            check(ms["trigger"] == "check" and ms["converged"], f"E2 seed {seed}: model switching kept as a check ({ms})")
        else:
            check(j["right"]["guess"]["source"] == "searched" and j["left"]["guess"]["source"] == "searched",
                  f"E2 seed {seed}: guesses searched")
        # outliers: 0.2 % of the samples moved by +-100 sigma
        data = np.genfromtxt(rec, delimiter=",", names=True)
        rng = np.random.default_rng(1000 + seed)
        m = int(0.002 * len(data))
        idx = rng.choice(len(data), m, replace=False)
        y = data["y"].copy()
        y[idx] += rng.choice([-1.0, 1.0], m) * 100.0 * sigma
        out = os.path.join(d, f"e2o_{seed}.csv")
        np.savetxt(out, np.c_[data["t"], data["v"], y], delimiter=",", header="t,v,y", comments="", fmt="%.17g")
        j = estimate(out)
        within(j, 1.0, f"E2+outliers seed {seed}")
        check(0.9 * m <= j["outliers"] <= 1.5 * m, f"E2+outliers seed {seed}: {j['outliers']} outliers reported ({m} injected)")
    for k, amp in ((0.3, 600), (2.0, 1200)):
        p = scaled_plant(d, k)
        for seed in range(1, 6):
            j = estimate(simulate(d, p, amp, seed, f"s{k}_{seed}.csv"))
            within(j, k, f"eq-34 x{k} seed {seed}")

    # --print-config writes the settings used; --config reads exactly that file back
    rec = os.path.join(d, "e2_1.csv")
    toml = lash("estimate", rec, "--model", "deadzone-deadband", "--print-config").stdout
    cfg = os.path.join(d, "used.toml")
    open(cfg, "w").write(toml)
    a = estimate(rec)
    b = json.loads(lash("estimate", rec, "--config", cfg, "--json").stdout)
    check(re.search(r"^derivative_threshold = ", toml, re.M) is not None, "printed config has the data-chosen dead band")
    check(all(a[s][p] == b[s][p] for s in ("right", "left") for p in ("a1", "b1", "c", "d")),
          "--print-config -> --config: identical estimates")
    # the thesis's settings are one option away; they do not reach the bounds on E2 (thesis: d <= 50 %)
    t = estimate(rec, "deadzone-deadband", "--preset", "thesis", "--guess-left", "-350", "--guess-right", "350")
    check(t["preset"] == "thesis", "--preset thesis")
    # options a model does not read are refused
    for model, opt in (("coupled-carts", ["--method", "iv"]), ("output-deadzone", ["--guess-left", "-1"]),
                       ("linear", ["--pooled"]), ("input-deadzone", ["--accel-limit", "1"])):
        r = lash("estimate", rec, "--model", model, *opt, ok=False)
        check(r.returncode == 2 and opt[0] in r.stderr, f"{model} {opt[0]}: exit {r.returncode}: {r.stderr.strip()}")
    # given guesses inside the deadzone (c_r = 200, c_l = -300): reported per side
    j = estimate(rec, "deadzone-deadband", "--guess-left", "-250", "--guess-right", "150")
    check(j["right"].get("reason") == "wrong_guess" and j["left"].get("reason") == "wrong_guess",
          f"guesses inside the deadzone: {j['right'].get('reason')}, {j['left'].get('reason')}")
    j = estimate(rec, "deadzone-deadband", "--guess-left", "-400", "--guess-right", "150")
    check(j["right"].get("reason") == "wrong_guess" and j["left"].get("reason") != "wrong_guess",
          "only the right guess inside: only the right side named")
    check(j["left"]["guess"]["source"] == "given" and j["left"]["guess"]["value"] == -400, "given guess honoured")

    # coupled carts through a 0.1 um linear scale
    for dd in (0.002, 0.005, 0.008):
        for wave in ("sine", "triangle"):
            for w in (2.0, 3.0, 4.0, 5.0):
                path = os.path.join(d, f"cc_{dd}_{wave}_{w}.csv")
                coupled_carts(path, dd, wave, w)
                j = estimate(path, "coupled-carts")
                err = math.inf if j["d"] is None else abs(j["d"] / dd - 1)
                check(err <= 0.05, f"coupled carts d = {dd} m {wave} {w} rad/s: {j['d']} ({100 * err:.2f} %)")

    # EMPS: only the column mapping
    emps = os.environ.get("LASH_EMPS_DIR", f"{SRC}/../shared/data/emps")
    if os.path.exists(f"{emps}/DATA_EMPS.mat"):
        j = estimate(f"{emps}/DATA_EMPS.mat", "output-deadzone", "--columns", "t,gtau*vir,diff(qm)/0.001")
        for side, ref in (("right", 20.14), ("left", -20.63)):
            p = j[side]
            fc = p["c"] / (p["b1"] / (1 + p["a1"]))
            check(abs(fc / ref - 1) <= 0.05, f"EMPS {side}: Coulomb force {fc:.3f} N (authors {ref} N)")
    else:
        print("SKIPPED EMPS: no data at", emps)

    # sweep: E3 and E4 with no estimator settings in the campaign
    for name, share in (("e3_motor_cart_lash", 1.0), ("e4_pilot_valve_lash", 0.970)):
        text = open(f"{SRC}/config/campaigns/{name}.toml").read()
        text = text[: text.index("[estimator]")]
        path = os.path.join(d, f"{name}_defaults.toml")
        open(path, "w").write(text)
        s = json.loads(lash("sweep", path, "-q", "-o", os.path.join(d, f"{name}.csv"), "--json").stdout)
        runs = len(open(os.path.join(d, f"{name}.csv")).read().splitlines()) - 1
        check(s["good"] / runs >= share, f"sweep {name} without [estimator]: {s['good']}/{runs} good (needs {share:.1%})")
        if name.startswith("e3"):
            # the defaults choose the tuned campaign's moving average for the encoder velocity: its
            # identified sides within 5 % of the rig (200 of 294; unfiltered defaults: 76 of 288)
            with open(os.path.join(d, f"{name}.csv")) as fh:
                ident = sum((r["identified_r"] == "1") + (r["identified_l"] == "1") for r in csv.DictReader(fh))
            check(s["sides_within_tolerance"] >= 0.65 * ident,
                  f"sweep {name} without [estimator]: {s['sides_within_tolerance']}/{ident} sides within 5 % (floor 65 %)")
sys.exit(fail)
