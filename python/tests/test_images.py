"""Images: writing EXR/PNG/PFM with metadata, reading back, showing inline in Jupyter."""
import numpy as np
import pytest

import candela
from conftest import furnace_dict


@pytest.fixture(scope="module")
def image():
    return candela.render(candela.load_dict(furnace_dict()), spp=2)


def test_an_image_is_a_float32_array_that_owns_its_pixels(image):
    assert isinstance(image, np.ndarray) and isinstance(image, candela.Image)
    assert image.dtype == np.float32 and image.shape == (24, 32, 3) and image.flags.c_contiguous
    # The render's pixels are handed over, not copied: the array's memory belongs to its base.
    assert image.base is not None
    half = image[:, :16]
    assert isinstance(half, candela.Image) and half.metadata == image.metadata


def test_exr_and_pfm_keep_every_bit_and_exr_the_metadata(image, tmp_path):
    for name in ("out.exr", "out.pfm"):
        image.write(tmp_path / name)
        back = candela.read_image(tmp_path / name)
        assert back.tobytes() == image.tobytes()
    back = candela.read_image(tmp_path / "out.exr")
    assert back.metadata["candela:spp"] == "2" and back.metadata["candela:integrator"] == "path"


def test_plain_arrays_write_too(tmp_path):
    ramp = np.linspace(0, 1, 12, dtype=np.float64).reshape(3, 4)
    candela.write_image(tmp_path / "ramp.exr", ramp, {"note": "grey"})
    back = candela.read_image(tmp_path / "ramp.exr")
    assert back.shape == (3, 4, 3) and np.allclose(back[:, :, 1], ramp) and back.metadata["note"] == "grey"
    with pytest.raises(ValueError, match="shape"):
        candela.write_image(tmp_path / "bad.exr", np.zeros((2, 2, 4)))


def test_png_is_srgb_and_jupyter_gets_the_same_bytes(image, tmp_path):
    png = image._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    image.write(tmp_path / "out.png")
    assert (tmp_path / "out.png").read_bytes() == png
    back = candela.read_image(tmp_path / "out.png")  # decoded from sRGB 8-bit
    assert np.allclose(back, np.clip(image, 0, 1), atol=0.01)
    assert candela.Image._repr_png_(np.zeros((2, 2)).view(candela.Image)) is None
