#!/usr/bin/env python3
"""RLS with lambda = 1 and a large P0 agrees with statsmodels RecursiveLS on the same
regression to 1e-6 relative, at the end and along the way (every 500 samples).

Data: a first-order plant y(k) = 0.9 y(k-1) + 0.5 v(k-1) - 150 + noise (c = -e/b1 = 300: on its
own side of zero, and between the guesses -1e9 and 350 as eq. 18 requires) with a seeded random
input, uniform over 400..2000 so that the constant column is not nearly collinear with v. `lash estimate --model input-deadzone` with guess_right below every input, so every
sample updates the right key: the regression is phi = [-y(k-1), v(k-1), 1] -> [a1, b1, e],
the thesis's 3-parameter RLS (eq. 13-16); lash reports c = -e/b1, converted back here."""
import csv, json, os, subprocess, sys, tempfile

import numpy as np

try:
    import statsmodels.api as sm
except ImportError:
    print("statsmodels missing: skipped")
    sys.exit(77)

LASH = os.environ["LASH"]
rng = np.random.default_rng(12345)
n = 5000
dt = 0.01
v = rng.uniform(400.0, 2000.0, n)              # always above the guess 350 -> every sample updates 'right'
y = np.zeros(n)
for k in range(1, n):
    y[k] = 0.9 * y[k - 1] + 0.5 * v[k - 1] - 150.0
y_meas = y + 2.0 * rng.standard_normal(n)      # measurement noise: LS is not exact, so the comparison is real

fail = 0
with tempfile.TemporaryDirectory() as d:
    data = os.path.join(d, "d.csv")
    with open(data, "w") as f:
        f.write("t,v,y\n")
        for k in range(n):
            f.write(f"{k * dt!r},{v[k]!r},{y_meas[k]!r}\n")
    trace = os.path.join(d, "trace.csv")
    out = subprocess.run([LASH, "estimate", "--model", "input-deadzone", "--guess-left", "-1e9", "--guess-right",
                          "350", "--preset", "thesis", "--outlier-gate", "0", "--lambda", "1", "--p0", "1e6", "--min-updates", "1",
                          data, "--json", "-o", trace],
                         check=True, capture_output=True, text=True).stdout
    j = json.loads(out)
    with open(trace) as f:
        rows = list(csv.DictReader(f))

# the same regression for statsmodels: row k is phi(k) = [-y(k-1), v(k-1), 1] with y(-1) = v(-1) = 0
y1 = np.concatenate([[0.0], y_meas[:-1]])
v1 = np.concatenate([[0.0], v[:-1]])
# Row 0 (phi(0) = [0, 0, 1]) is not an update in lash: v(-1) = 0 lies inside the guesses, so the
# first regression row is k = 1. coef[:, k] below is the estimate after rows 1..k.
endog = y_meas[1:]
exog = np.column_stack([-y1, v1, np.ones(n)])[1:]
res = sm.RecursiveLS(endog, exog).fit()
coef = np.concatenate([np.full((3, 1), np.nan), res.recursive_coefficients.filtered], axis=1)  # (3, n)

# lash's a1, b1, c = -e/b1 per step -> back to e
worst = 0.0
for k in list(range(500, n, 500)) + [n - 1]:
    a1 = float(rows[k]["a1_r"]); b1 = float(rows[k]["b1_r"]); e = -float(rows[k]["c_r"]) * b1
    ref = coef[:, k]
    for got, want, name in ((a1, ref[0], "a1"), (b1, ref[1], "b1"), (e, ref[2], "e")):
        rel = abs(got - want) / abs(want)
        worst = max(worst, rel)
        if rel > 1e-6:
            print(f"FAIL k={k} {name}: lash {got!r} statsmodels {want!r} rel {rel:.2e}")
            fail = 1
final = (j["right"]["a1"], j["right"]["b1"], -j["right"]["c"] * j["right"]["b1"])
for got, want, name in zip(final, coef[:, -1], ("a1", "b1", "e")):
    rel = abs(got - want) / abs(want)
    worst = max(worst, rel)
    print(f"{'ok  ' if rel <= 1e-6 else 'FAIL'} final {name}: lash {got!r} statsmodels {want!r} rel {rel:.2e}")
    fail |= rel > 1e-6
print(f"worst relative difference {worst:.2e} (bound 1e-6)")
sys.exit(1 if fail else 0)
