#!/usr/bin/env python3
"""candela against Blender's Cycles (CPU) on the same Cornell box (../shared/scenes/cornell-box/SPEC.md):
512 x 512, 256 spp, 16 bounces, box filter, no adaptive sampling, denoising or clamping, the same
thread count. The two renderers run alternately --repeat times (the machine is noisy); the table
gives each one's median render time, Msamples/s, the median time ratio and the relMSE (eps 0.01) of
each render against ../shared/scenes/cornell-box/reference.exr (equal quality).

Needs Blender (Debian: apt-get install blender). Usage:
  /usr/bin/python3 bench/cycles_vs_candela.py [--build build] [--repeat 3] [--spp 256] [--threads 2]
      [--candela-args "--sampler random"]
"""
import argparse
import os
import re
import shlex
import statistics
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared")
REFERENCE = os.path.join(SHARED, "scenes/cornell-box/reference.exr")


def rel_mse(path):
    a = oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)
    b = oiio.ImageBuf(REFERENCE).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)
    return float(np.mean((a - b) ** 2 / (b * b + 0.01)))


def run(cmd, pattern):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    m = re.search(pattern, p.stdout)
    if not m:
        sys.exit(f"no time in the output of {' '.join(cmd)}\n{p.stdout[-2000:]}")
    return float(m.group(1))


def compare(build, repeat, spp, threads, candela_args):
    """Runs candela and Cycles alternately `repeat` times and prints the Markdown table."""
    candela = os.path.join(build, "candela")
    pixels = 512 * 512
    times = {"candela": [], "cycles": []}
    errors = {"candela": [], "cycles": []}
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(repeat):
            out = os.path.join(tmp, "candela.exr")
            t = run([candela, "render", os.path.join(ROOT, "scenes/cornell-box.json"), "--spp", str(spp),
                     "--max-depth", "16", "--resolution", "512x512", "--threads", str(threads), "--seed", str(i + 1),
                     "-q", "-o", out] + shlex.split(candela_args), r"in ([\d.]+) s:")
            times["candela"].append(t)
            errors["candela"].append(rel_mse(out))
            out = os.path.join(tmp, "cycles.exr")
            t = run(["blender", "-b", "--factory-startup", "--python", os.path.join(ROOT, "bench/cycles/cornell_box.py"),
                     "--", "--spp", str(spp), "--threads", str(threads), "--seed", str(i + 1), "--resolution", "512",
                     "--out", out], r"cycles render seconds: ([\d.]+)")
            times["cycles"].append(t)
            errors["cycles"].append(rel_mse(out))
            print(f"run {i + 1}: candela {times['candela'][-1]:.2f} s, cycles {times['cycles'][-1]:.2f} s", file=sys.stderr)
    print(f"Cornell box 512 x 512, {spp} spp, max depth 16, {threads} threads, {repeat} alternating runs"
          f"{' (candela ' + candela_args + ')' if candela_args else ''}\n")
    print("| renderer | median time s | Msamples/s | relMSE (median) |")
    print("|---|---|---|---|")
    for name in ["candela", "cycles"]:
        t = statistics.median(times[name])
        print(f"| {name} | {t:.2f} | {pixels * spp / t * 1e-6:.2f} | {statistics.median(errors[name]):.5f} |")
    ratios = [c / y for c, y in zip(times["candela"], times["cycles"])]
    print(f"\ncandela / cycles time: median {statistics.median(ratios):.3f} (runs: {', '.join(f'{r:.3f}' for r in ratios)})\n")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", default=os.path.join(ROOT, "build"))
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--candela-args", default="", help="extra arguments for candela render")
    a = p.parse_args()
    compare(a.build, a.repeat, a.spp, a.threads, a.candela_args)


if __name__ == "__main__":
    main()
