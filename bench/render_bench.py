#!/usr/bin/env python3
"""Render benchmarks: runs `candela render` on benchmark scenes and prints wall time, Msamples/s,
Mrays/s (camera + bounce + shadow rays, as counted by the renderer), peak memory (max RSS) and
relMSE (eps 0.01) against a reference where one exists.

Usage: bench/render_bench.py [--build build] [--threads 2] [--repeat 1] [--quick]
Run it with Debian's /usr/bin/python3 (python3-numpy and python3-openimageio are needed for relMSE).
"""
import argparse
import os
import re
import resource
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared")

# name, scene, extra args, reference image
SCENES = [
    ("cornell-box 512x512 256spp depth16", os.path.join(ROOT, "scenes/cornell-box.json"),
     ["--spp", "256", "--max-depth", "16", "--resolution", "512x512"],
     os.path.join(SHARED, "scenes/cornell-box/reference.exr")),
]


def rel_mse(test_path, ref_path):
    try:
        import numpy as np
        import OpenImageIO as oiio
    except ImportError:
        return None
    a = oiio.ImageBuf(test_path).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)
    b = oiio.ImageBuf(ref_path).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)
    return float(np.mean((a - b) ** 2 / (b * b + 0.01)))


def run_one(candela, scene, args, threads, out):
    cmd = [candela, "render", scene, "-o", out, "--threads", str(threads), "-q"] + args
    start = time.monotonic()
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - start
    if proc.returncode != 0:
        sys.exit(f"benchmark failed: {' '.join(cmd)}\n{proc.stderr}")
    peak_kib = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    m = re.search(r"in ([\d.]+) s: ([\d.]+) Msamples/s, ([\d.]+) Mrays/s", proc.stdout)
    render_s, msps, mrps = (float(x) for x in m.groups())
    return wall, render_s, msps, mrps, max(peak_kib, before) / 1024.0


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", default=os.path.join(ROOT, "build"))
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--repeat", type=int, default=1, help="runs per scene; the median is reported")
    p.add_argument("--quick", action="store_true", help="16 spp instead of the full sample counts")
    a = p.parse_args()
    candela = os.path.join(a.build, "candela")
    print(f"{'scene':40} {'threads':>7} {'wall s':>8} {'render s':>8} {'Msamples/s':>10} {'Mrays/s':>8} "
          f"{'peak MiB':>8} {'relMSE':>8}")
    with tempfile.TemporaryDirectory() as tmp:
        for name, scene, args, ref in SCENES:
            if a.quick:
                args = [x if args[i - 1] != "--spp" else "16" for i, x in enumerate(args)]
            out = os.path.join(tmp, "bench.exr")
            runs = sorted((run_one(candela, scene, args, a.threads, out) for _ in range(a.repeat)), key=lambda r: r[1])
            wall, render_s, msps, mrps, peak = runs[len(runs) // 2]
            err = rel_mse(out, ref) if ref and os.path.exists(ref) else None
            print(f"{name:40} {a.threads:>7} {wall:>8.2f} {render_s:>8.2f} {msps:>10.3f} {mrps:>8.2f} {peak:>8.1f} "
                  f"{'' if err is None else f'{err:.5f}':>8}")


if __name__ == "__main__":
    main()
