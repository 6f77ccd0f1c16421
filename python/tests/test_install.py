"""`cmake --install` puts the package into the interpreter's site-packages: with prefix /usr
(under a DESTDIR) into lib/python3/dist-packages, the folder Debian's python3 searches; with
another prefix into lib/python3.X/dist-packages. The installed copy imports and works."""
import os
import subprocess
import sys
import sysconfig

import pytest

BUILD = os.environ.get("LASH_BUILD_DIR")


def install(*args, env=None):
    return subprocess.run(["cmake", "--install", BUILD, *args], capture_output=True, text=True,
                          env=dict(os.environ, **(env or {})))


def check_import(site):
    code = "import lash, numpy as np; print(lash.__file__); print(lash.signal('sine', 1.0, 0.01)[:3].tolist())"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=dict(os.environ, PYTHONPATH=str(site)), cwd="/")
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines()[0].startswith(str(site)), out.stdout
    return out.stdout


@pytest.mark.skipif(not BUILD, reason="LASH_BUILD_DIR not set")
def test_destdir_prefix_usr(tmp_path):
    r = install("--prefix", "/usr", env={"DESTDIR": str(tmp_path)})
    assert r.returncode == 0, r.stderr
    site = tmp_path / "usr" / "lib" / "python3" / "dist-packages"
    # the folder Debian's interpreter searches for /usr installs
    assert "/usr/lib/python3/dist-packages" in sys.path
    for f in ("__init__.py", "__init__.pyi", "can.py", "py.typed"):
        assert (site / "lash" / f).is_file(), f
    assert any(p.name.startswith("_lash.") and p.name.endswith(".so") for p in (site / "lash").iterdir())
    check_import(site)


@pytest.mark.skipif(not BUILD, reason="LASH_BUILD_DIR not set")
def test_other_prefix(tmp_path):
    r = install("--prefix", str(tmp_path / "p"))
    assert r.returncode == 0, r.stderr
    ver = "python%d.%d" % sys.version_info[:2]
    site = tmp_path / "p" / "lib" / ver / "dist-packages"
    assert (site / "lash" / "__init__.py").is_file()
    # for prefix /usr/local this is a folder on Debian's sys.path
    assert "/usr/local/lib/%s/dist-packages" % ver in sys.path
    check_import(site)
