#!/usr/bin/env python3
"""Writes scenes/cloud.vol, the density grid of scenes/cloud.json: a sparse cumulus-like cloud (a few
overlapping blobs with fractal noise eroding their edges) in a 96 x 64 x 96 grid, Mitsuba's .vol format
(version 3, float32, one channel). Deterministic (fixed seed); about 2.4 MB, so it is generated, not
committed. Usage: scenes/make_cloud.py [OUTPUT] [--resolution N] (N samples along x and z, 2N/3 along y).
"""
import argparse
import pathlib
import struct

import numpy as np


def value_noise(shape, cells, rng):
    """Smooth noise: random values on a coarse lattice, interpolated trilinearly through a smoothstep."""
    lattice = rng.random((cells + 2, cells + 2, cells + 2))
    coords = np.meshgrid(*[np.linspace(0, cells, n, endpoint=False) for n in shape], indexing="ij")
    index = [c.astype(int) for c in coords]
    frac = [(c - i) * (c - i) * (3 - 2 * (c - i)) for c, i in zip(coords, index)]
    out = 0
    for dz in (0, 1):
        for dy in (0, 1):
            for dx in (0, 1):
                w = ((frac[0] if dz else 1 - frac[0]) * (frac[1] if dy else 1 - frac[1]) *
                     (frac[2] if dx else 1 - frac[2]))
                out = out + w * lattice[index[0] + dz, index[1] + dy, index[2] + dx]
    return out


def cloud(nx, ny, nz, seed=7):
    rng = np.random.default_rng(seed)
    z, y, x = np.meshgrid(np.linspace(0, 1, nz), np.linspace(0, 1, ny), np.linspace(0, 1, nx), indexing="ij")
    # Blobs (centre x, y, z, radius), squashed vertically, over a flat base: a small cumulus.
    blobs = [(0.5, 0.4, 0.5, 0.28), (0.32, 0.35, 0.45, 0.2), (0.68, 0.38, 0.55, 0.22), (0.5, 0.6, 0.45, 0.2),
             (0.42, 0.32, 0.68, 0.17), (0.6, 0.3, 0.3, 0.16)]
    shape = np.zeros_like(x)
    for cx, cy, cz, r in blobs:
        shape = np.maximum(shape, 1 - np.sqrt((x - cx) ** 2 + ((y - cy) * 1.3) ** 2 + (z - cz) ** 2) / r)
    shape *= np.clip((y - 0.18) * 8, 0, 1)
    noise = sum(value_noise((nz, ny, nx), 4 * 2 ** o, rng) * 0.5 ** o for o in range(4)) / 1.875
    return (np.clip(shape * (1.6 + 3 * (noise - 0.5)), 0, None) * 8).astype(np.float32)


def write_vol(path, grid):
    nz, ny, nx = grid.shape
    header = b"VOL" + bytes([3]) + struct.pack("<5i", 1, nx, ny, nz, 1) + struct.pack("<6f", 0, 0, 0, 1, 1, 1)
    path.write_bytes(header + grid.astype("<f4").tobytes())


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("output", nargs="?", default=str(pathlib.Path(__file__).with_name("cloud.vol")))
    parser.add_argument("--resolution", type=int, default=96)
    args = parser.parse_args()
    n = args.resolution
    grid = cloud(n, max(2, 2 * n // 3), n)
    write_vol(pathlib.Path(args.output), grid)
    print(f"{args.output}: {grid.shape[2]} x {grid.shape[1]} x {grid.shape[0]}, "
          f"{100 * np.mean(grid > 0):.0f}% of the voxels non-empty, max density {grid.max():.2f}")


if __name__ == "__main__":
    main()
