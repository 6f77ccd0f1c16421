"""Every example under examples/python runs (headless matplotlib, Agg) and writes its figure."""
import os
import subprocess
import sys

import pytest

from conftest import SRC

EX = os.path.join(SRC, "examples", "python")


def run(script, *args, cwd):
    env = dict(os.environ, MPLBACKEND="Agg")
    out = subprocess.run([sys.executable, os.path.join(EX, script), *map(str, args)], cwd=cwd, env=env,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stdout + out.stderr
    return out.stdout


def is_png(path):
    with open(path, "rb") as f:
        return f.read(8) == b"\x89PNG\r\n\x1a\n" and os.path.getsize(path) > 5000


def test_01_identify(tmp_path):
    out = run("01_identify.py", "--out", tmp_path / "a.png", cwd=tmp_path)
    assert is_png(tmp_path / "a.png")
    assert "right side:" in out and "left side:" in out and out.count("95% in [") == 8, out


def test_02_simulate(tmp_path):
    out = run("02_simulate.py", "--out", tmp_path / "b.png", cwd=tmp_path)
    assert is_png(tmp_path / "b.png") and "deadzone -> linear -> deadband" in out, out


def test_03_can_decode(tmp_path):
    if not os.path.isdir(os.path.join(SRC, "..", "shared", "data", "can-corpus")):
        pytest.skip("no CAN corpus")
    out = run("03_can_decode.py", "--out", tmp_path / "c.png", cwd=tmp_path)
    assert is_png(tmp_path / "c.png"), out
    decoded = int(out.split("decoded ")[1].split()[0])
    assert decoded > 500, out


def test_04_compensate(tmp_path):
    out = run("04_compensate.py", "--out", tmp_path / "d.png", cwd=tmp_path)
    assert is_png(tmp_path / "d.png"), out
    # through the inverse the plant follows its target (exact identity up to rounding); without, it does not
    for line in (out.split("deadzone:")[1], out.split("backlash:")[1]):
        raw, comp = float(line.split("RMS error ")[1].split()[0]), float(line.split(", ")[1].split()[0])
        assert raw > 0.05 and comp < 1e-9, out


def test_05_fleet(tmp_path):
    fleet = tmp_path / "fleet"
    run("05_fleet.py", "--generate", 6, "--duration", 30, fleet, cwd=tmp_path)
    out = run("05_fleet.py", fleet, "--workers", 2, "--out", tmp_path / "r.csv", "--figure", tmp_path / "e.png",
              cwd=tmp_path)
    assert is_png(tmp_path / "e.png"), out
    with open(tmp_path / "r.csv") as f:
        lines = f.read().splitlines()
    assert lines[0].startswith("file,side,a1,a1_lo,a1_hi,b1") and len(lines) == 1 + 12
