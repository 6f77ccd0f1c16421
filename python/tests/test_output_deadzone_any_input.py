"""Issue 30 item 1 for the output-deadzone model (G -> DZ, docs/method.md §A4.3): lash.estimate with
its defaults on random-phase multisines and random-level steps through random plants, with E2-level
noise (sigma = 1.4 % of the output's amplitude). The plant is simulated here in numpy (x(k) =
-a1 x(k-1) + b1 v(k-1), y = DZ(x)), not by lash.

Measured before the output-deadzone model was refined by output error and took its zero threshold
from the noise (3 sigma): of 20 multisine runs, 4 identified a side, with b1 60-89 % and c 90-98 %
off (every noise sample above 0 inside the deadzone was a right-side update, and the regressor
y(k-1) is noisy). After: every side of every run identified, a1, b1, c within 0.4 %; 114 of the
120 95 % intervals hold the truth. Noise-free: the plant to 4e-6. In closed loop (a PI controller on a
random reference) every side within 0.33 %; on a PRBS each side is within 0.34 % or not
identified."""
import math

import numpy as np

import lash
from conftest import run_lash

DT = 0.005


def plant(seed):
    """seed's random plant: tau 0.05..0.5 s, K 0.5..3, edges 80..300 (output unit); and the
    generator the input and the noise are drawn from after it"""
    rng = np.random.default_rng([seed, 7])
    tau, k = rng.uniform(0.05, 0.5), rng.uniform(0.5, 3.0)
    a1 = -math.exp(-DT / tau)
    return rng, tau, k, a1, k * (1 + a1), rng.uniform(80, 300), -rng.uniform(80, 300)


