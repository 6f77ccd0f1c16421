"""Issue 30 item 2, the verdict as a property, with fixed seeds (scripts/verdict_property.py; the
longer runs and what they found: docs/identification.md, "The verdict as a property").

Random plants, inputs (multisine, random steps, PRBS, sine, chirp) and accepted settings, noise-free,
simulated by the script's own numpy plant. What always holds is asserted as such: settings lash
cannot run are refused naming the setting, and a1 >= 0 is never identified. The property itself
(every identified side within 1 % of the truth) holds with lash's defaults on these cases, and with
random settings too, --preset thesis included (its estimate is not refined, but checked by the
output-error fit: a side the fit moves is poor_fit, docs/method.md A4.4c). The counts here are the
measured ones for these seeds; the test fails when a change makes them worse, and prints every
violation."""
import os
import sys

import numpy as np

import lash

sys.path.insert(0, os.path.join(os.environ["LASH_SOURCE_DIR"], "scripts"))
import verdict_property as vp  # noqa: E402


def test_the_scripts_plant_is_the_thesis_model():
    # the independent simulator against lash's (a plant of the same blocks): the same bits
    rng = np.random.default_rng(5)
    p = vp.plant(rng)
    v = vp.signal("multisine", rng, 20000, 500.0)
    plant = lash.Plant(blocks=[{"kind": "deadzone", "left": p["cl"], "right": p["cr"]},
                               {"kind": "linear", "a1": p["a1"], "b1": p["b1"]},
                               {"kind": "deadband", "half_width": {"left": p["dl"], "right": p["dr"]}}], dt_s=vp.DT)
    assert plant.simulate(v)["y"].tobytes() == vp.simulate(p, v).tobytes()


def run(cases, seed, defaults, extra=None, noise=False):
    out = dict(ok=0, violation=0, refused=0, sides=0, worst=0.0)
    refused, violations = set(), []
    for i in range(cases):
        status, desc, info = vp.case(i, seed, noise, defaults, extra)  # noise-free unless asked
        if status != "refused":
            out["sides"] += info["sides"]
            out["worst"] = max([out["worst"]] + [float(b.split("%")[0].split()[-1]) for b in info["bad"] if "% off" in b])
        out[status] += 1
        if status == "refused":
            refused.add(info.split(":")[0])
        elif status == "violation":
            violations.append((desc, info["bad"]))
            print("VIOLATION", desc, info["bad"])
            assert not any("a1 = " in b for b in info["bad"]), "a1 >= 0 identified"
    return out, refused, violations


def test_random_settings():
    out, refused, violations = run(200, 2, False)
    print(out)
    # refusals: lambda = 1e-300 ("forgetting factor must be in [0.9, 1]") and model switching
    # without the pooled regression; nothing else the script draws is refused
    assert refused == {"lambda", "model-switching"}
    assert out["refused"] == 26
    # measured: 0 of 174 runs with a side off by more than 1 % (149 sides identified); 3 before
    # the thesis preset's output-error check (all --preset thesis, 152 sides), 12 before the
    # refinement
    assert out["violation"] == 0 and out["sides"] >= 145


def test_defaults():
    out, refused, violations = run(300, 3, True)
    print(out)
    assert out["refused"] == 0
    # measured: 0 of 300 runs with a side off by more than 1 %; 2 before the output-error fit's
    # further starts (two sines that pass one edge by 7 % or never reach it, where the first fit
    # stops in a local minimum: docs/method.md §A4.4c), 5 before the refinement, 7 before model
    # switching checked the dy/dt switching
    assert out["violation"] == 0


