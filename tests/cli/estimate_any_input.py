#!/usr/bin/env python3
"""Issue 30 item 1, measured: `lash estimate --model deadzone-deadband` with its defaults on 20
random-phase multisines, 20 random-level step sequences and 20 closed-loop operating records,
each through its own random DZ -> G -> DB plant (edges 80-300, half-widths 5-50, tau 0.05-0.5 s,
K 0.5-3) with E2-level noise (scripts/any_input_measure.py). Truth: the plant's values. A run
counts when every side is identified with a1 within 1 %, b1 3 %, c 3 %, d 10 % (issue 30's
bounds). Floors: what the output-error refinement (docs/method.md §A4.4c) reaches today: every
run but multisine seed 8, whose deadbands (47 / 45) swallow most of the slow plant's motion (the
output's peak is 24): it must be `identified: false` with an input reason. Before the refinement:
multisine 13, steps 19, closed-loop 0; before model switching: 0 / 2. No run may be identified
outside the bounds. The same plants without their deadband through --model input-deadzone.
Item 3: the coverage of the identified sides' 95 % intervals over the same runs."""
import json, os, subprocess, sys, tempfile

SRC = os.environ["LASH_SOURCE_DIR"]
sys.path.insert(0, os.path.join(SRC, "scripts"))
from any_input_measure import TOL, run_one, within_bounds  # noqa: E402

LASH = os.environ["LASH"]
fail = 0


def check(cond, what):
    global fail
    print(("ok   " if cond else "FAIL ") + what)
    fail |= not cond


# --model-switching forces the iteration; it needs the pooled regression, and only
# deadzone-deadband reads it (exit 2 naming the option)
with tempfile.TemporaryDirectory() as d:
    r = run_one(LASH, "multisine", 1, d)
    rec = os.path.join(d, "multisine1_rec.csv")
    p = subprocess.run([LASH, "estimate", rec, "--model", "deadzone-deadband", "--model-switching", "--json"],
                       capture_output=True, text=True)
    j = json.loads(p.stdout) if p.returncode == 0 else {}
    check(p.returncode == 0 and j["model_switching"]["used"] and j["model_switching"]["starts"] >= 1,
          f"--model-switching: used ({j.get('model_switching')})")
    for extra in (["--model", "deadzone-deadband", "--pooled=false"], ["--model", "input-deadzone"]):
        p = subprocess.run([LASH, "estimate", rec, "--model-switching", *extra], capture_output=True, text=True)
        check(p.returncode == 2 and "model-switching" in p.stderr, f"--model-switching {extra}: exit {p.returncode}: "
              f"{p.stderr.strip()}")
INPUT_REASONS = {"not_updated", "not_excited", "wrong_guess"}


def measure(model, floors, why, covered):
    """20 seeds of each kind: the runs within the bounds against the floor; every run outside
    them not identified (deadzone-deadband: with an input reason); the intervals' coverage into
    `covered`. Returns (identified sides, of them with intervals)."""
    global fail
    sides = with_ci = 0
    with tempfile.TemporaryDirectory() as d:
        for kind, floor in floors.items():
            good = 0
            for seed in range(1, 21):
                r = run_one(LASH, kind, seed, d, model=model)
                sides += r["sides_identified"]
                with_ci += sum(r["cover"][f"a1_{s}"] is not None for s in "rl")
                for key, inside in r["cover"].items():
                    if inside is not None:
                        covered[key.split("_")[0]][0] += inside
                        covered[key.split("_")[0]][1] += 1
                ok = within_bounds(r)
                good += ok
                if not ok:  # outside the bounds: never identified
                    check(not r["identified"] and (why is None or any(x in why for x in r["reasons"].values())),
                          f"{model} {kind} seed {seed}: outside the bounds, so not identified ({r['reasons']})")
                print(f"{model} {kind} seed {seed}: {'within' if ok else 'not within'} the bounds; "
                      + " ".join(f"{k} {100 * v:.2f}%" for k, v in r["errs"].items()))
            print(("ok   " if good >= floor else "FAIL ") + f"{model} {kind}: {good} of 20 runs within the bounds "
                  f"(floor {floor})")
            fail |= good < floor
    return sides, with_ci


covered = {k: [0, 0] for k in TOL}  # per parameter: truth inside the 95 % interval, intervals
sides, with_ci = measure("deadzone-deadband", {"multisine": 19, "steps": 20, "closed-loop": 20}, INPUT_REASONS,
                         covered)
# input-deadzone on the same plants without their deadband (DZ -> G): the output-error fit takes
# the runs within the bounds (a1 1 %, b1 3 %, c 3 %) from 0 (12 identified outside: b1 up to 62 %
# off, the regressor y(k-1)'s noise) to 20 / 20 / 19; the closed-loop run left (seed 4) has both
# sides unphysical and no start for the fit
cov_dz = {k: [0, 0] for k in TOL if k != "d"}
s_dz, ci_dz = measure("input-deadzone", {"multisine": 20, "steps": 20, "closed-loop": 19}, None, cov_dz)
# Issue 30 item 3: the 95 % intervals of the identified sides hold the truth at least 90 % of the
# time, per parameter (the output-error fit's sigma^2 (J'J)^-1 by the delta method,
# docs/identification.md); and most identified sides have one (measured: 118 of 118)
for model, cov in (("deadzone-deadband", covered), ("input-deadzone", cov_dz)):
    for k, (inside, n) in cov.items():
        check(n > 0 and inside >= 0.90 * n, f"{model} {k}: the truth inside {inside} of {n} 95 % intervals (>= 90 %)")
check(with_ci >= 110, f"deadzone-deadband: {with_ci} of {sides} identified sides have 95 % intervals (floor 110)")
check(ci_dz >= 110, f"input-deadzone: {ci_dz} of {s_dz} identified sides have 95 % intervals (floor 110)")
# Closed-loop operating data (the valve scenario's PI + feedforward + deadzone inverse tracking a
# random-level reference, scripts/any_input_measure.py closed_loop), noise-free: every side of
# every seed identified, every parameter within 1e-4 of the plant (measured: 9.2e-6 at worst).
# With E2-level noise fed back through the controller: the floor above.
with tempfile.TemporaryDirectory() as d:
    worst, ident = 0.0, 0
    for seed in range(1, 21):
        r = run_one(LASH, "closed-loop", seed, d, noise=False)
        ident += r["identified"]
        worst = max(worst, max(r["errs"].values()))
    check(ident == 20 and worst <= 1e-4, f"closed-loop, noise-free: {ident} of 20 runs identified, worst relative "
          f"error {worst:.3g} (<= 1e-4)")
sys.exit(fail)
