"""traverse(): read and change a loaded scene's parameters, render again without reloading."""
import numpy as np
import pytest

import candela
from conftest import SOURCE_DIR, furnace_dict

SETTINGS = dict(spp=4, resolution=(32, 32), seed=7)


def test_doubling_the_light_doubles_the_image():
    scene = candela.load_file(SOURCE_DIR / "scenes/cornell-box.json")
    params = candela.traverse(scene)
    before = candela.render(scene, **SETTINGS)
    params["shapes.light.emission"] = tuple(2 * c for c in params["shapes.light.emission"])
    after = candela.render(scene, **SETTINGS)
    # Every sample's radiance scales with the one light; the sampling decisions do not change.
    assert np.allclose(after, 2 * before, rtol=1e-5, atol=1e-7)
    assert before.max() > 0


def test_a_point_lights_intensity_scales_its_image():
    scene_dict = furnace_dict()
    scene_dict["lights"] = [{"type": "point", "position": [0, 3, 3], "intensity": [10, 10, 10]}]
    scene = candela.load_dict(scene_dict)
    before = candela.render(scene, **SETTINGS)
    candela.traverse(scene)["lights.0.intensity"] = 20
    assert np.allclose(candela.render(scene, **SETTINGS), 2 * before, rtol=1e-5, atol=1e-7)


def test_material_camera_and_transform_edits_change_the_image_as_a_reloaded_edited_file_does():
    edited = furnace_dict()
    edited["materials"]["grey"]["reflectance"] = [0.2, 0.4, 0.6]
    edited["camera"]["fov"] = 25
    edited["shapes"][0]["transform"] = [{"translate": [0.5, 0, 0]}]
    scene = candela.load_dict(furnace_dict())
    params = candela.traverse(scene)
    params["materials.grey.reflectance"] = (0.2, 0.4, 0.6)
    params["camera.fov"] = 25
    matrix = np.eye(4)
    matrix[0, 3] = 0.5
    params["shapes.ball.to_world"] = matrix
    assert np.array_equal(params["shapes.ball.to_world"], matrix)
    assert candela.render(scene, **SETTINGS).tobytes() == candela.render(candela.load_dict(edited), **SETTINGS).tobytes()


def test_roughness_and_the_listing():
    scene = candela.load_dict({
        "materials": {"metal": {"type": "conductor", "roughness": 0.1}, "glass": {"type": "dielectric", "ior": 1.5}},
        "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "metal"},
                   {"type": "sphere", "center": [3, 0, 0], "radius": 1, "material": "glass"}],
        "lights": [{"type": "sky", "radiance": 1}]})
    params = candela.traverse(scene)
    assert params["materials.metal.roughness"] == pytest.approx(0.1)
    params["materials.metal.roughness"] = 0.3
    params["materials.glass.ior"] = 1.33
    assert params["materials.metal.roughness"] == pytest.approx(0.3)
    assert params["materials.glass.ior"] == pytest.approx(1.33)
    listing = repr(params)
    for name in params:
        assert name in listing
    assert params.range("camera.fov") == "0 < fov < 180"
    assert len(params) == len(list(params.keys()))


def test_bad_edits_are_refused_and_change_nothing():
    scene = candela.load_dict(furnace_dict())
    params = candela.traverse(scene)
    before = scene.to_json()
    with pytest.raises(KeyError, match="materials.grey.reflectance"):
        params["materials.gray.reflectance"] = 0.5  # a typo: the message names the near ones
    with pytest.raises(ValueError, match="outside its range"):
        params["camera.fov"] = 190
    with pytest.raises(ValueError, match="outside its range"):
        params["materials.grey.reflectance"] = (0.5, -0.1, 0.5)
    with pytest.raises(ValueError, match="outside its range"):
        params["materials.grey.reflectance"] = float("nan")
    with pytest.raises(TypeError, match="expected a number"):
        params["camera.fov"] = "wide"
    with pytest.raises(TypeError, match="three numbers"):
        params["materials.grey.reflectance"] = (0.5, 0.5)
    with pytest.raises(ValueError, match="singular"):
        params["shapes.ball.to_world"] = np.zeros((4, 4))
    with pytest.raises(TypeError, match="4x4"):
        params["shapes.ball.to_world"] = np.eye(3)
    with pytest.raises(TypeError):
        del params["camera.fov"]
    with pytest.raises(KeyError):
        params["no.such.parameter"]
    assert scene.to_json() == before


def test_renders_after_an_edit_read_no_file_again(tmp_path):
    # The texture and the environment map are read when the scene is loaded: removing the files
    # afterwards changes nothing, through edits and any number of renders.
    for name in ("checker.ppm", "sky.hdr"):
        (tmp_path / name).write_bytes((SOURCE_DIR / "tests/data/textures" / name).read_bytes())
    scene = candela.load_dict({
        "textures": {"checker": {"type": "image", "filename": "checker.ppm"}},
        "materials": {"m": {"type": "diffuse", "reflectance": "checker"}},
        "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}],
        "lights": [{"type": "environment", "filename": "sky.hdr"}]}, base_dir=tmp_path)
    before = candela.render(scene, **SETTINGS)
    for name in ("checker.ppm", "sky.hdr"):
        (tmp_path / name).unlink()
    params = candela.traverse(scene)
    params["lights.0.scale"] = 2
    assert np.allclose(candela.render(scene, **SETTINGS), 2 * before, rtol=1e-5, atol=1e-7)
    params["lights.0.scale"] = 1
    assert candela.render(scene, **SETTINGS).tobytes() == before.tobytes()


def fog_dict(sigma_t, albedo, g, emission, scale):
    """The furnace's sphere inside a fog-filled box (the camera outside), rendered by volpath."""
    d = furnace_dict()
    d["render"]["integrator"] = "volpath"
    d["media"] = {"fog": {"type": "homogeneous", "sigma_t": sigma_t, "albedo": albedo, "g": g,
                          "emission": emission, "scale": scale}}
    d["materials"]["boundary"] = {"type": "interface"}
    d["shapes"].append({"type": "box", "min": [-2, -2, -2], "max": [2, 2, 2], "material": "boundary",
                        "interior": "fog"})
    return d


def test_medium_edits_render_as_the_edited_file_does():
    scene = candela.load_dict(fog_dict([0.5, 0.25, 0.5], 0.5, 0, 0, 1))
    params = candela.traverse(scene)
    assert params["media.fog.g"] == 0
    params["media.fog.sigma_t"] = (0.25, 0.5, 0.75)
    params["media.fog.albedo"] = (0.5, 0.75, 0.25)
    params["media.fog.g"] = 0.5
    params["media.fog.emission"] = (1, 2, 3)
    params["media.fog.scale"] = 2
    edited = candela.load_dict(fog_dict([0.25, 0.5, 0.75], [0.5, 0.75, 0.25], 0.5, [1, 2, 3], 2))
    assert candela.render(scene, **SETTINGS).tobytes() == candela.render(edited, **SETTINGS).tobytes()
    with pytest.raises(ValueError, match="outside its range"):
        params["media.fog.albedo"] = (0.5, 1.2, 0.5)
    with pytest.raises(ValueError, match="outside its range"):
        params["media.fog.g"] = 1
    assert params["media.fog.g"] == 0.5
