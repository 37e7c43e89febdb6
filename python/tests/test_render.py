"""render(): the same bytes as the command line, keywords that mirror its flags, progress, metadata."""
import re

import numpy as np
import pytest

import candela
from conftest import SOURCE_DIR, furnace_dict, run_cli


def test_the_furnace_rendered_from_python_is_the_command_line_image_byte_for_byte(furnace_file, tmp_path):
    for settings in ([], ["--integrator", "bdpt", "--spp", "3"], ["--sampler", "zsobol", "--transport", "spectral"]):
        exr = tmp_path / "cli.exr"
        result = run_cli("render", furnace_file, "-o", exr, "-q", *settings)
        assert result.returncode == 0, result.stderr
        keywords = {flag[2:].replace("-", "_"): value for flag, value in zip(settings[::2], settings[1::2])}
        keywords = {k: int(v) if v.isdigit() else v for k, v in keywords.items()}
        image = candela.render(candela.load_file(furnace_file), **keywords)
        cli = candela.read_image(exr)
        assert image.dtype == np.float32 and image.shape == (24, 32, 3)
        assert image.tobytes() == np.ascontiguousarray(cli).tobytes(), settings
        # The metadata is the command line's, but for the time it took.
        timeless = {k: v for k, v in cli.metadata.items() if k.startswith("candela:") and "time" not in k}
        assert {k: image.metadata[k] for k in timeless} == timeless


def test_the_image_does_not_depend_on_the_thread_count():
    scene = candela.load_dict(furnace_dict())
    one = candela.render(scene, threads=1, spp=8)
    two = candela.render(scene, threads=2, spp=8)
    assert one.tobytes() == two.tobytes()


def test_the_furnace_converges_to_its_analytic_value():
    # A convex diffuse sphere of albedo a under a uniform sky of radiance L reflects a x L everywhere
    # (every direction above a point of it sees the sky); pixels that see only the sky are L.
    scene = candela.load_dict(furnace_dict(albedo=0.5, sky=2.0))
    renders = np.stack([candela.render(scene, spp=16, seed=seed, resolution=(16, 12))[5:7, 7:9] for seed in range(8)])
    mean = renders.mean(axis=0)
    standard_error = renders.std(axis=0, ddof=1) / np.sqrt(len(renders))
    assert np.all(np.abs(mean - 1.0) <= 4 * standard_error + 1e-6), (mean, standard_error)
    corner = candela.render(scene, spp=4, resolution=(16, 12))[0, 0]
    assert np.all(corner == 2.0)


def test_each_keyword_is_a_command_line_flag():
    help_text = run_cli("render", "--help").stdout
    flags = set(re.findall(r"--([a-z][a-z0-9-]*)", help_text))
    for keyword in candela.render_keywords():
        assert keyword.replace("_", "-") in flags, keyword


def test_keywords_apply_to_one_render_only():
    scene = candela.load_dict(furnace_dict())
    assert candela.render(scene, resolution=(8, 6), spp=1).shape == (6, 8, 3)
    assert candela.render(scene, resolution="10x4", spp=1).shape == (4, 10, 3)
    image = candela.render(scene)
    assert image.shape == (24, 32, 3) and image.metadata["candela:spp"] == "4"
    assert scene.settings()["spp"] == 4


def test_progress_is_reported_to_a_callable():
    reports = []
    candela.render(candela.load_dict(furnace_dict()), spp=64, resolution=(256, 256), progress=lambda f, t: reports.append((f, t)))
    assert reports, "a render of this size takes longer than one report interval"
    fractions = [f for f, _ in reports]
    assert all(0 <= f <= 1 for f in fractions) and fractions == sorted(fractions)
    assert all(t >= 0 for _, t in reports)


def test_the_text_bar_draws_on_a_stream(capsys):
    candela.render(candela.load_dict(furnace_dict()), spp=64, resolution=(256, 256), progress=True)
    assert "%" in capsys.readouterr().err


def test_an_exception_in_the_progress_callable_stops_the_render():
    def fail(fraction, elapsed):
        raise RuntimeError("stop here")
    with pytest.raises(RuntimeError, match="stop here"):
        candela.render(candela.load_dict(furnace_dict()), spp=100000, resolution=(128, 128), progress=fail)


def test_error_estimates_targets_and_auto_reach_the_metadata():
    scene = candela.load_dict(furnace_dict())
    image = candela.render(scene, spp=16, estimate_error=True)
    assert float(image.metadata["candela:relmse_estimate"]) > 0
    image = candela.render(scene, target_error=0.01, time_limit="20s")
    assert image.metadata["candela:target_reached"] == "true"
    image = candela.render(scene, integrator="auto", time_limit=1.0)
    assert image.metadata["candela:integrator"] in ("path", "bdpt", "mlt")
    assert "chose" in image.metadata["candela:auto"]


def test_the_builtin_scene_renders():
    image = candela.render(candela.builtin_scene(), spp=1, resolution=(32, 32))
    assert image.metadata["candela:scene"] == "<built-in cornell-box.json>"
    assert 0.02 < float(image.mean()) < 1


def test_other_python_threads_run_while_a_render_holds_no_gil():
    import threading
    import time
    scene = candela.load_dict(furnace_dict())
    done = threading.Event()
    worker = threading.Thread(target=lambda: (candela.render(scene, spp=128, resolution=(256, 256), progress=False),
                                              done.set()))
    worker.start()
    time.sleep(0.05)
    count, start = 0, time.monotonic()
    while time.monotonic() - start < 0.2:
        count += 1
    still_rendering = not done.is_set()
    worker.join()
    assert still_rendering, "the render should take longer than this test's counting"
    assert count > 10000
