#!/usr/bin/env python3
"""Must-show checks of issue 13 (docs/compensation.md), every ratio measured in the same run of
this test, on the scenarios shipped in config/scenarios/closed_loop/:
 - valve, deadzone 288 -> 380 mA at 20 s, sine reference: over the window after the drift
   adaptive RMS error <= 0.5 x fixed and <= 0.3 x none;
 - coupled carts, clearance 5 -> 8 mm per side at 20 s: adaptive <= 0.5 x none and <= 0.7 x fixed,
   with lash's deadzone-deadband estimator inside the compensator;
 - no drift, exact nominal parameters (valve and carts): adaptive <= 1.1 x fixed;
 - constant set point for the whole run: adaptive makes no change without dither (and the
   verdict says why), and does adapt with its dither on;
 - the JSON's tracking.rms_error / max_abs_error agree with the trace (-o) recomputed here."""
import csv, json, math, os, subprocess, sys, tempfile

lash = os.environ["LASH"]
src = os.environ["LASH_SOURCE_DIR"]
scen = os.path.join(src, "config", "scenarios", "closed_loop")
tmp = tempfile.mkdtemp()
fail = []


def run(path, mode, trace=None):
    cmd = [lash, "closed-loop", "--scenario", path, "--compensation", mode, "--json"]
    if trace:
        cmd += ["-o", trace]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        print(p.stdout, p.stderr)
        sys.exit(1)
    return json.loads(p.stdout)


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        fail.append(what)


def trio(name):
    path = os.path.join(scen, name + ".toml")
    r = {m: run(path, m) for m in ("none", "fixed", "adaptive")}
    e = {m: r[m]["tracking"]["rms_error"] for m in r}
    print(f"{name}: rms none {e['none']:.6g}, fixed {e['fixed']:.6g}, adaptive {e['adaptive']:.6g} "
          f"[{r['none']['tracking']['unit']}]; adaptive/fixed {e['adaptive'] / e['fixed']:.3f}, "
          f"adaptive/none {e['adaptive'] / e['none']:.3f}; final {r['adaptive']['compensation']['final']}, "
          f"updates {r['adaptive']['adaptation']['updates']}")
    return r, e


r, e = trio("valve_deadzone_drift")
check(e["adaptive"] <= 0.5 * e["fixed"], "valve drift: adaptive <= 0.5 x fixed")
check(e["adaptive"] <= 0.3 * e["none"], "valve drift: adaptive <= 0.3 x none")
fin = r["adaptive"]["compensation"]["final"]
check(abs(fin["right"] - 380.0) < 0.08 * 380, f"valve drift: adapted right edge {fin['right']:.1f} mA within 8 % of 380")
check(r["fixed"]["compensation"]["final"] == {"right": 288.0, "left": -296.0}, "valve drift: fixed keeps the nominal")
check(r["fixed"]["adaptation"]["updates"] == 0 and r["none"]["adaptation"]["updates"] == 0, "only adaptive updates")

r, e = trio("carts_clearance_drift")
check(e["adaptive"] <= 0.5 * e["none"], "carts drift: adaptive <= 0.5 x none")
check(e["adaptive"] <= 0.7 * e["fixed"], "carts drift: adaptive <= 0.7 x fixed")
fin = r["adaptive"]["compensation"]["final"]
check(abs(fin["right"] - 0.008) < 0.001 and abs(fin["left"] - 0.008) < 0.001,
      f"carts drift: adapted half-widths {fin} within 1 mm of 8 mm")
a = r["adaptive"]["adaptation"]
check(a["estimator"]["model"] == "deadzone-deadband" and a["estimator_identified"],
      f"carts drift: lash's deadzone-deadband estimator identified both sides ({a['estimator_reason']})")
check(a["dither_amplitude"] == 0 and a["estimator"]["input_shift"] > 0,
      f"carts drift: excitation reported (dither {a['dither_amplitude']} m, input shift {a['estimator']['input_shift']} m)")

for name in ("valve_no_drift", "carts_no_drift"):
    r, e = trio(name)
    check(e["adaptive"] <= 1.1 * e["fixed"], f"{name}: adaptive <= 1.1 x fixed (no harm)")

# The JSON's figures against the trace, recomputed over the score window.
path = os.path.join(scen, "valve_deadzone_drift.toml")
tr = os.path.join(tmp, "valve.csv")
j = run(path, "adaptive", tr)
rows = list(csv.DictReader(open(tr)))
t0, t1 = j["score_window_s"]
err = [float(x["reference_kPa"]) - float(x["pressure_kPa"]) for x in rows if t0 - 1e-9 <= float(x["t"]) <= t1 + 1e-9]
rms = math.sqrt(sum(x * x for x in err) / len(err))
check(abs(rms - j["tracking"]["rms_error"]) <= 1e-6 * rms, f"trace RMS {rms:.6g} = JSON {j['tracking']['rms_error']:.6g}")
check(abs(max(abs(x) for x in err) - j["tracking"]["max_abs_error"]) <= 1e-9, "trace max |error| = JSON")
changes = sum(1 for a, b in zip(rows, rows[1:]) if a["edge_right_mA"] != b["edge_right_mA"] or a["edge_left_mA"] != b["edge_left_mA"])
check(abs(changes - j["adaptation"]["updates"]) <= 1, f"trace parameter changes {changes} = adaptation.updates {j['adaptation']['updates']}")

# A constant set point (with the 288 -> 380 mA drift): no adaptation without dither, and the
# verdict says why; with the dither on it adapts towards the drifted edge.
base = open(os.path.join(scen, "valve_deadzone_drift.toml")).read()
const = base.replace('kind = "sine"\namplitude = 600\nfrequency = 1.5707963        # [rad/s]: period 4 s',
                     'kind = "constant"\namplitude = 500')
assert const != base, "valve_deadzone_drift.toml changed: update this test's replacement"
cpath = os.path.join(tmp, "constant.toml")
open(cpath, "w").write(const)
j = run(cpath, "adaptive")
a = j["adaptation"]
print("constant, no dither:", a)
check(a["updates"] == 0, "constant set point: no change of the inverse without dither")
check(j["compensation"]["final"] == {"right": 288.0, "left": -296.0}, "constant set point: nominal inverse kept")
check(a["reason"] in ("not_excited", "not_identified") and len(a["estimator_reason"]) > 20,
      f"constant set point: the verdict says why ({a['reason']}: {a['estimator_reason']})")
dpath = os.path.join(tmp, "dither.toml")
open(dpath, "w").write(const.replace("deadzone_left = -296", "deadzone_left = -296\ndither_amplitude = 60\ndither_period_s = 1.0"))
j = run(dpath, "adaptive")
print("constant, dither 60 mA / 1 s:", j["adaptation"], j["compensation"]["final"])
check(j["adaptation"]["updates"] > 0 and j["adaptation"]["dither_amplitude"] == 60
      and j["compensation"]["final"]["right"] > 330, "constant set point with dither: the inverse adapts towards 380 mA")

sys.exit(1 if fail else 0)
