#!/usr/bin/env python3
"""Issue 30 item 2, the verdict as a property: over random plants (edges, backlash widths,
dynamics), random inputs (random-phase multisine, random-level steps, PRBS, sine, chirp) and
random accepted settings (preset, method, pooling, lambda, p0, filter length, gates, update and fit
thresholds, model switching), on noise-free data, every side lash calls `identified` holds every
parameter within 1 % of the truth; a1 >= 0 is never identified; settings lash cannot run are
refused (lash.InputError) or leave the sides unidentified.

The plant is simulated here with numpy, independently of lash's simulator: deadzone ->
y(k) = -a1 y(k-1) + b1 u(k-1) -> backlash (play operator of half-width d_r while v(k-1) >= 0,
d_l while v(k-1) < 0: the sides of the thesis's switched model).

usage: verdict_property.py [--cases N] [--seed S] [--noise] [--show K]
prints one line per violation (at most --show) and the counts; exit 1 when a case violates."""
import argparse
import json
import math
import sys

import numpy as np

import lash

DT = 0.005
TOL = 0.01  # noise-free: every parameter of an identified side within 1 %
LAMBDAS = [1.0, 1.0, 0.99999, 0.9999, 0.999, 0.99, 1e-300]
P0 = [1.0, 1e2, 1e4, 1e6, 1e8]
FILTERS = [1, 5, 20, 40, 80]
MIN_UPDATES = [10, 50, 200, 1000]
FIT = [0.05, 0.2, 0.5]
GATES = [0.0, 12.0]
KINDS = ["multisine", "steps", "prbs", "sine", "chirp"]


def plant(rng):
    """edges 30..400 each side, half-widths 2..60, tau 0.02..1 s, K 0.2..5"""
    tau, k = rng.uniform(0.02, 1.0), rng.uniform(0.2, 5.0)
    a1 = -math.exp(-DT / tau)
    return dict(cr=rng.uniform(30, 400), cl=-rng.uniform(30, 400), dr=rng.uniform(2, 60), dl=rng.uniform(2, 60),
                a1=a1, b1=k * (1 + a1))


def signal(kind, rng, n, amp):
    t = np.arange(n) * DT
    if kind == "multisine":
        lines = int(rng.integers(5, 40))
        f = np.linspace(rng.uniform(0.02, 0.1), rng.uniform(0.5, 3.0), lines)
        x = np.sin(2 * np.pi * np.outer(t, f) + rng.uniform(0, 2 * np.pi, lines)).sum(axis=1)
        return amp * x / np.abs(x).max()
    if kind == "sine":
        return amp * np.sin(2 * np.pi * rng.uniform(0.05, 1.0) * t + rng.uniform(0, 2 * np.pi))
    if kind == "chirp":  # linear sweep f0 -> f1 over the record
        f0, f1 = rng.uniform(0.02, 0.2), rng.uniform(0.5, 3.0)
        return amp * np.sin(2 * np.pi * (f0 * t + (f1 - f0) * t * t / (2 * t[-1])))
    v = np.empty(n)
    k = 0
    hold = rng.uniform(0.05, 0.5)  # PRBS: +-amp, each level held a random multiple of one clock
    sign = 1.0
    while k < n:
        if kind == "prbs":
            h = int(hold / DT) * int(rng.integers(1, 6))
            sign = -sign
            level = sign * amp
        else:  # random-level steps, held 0.2..1 s
            h = int(rng.uniform(0.2, 1.0) / DT)
            level = rng.uniform(-amp, amp)
        v[k:k + h] = level
        k += max(h, 1)
    return v


def simulate(p, v):
    u = np.where(v > p["cr"], v - p["cr"], np.where(v < p["cl"], v - p["cl"], 0.0))
    y = np.zeros(len(v))
    x = 0.0  # the linear block's output; y is the backlash's
    out = 0.0
    for k in range(1, len(v)):
        x = -p["a1"] * x + p["b1"] * u[k - 1]
        d = p["dr"] if v[k - 1] >= 0 else p["dl"]  # the side: the sign of v(k-1), as the thesis's model
        if x > out + d:
            out = x - d
        elif x < out - d:
            out = x + d
        y[k] = out
    return y


def settings(rng):
    s = dict(preset=str(rng.choice(["lash", "lash", "thesis"])), outlier_gate=float(rng.choice(GATES)))
    ks = {}
    if rng.random() < 0.5:
        ks["rls"] = {"lambda": float(rng.choice(LAMBDAS)), "p0": float(rng.choice(P0))}
    if rng.random() < 0.4:
        ks["method"] = str(rng.choice(["rls", "iv"]))
    if rng.random() < 0.3:
        ks["pooled"] = bool(rng.random() < 0.5)
    if rng.random() < 0.4:
        ks["noise"] = {"filter_length": int(rng.choice(FILTERS))}
    if rng.random() < 0.3:
        ks["min_updates"] = int(rng.choice(MIN_UPDATES))
    if rng.random() < 0.3:
        ks["fit_threshold"] = float(rng.choice(FIT))
    if rng.random() < 0.2:
        ks["model_switching"] = True
    s["keys"] = ks
    return s


def relerr(got, want):
    return math.inf if got is None else abs(got / want - 1.0)


