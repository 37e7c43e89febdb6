"""Every kind of bad input raises a Python exception with candela's message; none crashes."""
import pytest

import candela
from conftest import SHARED_DIR, SOURCE_DIR, furnace_dict


@pytest.fixture
def scene():
    return candela.load_dict(furnace_dict())


def test_wrong_types_raise_type_error(scene):
    with pytest.raises(TypeError, match="spp must be an integer, got float"):
        candela.render(scene, spp=2.5)
    with pytest.raises(TypeError, match="must be an integer, got bool"):
        candela.render(scene, seed=True)
    with pytest.raises(TypeError, match="clamp must be a number, got str"):
        candela.render(scene, clamp="4")
    with pytest.raises(TypeError, match="integrator must be a string"):
        candela.render(scene, integrator=3)
    with pytest.raises(TypeError, match="resolution"):
        candela.render(scene, resolution=(1, 2, 3))
    with pytest.raises(TypeError, match="candela.Scene"):
        candela.render("scene.json")
    with pytest.raises(TypeError, match="progress"):
        candela.render(scene, progress="yes")
    with pytest.raises(TypeError, match="dict"):
        candela.load_dict([1, 2])


def test_unknown_keywords_raise_type_error(scene):
    with pytest.raises(TypeError, match="unexpected keyword argument 'sppp'"):
        candela.render(scene, sppp=4)


def test_values_the_command_line_refuses_raise_usage_error(scene):
    for keywords, message in [
        (dict(integrator="photon"), "unknown integrator 'photon'"),
        (dict(spp=0), "spp: 0 is out of range"),
        (dict(max_depth=-1), "max_depth: -1 is out of range"),
        (dict(spp=2**40), "spp: 1099511627776 is out of range"),
        (dict(sampler="halton"), "sampler: unknown value 'halton'"),
        (dict(resolution="big"), "resolution: expected WIDTHxHEIGHT"),
        (dict(resolution=(0, 10)), "resolution 0x10 is out of range"),
        (dict(time_limit="soon"), "time_limit: expected seconds or a duration"),
        (dict(time_limit=-1), "time_limit: expected seconds or a duration"),
        (dict(time_limit=0), "time_limit: must be more than 0"),
        (dict(clamp=float("nan")), "clamp: must be a positive number"),
        (dict(integrator="mlt", adaptive_spp=32), "adaptive_spp"),
        (dict(mlt_large_step=0.8, mlt_lens=0.5, integrator="mlt"), "must be at most 1"),
        (dict(target_error=0.01, adaptive_threshold=0.1), "target_error: adaptive sampling"),
    ]:
        with pytest.raises(candela.UsageError, match=message):
            candela.render(scene, **keywords)
    assert issubclass(candela.UsageError, ValueError)


def test_bad_scene_files_raise_scene_error_with_the_place(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{\n  "shapes": [\n    { "type": "sphere", "center": [0, 0, 0], "radius": -1 }\n  ]\n}\n')
    with pytest.raises(candela.SceneError) as error:
        candela.load_file(bad)
    assert error.value.file == str(bad) and error.value.line == 3 and error.value.pointer == "/shapes/0/radius"
    assert "radius" in str(error.value)

    pbrt = tmp_path / "bad.pbrt"
    pbrt.write_text('WorldBegin\nShape "sphere" "float radius" [ "one" ]\n')
    with pytest.raises(candela.SceneError) as error:
        candela.load_file(pbrt)
    assert error.value.file == str(pbrt) and error.value.line == 2

    with pytest.raises(candela.SceneError, match="not found"):
        candela.load_file(tmp_path / "missing.json")
    with pytest.raises(candela.SceneError, match="unsupported scene file extension"):
        candela.load_file(SHARED_DIR / "README.md")
    mesh_missing = tmp_path / "mesh.json"
    mesh_missing.write_text('{ "shapes": [ { "type": "mesh", "file": "nowhere.ply" } ] }')
    with pytest.raises(candela.SceneError, match="nowhere.ply"):
        candela.load_file(mesh_missing)


def test_bad_dicts_raise_scene_error_with_the_json_pointer():
    scene = furnace_dict()
    scene["shapes"][0]["radius"] = -1
    with pytest.raises(candela.SceneError) as error:
        candela.load_dict(scene)
    assert error.value.pointer == "/shapes/0/radius" and error.value.file == "<dict>" and error.value.line == 0
    assert str(error.value).startswith("<dict>: at /shapes/0/radius: ")
    scene = furnace_dict()
    scene["camera"]["colour"] = 1
    with pytest.raises(candela.SceneError, match="colour"):
        candela.load_dict(scene)
    scene = furnace_dict()
    scene["lights"][0]["radiance"] = float("nan")
    with pytest.raises(candela.SceneError, match="NaN"):
        candela.load_dict(scene)
    with pytest.raises(TypeError, match="cannot go in a scene"):
        candela.load_dict({"render": {"spp": object()}})
    assert issubclass(candela.SceneError, ValueError)


def test_writing_to_a_missing_directory_raises_and_writes_nothing(tmp_path):
    image = candela.render(candela.load_dict(furnace_dict()), spp=1)
    with pytest.raises(RuntimeError, match="cannot write image"):
        image.write(tmp_path / "no-such-dir" / "out.exr")
    with pytest.raises(RuntimeError, match="unsupported image format"):
        image.write(tmp_path / "out.jpg")
    assert list(tmp_path.iterdir()) == []
