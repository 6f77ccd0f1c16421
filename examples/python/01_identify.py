#!/usr/bin/env python3
"""01 — identify a deadzone/backlash actuator from one noisy record.

Simulates the thesis plant (deadzone c_l = -300, c_r = 200 -> first-order lag per side ->
deadband d_l = 50, d_r = 30; T = 5 ms) with measurement noise of variance 200, runs lash's
switching estimator over the record (lash.estimate, the E2 settings), prints the parameters
per side with their 95 % intervals, and draws measured vs simulated output and the
parameter convergence.

    python3 examples/python/01_identify.py [--out 01_identify.png]
"""
import argparse
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import lash  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
PLANT = os.path.join(HERE, "..", "..", "config", "plants", "thesis_eq34.toml")

# config/scenarios/e2.toml: consistent MA40 filtering, pooled IV regression, lambda = 1
E2 = dict(guess_left=-350.0, guess_right=350.0, pooled=True, method="iv", iv_delay=45, direction_run=41,
          rls={"lambda": 1.0, "p0": 1000.0},
          noise={"filter_length": 40, "filter_input": True, "derivative_filter_length": 20,
                 "derivative_threshold": 150.0, "align_delay": 10})


def interval(side, key, values):
    """The 95 % interval of a parameter: the estimator's own (ci95, when this lash reports it),
    else the spread of its trace over the last quarter of the record (min, max)."""
    ci = side.get("ci95") if isinstance(side.get("ci95"), dict) else None
    if ci and ci.get(key) is not None:
        return tuple(ci[key]), "ci95"
    tail = values[3 * len(values) // 4:]
    tail = tail[np.isfinite(tail)]
    return (float(tail.min()), float(tail.max())) if len(tail) else (math.nan, math.nan), "last-quarter range"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default="01_identify.png", help="figure file (PNG)")
    ap.add_argument("--duration", type=float, default=200.0, help="record length [s]")
    args = ap.parse_args()

    plant = lash.Plant.from_toml(PLANT)
    v = lash.signal("sine", args.duration, plant.dt_s, amplitude=600.0, frequency_rad_s=1.0)
    rec = plant.simulate(v, noise_variance=200.0, seed=1)           # y has noise, y_true not

    r = lash.estimate(rec["t"], rec["v"], rec["y"], model="deadzone-deadband", trace=True, **E2)
    res = r.to_dict()
    print("%d samples at dt = %g s, NRMSE %.2f %% over [%g, %g] s" % (r.samples, r.dt_s, 100 * r.nrmse,
                                                                       *r.nrmse_window_s))
    truth = {"right": dict(a1=-0.96, b1=0.1, c=200.0, d=30.0), "left": dict(a1=-0.94, b1=0.15, c=-300.0, d=50.0)}
    suffix = {"right": "_r", "left": "_l"}
    for side in ("right", "left"):
        s = res[side]
        print("%s side: %s" % (side, "identified" if s["identified"] else "NOT identified (%s)" % s.get("reason", "")))
        for key in ("a1", "b1", "c", "d"):
            lo, hi = interval(s, key, r.params[key + suffix[side]])[0]
            val = s[key]
            print("  %-2s = %10.4f   95%% in [%10.4f, %10.4f]   true %g" % (key, val if val is not None else math.nan,
                                                                          lo, hi, truth[side][key]))

    fig, ax = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    ax[0].plot(rec["t"], rec["y"], lw=0.5, color="0.6", label="y measured")
    ax[0].plot(rec["t"], r.ysim, lw=1.0, label="y simulated by the identified model")
    ax[0].set_ylabel("y [output unit]")
    ax[0].legend(loc="upper right")
    for key, color in (("c_r", "C0"), ("c_l", "C1")):
        ax[1].plot(rec["t"], r.params[key], color=color, label=key)
    ax[1].axhline(200, color="C0", ls=":")
    ax[1].axhline(-300, color="C1", ls=":")
    ax[1].set_ylabel("deadzone c [input unit]")
    ax[1].legend(loc="right")
    for key, color in (("d_r", "C2"), ("d_l", "C3")):
        ax[2].plot(rec["t"], r.params[key], color=color, label=key)
    ax[2].axhline(30, color="C2", ls=":")
    ax[2].axhline(50, color="C3", ls=":")
    ax[2].set_ylim(0, 100)
    ax[2].set_ylabel("deadband d [output unit]")
    ax[2].set_xlabel("t [s]")
    ax[2].legend(loc="right")
    fig.suptitle("lash.estimate on a noisy record (dotted: true values)")
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print("figure ->", args.out)


if __name__ == "__main__":
    main()