def test_model_switching_checks_a_biased_ydot_result():
    # noise-free sines and chirps (defaults, seed 3) whose dy/dt switching identified both sides
    # with d 2-21 % off and batch-means intervals of about +-0.3 % (measured before the check,
    # 2c2b43d): model switching checks every such result and replaces it (docs/method.md A4.4b);
    # the result is then within 0.1 % of the script's plant on every parameter of both sides
    for i in (26, 247, 374, 375, 487):
        p, kind, amp, v, y, rng = vp.draw(i, 3, False)
        r = lash.estimate(np.arange(len(v)) * vp.DT, v, y, model="deadzone-deadband").to_dict()
        ms = r["model_switching"]
        assert kind in ("sine", "chirp") and ms["trigger"] == "check" and ms["used"] and ms["converged"], (i, ms)
        for side, c, d in (("right", p["cr"], p["dr"]), ("left", p["cl"], p["dl"])):
            j = r[side]
            assert j["identified"], (i, side, j)
            for k, want in (("a1", p["a1"]), ("b1", p["b1"]), ("c", c), ("d", d)):
                assert abs(j[k] / want - 1.0) < 1e-3, (i, side, k, j[k], want)


def test_output_error_restarts_leave_a_local_minimum():
    # noise-free cases (defaults, seed 3) where the output-error fit from the switching estimate
    # stopped in a local minimum (measured before the further starts: b1 4-77 %, d 20-47 % off on
    # one side, identified; case 168 stopped at 40 passes and was not_excited): its residual is
    # not white, so further starts run (docs/method.md §A4.4c), and the fit kept is the plant to
    # 1e-6 on every side it identifies. Case 2's sine never reaches the right edge (330.97 >
    # 296.6): that side stays unidentified.
    for i in (2, 148, 168, 479, 726):
        p, kind, amp, v, y, rng = vp.draw(i, 3, False)
        r = lash.estimate(np.arange(len(v)) * vp.DT, v, y, model="deadzone-deadband").to_dict()
        oe = r["output_error"]
        assert oe["used"] and oe["starts"] > 1 and oe["best_start"] > 0, (i, oe)
        assert oe["rms"] < 1e-9, (i, oe)  # the record's level: noise-free
        for side, c, d in (("right", p["cr"], p["dr"]), ("left", p["cl"], p["dl"])):
            j = r[side]
            assert j["identified"] == (not (i == 2 and side == "right")), (i, side, j["reason"])
            if j["identified"]:
                for k, want in (("a1", p["a1"]), ("b1", p["b1"]), ("c", c), ("d", d)):
                    assert abs(j[k] / want - 1.0) < 1e-6, (i, side, k, j[k], want)


def test_joint_check_takes_the_side_fitted_with_a_rejected_one():
    # Case 386 of seed 3 with E2 noise: a sine 2.4 x the right edge (311); the right guess lies
    # inside the deadzone, the output-error fit from that estimate ends with c_r = 224, K_r 22 %
    # low and d_r = 0 (uncertain: its interval reaches d < 0). The left side, fitted together
    # with it, came out with d_l = 28.2 against the plant's 48.2 (41 % off) and a 95 % interval
    # of +-9.7 % -- identified before the joint check; now poor_fit, the check in the JSON.
    p, kind, amp, v, y, rng = vp.draw(386, 3, True)
    r = lash.estimate(np.arange(len(v)) * vp.DT, v, y, model="deadzone-deadband").to_dict()
    assert kind == "sine" and r["output_error"]["used"]
    assert not r["right"]["identified"] and r["right"]["reason"] == "wrong_guess"  # the guess report's
    assert abs(r["left"]["d"] / p["dl"] - 1.0) > 0.3  # the value the check keeps from being a result
    lo, hi = r["left"]["ci95"]["d"]
    assert not lo <= p["dl"] <= hi
    assert not r["left"]["identified"] and r["left"]["reason"] == "poor_fit"
    assert r["output_error"]["joint_check"] == {"flagged": True, "rejected": "right", "reason": "uncertain",
                                                "guess_inside": True}
    # a case the check leaves alone (both sides identified, within 5 %): case 0
    p, kind, amp, v, y, rng = vp.draw(0, 3, True)
    r = lash.estimate(np.arange(len(v)) * vp.DT, v, y, model="deadzone-deadband").to_dict()
    assert r["output_error"]["joint_check"] == {"flagged": False}
    assert r["right"]["identified"] and r["left"]["identified"]


