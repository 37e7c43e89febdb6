"""Shared fixtures of the Python module's tests (run by ctest: python/CMakeLists.txt sets the paths)."""
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("CANDELA_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
SHARED_DIR = pathlib.Path(os.environ.get("CANDELA_SHARED_DIR", SOURCE_DIR.parent / "shared"))
CLI = os.environ.get("CANDELA_CLI", str(SOURCE_DIR / "build" / "candela"))


def furnace_dict(albedo=0.8, sky=1.0):
    """A diffuse sphere under a uniform sky: every pixel of the sphere converges to sky x albedo /
    (1 - ...) in the limit, and the background is the sky itself; small enough to render in a blink."""
    return {
        "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 40, "width": 32, "height": 24},
        "render": {"spp": 4, "max_depth": 8, "seed": 3},
        "materials": {"grey": {"type": "diffuse", "reflectance": albedo}},
        "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "grey", "name": "ball"}],
        "lights": [{"type": "sky", "radiance": sky}],
    }


@pytest.fixture
def furnace_file(tmp_path):
    import json
    path = tmp_path / "furnace.json"
    path.write_text(json.dumps(furnace_dict()))
    return path


def run_cli(*args, **kwargs):
    """The command line, as a user runs it; returns the CompletedProcess (output as text)."""
    return subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, timeout=300, **kwargs)
