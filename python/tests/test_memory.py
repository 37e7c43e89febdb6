"""No references or memory leak over 100 renders (and edits)."""
import gc
import sys

import candela
from conftest import furnace_dict


def resident_bytes():
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[1]) * 4096


def test_memory_stays_flat_over_100_renders():
    scene = candela.load_dict(furnace_dict())
    params = candela.traverse(scene)

    def one_render(i):
        params["materials.grey.reflectance"] = 0.5 + 0.001 * (i % 10)
        # 256 x 256 float32 RGB: 768 KiB per image, so a leaked image per render would add 75 MiB.
        image = candela.render(scene, spp=1, max_depth=2, resolution=(256, 256), progress=False)
        assert image.shape == (256, 256, 3)
        image._repr_png_()

    for i in range(10):  # warm up: allocator pools, TBB's threads, caches
        one_render(i)
    gc.collect()
    objects, references, before = len(gc.get_objects()), sys.getrefcount(scene), resident_bytes()
    for i in range(100):
        one_render(i)
    gc.collect()
    grown = resident_bytes() - before
    assert grown < 16 * 2**20, f"resident memory grew by {grown / 2**20:.1f} MiB over 100 renders"
    assert sys.getrefcount(scene) == references
    assert len(gc.get_objects()) - objects < 100
