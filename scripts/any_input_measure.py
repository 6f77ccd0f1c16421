#!/usr/bin/env python3
"""Issue 30 item 1: lash estimate --model deadzone-deadband with its defaults on the inputs users
have: random-phase multisines and random-level steps, through random DZ -> G -> DB plants (edges,
widths and dynamics not from the thesis) with E2-level measurement noise (sigma = 1.4 % of the
output's amplitude, as E2's variance 200 on E1's +-1000). Prints each run's worst errors and
returns them; tests/cli/estimate_any_input.py asserts on them.
usage: any_input_measure.py LASH [N | A-B (seeds)] [kind ...]"""
import json, os, subprocess, sys, tempfile

import numpy as np

DT = 0.005
TOL = {"a1": 0.01, "b1": 0.03, "c": 0.03, "d": 0.10}  # issue 30's bounds (relative)


def plant(rng):
    """a random plant: edges 80..300 (each side), half-widths 5..50, tau 0.05..0.5 s, K 0.5..3"""
    cr, cl = rng.uniform(80, 300), -rng.uniform(80, 300)
    dr, dl = rng.uniform(5, 50), rng.uniform(5, 50)
    tau, k = rng.uniform(0.05, 0.5), rng.uniform(0.5, 3.0)
    a1 = -np.exp(-DT / tau)
    b1 = k * (1 + a1)
    return dict(cr=cr, cl=cl, dr=dr, dl=dl, a1=a1, b1=b1)


def plant_toml(p):
    return (f'name = "random"\ndt = {DT}\n\n[[blocks]]\nkind = "deadzone"\nleft = {p["cl"]!r}\nright = {p["cr"]!r}\n\n'
            f'[[blocks]]\nkind = "linear"\na1 = {p["a1"]!r}\nb1 = {p["b1"]!r}\n\n'
            f'[[blocks]]\nkind = "deadband"\nhalf_width = {{ left = {p["dl"]!r}, right = {p["dr"]!r} }}\n')


def signal(kind, rng, n, amp):
    t = np.arange(n) * DT
    if kind == "multisine":  # 25 random-phase lines 0.05-1.5 Hz (issue 30's record)
        f = np.linspace(0.05, 1.5, 25)
        x = np.sin(2 * np.pi * np.outer(t, f) + rng.uniform(0, 2 * np.pi, 25)).sum(axis=1)
        return amp * x / np.abs(x).max()
    # random-level steps: levels uniform in [-amp, amp], each held 0.2-1 s
    v = np.empty(n)
    k = 0
    while k < n:
        h = int(rng.uniform(0.2, 1.0) / DT)
        v[k:k + h] = rng.uniform(-amp, amp)
        k += h
    return v


def run_one(lash, kind, seed, d, duration=150.0, amp=500.0):
    rng = np.random.default_rng(1000 * seed + (1 if kind == "multisine" else 2))
    p = plant(rng)
    n = int(round(duration / DT))
    v = signal(kind, rng, n, amp)
    inp, pl, rec = (os.path.join(d, f"{kind}{seed}_{x}") for x in ("in.csv", "plant.toml", "rec.csv"))
    np.savetxt(inp, np.c_[np.arange(n) * DT, v], delimiter=",", header="t,v", comments="", fmt="%.17g")
    open(pl, "w").write(plant_toml(p))
    # noise: 1.4 % of the noise-free output's amplitude
    sim = subprocess.run([lash, "simulate", pl, "--input-file", inp, "-o", rec], capture_output=True, text=True)
    assert sim.returncode == 0, sim.stderr
    y0 = np.genfromtxt(rec, delimiter=",", names=True)["y"]
    sigma = 0.014 * np.abs(y0).max()
    sim = subprocess.run([lash, "simulate", pl, "--input-file", inp, "--noise-variance", repr(sigma ** 2),
                          "--seed", str(seed), "-o", rec], capture_output=True, text=True)
    assert sim.returncode == 0, sim.stderr
    extra = os.environ.get("ANY_INPUT_ARGS", "").split()  # settings to compare (exploration)
    e = subprocess.run([lash, "estimate", rec, "--model", "deadzone-deadband", "--json", *extra], capture_output=True,
                       text=True)
    assert e.returncode == 0, e.stderr
    j = json.loads(e.stdout)
    truth = {"right": dict(a1=p["a1"], b1=p["b1"], c=p["cr"], d=p["dr"]),
             "left": dict(a1=p["a1"], b1=p["b1"], c=p["cl"], d=p["dl"])}
    errs, ident, cover = {}, True, {}
    for side in ("right", "left"):
        ident = ident and j[side]["identified"]
        for k, want in truth[side].items():
            got = j[side][k]
            errs[f"{k}_{side[0]}"] = float("inf") if got is None else abs(got / want - 1)
            # an identified side's 95 % interval: does it hold the truth? (None: no interval)
            ci = j[side]["ci95"].get(k) if j[side]["identified"] else None
            cover[f"{k}_{side[0]}"] = None if ci is None else bool(ci[0] <= want <= ci[1])
    return dict(kind=kind, seed=seed, identified=ident, errs=errs, plant=p, sigma=sigma,
                switching=j.get("model_switching"), cover=cover,
                sides_identified=sum(bool(j[s]["identified"]) for s in ("right", "left")))


def main():
    lash = sys.argv[1]
    arg = sys.argv[2] if len(sys.argv) > 2 else "20"  # N (seeds 1..N) or A-B
    lo, hi = (int(x) for x in arg.split("-")) if "-" in arg else (1, int(arg))
    kinds = sys.argv[3:] or ["multisine", "steps"]
    out = []
    with tempfile.TemporaryDirectory() as d:
        for kind in kinds:
            for seed in range(lo, hi + 1):
                r = run_one(lash, kind, seed, d)
                ok = r["identified"] and all(r["errs"][f"{k}_{s}"] <= TOL[k] for k in TOL for s in "rl")
                worst = {k: max(r["errs"][f"{k}_r"], r["errs"][f"{k}_l"]) for k in TOL}
                print(f"{kind:9s} seed {seed:2d} {'ok  ' if ok else 'FAIL'} identified {r['identified']} " +
                      " ".join(f"{k} {100 * w:.2f}%" for k, w in worst.items()) +
                      f" passes {r['switching'] and r['switching']['passes']}", flush=True)
                out.append(r)
    return out


if __name__ == "__main__":
    main()
