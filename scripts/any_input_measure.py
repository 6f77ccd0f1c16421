#!/usr/bin/env python3
"""Issue 30 item 1: lash estimate --model deadzone-deadband with its defaults on the inputs users
have: random-phase multisines, random-level steps and closed-loop operating data (the valve
scenario's controller law on the plant, tracking a random-level reference), through random
DZ -> G -> DB plants (edges,
widths and dynamics not from the thesis) with E2-level measurement noise (sigma = 1.4 % of the
output's amplitude, as E2's variance 200 on E1's +-1000). Prints each run's worst errors and
returns them; tests/cli/estimate_any_input.py asserts on them.
usage: any_input_measure.py LASH [N | A-B (seeds)] [kind ...]   (kinds: multisine steps closed-loop)
ANY_INPUT_MODEL=input-deadzone: the plants without their deadband, --model input-deadzone."""
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
    """DZ -> G -> DB; without the deadband block when both half-widths are 0 (input-deadzone's plant)"""
    toml = (f'name = "random"\ndt = {DT}\n\n[[blocks]]\nkind = "deadzone"\nleft = {p["cl"]!r}\nright = {p["cr"]!r}\n\n'
            f'[[blocks]]\nkind = "linear"\na1 = {p["a1"]!r}\nb1 = {p["b1"]!r}\n')
    if p["dl"] == 0 and p["dr"] == 0:
        return toml
    return toml + f'\n[[blocks]]\nkind = "deadband"\nhalf_width = {{ left = {p["dl"]!r}, right = {p["dr"]!r} }}\n'


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


class PlantSim:
    """The plant of plant_toml(p) written out by hand, one sample at a time (lash's Plant: y(k) from
    v up to k-1; the deadband's side by the sign of v(k-1)); checked against `lash simulate`."""

    def __init__(self, p):
        self.p, self.w, self.u1, self.v1, self.y = p, 0.0, 0.0, 0.0, 0.0

    def output(self):  # y(k), before v(k) is known
        p = self.p
        self.w = -p["a1"] * self.w + p["b1"] * self.u1
        d = p["dr"] if self.v1 >= 0 else p["dl"]
        if self.w < self.y - d:
            self.y = self.w + d
        elif self.w > self.y + d:
            self.y = self.w - d
        return self.y

    def drive(self, v):  # v(k)
        p = self.p
        self.u1 = v - p["cr"] if v > p["cr"] else (v - p["cl"] if v < p["cl"] else 0.0)
        self.v1 = v


def closed_loop(p, rng, n, sigma, noise_seed):
    """The valve scenario's law (config/scenarios/closed_loop/valve_no_drift.toml) scaled to the
    plant's gain K: u = kp (r - y) + ki int(r - y) + r/K (integration held while the command is
    clamped), i = DI(u) with a deadzone inverse at 90 % of the true edges (a rough calibration),
    clamped to +-2000. The reference: random levels in +-400 K held 0.5-2 s. Returns (v, y) with
    the measured y (noise sigma, fed back)."""
    k_gain = p["b1"] / (1 + p["a1"])
    kp, ki = 0.5 * 2.15 / k_gain, 10.0 * 2.15 / k_gain
    noise = np.random.default_rng(noise_seed).normal(0.0, sigma, n) if sigma > 0 else np.zeros(n)
    r = np.empty(n)
    k = 0
    while k < n:
        h = int(rng.uniform(0.5, 2.0) / DT)
        r[k:k + h] = rng.uniform(-400, 400) * k_gain
        k += h
    sim, integ = PlantSim(p), 0.0
    v, y = np.empty(n), np.empty(n)
    for k in range(n):
        y[k] = sim.output() + noise[k]
        e = r[k] - y[k]
        u = kp * e + integ + r[k] / k_gain
        i = u + 0.9 * p["cr"] if u > 0 else (u + 0.9 * p["cl"] if u < 0 else 0.0)
        if abs(i) < 2000:
            integ += ki * DT * e
        v[k] = min(2000.0, max(-2000.0, i))
        sim.drive(v[k])
    return v, y


