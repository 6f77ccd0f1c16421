"""lash.Estimator(reguess=True): the switching guesses follow the evidence online (docs/method.md A4.8).
The plant (first order behind a deadzone, eq. 17) is simulated here with numpy."""
import math

import numpy as np

import lash


def plant(edges_r, n, dt=0.01, seed=1):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    v = 8.0 * np.sin(2 * math.pi * 0.25 * t)
    y = np.zeros(n)
    for k in range(1, n):
        cr = edges_r[k - 1]
        u = v[k - 1] - cr if v[k - 1] > cr else (v[k - 1] + 2.0 if v[k - 1] < -2.0 else 0.0)
        y[k] = 0.9 * y[k - 1] + 0.1 * u
    return v, y + 1e-3 * rng.standard_normal(n)


def run(reguess):
    n = 12000
    edge = np.where(np.arange(n) < 4000, 2.0, 5.0)  # the right edge moves past the guess 3 at 40 s
    v, y = plant(edge, n)
    e = lash.Estimator("input-deadzone", 0.01, guess_right=3.0, guess_left=-3.0, reguess=reguess, preset="thesis")
    e.update_many(v, y)
    return e


def test_guess_follows_an_edge_that_drifts_past_it():
    e = run(True)
    assert e.reguesses["right"] >= 1
    assert e.guesses["right"] > 5.0  # beyond the new edge
    assert abs(e.params()["c_r"] - 5.0) < 0.05 * 5.0
    assert e.reguesses["left"] == 0  # the left side's guess was right all along


def test_without_reguess_the_side_stays_wrong():
    e = run(False)
    assert e.reguesses["right"] == 0 and e.guesses["right"] == 3.0
    assert not math.isfinite(e.params()["c_r"])  # wrong_guess: not identified
