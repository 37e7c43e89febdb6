"""render(..., denoise=True) and candela.denoise (docs/denoising.md): the denoised image with both
error estimates, the raw image and the denoiser's input beside it, the same bytes as the command line's
--denoise, and clear errors for what cannot be denoised."""
import numpy as np
import pytest

import candela
from conftest import SOURCE_DIR, run_cli


@pytest.fixture(scope="module")
def denoised():
    """The built-in Cornell box, small, denoised."""
    return candela.render(candela.builtin_scene(), spp=16, resolution=(48, 48), seed=2, denoise=True, progress=False)


def test_render_returns_the_denoised_image_with_both_estimates(denoised):
    meta = denoised.metadata
    assert denoised.shape == (48, 48, 3) and denoised.dtype == np.float32
    assert meta["candela:denoised"] == "true"
    raw, estimate = float(meta["candela:relmse_estimate"]), float(meta["candela:denoised_relmse_estimate"])
    low, high = map(float, meta["candela:denoised_relmse_interval95"].split())
    assert 0 <= low <= estimate <= high
    assert raw > 0 and estimate > 0  # how much the filters gain is the denoiser's tests' to check
    assert float(meta["candela:denoise_seconds"]) >= 0
    # The raw image beside it: the render with the same two halves and no denoising.
    assert isinstance(denoised.noisy, candela.Image)
    plain = candela.render(candela.builtin_scene(), spp=16, resolution=(48, 48), seed=2, estimate_error=True,
                           progress=False)
    np.testing.assert_array_equal(denoised.noisy, plain)
    assert plain.metadata["candela:relmse_estimate"] == meta["candela:relmse_estimate"]
    assert not np.array_equal(denoised, plain)
    assert plain.noisy is None and plain.denoise_input is None
    assert denoised[:4].noisy is None  # a slice is not the render


def test_denoising_is_deterministic(denoised):
    again, relmse = candela.denoise(denoised)
    np.testing.assert_array_equal(again, denoised)
    assert relmse == pytest.approx(float(denoised.metadata["candela:denoised_relmse_estimate"]), rel=1e-5)
    assert again.metadata["candela:scene"] == denoised.metadata["candela:scene"]
    # From the arrays themselves, and whatever the thread count the render had.
    given = denoised.denoise_input
    from_arrays, _ = candela.denoise(given["half_a"], given["half_b"], given["albedo"], given["normal"],
                                     given["depth"], share_a=given["share_a"])
    np.testing.assert_array_equal(from_arrays, denoised)
    one_thread = candela.render(candela.builtin_scene(), spp=16, resolution=(48, 48), seed=2, denoise=True,
                                threads=1, progress=False)
    np.testing.assert_array_equal(one_thread, denoised)


def test_the_same_bytes_as_the_command_line(denoised, tmp_path):
    out = tmp_path / "d.exr"
    # The built-in scene is scenes/cornell-box.json.
    r = run_cli("render", SOURCE_DIR / "scenes" / "cornell-box.json", "--denoise", "--spp", "16", "--resolution",
                "48x48", "--seed", "2", "-q", "-o", out)
    assert r.returncode == 0, r.stderr
    assert "denoised: relMSE" in r.stdout
    written = candela.read_image(out)
    np.testing.assert_array_equal(written, denoised)
    assert written.metadata["candela:denoised_relmse_estimate"] == denoised.metadata["candela:denoised_relmse_estimate"]


def test_denoise_takes_shared_features_and_a_noiseless_image_comes_back_unchanged():
    h, w = 20, 24
    y, x = np.mgrid[0:h, 0:w]
    image = np.stack([0.1 + 0.01 * x, 0.2 + 0.0 * x, 0.3 + 0.01 * y], axis=-1).astype(np.float32)
    albedo = np.full((h, w, 3), 0.5, np.float32)
    normal = np.zeros((h, w, 3), np.float32)
    normal[..., 2] = 1
    depth = np.full((h, w), 2.0, np.float32)
    result, relmse = candela.denoise(image, image.copy(), albedo, normal, depth)
    np.testing.assert_array_equal(result, image)
    assert relmse == 0
    assert result.metadata["candela:denoised"] == "true"


def test_errors_are_clear(denoised):
    scene = candela.builtin_scene()
    with pytest.raises(candela.UsageError, match="denoise: the sppm integrator"):
        candela.render(scene, denoise=True, integrator="sppm", resolution=(16, 16), progress=False)
    with pytest.raises(TypeError, match="denoise must be True or False"):
        candela.render(scene, denoise="yes", progress=False)
    plain = candela.render(scene, spp=1, resolution=(8, 8), progress=False)
    with pytest.raises(ValueError, match="render with denoise=True"):
        candela.denoise(plain)
    given = denoised.denoise_input
    with pytest.raises(TypeError, match="missing albedo, normal, depth"):
        candela.denoise(given["half_a"], given["half_b"])
    with pytest.raises(ValueError, match=r"half_b must have shape \(48, 48, 3\)"):
        candela.denoise(given["half_a"], given["half_b"][:10], given["albedo"], given["normal"], given["depth"])
    with pytest.raises(ValueError, match=r"depth\[1\] must have shape \(48, 48\)"):
        candela.denoise(given["half_a"], given["half_b"], given["albedo"], given["normal"],
                        (given["depth"][0], given["depth"][1][:, :3]))
    nan = given["half_a"].copy()
    nan[3, 4, 1] = np.nan
    with pytest.raises(ValueError, match="half_a has NaN"):
        candela.denoise(nan, given["half_b"], given["albedo"], given["normal"], given["depth"])
    with pytest.raises(ValueError, match=r"share_a must be within \[0, 1\]"):
        candela.denoise(given["half_a"], given["half_b"], given["albedo"], given["normal"], given["depth"],
                        share_a=np.full((48, 48), 1.5))
    with pytest.raises(ValueError, match="half_a must have shape"):
        candela.denoise(np.zeros((4, 4)), np.zeros((4, 4)), np.zeros((4, 4)), np.zeros((4, 4)), np.zeros((4, 4)))
