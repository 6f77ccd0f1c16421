#!/usr/bin/env python3
"""Issue 12 must-show: records that cannot identify a model — constant input, all-zero data,
input kept inside the deadzone, an output step with zero input — give, for every model,
`identified: false` on every side with the right `reason`, exit status 0, and no NaN or
infinity anywhere in the JSON (null instead). The records are written here by hand; the
expected reasons follow from the definitions in include/lash/identify/verdict.hpp:
 - not_excited: the side was updated but its input v (or its output regressor y) took one value;
 - not_updated: the switching rule never (or too rarely) selected the side."""
import json, math, os, subprocess, sys, tempfile

LASH = os.environ["LASH"]
fail = 0
DT, N = 0.005, 2000  # 10 s


def check(cond, what):
    global fail
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        fail = 1


def write(path, v, y):
    with open(path, "w") as f:
        f.write("t,v,y\n")
        for k in range(N):
            f.write(f"{k * DT!r},{v[k]!r},{y[k]!r}\n")


def first_order_dz(v, a1=-0.96, b1=0.1, cl=-300.0, cr=200.0):
    """The right/left first-order lag behind an input deadzone (thesis eq. 17), by hand."""
    y, out = 0.0, []
    for k in range(N):
        out.append(y)
        u = v[k] - cr if v[k] > cr else (v[k] - cl if v[k] < cl else 0.0)
        y = -a1 * y + b1 * u
    return out


def reject(c):
    raise ValueError(f"non-finite number {c} in the JSON")


cases = {
    "constant_input": ([500.0] * N, None),
    "all_zero": ([0.0] * N, [0.0] * N),
    "inside_deadzone": ([150.0 * math.sin(2 * math.pi * 0.5 * k * DT) for k in range(N)], [0.0] * N),
    "output_step_zero_input": ([0.0] * N, [0.0 if k * DT < 2.0 else 100.0 for k in range(N)]),
}
cases["constant_input"] = (cases["constant_input"][0], first_order_dz(cases["constant_input"][0]))

NU, NE = "not_updated", "not_excited"
# expected reason per (case, model): linear one value, the others (right, left)
expect = {
    "constant_input": {"linear": NE, "input-deadzone": (NE, NU), "output-deadzone": (NE, NU),
                       "deadzone-deadband": (NU, NU), "coupled-carts": (NE, NU)},
    "all_zero": {"linear": NE, "input-deadzone": (NU, NU), "output-deadzone": (NU, NU),
                 "deadzone-deadband": (NU, NU), "coupled-carts": (NU, NU)},
    "inside_deadzone": {"linear": NE, "input-deadzone": (NU, NU), "output-deadzone": (NU, NU),
                        "deadzone-deadband": (NU, NU), "coupled-carts": (NU, NU)},
    "output_step_zero_input": {"linear": NE, "input-deadzone": (NU, NU), "output-deadzone": (NE, NU),
                               "deadzone-deadband": (NU, NU), "coupled-carts": (NU, NU)},
}
guesses = ["--guess-left", "-350", "--guess-right", "350"]

with tempfile.TemporaryDirectory() as d:
    for name, (v, y) in cases.items():
        path = os.path.join(d, name + ".csv")
        write(path, v, y)
        for model, want in expect[name].items():
            args = [LASH, "estimate", "--model", model, path, "--json"]
            if model in ("input-deadzone", "deadzone-deadband"):
                args += guesses
            p = subprocess.run(args, capture_output=True, text=True)
            check(p.returncode == 0, f"{name} {model}: exit {p.returncode} {p.stderr.strip()}")
            try:
                j = json.loads(p.stdout, parse_constant=reject)
            except ValueError as e:
                check(False, f"{name} {model}: {e}")
                continue
            if model == "linear":
                got = (j["identified"], j["reason"])
                check(got == (False, want), f"{name} {model}: identified/reason {got}, want (False, {want!r})")
            else:
                for side, w in zip(("right", "left"), want):
                    s = j[side]
                    got = (s["identified"], s["reason"])
                    check(got == (False, w), f"{name} {model} {side}: identified/reason {got}, want (False, {w!r})")
            if model == "coupled-carts":
                check(j["d"] is None and j["d_reason"] == NU, f"{name} {model}: d {j['d']} reason {j['d_reason']}")

sys.exit(fail)
