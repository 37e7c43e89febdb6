"""cmake --install puts a working package in the interpreter's site-packages (here under DESTDIR)."""
import os
import pathlib
import subprocess
import sys

import pytest

BUILD_DIR = os.environ.get("CANDELA_BUILD_DIR")


@pytest.mark.skipif(not BUILD_DIR, reason="needs CANDELA_BUILD_DIR (set by ctest)")
def test_the_installed_package_imports_and_renders(tmp_path):
    result = subprocess.run(["cmake", "--install", BUILD_DIR], env=dict(os.environ, DESTDIR=str(tmp_path)),
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stdout + result.stderr
    packages = list(tmp_path.rglob("candela/__init__.py"))
    assert len(packages) == 1, packages
    site = packages[0].parent.parent
    assert "dist-packages" in str(site) or "site-packages" in str(site)
    assert list(tmp_path.rglob("bin/candela")), "the command line is installed too"
    script = ("import candela, sys; assert candela.__file__.startswith(sys.argv[1]), candela.__file__; "
              "print(candela.render(candela.builtin_scene(), spp=1, resolution=(8, 8), progress=False).shape)")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(site)
    run = subprocess.run([sys.executable, "-c", script, str(site)], env=env, capture_output=True, text=True,
                         timeout=120, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "(8, 8, 3)"
