"""lash.sweep: one dict per run, equal to the rows of `lash sweep`'s results CSV (read by Python's
csv module) for a small campaign derived from E3; any thread count gives the same rows."""
import csv

import lash
from conftest import run_lash, same_value

CAMPAIGN = """
name = "E3 small"
rig = "motor_cart"
dt_s = 0.001
duration_s = 10.0
nrmse_window_s = [5.0, 10.0]
good_nrmse = 0.10
seed = 3003

[matrix]
waveforms = ["sine", "square"]
amplitudes = [4.0, 8.0]
frequencies_rad_s = [2.0]
repeats = 1

[estimator]
model = "output-deadzone"

[estimator.rls]
lambda = 0.99
p0 = 1000.0
"""


def cell(text):
    for conv in (int, float):
        try:
            return conv(text)
        except ValueError:
            pass
    return text


def test_sweep_equals_cli_csv(tmp_path):
    camp = tmp_path / "small.toml"
    camp.write_text(CAMPAIGN)
    out = tmp_path / "results.csv"
    run_lash("sweep", camp, "-q", "-o", out)
    with open(out) as f:
        cli = [{k: cell(v) for k, v in row.items()} for row in csv.DictReader(f)]
    py = lash.sweep(str(camp), jobs=2)
    assert len(py) == len(cli) == 4
    for a, b in zip(py, cli):
        assert list(a) == list(b)
        for k in a:
            assert same_value(a[k], b[k]), (k, a[k], b[k])
    one = lash.sweep(str(camp), jobs=1)
    assert all(same_value(a[k], b[k]) for a, b in zip(one, py) for k in a)
    assert {r["waveform"] for r in py} == {"sine", "square"}
    assert all(0 <= r["nrmse"] < 1 for r in py)
