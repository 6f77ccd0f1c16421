#!/usr/bin/env python3
"""docs/excite.md's measurement: for each `lash excite --kind`, generate the input from rough edge
bounds, run it through `lash simulate --input-file` on a deadzone-deadband plant file, run
`lash estimate --model deadzone-deadband --json` on the result, and report the largest relative
error of a1, b1, c, d over both sides against the plant file's values, per duration.

Usage: excite_measure.py LASH PLANT.toml C_L,C_R [--durations 30,60,...] [--kinds sine,...]
       [--noise-variance V] [--seeds 1,2,3]
Also importable: truth(plant) and identify(...) are what tests/cli/excite_identifies.py uses."""
import json, os, subprocess, sys, tempfile, tomllib


def truth(plant):
    """Per side a1, b1, c, d of a DZ -> linear -> DB plant file."""
    with open(plant, "rb") as f:
        p = tomllib.load(f)
    dz = next(b for b in p["blocks"] if b["kind"] == "deadzone")
    lin = next(b for b in p["blocks"] if b["kind"] == "linear")
    db = next(b for b in p["blocks"] if b["kind"] in ("deadband", "backlash"))
    hw = db.get("half_width", None)
    if hw is None:
        w = db["width"]
        hw = {"left": w["left"] / 2, "right": w["right"] / 2} if isinstance(w, dict) else w / 2
    out = {}
    for side in ("right", "left"):
        l = lin[side] if side in lin else lin
        out[side] = {"a1": l["a1"], "b1": l["b1"], "c": dz[side], "d": hw[side] if isinstance(hw, dict) else hw}
    return out


def identify(lash, plant, edges, kind, duration, d, noise_variance=4.0, seed=1):
    """excite -> simulate -> estimate; returns (estimate JSON, worst relative error, stderr of excite)"""
    inp, rec = os.path.join(d, "in.csv"), os.path.join(d, "rec.csv")
    dt = str(tomllib.load(open(plant, "rb"))["dt"])
    e = subprocess.run([lash, "excite", f"--edges={edges}", "--dt", dt, "--duration", str(duration), "--kind", kind,
                        "--seed", str(seed), "-o", inp], capture_output=True, text=True, check=True)
    subprocess.run([lash, "simulate", plant, "--input-file", inp, "--noise-variance", str(noise_variance),
                    "--seed", str(seed), "-o", rec], capture_output=True, text=True, check=True)
    p = subprocess.run([lash, "estimate", rec, "--model", "deadzone-deadband", "--json"], capture_output=True,
                       text=True, check=True)
    j = json.loads(p.stdout)
    tr = truth(plant)
    worst = 0.0
    for side in ("right", "left"):
        for k, want in tr[side].items():
            got = j[side][k]
            worst = max(worst, float("inf") if got is None else abs(got - want) / abs(want))
    return j, worst, e.stderr


if __name__ == "__main__":
    lash, plant, edges = sys.argv[1:4]
    opts = dict(zip(sys.argv[4::2], sys.argv[5::2]))
    durations = [float(x) for x in opts.get("--durations", "30,60,90,120,180,240").split(",")]
    kinds = opts.get("--kinds", "sine,multisine,prbs").split(",")
    seeds = [int(x) for x in opts.get("--seeds", "1").split(",")]
    nv = float(opts.get("--noise-variance", "4"))
    print("kind duration_s seed worst_rel_err_pct identified_r identified_l reasons")
    with tempfile.TemporaryDirectory() as d:
        for kind in kinds:
            for dur in durations:
                for seed in seeds:
                    j, worst, _ = identify(lash, plant, edges, kind, dur, d, nv, seed)
                    print(f"{kind} {dur:g} {seed} {100 * worst:.2f} {j['right']['identified']} {j['left']['identified']} "
                          f"{j['right']['reason']}/{j['left']['reason']}", flush=True)
