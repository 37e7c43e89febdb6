#!/usr/bin/env python3
"""Writes the meshes of scenes/city-night.json, a generated city at night lit by 23,160 emissive
triangles: lit windows in three colours on a grid of towers, and a string of street lamps along every
street. Most lights are far from any given point, face away or are hidden, so choosing lights by power
alone spends most shadow rays on lights that give nothing; the light BVH (light_selection "bvh") is made
for this (6.5x lower relMSE at equal samples, docs/performance.md). Deterministic
(fixed seed); about 2 MB of OBJ, so it is generated, not committed.

With --road it writes instead the mesh of scenes/lamp-road.json: a straight road 65 km long with a lamp
every 25 m on both kerbs, 5,200 lamps (10,400 emissive triangles), the string of lamps where any point is
near a handful of them and choosing by power almost never picks one of those.

Usage: scenes/make_city.py [OUTPUT_DIR] [--blocks N] (N x N towers; default 14, the scene's)
       scenes/make_city.py [OUTPUT_DIR] --road
"""
import argparse
import pathlib
import random

PITCH = 20.0   # a block: a 12 x 12 tower and an 8-wide street
TOWER = 12.0
FLOOR = 3.5


class Obj:
    def __init__(self):
        self.lines, self.count = [], 0

    def quad(self, a, b, c, d):
        """A quad a b c d, counter-clockwise seen from the side its normal (b - a) x (d - a) faces."""
        for p in (a, b, c, d):
            self.lines.append("v %.4f %.4f %.4f" % tuple(p))
        n = self.count
        self.lines.append("f %d %d %d" % (n + 1, n + 2, n + 3))
        self.lines.append("f %d %d %d" % (n + 1, n + 3, n + 4))
        self.count += 4

    def box(self, lo, hi):
        x0, y0, z0 = lo
        x1, y1, z1 = hi
        self.quad((x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0))  # top (+y)
        self.quad((x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0))  # -z
        self.quad((x1, y0, z1), (x0, y0, z1), (x0, y1, z1), (x1, y1, z1))  # +z
        self.quad((x0, y0, z1), (x0, y0, z0), (x0, y1, z0), (x0, y1, z1))  # -x
        self.quad((x1, y0, z0), (x1, y0, z1), (x1, y1, z1), (x1, y1, z0))  # +x

    def write(self, path):
        path.write_text("\n".join(self.lines) + "\n")


def city(blocks, seed=3):
    rng = random.Random(seed)
    towers, lamps = Obj(), Obj()
    windows = [Obj(), Obj(), Obj()]  # warm, neutral, cool (the scene gives each its radiance)
    offset = -blocks * PITCH / 2
    for i in range(blocks):
        for j in range(blocks):
            x0, z0 = offset + i * PITCH + 4, offset + j * PITCH + 4
            x1, z1 = x0 + TOWER, z0 + TOWER
            height = rng.uniform(12, 70)
            towers.box((x0, 0, z0), (x1, height, z1))
            floors = int((height - 2) / FLOOR)
            eps = 0.03
            # Four columns of windows per facade; each lit with probability 0.3, facing out.
            for floor in range(floors):
                y0 = 2 + floor * FLOOR
                y1 = y0 + 1.8
                for col in range(4):
                    s0 = 1.5 + 3 * col - 0.7
                    s1 = s0 + 1.4
                    for side in range(4):
                        if rng.random() > 0.3:
                            continue
                        w = windows[rng.randrange(3)]
                        if side == 0:  # -z facade
                            w.quad((x1 - s0, y0, z0 - eps), (x1 - s1, y0, z0 - eps), (x1 - s1, y1, z0 - eps),
                                   (x1 - s0, y1, z0 - eps))
                        elif side == 1:  # +z facade
                            w.quad((x0 + s0, y0, z1 + eps), (x0 + s1, y0, z1 + eps), (x0 + s1, y1, z1 + eps),
                                   (x0 + s0, y1, z1 + eps))
                        elif side == 2:  # -x facade
                            w.quad((x0 - eps, y0, z0 + s0), (x0 - eps, y0, z0 + s1), (x0 - eps, y1, z0 + s1),
                                   (x0 - eps, y1, z0 + s0))
                        else:  # +x facade
                            w.quad((x1 + eps, y0, z1 - s0), (x1 + eps, y0, z1 - s1), (x1 + eps, y1, z1 - s1),
                                   (x1 + eps, y1, z1 - s0))
    # Street lamps: a downward-facing 0.5 x 0.5 panel 6 units up, every 10 units along both kerbs of
    # every street in both directions.
    def lamp(x, z):
        h, r = 6.0, 0.25
        lamps.quad((x - r, h, z - r), (x + r, h, z - r), (x + r, h, z + r), (x - r, h, z + r))

    for k in range(blocks + 1):
        street = offset + k * PITCH  # the street's centre line
        for kerb in (-3.0, 3.0):
            for step in range(blocks * 2):
                along = offset + step * PITCH / 2 + 5
                lamp(street + kerb, along)
                lamp(along, street + kerb)
    return towers, windows, lamps


def road(lamps_per_kerb=2600, spacing=25.0):
    """Lamps along z from 0: downward-facing 0.6 x 0.6 panels 8 up, at x = -6 and 6."""
    lamps = Obj()
    h, r = 8.0, 0.3
    for k in range(lamps_per_kerb):
        z = k * spacing
        for x in (-6.0, 6.0):
            lamps.quad((x - r, h, z - r), (x + r, h, z - r), (x + r, h, z + r), (x - r, h, z + r))
    return lamps


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("output", nargs="?", default=str(pathlib.Path(__file__).resolve().parent))
    parser.add_argument("--blocks", type=int, default=14)
    parser.add_argument("--road", action="store_true", help="the lamps of lamp-road.json instead")
    args = parser.parse_args()
    out = pathlib.Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    if args.road:
        lamps = road()
        lamps.write(out / "road-lamps.obj")
        print(f"{out}: {lamps.count // 2} emissive triangles along the road")
        return
    towers, windows, lamps = city(args.blocks)
    towers.write(out / "city-towers.obj")
    for name, w in zip(("warm", "neutral", "cool"), windows):
        w.write(out / f"city-windows-{name}.obj")
    lamps.write(out / "city-lamps.obj")
    triangles = sum(w.count // 2 for w in windows) + lamps.count // 2
    print(f"{out}: {args.blocks}^2 towers, {triangles} emissive triangles")


if __name__ == "__main__":
    main()