def draw(i, seed, noise):
    """case i's plant, input kind, amplitude, v and y; and its generator, to draw the settings"""
    rng = np.random.default_rng([seed, i])
    p = plant(rng)
    kind = str(rng.choice(KINDS))
    n = int(rng.uniform(40, 150) / DT)
    amp = max(p["cr"], -p["cl"]) * rng.uniform(0.8, 4.0)
    v = signal(kind, rng, n, amp)
    y = simulate(p, v)
    if noise:  # E2-level: 1.4 % of the output's amplitude
        y = y + rng.normal(0.0, 0.014 * np.abs(y).max(), n)
    return p, kind, amp, v, y, rng


def case(i, seed, noise, defaults=False, extra=None):
    p, kind, amp, v, y, rng = draw(i, seed, noise)
    n = len(v)
    s = settings(rng)
    if defaults:
        s = dict(preset="lash", outlier_gate=12.0, keys=dict(extra or {}))
    t = np.arange(n) * DT
    desc = dict(case=i, kind=kind, n=n, amp=round(amp, 1), preset=s["preset"], gate=s["outlier_gate"], **s["keys"],
                plant={k: round(x, 5) for k, x in p.items()})
    try:
        r = lash.estimate(t, v, y, model="deadzone-deadband", preset=s["preset"], outlier_gate=s["outlier_gate"],
                          **s["keys"]).to_dict()
    except lash.InputError as e:
        return "refused", desc, str(e)
    truth = {"right": dict(a1=p["a1"], b1=p["b1"], c=p["cr"], d=p["dr"]),
             "left": dict(a1=p["a1"], b1=p["b1"], c=p["cl"], d=p["dl"])}
    tol = 0.05 if noise else TOL
    bad, sides, cover, no_interval = [], 0, [], 0
    for side in ("right", "left"):
        j = r[side]
        if not j["identified"]:
            continue
        sides += 1
        # item 3: does each 95 % interval hold the truth? (a side may have none: too few sections)
        if j["ci95"].get("a1") is None:
            no_interval += 1
        for k, want in truth[side].items():
            ci = j["ci95"].get(k)
            if ci is not None:
                cover.append((k, ci[0] <= want <= ci[1]))
        if j["a1"] is None or j["a1"] >= 0:
            bad.append(f"{side}: a1 = {j['a1']} identified")
        for k, want in truth[side].items():
            e = relerr(j[k], want)
            if e > tol:
                bad.append(f"{side} {k} {100 * e:.2f}% off ({j[k]} vs {want:.6g})")
    return ("violation" if bad else "ok"), desc, dict(sides=sides, bad=bad, cover=cover, no_interval=no_interval)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", type=int, default=200)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--noise", action="store_true", help="E2-level noise (tolerance 5 %%)")
    ap.add_argument("--show", type=int, default=20)
    ap.add_argument("--defaults", action="store_true", help="lash's defaults only (no random settings)")
    ap.add_argument("--keys", default="{}", help="with --defaults: settings to add (JSON), to compare")
    a = ap.parse_args()
    counts = dict(ok=0, violation=0, refused=0)
    sides = bad_sides = gross = a1_ident = 0
    by_kind = {k: [0, 0] for k in KINDS}  # cases run, violations
    refused_by = {}
    cover = {k: [0, 0] for k in ("a1", "b1", "c", "d")}  # held, intervals
    no_interval = 0
    shown = 0
    for i in range(a.cases):
        status, desc, info = case(i, a.seed, a.noise, a.defaults, json.loads(a.keys))
        counts[status] += 1
        if status == "refused":
            field = info.split(":")[0]
            refused_by[field] = refused_by.get(field, 0) + 1
            continue
        sides += info["sides"]
        no_interval += info["no_interval"]
        for k, held in info["cover"]:
            cover[k][0] += held
            cover[k][1] += 1
        by_kind[desc["kind"]][0] += 1
        if status == "violation":
            by_kind[desc["kind"]][1] += 1
            bad_sides += len({b.split()[0].rstrip(":") for b in info["bad"]})
            gross += any("% off" in b and float(b.split("% off")[0].split()[-1]) > 20 for b in info["bad"])
            a1_ident += any("a1 = " in b for b in info["bad"])
        if status == "violation" and shown < a.show:
            shown += 1
            print(f"VIOLATION {desc}: {'; '.join(info['bad'])}", flush=True)
    print(f"cases {a.cases} (seed {a.seed}, {'E2 noise, 5 %' if a.noise else 'noise-free, 1 %'}): "
          f"ok {counts['ok']}, violations {counts['violation']}, refused {counts['refused']}; "
          f"identified sides {sides}, of them off by more than the tolerance {bad_sides}; cases with an "
          f"error above 20 % {gross}; a1 >= 0 identified {a1_ident}")
    print("violations by input (cases run, violations): " +
          ", ".join(f"{k} {n}/{v}" for k, (n, v) in by_kind.items()))
    print(f"95 % intervals holding the truth, over identified sides with intervals ({no_interval} without): " +
          ", ".join(f"{k} {h}/{m}" for k, (h, m) in cover.items()))
    if refused_by:
        print("refused, by the field named: " + ", ".join(f"{k} {n}" for k, n in sorted(refused_by.items())))
    return 1 if counts["violation"] else 0


if __name__ == "__main__":
    sys.exit(main())