def case(seed, kind):
    rng, tau, k, a1, b1, cr, cl = plant(seed)
    n = 30000
    t = np.arange(n) * DT
    if kind == "multisine":
        f = np.linspace(0.05, 1.5, 25)
        x = np.sin(2 * np.pi * np.outer(t, f) + rng.uniform(0, 2 * np.pi, 25)).sum(axis=1)
        v = x / np.abs(x).max()
    else:  # random levels held 0.5 s
        v = np.repeat(rng.uniform(-1.0, 1.0, n // 100 + 1), 100)[:n]
    v = v * 2.5 * max(cr, -cl) / k
    x, y0 = 0.0, np.zeros(n)
    for i in range(1, n):
        x = -a1 * x + b1 * v[i - 1]
        y0[i] = x - cr if x > cr else (x - cl if x < cl else 0.0)
    y = y0 + rng.normal(0.0, 0.014 * np.abs(y0).max(), n)
    return t, v, y, dict(a1=a1, b1=b1, right=cr, left=cl)


def test_output_deadzone_identifies_from_multisines_and_steps_with_noise():
    worst = {"a1": 0.0, "b1": 0.0, "c": 0.0}
    covered, intervals = 0, 0
    for kind in ("multisine", "steps"):
        for seed in range(1, 11):
            t, v, y, p = case(seed, kind)
            r = lash.estimate(t, v, y, model="output-deadzone").to_dict()
            assert r["output_error"]["used"], (kind, seed, r["output_error"])
            for side in ("right", "left"):
                j = r[side]
                assert j["identified"], (kind, seed, side, j["reason"])
                for key, want in (("a1", p["a1"]), ("b1", p["b1"]), ("c", p[side])):
                    worst[key] = max(worst[key], abs(j[key] / want - 1.0))
                    lo, hi = j["ci95"][key]
                    covered += lo <= want <= hi
                    intervals += 1
    print(worst, covered, intervals)
    # issue 30's bounds: a1 1 %, b1 3 %, c 3 % (measured: 0.007 %, 0.37 %, 0.39 %)
    assert worst["a1"] <= 0.01 and worst["b1"] <= 0.03 and worst["c"] <= 0.03, worst
    # the 95 % intervals hold the truth at least 90 % of the time
    assert covered >= 0.90 * intervals, (covered, intervals)


def closed_loop(seed, noise=True):
    """The same random plants under a PI controller (kp = 0.3/K, ki = kp/tau, the input clamped
    to 4 max|c|/K) tracking a random reference (levels in +-1.5 max|c|, held 1 s): the noise is
    in the loop (the controller reads y + e), sigma = 1.4 % of 2.5 max|c|."""
    rng, tau, k, a1, b1, cr, cl = plant(seed)
    n = 30000
    e_n = rng.normal(0.0, 0.014 * 2.5 * max(cr, -cl), n) if noise else np.zeros(n)
    ref = np.repeat(rng.uniform(-1.5, 1.5, n // 200 + 1), 200)[:n] * max(cr, -cl)
    kp, ki, vmax = 0.3 / k, 0.3 / (k * tau), 4.0 * max(cr, -cl) / k
    v, y = np.zeros(n), np.zeros(n)
    x = integ = 0.0
    for i in range(n):
        y0 = 0.0
        if i > 0:
            x = -a1 * x + b1 * v[i - 1]
            y0 = x - cr if x > cr else (x - cl if x < cl else 0.0)
        y[i] = y0 + e_n[i]
        integ += (ref[i] - y[i]) * DT
        v[i] = max(-vmax, min(vmax, kp * (ref[i] - y[i]) + ki * integ))
    return np.arange(n) * DT, v, y, dict(a1=a1, b1=b1, right=cr, left=cl)


def test_output_deadzone_identifies_in_closed_loop():
    # issue 30's closed-loop operating data: the output-error fit is consistent in closed loop for
    # a strictly proper plant (docs/method.md A4.4c, the direct approach). Measured: every side of
    # the 10 seeds identified, a1 within 0.014 %, b1 0.33 %, c 0.33 %; noise-free the plant
    worst = {"a1": 0.0, "b1": 0.0, "c": 0.0}
    for seed in range(1, 11):
        t, v, y, p = closed_loop(seed)
        r = lash.estimate(t, v, y, model="output-deadzone").to_dict()
        assert r["output_error"]["used"], (seed, r["output_error"])
        for side in ("right", "left"):
            j = r[side]
            assert j["identified"], (seed, side, j["reason"])
            for key, want in (("a1", p["a1"]), ("b1", p["b1"]), ("c", p[side])):
                worst[key] = max(worst[key], abs(j[key] / want - 1.0))
    print(worst)
    assert worst["a1"] <= 0.01 and worst["b1"] <= 0.03 and worst["c"] <= 0.03, worst
    t, v, y, p = closed_loop(1, noise=False)
    r = lash.estimate(t, v, y, model="output-deadzone").to_dict()
    for side in ("right", "left"):
        for key, want in (("a1", p["a1"]), ("b1", p["b1"]), ("c", p[side])):
            assert abs(r[side][key] / want - 1.0) < 1e-4, (side, key, r[side][key], want)


def test_output_deadzone_on_a_prbs_is_right_or_not_identified(tmp_path):
    # a two-level input (+-2.5 max|c|/K, each level held 0.3 s): a side whose updates sit at its
    # own level is not_excited (b1 and c are one sum there); where the output passes a side while
    # the input has switched, the side sees both levels and is identified. Measured with noise:
    # seeds 3, 4, 5, 9, 10 both sides within 0.34 %; 2, 6, 7, 8 both not_excited; seed 1 right
    # not_excited and left poor_fit: the refinement cannot run with a side unexcited, so its fit
    # checks the other side (docs/method.md A4.4c) and moves c by 43 % (before the check: left
    # identified with c 43 % off)
    identified = 0
    for seed in range(1, 11):
        rng, tau, k, a1, b1, cr, cl = plant(seed)
        n = 30000
        e_n = rng.normal(0.0, 0.014 * 2.5 * max(cr, -cl), n)
        v = np.repeat(np.where(rng.random(n // 60 + 1) < 0.5, -1.0, 1.0), 60)[:n] * 2.5 * max(cr, -cl) / k
        x, y = 0.0, np.zeros(n)
        for i in range(1, n):
            x = -a1 * x + b1 * v[i - 1]
            y[i] = x - cr if x > cr else (x - cl if x < cl else 0.0)
        r = lash.estimate(np.arange(n) * DT, v, y + e_n, model="output-deadzone").to_dict()
        if seed == 1:
            # the CLI's text names the flagged side and what to do: lash's preset already tried
            # the refinement, so the advice is the input's, not "use lash's preset"
            path = tmp_path / "prbs.csv"
            np.savetxt(path, np.column_stack([np.arange(n) * DT, v, y + e_n]), delimiter=",", header="t,v,y",
                       comments="")
            out = run_lash("estimate", path, "--model", "output-deadzone")
            assert r["output_error"]["check"]["left"]["moved"] == "c", r["output_error"]
            line = [x for x in out.splitlines() if x.startswith("output error check:")]
            assert len(line) == 1 and "left side's c by" in line[0], out
            assert "drive beyond both edges" in line[0] and "use lash's preset" not in line[0], line
        for side, c in (("right", cr), ("left", cl)):
            j = r[side]
            if not j["identified"]:
                assert j["reason"] in ("not_excited", "poor_fit"), (seed, side, j["reason"])
                continue
            identified += 1
            for key, want in (("a1", a1), ("b1", b1), ("c", c)):
                assert abs(j[key] / want - 1.0) <= 0.03, (seed, side, key, j[key], want)
    assert identified >= 10, identified


def test_output_deadzone_noise_free_is_the_plant():
    for kind in ("multisine", "steps"):
        for seed in (1, 2, 3):
            t, v, y, p = case(seed, kind)
            x, y0 = 0.0, np.zeros(len(v))
            for i in range(1, len(v)):
                x = -p["a1"] * x + p["b1"] * v[i - 1]
                y0[i] = x - p["right"] if x > p["right"] else (x - p["left"] if x < p["left"] else 0.0)
            r = lash.estimate(t, v, y0, model="output-deadzone").to_dict()
            for side in ("right", "left"):
                j = r[side]
                assert j["identified"], (kind, seed, side, j["reason"])
                for key, want in (("a1", p["a1"]), ("b1", p["b1"]), ("c", p[side])):
                    assert abs(j[key] / want - 1.0) < 1e-5, (kind, seed, side, key, j[key], want)  # measured: 3.9e-6


def test_a_quantised_output_is_not_refined_by_default():
    # an output on a grid (an encoder velocity): lash's defaults keep the switching estimate (the
    # motor cart's rig, docs/sweep.md); --output-error / output_error=True refines it
    t, v, y, p = case(1, "multisine")
    q = 0.5
    yq = np.round(y / q) * q
    r = lash.estimate(t, v, yq, model="output-deadzone").to_dict()
    assert "output_error" not in r or not r["output_error"]["used"], r.get("output_error")
    r = lash.estimate(t, v, yq, model="output-deadzone", output_error=True).to_dict()
    assert r["output_error"]["used"], r["output_error"]
