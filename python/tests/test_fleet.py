"""Fleet identification on Dask (examples/python/05_fleet.py): 200 generated records whose
backlash grows over the fleet; a LocalCluster of 2 workers gives exactly the rows of a serial
run, and the injected trend is recovered (Spearman rank correlation >= 0.9, scipy)."""
import importlib.util
import math
import os

import pytest
from scipy.stats import spearmanr

from conftest import SRC, same_value

pytest.importorskip("dask.distributed")
spec = importlib.util.spec_from_file_location("fleet", os.path.join(SRC, "examples", "python", "05_fleet.py"))
fleet = importlib.util.module_from_spec(spec)
spec.loader.exec_module(fleet)

N = 200


def test_cluster_equals_serial_and_trend_recovered(tmp_path):
    folder = tmp_path / "fleet"
    fleet.generate(str(folder), N, duration_s=30.0)
    files = fleet.records(str(folder))
    assert len(files) == N
    serial = fleet.run_serial(files)
    cluster = fleet.run_dask(files, workers=2)
    assert len(serial) == len(cluster) == 2 * N
    for a, b in zip(serial, cluster):
        assert list(a) == list(b)
        assert all(same_value(a[k], b[k]) for k in a), (a, b)
    # the injected backlash grows with the record index: its rank order must come back
    for side in ("right", "left"):
        rows = [r for r in serial if r["side"] == side]
        ok = [i for i, r in enumerate(rows) if math.isfinite(r["d"])]
        assert len(ok) >= 0.9 * N, (side, len(ok))
        rho = spearmanr(ok, [rows[i]["d"] for i in ok]).correlation
        print("%s: d reported for %d of %d records (%d identified by the verdict), Spearman rho(d, index) = %.4f"
              % (side, len(ok), N, sum(r["identified"] for r in rows), rho))
        assert rho >= 0.9, (side, rho)
    fleet.write_csv(str(tmp_path / "r.csv"), serial)
    fleet.plot(str(tmp_path / "f.png"), serial)
    assert os.path.getsize(tmp_path / "f.png") > 5000
