#!/usr/bin/env python3
"""02 — build a plant from blocks and simulate it.

A deadzone (c_l = -1.5 V, c_r = 1.0 V), a first-order lag per direction (a1, b1 at T = 10 ms:
gain K = b1/(1 + a1) = 2.0 mm/V for v >= 0, 1.7 mm/V for v < 0) and a backlash (deadband) of
half-width d = 0.5 mm, driven by a randomized input (low-passed Gaussian) and by steps;
plots every block's output.

    python3 examples/python/02_simulate.py [--out 02_simulate.png]
"""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import lash  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="02_simulate.png", help="figure file (PNG)")
    args = ap.parse_args()

    dt = 0.01  # [s]
    plant = lash.Plant(dt_s=dt, blocks=[
        {"kind": "deadzone", "left": -1.5, "right": 1.0},                        # [V]
        {"kind": "linear", "right": {"a1": -0.95, "b1": 0.10}, "left": {"a1": -0.93, "b1": 0.12}},
        {"kind": "deadband", "half_width": {"left": 0.5, "right": 0.5}},          # [mm]
    ])
    print("plant:", " -> ".join(plant.blocks), "at dt = %g s" % plant.dt_s)
    inputs = {
        "randomized": lash.signal("randomized", 40.0, dt, variance=40.0, tau_s=0.5, seed=11),   # [V]
        "steps": lash.signal("steps", 40.0, dt, steps=[(2, 3.0), (12, -0.8), (20, -4.0), (30, 1.2)]),
    }
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    for col, (name, v) in enumerate(inputs.items()):
        tr = plant.simulate(v, noise_variance=0.0)
        print("%-10s: %d samples, y in [%.3f, %.3f] mm" % (name, len(tr["t"]), tr["y"].min(), tr["y"].max()))
        ax = axes[0, col]
        ax.plot(tr["t"], tr["v"], label="v [V]")
        ax.plot(tr["t"], tr["x1_deadzone"], label="after the deadzone")
        ax.set_title(name)
        ax.legend(loc="upper right")
        ax = axes[1, col]
        ax.plot(tr["t"], tr["x2_linear"], label="after the lag [mm]")
        ax.plot(tr["t"], tr["y"], label="y: after the backlash [mm]")
        ax.set_xlabel("t [s]")
        ax.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print("figure ->", args.out)


if __name__ == "__main__":
    main()
