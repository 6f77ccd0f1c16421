#!/usr/bin/env python3
"""Issue 12 must-show: over 20 seeds of E2 (the eq-34 plant, 1 Hz sine of amplitude 600, noise
variance 200, 200 s), `lash estimate rec.csv --model deadzone-deadband --json` with lash's default
settings gives 95 % intervals (ci95) that contain the truth for >= 85 % of the (parameter, seed)
pairs — a1, b1, c, d, K, tau_s per side — and none wider than +-25 % of its parameter.
Truth: the plant file's parameters (thesis eq. 34); K = b1/(1 + a1), tau = -T/ln(-a1) by hand."""
import json, math, os, subprocess, sys, tempfile

LASH = os.environ["LASH"]
SRC = os.environ["LASH_SOURCE_DIR"]
truth = {"right": dict(a1=-0.96, b1=0.1, c=200.0, d=30.0), "left": dict(a1=-0.94, b1=0.15, c=-300.0, d=50.0)}
for s in truth.values():
    s["K"] = s["b1"] / (1 + s["a1"])
    s["tau_s"] = -0.005 / math.log(-s["a1"])
pairs = covered = wide = 0
with tempfile.TemporaryDirectory() as d:
    for seed in range(1, 21):
        rec = os.path.join(d, f"e2_{seed}.csv")
        subprocess.run([LASH, "simulate", f"{SRC}/config/plants/thesis_eq34.toml", "--input", "sine", "--amplitude", "600",
                        "--frequency", "1", "--duration", "200", "--noise-variance", "200", "--seed", str(seed), "-o", rec],
                       check=True, capture_output=True)
        j = json.loads(subprocess.run([LASH, "estimate", rec, "--model", "deadzone-deadband", "--json"], check=True,
                                      capture_output=True, text=True).stdout)
        for side, t in truth.items():
            for k, v in t.items():
                pairs += 1
                iv = j[side]["ci95"][k]
                if iv is not None and iv[0] <= v <= iv[1]:
                    covered += 1
                else:
                    print(f"seed {seed} {side} {k}: {v} not in {iv}")
                if iv is None or (iv[1] - iv[0]) / 2 > 0.25 * abs(v):
                    wide += 1
                    print(f"seed {seed} {side} {k}: interval {iv} missing or wider than +-25 % of {v}")
share = covered / pairs
print(f"{covered}/{pairs} = {100 * share:.1f} % of (parameter, seed) pairs covered; {wide} missing or too wide")
sys.exit(0 if share >= 0.85 and wide == 0 else 1)
