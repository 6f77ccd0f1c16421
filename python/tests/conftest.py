"""Shared helpers of the lash Python tests (run by ctest: PYTHONPATH, LASH, LASH_SOURCE_DIR set)."""
import math
import os
import subprocess

import numpy as np
import pytest

LASH = os.environ.get("LASH", "")
SRC = os.environ.get("LASH_SOURCE_DIR", os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
CORPUS = os.path.join(SRC, "..", "shared", "data", "can-corpus")

# E2 (config/scenarios/e2.toml): the thesis plant, sine 600, 1 rad/s, noise variance 200, 200 s.
E2_SETTINGS = dict(guess_left=-350.0, guess_right=350.0, pooled=True, method="iv", iv_delay=45, direction_run=41,
                   min_updates=50, rls={"lambda": 1.0, "p0": 1000.0, "eta0": [1.0, 1.0, 1.0]},
                   noise={"filter_length": 40, "filter_input": True, "derivative_filter_length": 20,
                          "derivative_threshold": 150.0, "align_delay": 10})


def same_value(a, b):
    """Equality where NaN equals NaN (results of two runs, cell by cell)."""
    if isinstance(a, float) and math.isnan(a):
        return isinstance(b, float) and math.isnan(b)
    return a == b


def run_lash(*args):
    return subprocess.run([LASH, *map(str, args)], check=True, capture_output=True, text=True).stdout


def read_csv(path):
    """A CSV with a header line as a dict of float arrays (numpy's parser, not lash's)."""
    with open(path) as f:
        names = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {n: data[:, i] for i, n in enumerate(names)}


def toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"%s"' % v
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    return repr(v)


def write_settings_toml(path, model, settings):
    """The same settings as an estimator config file for `lash estimate --config`."""
    top = ['model = "%s"' % model]
    tables = []
    for k, v in settings.items():
        if isinstance(v, dict):
            tables.append("[%s]" % k)
            tables += ["%s = %s" % (kk, toml_value(vv)) for kk, vv in v.items()]
        else:
            top.append("%s = %s" % (k, toml_value(v)))
    with open(path, "w") as f:
        f.write("\n".join(top + tables) + "\n")


@pytest.fixture(scope="session")
def e2_csv(tmp_path_factory):
    """E2 data written by `lash simulate` (seed 1)."""
    d = tmp_path_factory.mktemp("e2")
    path = d / "e2.csv"
    run_lash("simulate", os.path.join(SRC, "config/plants/thesis_eq34.toml"), "--input", "sine", "--amplitude", 600,
             "--frequency", 1, "--duration", 200, "--noise-variance", 200, "--seed", 1, "-o", path)
    return str(path)
