#!/usr/bin/env python3
"""Speed of lash's RLS against statsmodels RecursiveLS on the same regression, one run each.

The regression is the thesis's 3-parameter RLS (eq. 13-16): phi = [-y(k-1), v(k-1), 1] on a
noisy first-order plant; `lash estimate --model input-deadzone` with a guess below every input
updates on every sample, lambda = 1, P0 = 1e6 (the settings of tests/cli/identify_rls_statsmodels.py,
which checks that both agree to 1e-6). Prints both times, the final estimates and the ratio.

usage: LASH=build/bin/lash /usr/bin/python3 bench/rls_vs_statsmodels.py [samples]
"""
import json, os, re, subprocess, sys, tempfile, time

import numpy as np
import statsmodels.api as sm

n = int(sys.argv[1]) if len(sys.argv) > 1 else 200000
lash = os.environ.get("LASH", "build/bin/lash")
rng = np.random.default_rng(1)
v = 100.0 + 50.0 * rng.standard_normal(n)
y = np.zeros(n)
for k in range(1, n):
    y[k] = 0.9 * y[k - 1] + 0.5 * v[k - 1] + 150.0
y += 2.0 * rng.standard_normal(n)

with tempfile.TemporaryDirectory() as d:
    path = os.path.join(d, "rec.csv")
    np.savetxt(path, np.column_stack([np.arange(n) * 0.01, v, y]), delimiter=",", header="t,v,y", comments="",
               fmt="%.17g")
    t0 = time.perf_counter()
    p = subprocess.run([lash, "estimate", "--model", "input-deadzone", "--guess-left", "-1e9", "--guess-right", "-250",
                        "--lambda", "1", "--p0", "1e6", "--min-updates", "1", "--timing", "--json", path],
                       check=True, capture_output=True, text=True)
    lash_wall = time.perf_counter() - t0
    lash_est = float(re.search(r"in ([0-9.e+-]+) s", p.stderr).group(1))
    j = json.loads(p.stdout)

y1 = np.concatenate([[0.0], y[:-1]])
v1 = np.concatenate([[0.0], v[:-1]])
exog = np.column_stack([-y1, v1, np.ones(n)])
t0 = time.perf_counter()
res = sm.RecursiveLS(y, exog).fit()
sm_time = time.perf_counter() - t0
c = res.params

print(f"samples                         {n}")
print(f"statsmodels RecursiveLS fit     {sm_time:.4f} s   a1={c[0]:.9f} b1={c[1]:.9f} e={c[2]:.6f}")
print(f"lash RLS (estimator only)       {lash_est:.6f} s   a1={j['right']['a1']:.9f} b1={j['right']['b1']:.9f} "
      f"e={-j['right']['c'] * j['right']['b1']:.6f}")
print(f"lash estimate, whole process    {lash_wall:.4f} s   (CSV parsing included)")
print(f"speed ratio statsmodels / lash: {sm_time / lash_est:.0f}x (estimator), {sm_time / lash_wall:.1f}x (whole process)")