def test_the_thesis_preset_is_checked_by_output_error():
    # noise-free cases (random settings, seed 3) that --preset thesis identified with a side far
    # off, measured before the output-error check (docs/method.md A4.4c): case 566 right c 4.59
    # (truth 321.9) and d 1214 (30.6), NRMSE 18.7 % under the 20 % threshold; case 8 left d 1.29 %
    # off. With the check (the thesis preset's default) the fit from the estimate moves them to
    # the plant, and the sides are poor_fit; the JSON names the parameter moved furthest and by
    # how much, which is |plant / estimate - 1| (the fit reaches the plant: noise-free). A side the
    # fit leaves where it is stays identified (case 8's right side, within 0.07 %).
    for i, flagged in ((566, {"right": "c", "left": "d"}), (8, {"left": "d"})):
        p, kind, amp, v, y, rng = vp.draw(i, 3, False)
        s = vp.settings(rng)
        assert s["preset"] == "thesis"
        t = np.arange(len(v)) * vp.DT
        kw = dict(model="deadzone-deadband", preset="thesis", outlier_gate=s["outlier_gate"], **s["keys"])
        off = lash.estimate(t, v, y, output_error_check=False, **kw).to_dict()
        on = lash.estimate(t, v, y, **kw).to_dict()
        check = on["output_error"]["check"]
        assert not on["output_error"]["used"]
        for side, c, d in (("right", p["cr"], p["dr"]), ("left", p["cl"], p["dl"])):
            truth = dict(a1=p["a1"], b1=p["b1"], c=c, d=d)
            assert off[side]["identified"], (i, side)
            for k in truth:  # the estimate itself is kept
                assert on[side][k] == off[side][k], (i, side, k)
            err = max(abs(off[side][k] / w - 1.0) for k, w in truth.items())
            if side in flagged:
                k = flagged[side]
                assert err > 0.01 and not on[side]["identified"] and on[side]["reason"] == "poor_fit", (i, side)
                assert check[side]["moved"] == k, (i, side, check[side])
                assert abs(check[side]["by"] / abs(truth[k] / off[side][k] - 1.0) - 1.0) < 1e-4, (i, side, check)
            else:
                assert err < 0.01 and on[side]["identified"] and check[side] is None, (i, side, err)


def test_interval_coverage_with_noise():
    # item 3 over the property's cases with E2-level noise (1.4 % of the output's amplitude) and
    # lash's defaults: of the identified sides that have intervals, the share whose 95 % interval
    # holds the true value, per parameter. Measured: a1 917/979, b1 913/979, c 939/979, d 923/979
    # (93.7 / 93.3 / 95.9 / 94.3 %; the output-error fit's intervals, every identified side has
    # one); before the refinement 93.5-96.7 % of 601, 178 sides without. On the first 300
    # cases alone a1 was 158/177 (89.3 %, measured before model switching checked every dy/dt
    # result): fewer cases than this spread about 90 % leaves to chance.
    cover = {k: [0, 0] for k in ("a1", "b1", "c", "d")}
    for i in range(1000):
        status, desc, info = vp.case(i, 3, True, True)
        for k, held in info["cover"]:
            cover[k][0] += held
            cover[k][1] += 1
    print(cover)
    assert cover["a1"][1] >= 950
    for k, (held, m) in cover.items():
        assert held >= 0.90 * m, (k, held, m)


def test_ci_tolerance_makes_identified_mean_within_it():
    # verdict check 8 (ci_tolerance, docs/identification.md): a side is identified only when its
    # 95 % intervals of K, tau, c and d each lie within the tolerance. Measured on these cases:
    # noise-free at 1 %: 336 sides identified (339 without it), none off by more than 1 % (2 cases
    # without it); with E2 noise at 5 %: 397 sides of 500 cases, none off by more than 5 %. Before
    # the output-error refinement: 273 sides, 3 off (d 3.63 %), and 25 sides, 2 off. The counts
    # may only get better; the sides identified must stay (a verdict that identified nothing
    # would pass the rest).
    out, refused, violations = run(300, 3, True, {"ci_tolerance": 0.01})
    print(out)
    assert out["refused"] == 0 and out["sides"] >= 330
    assert out["violation"] == 0
    out, refused, violations = run(500, 3, True, {"ci_tolerance": 0.05}, noise=True)
    print(out)
    assert out["sides"] >= 390
    assert out["violation"] == 0
