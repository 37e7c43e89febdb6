"""Importing candela from an interpreter it was not built for says which one it was built for, which one
is running, and the cmake command that builds it for the running one (candela/_build_info.py, which
CMake writes, against sys.version_info; docs/python.md, "Building for your interpreter")."""
import glob
import os
import pathlib
import platform
import shutil
import subprocess
import sys

import pytest

import candela

PACKAGE = pathlib.Path(candela.__file__).parent


def import_candela(python, pythonpath, cwd, prelude=""):
    """`import candela` in a fresh interpreter; returns the CompletedProcess."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["PYTHONPATH"] = str(pythonpath)
    return subprocess.run([python, "-c", prelude + "import candela"], env=env, cwd=cwd, capture_output=True,
                          text=True, timeout=120)


def copy_package(tmp_path, build_info=None, extension=True):
    """The built package in tmp_path/candela, with `build_info` (a dict) as its _build_info.py."""
    target = tmp_path / "candela"
    shutil.copytree(PACKAGE, target, ignore=shutil.ignore_patterns("__pycache__", *([] if extension else ["_candela*"])))
    if build_info is not None:
        (target / "_build_info.py").write_text("".join(f"{k} = {v!r}\n" for k, v in build_info.items()))
    return target


def test_the_build_info_names_this_interpreter():
    info = candela._build_info
    assert info.version.split(".")[:2] == platform.python_version().split(".")[:2]
    assert (PACKAGE / info.extension).is_file()
    assert os.path.isfile(info.executable)
    assert (pathlib.Path(info.source_dir) / "python" / "candela" / "__init__.py").is_file()
    assert pathlib.Path(info.build_dir, "python", "candela", "_build_info.py").is_file()


def test_a_build_for_another_python_version_names_both_interpreters_and_the_cmake_command(tmp_path):
    major, minor = sys.version_info[:2]
    other = f"{major}.{minor + 1}.0"
    copy_package(tmp_path, {"executable": "/opt/python-elsewhere/bin/python3", "version": other,
                            "extension": f"_candela.cpython-{major}{minor + 1}-x86_64-linux-gnu.so",
                            "source_dir": "/src/candela", "build_dir": "/src/candela/build"})
    run = import_candela(sys.executable, tmp_path, tmp_path)
    assert run.returncode != 0
    message = run.stderr[run.stderr.index("ImportError: "):]
    assert f"is for Python {major}.{minor + 1}, and this interpreter is Python {major}.{minor}" in message
    assert f"built for:   /opt/python-elsewhere/bin/python3 (Python {other})" in message
    assert f"running now: {sys.executable} (Python {platform.python_version()})" in message
    assert f"cmake -S /src/candela -B /src/candela/build -DPython_EXECUTABLE={sys.executable}\n" in message
    assert "cmake --build /src/candela/build\n" in message
    assert "PYTHONPATH=/src/candela/build/python" in message and "cmake --install /src/candela/build" in message
    assert "Or run the interpreter it was built for: /opt/python-elsewhere/bin/python3" in message
    assert "Traceback" not in message.split("ImportError: ", 1)[1], "the message is the last thing printed"


def test_an_extension_that_does_not_load_names_the_interpreter_and_the_cmake_command(tmp_path):
    copy_package(tmp_path, extension=False)
    run = import_candela(sys.executable, tmp_path, tmp_path)
    assert run.returncode != 0
    message = run.stderr[run.stderr.index("ImportError: candela cannot be imported"):]
    assert "its extension module _candela does not load" in message
    info = candela._build_info
    assert f"built for:   {info.executable} (Python {info.version})" in message
    assert f"running now: {sys.executable} (Python {platform.python_version()})" in message
    assert f"-DPython_EXECUTABLE={sys.executable}" in message


def test_numpy_missing_says_so_and_how_to_install_it(tmp_path):
    # sys.modules["numpy"] = None makes `import numpy` fail as it does where NumPy is not installed.
    run = import_candela(sys.executable, PACKAGE.parent, tmp_path, prelude="import sys; sys.modules['numpy'] = None; ")
    assert run.returncode != 0
    message = run.stderr[run.stderr.index("ImportError: candela cannot be imported"):]
    assert "NumPy is not installed for this interpreter" in message
    assert f"running now: {sys.executable} (Python {platform.python_version()})" in message
    assert "-m pip install numpy" in message


def other_interpreters():
    """Python 3.8 or later interpreters of another minor version than this one, where there are any
    (python3.X on PATH, pyenv's versions)."""
    candidates = [shutil.which(f"python3.{minor}") for minor in range(8, 20)]
    pyenv = os.environ.get("PYENV_ROOT", os.path.expanduser("~/.pyenv"))
    candidates += sorted(glob.glob(os.path.join(pyenv, "versions", "3.*", "bin", "python3")))
    found = {}
    for python in filter(None, candidates):
        try:
            run = subprocess.run([python, "-c", "import sys; print(sys.executable, *sys.version_info[:2])"],
                                 capture_output=True, text=True, timeout=30)
        except (OSError, subprocess.TimeoutExpired):
            continue
        if run.returncode == 0 and len(run.stdout.split()) == 3:
            executable, major, minor = run.stdout.split()
            if (int(major), int(minor)) >= (3, 8) and (int(major), int(minor)) != sys.version_info[:2]:
                found.setdefault((int(major), int(minor)), executable)
    return sorted(found.values())


def test_another_installed_interpreter_gets_the_message(tmp_path):
    """The real case: the package as built, imported by another Python found on this machine."""
    pythons = other_interpreters()
    if not pythons:
        pytest.skip("no Python 3.8+ of another minor version on this machine")
    for python in pythons:
        run = import_candela(python, PACKAGE.parent, tmp_path)
        assert run.returncode != 0, python
        message = run.stderr[run.stderr.index("ImportError: candela cannot be imported"):]
        assert f"built for:   {candela._build_info.executable} (Python {candela._build_info.version})" in message
        assert f"running now: {python} (Python " in message
        assert f"-DPython_EXECUTABLE={python}" in message, message
