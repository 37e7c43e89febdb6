#!/usr/bin/env python3
"""candela's volpath against Cycles' volume rendering at equal time: the Cornell box filled with
homogeneous grey fog (sigma_s 0.0016, sigma_a 0.0004 per mm, Henyey-Greenstein g 0.3; a box just inside
the walls, the camera outside it), max depth 16, box filter, no adaptive sampling, denoising or clamping,
the same thread count. relMSE (eps 0.01) of each against a long candela render (the reference; BDPT and
MLT agree with volpath on this scene, tests/bidirectional_test.cpp). Cycles renders at --spp; candela at
the spp that takes the same time (measured, then scaled). Efficiency ratio = (relMSE x time) of Cycles
over candela's: above 1 = candela better. candela renders with volpath's equiangular sampling on and off
(--equiangular both, the default), each at Cycles' time, so the two are compared in the same run too.

Needs Blender (Debian: apt-get install blender). Usage:
  /usr/bin/python3 bench/cycles_fog_vs_candela.py [--build build] [--resolution 128] [--spp 64]
      [--reference-spp 2048] [--seeds 2] [--threads 2] [--equiangular on|off|both]
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SIGMA_S, SIGMA_A, G = 0.0016, 0.0004, 0.3


def pixels(path):
    return oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)


def rel_mse(a, b):
    return float(np.mean((a - b) ** 2 / (b * b + 0.01)))


def run(cmd, pattern):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    m = re.search(pattern, p.stdout + p.stderr)
    if not m:
        sys.exit(f"no time in the output of {' '.join(cmd)}\n{p.stdout[-2000:]}")
    return float(m.group(1))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", default=os.path.join(ROOT, "build"))
    p.add_argument("--resolution", type=int, default=128)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--reference-spp", type=int, default=2048)
    p.add_argument("--seeds", type=int, default=2)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--equiangular", choices=["on", "off", "both"], default="both",
                   help="candela volpath's --equiangular (the reference always renders with it on)")
    a = p.parse_args()
    candela = os.path.join(a.build, "candela")
    with tempfile.TemporaryDirectory() as tmp:
        scene = json.load(open(os.path.join(ROOT, "scenes/cornell-box.json")))
        scene["media"] = {"fog": {"type": "homogeneous", "sigma_s": SIGMA_S, "sigma_a": SIGMA_A, "g": G}}
        scene["materials"]["fog boundary"] = {"type": "interface"}
        scene["shapes"].append({"type": "box", "min": [1, 1, 1], "max": [555, 547, 558], "material": "fog boundary",
                                "interior": "fog"})
        scene_file = os.path.join(tmp, "foggy-cornell-box.json")
        json.dump(scene, open(scene_file, "w"))
        res = f"{a.resolution}x{a.resolution}"

        def render_candela(spp, seed, out, equiangular="on"):
            return run([candela, "render", scene_file, "--integrator", "volpath", "--spp", str(spp), "--max-depth", "16",
                        "--resolution", res, "--filter", "box", "--threads", str(a.threads), "--seed", str(seed),
                        "--equiangular", equiangular, "-q", "-o", out], r"in ([\d.]+) s:")

        modes = ["on", "off"] if a.equiangular == "both" else [a.equiangular]

        ref_file = os.path.join(tmp, "reference.exr")
        t_ref = render_candela(a.reference_spp, 1000, ref_file)
        ref = pixels(ref_file)
        print(f"reference: candela volpath, {a.reference_spp} spp in {t_ref:.1f} s", file=sys.stderr)
        rows = {"cycles": []}
        for mode in modes:
            rows[f"candela (equiangular {mode})"] = []
        for seed in range(1, a.seeds + 1):
            out = os.path.join(tmp, "cycles.exr")
            t_c = run(["blender", "-b", "--factory-startup", "--python", os.path.join(ROOT, "bench/cycles/cornell_box.py"),
                       "--", "--spp", str(a.spp), "--threads", str(a.threads), "--seed", str(seed), "--resolution",
                       str(a.resolution), "--out", out, "--fog", f"{SIGMA_S},{SIGMA_A},{G}"],
                      r"cycles render seconds: ([\d.]+)")
            rows["cycles"].append((a.spp, t_c, rel_mse(pixels(out), ref)))
            # candela at equal time: measure at the same spp, then scale the spp to Cycles' time.
            for mode in modes:
                out = os.path.join(tmp, "candela.exr")
                t_k = render_candela(a.spp, seed, out, mode)
                spp = max(1, round(a.spp * t_c / t_k))
                t_k = render_candela(spp, seed, out, mode)
                rows[f"candela (equiangular {mode})"].append((spp, t_k, rel_mse(pixels(out), ref)))
                print(f"seed {seed}: cycles {a.spp} spp {t_c:.2f} s; candela (equiangular {mode}) {spp} spp {t_k:.2f} s",
                      file=sys.stderr)
        print(f"Foggy Cornell box {res}, max depth 16, {a.threads} threads, median of {a.seeds} seeds; relMSE against "
              f"candela volpath at {a.reference_spp} spp\n")
        print("| renderer | spp | time s | relMSE | relMSE x time |")
        print("|---|---|---|---|---|")
        products = {}
        for name, r in rows.items():
            spp = statistics.median(x[0] for x in r)
            t = statistics.median(x[1] for x in r)
            e = statistics.median(x[2] for x in r)
            products[name] = statistics.median(x[1] * x[2] for x in r)
            print(f"| {name} | {spp:g} | {t:.2f} | {e:.5f} | {products[name]:.5f} |")
        print()
        for mode in modes:
            print(f"efficiency, candela (equiangular {mode}) over Cycles (relMSE x time of Cycles / candela's): "
                  f"{products['cycles'] / products[f'candela (equiangular {mode})']:.2f}")
        if len(modes) == 2:
            print(f"efficiency, equiangular on over off (relMSE x time off / on): "
                  f"{products['candela (equiangular off)'] / products['candela (equiangular on)']:.2f}")


if __name__ == "__main__":
    main()
