#!/usr/bin/env python3
"""Drift events of the adaptive compensator over 20 seeds (docs/compensation.md "Drift events"):
0 false alarms on the no-drift scenarios run for 60 s; every step drift of >= 20 % of nominal
detected within 3 s, every ramp within 10 s of its end, and the event detecting it points the
way the parameter moved (sign of new - old). The drift times and sizes come from the scenario
files (tomllib); a drift event before the first drift is a false alarm."""
import json, os, re, subprocess, sys, tempfile, tomllib
from pathlib import Path

lash, root = os.environ["LASH"], Path(os.environ["LASH_SOURCE_DIR"])
d = root / "config/scenarios/closed_loop"
seeds = range(1, 21)
fails = 0


def check(ok, what):
    global fails
    print(("ok   " if ok else "FAIL ") + what)
    fails += 0 if ok else 1


with tempfile.TemporaryDirectory() as tmp:
    false_alarms, hours = 0, 0.0
    for f in sorted(d.glob("*.toml")):
        sc = tomllib.loads(f.read_text())
        drifts = sc.get("drift", [])
        comp = sc["compensation"]
        valve = sc["rig"] == "pilot_valve"
        text = f.read_text()
        if not drifts:
            text = re.sub(r"^duration_s = .*$", "duration_s = 60", text, flags=re.M)
        delays, wrong_way = [], 0
        for seed in seeds:
            p = Path(tmp) / f"{f.stem}_{seed}.toml"
            p.write_text(re.sub(r"^seed = .*$", f"seed = {seed}", text, flags=re.M))
            out = subprocess.run([lash, "closed-loop", "--scenario", str(p), "--compensation", "adaptive", "--json"],
                                 check=True, capture_output=True, text=True).stdout
            ev = [e for e in json.loads(out)["adaptation"]["events"] if e["kind"] == "drift"]
            t0 = drifts[0]["at_s"] if drifts else float("inf")
            fa = [e for e in ev if e["t_s"] < t0]
            false_alarms += len(fa)
            if fa: print("  false alarm", f.stem, seed, [(e["parameter"], e["t_s"], round(e["old"]), round(e["new"])) for e in fa])
            if drifts and not [e for e in ev if e["t_s"] >= t0]: print("  missed", f.stem, seed)
            hours += min(t0, 60.0 if not drifts else sc["duration_s"]) / 3600.0
            for dr in drifts:
                if valve:
                    side = "right" if dr["param"] == "deadzone_right_mA" else "left"
                    nominal = abs(comp["deadzone_" + side])
                    before = abs(sc["rig_params"][dr["param"]])
                    change = abs(dr["value"]) - before
                    params = {"edge_" + side}
                else:
                    change = dr["value"] - sc["rig_params"]["half_clearance_m"]
                    nominal = comp["deadband_right"]
                    params = {"deadband_right", "deadband_left"}
                size = abs(change) / nominal
                if size < 0.2:
                    continue
                end = dr["at_s"] + dr.get("ramp_s", 0.0)
                hit = [e for e in ev if e["parameter"] in params and e["t_s"] >= dr["at_s"]]
                delay = (hit[0]["t_s"] - (end if dr.get("ramp_s", 0.0) > 0 else dr["at_s"])) if hit else float("inf")
                delays.append(delay)
                if hit and (hit[0]["new"] - hit[0]["old"]) * change <= 0:
                    wrong_way += 1
                    print("  wrong way", f.stem, seed, hit[0])
        if delays:
            kind = "ramp: delay after its end" if any(x.get("ramp_s", 0) > 0 for x in drifts) else "step"
            bound = 10.0 if "ramp" in kind else 3.0
            print(f"{f.stem} ({kind}): detection delay over {len(seeds)} seeds: min {min(delays):.2f} s, "
                  f"median {sorted(delays)[len(delays) // 2]:.2f} s, max {max(delays):.2f} s")
            check(max(delays) <= bound, f"{f.stem}: every drift detected within {bound:g} s")
            check(wrong_way == 0, f"{f.stem}: every detecting event points the way the parameter moved")
    print(f"false alarms: {false_alarms} in {hours:.3f} h of runs before any drift "
          f"({false_alarms / hours:.2f} per hour)")
check(false_alarms == 0, "no drift event before a drift (the no-drift scenarios: 20 seeds x 60 s)")
sys.exit(1 if fails else 0)
