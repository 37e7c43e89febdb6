"""The scripts in examples/ run as documented (docs/python.md)."""
import os
import pathlib
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

EXAMPLES = sorted((SOURCE_DIR / "examples").glob("*.py"))


@pytest.mark.parametrize("script", EXAMPLES, ids=[p.name for p in EXAMPLES])
def test_the_example_runs(script, tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg", CANDELA_EXAMPLE_QUICK="1")
    result = subprocess.run([sys.executable, str(script), str(tmp_path)], capture_output=True, text=True, env=env,
                            timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    assert any(tmp_path.iterdir()), "the example writes its results to the directory it is given"


def test_there_are_examples():
    assert EXAMPLES