def run_one(lash, kind, seed, d, duration=150.0, amp=500.0, noise=True, model="deadzone-deadband"):
    """model input-deadzone: the same random plant without its deadband (DZ -> G), estimated with
    --model input-deadzone; its errors and intervals have no d"""
    rng = np.random.default_rng(1000 * seed + {"multisine": 1, "steps": 2, "closed-loop": 3}[kind])
    p = plant(rng)
    if model == "input-deadzone":
        p["dl"] = p["dr"] = 0.0
    n = int(round(duration / DT))
    inp, pl, rec = (os.path.join(d, f"{kind}{seed}_{x}") for x in ("in.csv", "plant.toml", "rec.csv"))
    if kind == "closed-loop":
        state = rng.bit_generator.state
        y0 = closed_loop(p, rng, n, 0.0, seed)[1]
        rng.bit_generator.state = state  # the same reference with noise
        sigma = 0.014 * np.abs(y0).max() if noise else 0.0
        v, y = closed_loop(p, rng, n, sigma, seed)
        np.savetxt(rec, np.c_[np.arange(n) * DT, v, y], delimiter=",", header="t,v,y", comments="", fmt="%.17g")
        return estimate_run(lash, kind, seed, rec, p, sigma, model)
    v = signal(kind, rng, n, amp)
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
    return estimate_run(lash, kind, seed, rec, p, sigma, model)


def estimate_run(lash, kind, seed, rec, p, sigma, model="deadzone-deadband"):
    extra = os.environ.get("ANY_INPUT_ARGS", "").split()  # settings to compare (exploration)
    e = subprocess.run([lash, "estimate", rec, "--model", model, "--json", *extra], capture_output=True, text=True)
    assert e.returncode == 0, e.stderr
    j = json.loads(e.stdout)
    truth = {"right": dict(a1=p["a1"], b1=p["b1"], c=p["cr"], d=p["dr"]),
             "left": dict(a1=p["a1"], b1=p["b1"], c=p["cl"], d=p["dl"])}
    if model == "input-deadzone":
        for t in truth.values():
            del t["d"]
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
                switching=j.get("model_switching"), cover=cover, output_error=j.get("output_error"),
                reasons={s: j[s]["reason"] for s in ("right", "left")},
                sides_identified=sum(bool(j[s]["identified"]) for s in ("right", "left")))


def within_bounds(r):
    """identified, and every parameter the model has (input-deadzone: no d) within TOL"""
    tol = {k: t for k, t in TOL.items() if f"{k}_r" in r["errs"]}
    return r["identified"] and all(r["errs"][f"{k}_{s}"] <= tol[k] for k in tol for s in "rl")


def main():
    lash = sys.argv[1]
    arg = sys.argv[2] if len(sys.argv) > 2 else "20"  # N (seeds 1..N) or A-B
    lo, hi = (int(x) for x in arg.split("-")) if "-" in arg else (1, int(arg))
    kinds = sys.argv[3:] or ["multisine", "steps"]
    model = os.environ.get("ANY_INPUT_MODEL", "deadzone-deadband")
    out = []
    with tempfile.TemporaryDirectory() as d:
        for kind in kinds:
            for seed in range(lo, hi + 1):
                r = run_one(lash, kind, seed, d, model=model)
                ok = within_bounds(r)
                worst = {k: max(r["errs"][f"{k}_r"], r["errs"][f"{k}_l"]) for k in TOL if f"{k}_r" in r["errs"]}
                print(f"{kind:9s} seed {seed:2d} {'ok  ' if ok else 'FAIL'} identified {r['identified']} " +
                      " ".join(f"{k} {100 * w:.2f}%" for k, w in worst.items()) +
                      f" passes {r['switching'] and r['switching']['passes']}", flush=True)
                out.append(r)
    return out


if __name__ == "__main__":
    main()
