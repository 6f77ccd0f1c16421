"""Issue 30 item 1 for the output-deadzone model (G -> DZ, docs/method.md §A4.3): lash.estimate with
its defaults on random-phase multisines and random-level steps through random plants, with E2-level
noise (sigma = 1.4 % of the output's amplitude). The plant is simulated here in numpy (x(k) =
-a1 x(k-1) + b1 v(k-1), y = DZ(x)), not by lash.

Measured before the output-deadzone model was refined by output error and took its zero threshold
from the noise (3 sigma): of 20 multisine runs, 4 identified a side, with b1 60-89 % and c 90-98 %
off (every noise sample above 0 inside the deadzone was a right-side update, and the regressor
y(k-1) is noisy). After: every side of every run identified, a1, b1, c within 0.4 %; 114 of the
120 95 % intervals hold the truth. Noise-free: the plant to 4e-6."""
import math

import numpy as np

import lash

DT = 0.005


def case(seed, kind):
    rng = np.random.default_rng([seed, 7])
    tau, k = rng.uniform(0.05, 0.5), rng.uniform(0.5, 3.0)
    a1 = -math.exp(-DT / tau)
    b1 = k * (1 + a1)
    cr, cl = rng.uniform(80, 300), -rng.uniform(80, 300)  # output unit
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
