"""load_file() for every format candela reads, load_dict() for every example of the scene format."""
import json
import re

import numpy as np
import pytest

import candela
from conftest import SHARED_DIR, SOURCE_DIR, furnace_dict

MITSUBA_SCENE = SHARED_DIR / "scenes/mitsuba-tests/tests/scenes/instancing/test_instancing_path.xml"


@pytest.mark.parametrize("path", [
    SOURCE_DIR / "scenes/cornell-box.json",
    SOURCE_DIR / "scenes/cornell-box.pbrt",
    MITSUBA_SCENE,
    SHARED_DIR / "meshes/gltf-sample-assets/Box/glTF/Box.gltf",
    SHARED_DIR / "meshes/cornell-box/CornellBox-Original.obj",
    SHARED_DIR / "meshes/ply-tests/cube.ply",
])
def test_every_format_loads_and_renders(path):
    scene = candela.load_file(path)
    assert scene.name == str(path)
    image = candela.render(scene, spp=1, resolution=(16, 16), max_depth=2)
    assert image.shape == (16, 16, 3) and np.isfinite(image).all() and image.max() > 0


def test_mitsuba_parameters_override_the_defaults():
    assert candela.load_file(MITSUBA_SCENE).settings()["spp"] == 64
    scene = candela.load_file(MITSUBA_SCENE, spp=5)
    assert scene.settings()["spp"] == 5
    # A value the reader refuses names the parameter's place in the file.
    with pytest.raises(candela.SceneError, match=r"test_instancing_path.xml:\d+: .*direct"):
        candela.load_file(MITSUBA_SCENE, integrator="direct")
    with pytest.raises(TypeError, match="Mitsuba"):
        candela.load_file(SOURCE_DIR / "scenes/cornell-box.json", spp=4)


def test_the_readers_warnings_become_scene_warnings(tmp_path):
    # Every reader's warnings (io/warnings.h) come back to the package, named by their place.
    pbrt = tmp_path / "sobol.pbrt"
    pbrt.write_text('Sampler "sobol"\nWorldBegin\nShape "sphere"\n')
    with pytest.warns(candela.SceneWarning, match=r"sobol\.pbrt:1:9: warning: sobol: using candela's zsobol sampler"):
        candela.load_file(pbrt)
    obj = tmp_path / "quad.obj"
    obj.write_text("mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")
    with pytest.warns(candela.SceneWarning, match=r"material library '.*nowhere\.mtl'"):
        candela.load_file(obj)


def scene_format_examples():
    """Each ```json block of docs/scene-format.md, with the line it ends on."""
    examples, block, start = [], None, 0
    for number, line in enumerate((SOURCE_DIR / "docs/scene-format.md").read_text().splitlines(), 1):
        if block is None and line == "```json":
            block, start = [], number
        elif block is not None and line == "```":
            examples.append(pytest.param("\n".join(block), id=f"line{start}"))
            block = None
        elif block is not None:
            block.append(line)
    assert len(examples) >= 20
    return examples


@pytest.mark.parametrize("text", scene_format_examples())
def test_load_dict_reads_every_example_of_the_scene_format(text):
    # Mesh file examples are written as if the scene file were in scenes/.
    scene = candela.load_dict(json.loads(text), base_dir=SOURCE_DIR / "scenes")
    # What it reads is a scene to_dict() describes completely enough to read again.
    assert candela.load_dict(scene.to_dict()).to_dict().keys() == scene.to_dict().keys()


def test_a_scene_goes_to_a_dict_and_back_to_the_same_image():
    scene = candela.load_file(SOURCE_DIR / "scenes/cornell-box.pbrt")
    again = candela.load_dict(scene.to_dict())
    settings = dict(spp=2, resolution=(24, 24))
    assert candela.render(scene, **settings).tobytes() == candela.render(again, **settings).tobytes()


def test_numpy_values_may_go_in_a_dict():
    scene = furnace_dict()
    scene["materials"]["grey"]["reflectance"] = np.array([0.2, 0.3, 0.4], dtype=np.float32)
    scene["render"]["spp"] = np.int64(2)
    assert candela.traverse(candela.load_dict(scene))["materials.grey.reflectance"] == pytest.approx((0.2, 0.3, 0.4))
