#!/usr/bin/env python3
"""The majorant grid against one global majorant on a sparse heterogeneous cloud (scenes/cloud.json,
its density written by scenes/make_cloud.py): both render the same expectation, so the comparison is
efficiency, 1 / (relMSE x time), relMSE (eps 0.01) against a long render with the majorant grid.

Usage (from the repository root, after building build/): bench/majorant_grid.py [--spp N] [--seeds K]
Environment: CANDELA (default build/candela). Prints one line per setting and the efficiency ratio.
"""
import argparse
import json
import os
import pathlib
import re
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

ROOT = pathlib.Path(__file__).resolve().parent.parent
CANDELA = os.environ.get("CANDELA", str(ROOT / "build/candela"))
WORK = pathlib.Path("/tmp/candela-majorant-bench")


def render(scene, out, spp, seed):
    r = subprocess.run([CANDELA, "render", str(scene), "-o", str(out), "--spp", str(spp), "--seed", str(seed)],
                       check=True, capture_output=True, text=True)
    seconds = float(re.search(r"spp in ([0-9.]+) s", r.stdout + r.stderr).group(1))
    return oiio.ImageBuf(str(out)).get_pixels(oiio.FLOAT)[:, :, :3], seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--reference-spp", type=int, default=2048)
    parser.add_argument("--resolution", default="200x134")
    args = parser.parse_args()
    WORK.mkdir(exist_ok=True)
    subprocess.run([sys.executable, str(ROOT / "scenes/make_cloud.py"), str(WORK / "cloud.vol")], check=True)
    scene = json.loads((ROOT / "scenes/cloud.json").read_text())
    w, h = map(int, args.resolution.split("x"))
    scene["camera"].update(width=w, height=h)
    scenes = {}
    for name, cells in (("majorant grid (4^3 samples per cell)", 4), ("one global majorant", 0)):
        s = json.loads(json.dumps(scene))
        s["media"]["cloud"]["density"]["filename"] = str(WORK / "cloud.vol")
        s["media"]["cloud"]["majorant_cell_samples"] = cells
        path = WORK / f"cloud_{cells}.json"
        path.write_text(json.dumps(s))
        scenes[name] = path
    first = next(iter(scenes.values()))
    ref, ref_seconds = render(first, WORK / "reference.exr", args.reference_spp, 1000)
    print(f"reference: {args.reference_spp} spp in {ref_seconds:.1f} s ({args.resolution})")
    efficiency = {}
    for name, path in scenes.items():
        errors, times = [], []
        for seed in range(1, args.seeds + 1):
            img, seconds = render(path, WORK / "test.exr", args.spp, seed)
            errors.append(float(np.mean((img - ref) ** 2 / (ref ** 2 + 0.01))))
            times.append(seconds)
        e, t = float(np.median(errors)), float(np.median(times))
        efficiency[name] = 1 / (e * t)
        print(f"{name}: {args.spp} spp, median over {args.seeds} seeds: {t:.2f} s, relMSE {e:.3g}, "
              f"efficiency {efficiency[name]:.3g}")
    a, b = efficiency.values()
    print(f"majorant grid / global majorant efficiency: {a / b:.2f}")


if __name__ == "__main__":
    main()
