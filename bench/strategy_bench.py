#!/usr/bin/env python3
"""Sampling-strategy benchmark: relMSE (eps 0.01) at equal spp and at equal time for each pixel
sampler, each direction-sampling strategy, MIS on/off, shadow-ray counts and light selection, and
adaptive against uniform sampling at equal total samples. Prints markdown tables for
docs/performance.md.

Scenes: the Cornell box (reference: ../shared/scenes/cornell-box/reference.exr) and
bench/scenes/soft-shadows.json (reference rendered once by this script at high spp, cached in the
build folder). Usage: bench/strategy_bench.py [--build build] [--spp 64] [--threads 2] [--seeds 2]
[--adaptive-only] [--scene cornell-box|soft-shadows]
Run with Debian's /usr/bin/python3 (needs python3-numpy, python3-openimageio).
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared")


def load(path):
    return oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)


def rel_mse(a, b):
    return float(np.mean((a - b) ** 2 / (b * b + 0.01)))


def render(candela, scene, out, args, threads):
    cmd = [candela, "render", scene, "-o", out, "--threads", str(threads), "-q"] + args
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr}")
    m = re.search(r"in ([\d.]+) s: ([\d.]+) Msamples/s", p.stdout)
    return float(m.group(1))


def table(title, rows):
    print(f"\n### {title}\n")
    print("| configuration | time s | relMSE (equal spp) | relMSE x time / baseline time (equal time) |")
    print("|---|---|---|---|")
    base_time = rows[0][1]
    for name, t, e in rows:
        print(f"| {name} | {t:.2f} | {e:.5f} | {e * t / base_time:.5f} |")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", default=os.path.join(ROOT, "build"))
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--seeds", type=int, default=2, help="renders per configuration (relMSE averaged)")
    p.add_argument("--adaptive-only", action="store_true", help="only the adaptive-sampling tables")
    p.add_argument("--scene", choices=["cornell-box", "soft-shadows"], help="only this scene")
    a = p.parse_args()
    candela = os.path.join(a.build, "candela")
    scenes = {
        "cornell-box": (os.path.join(ROOT, "scenes/cornell-box.json"), os.path.join(SHARED, "scenes/cornell-box/reference.exr")),
        "soft-shadows": (os.path.join(ROOT, "bench/scenes/soft-shadows.json"), None),
    }
    cache = os.path.join(a.build, "bench-cache")
    os.makedirs(cache, exist_ok=True)
    ss_ref = os.path.join(cache, "soft-shadows-reference.exr")
    if not os.path.exists(ss_ref):
        print("rendering the soft-shadows reference (4096 spp, zsobol)...", file=sys.stderr)
        render(candela, scenes["soft-shadows"][0], ss_ref, ["--spp", "4096", "--sampler", "zsobol", "--seed", "12345"], a.threads)
    scenes["soft-shadows"] = (scenes["soft-shadows"][0], ss_ref)

    spp = ["--spp", str(a.spp)]
    groups = [
        ("pixel samplers", [(n, spp + ["--sampler", n]) for n in ["random", "stratified", "poisson", "zsobol"]]),
        ("direction sampling and MIS (zsobol)", [
            ("bsdf + MIS", spp + ["--sampler", "zsobol"]),
            ("cosine + MIS", spp + ["--sampler", "zsobol", "--direction-sampling", "cosine"]),
            ("uniform + MIS", spp + ["--sampler", "zsobol", "--direction-sampling", "uniform"]),
            ("bsdf, no MIS", spp + ["--sampler", "zsobol", "--no-mis"]),
            ("uniform, no MIS (the paper)", spp + ["--sampler", "zsobol", "--direction-sampling", "uniform", "--no-mis"]),
        ]),
        ("shadow rays and light selection (zsobol)", [
            ("1 ray, by power", spp + ["--sampler", "zsobol"]),
            ("4 rays, by power", spp + ["--sampler", "zsobol", "--shadow-rays", "4"]),
            ("4 rays, paper's rule", spp + ["--sampler", "zsobol", "--shadow-rays", "4", "--light-selection", "paper"]),
        ]),
    ]
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out.exr")
        for scene_name, (scene, ref_path) in scenes.items():
            if a.scene and scene_name != a.scene:
                continue
            ref = load(ref_path)
            print(f"\n## {scene_name} ({a.spp} spp, {a.threads} threads, mean of {a.seeds} seeds)")
            if not a.adaptive_only:
                for title, configs in groups:
                    rows = []
                    for name, args in configs:
                        t = e = 0.0
                        for s in range(a.seeds):
                            t += render(candela, scene, out, args + ["--seed", str(s + 1)], a.threads)
                            e += rel_mse(load(out), ref)
                        rows.append((name, t / a.seeds, e / a.seeds))
                    table(title, rows)
            adaptive_tables(candela, scene, ref, out, tmp, a)


def adaptive_tables(candela, scene, ref, out, tmp, a):
    """Adaptive against uniform sampling at equal total samples: a budget (--adaptive-spp, exactly
    the same total), then a threshold (uniform given the mean spp the threshold ended with)."""
    print(f"\n### adaptive sampling with a budget (batches of 16, mean of {a.seeds} seeds)\n")
    print("| sampler | spp | uniform time s | uniform relMSE | adaptive time s | adaptive relMSE | relMSE ratio |")
    print("|---|---|---|---|---|---|---|")
    for sampler in ["zsobol", "random"]:
        for spp in [a.spp, 4 * a.spp]:
            t_un = e_un = t_ad = e_ad = 0.0
            for s in range(a.seeds):
                seed = ["--sampler", sampler, "--seed", str(s + 1)]
                t_un += render(candela, scene, out, seed + ["--spp", str(spp)], a.threads) / a.seeds
                e_un += rel_mse(load(out), ref) / a.seeds
                t_ad += render(candela, scene, out, seed + ["--adaptive-spp", str(spp)], a.threads) / a.seeds
                e_ad += rel_mse(load(out), ref) / a.seeds
            print(f"| {sampler} | {spp} | {t_un:.2f} | {e_un:.6f} | {t_ad:.2f} | {e_ad:.6f} | {e_ad / e_un:.3f} |")
    t_ad = render(candela, scene, out, ["--sampler", "zsobol", "--adaptive-threshold", "0.05",
                                        "--adaptive-batch", "16", "--max-spp", str(8 * a.spp),
                                        "--spp-map", os.path.join(tmp, "map.exr")], a.threads)
    e_ad = rel_mse(load(out), ref)
    counts = load(os.path.join(tmp, "map.exr"))[:, :, 0]
    mean_spp = float(counts.mean())
    equal = max(1, int(round(mean_spp)))
    t_un = render(candela, scene, out, ["--sampler", "zsobol", "--spp", str(equal)], a.threads)
    e_un = rel_mse(load(out), ref)
    print(f"\n### adaptive sampling with a threshold (0.05, batches of 16, max {8 * a.spp} spp, zsobol)\n")
    print("| configuration | mean spp | time s | relMSE |")
    print("|---|---|---|---|")
    print(f"| uniform | {equal} | {t_un:.2f} | {e_un:.5f} |")
    print(f"| adaptive | {mean_spp:.1f} | {t_ad:.2f} | {e_ad:.5f} |")

if __name__ == "__main__":
    main()
