#!/usr/bin/env python3
"""How good is candela's own error estimate (--estimate-error, film/error_estimate.h), and how close does
--target-error land? Against pbrt-v4's converged renders of Bitterli's scenes (../shared), relMSE with eps 0.01.

1. Accuracy: each scene at three budgets and several seeds, rendered with --estimate-error; the reported
   estimate against the true relMSE of the same image: the ratio estimate / truth and whether the truth lies in
   the reported 95% interval.
2. Targets: --target-error at two targets per scene: the true relMSE reached, and the time spent against what a
   user who knew the right spp would have spent (the least spp at which a plain render with the same seed meets
   the target, found by rendering around the 1/spp law's guess, rendered plainly and timed).

Usage: /usr/bin/python3 bench/error_estimate_accuracy.py [--build build] [--seeds 5] [--threads 2] [--skip-targets | --targets-only]
       [--repeat 3] [--target-seeds 11] [--loose-only]
       [--scenes cornell-box,veach-mis,veach-ajar,veach-bidir]
Run it with Debian's /usr/bin/python3 (python3-numpy and python3-openimageio).
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BITTERLI = os.path.join(os.path.dirname(ROOT), "shared", "scenes", "bitterli")

# scene: resolution of the reference, integrator, budgets (spp), targets
SCENES = {
    "cornell-box": ("256x256", "path", [16, 64, 256], [0.01, 0.002]),
    "veach-mis": ("320x180", "path", [16, 64, 256], [0.05, 0.01]),
    "veach-ajar": ("320x180", "path", [16, 64, 256], [2.0, 1.0]),
    "veach-bidir": ("192x192", "bdpt", [4, 16, 64], [0.05, 0.02]),
}


def read(path):
    return oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)


def relmse(test, ref):
    return float(np.mean((test - ref) ** 2 / (ref ** 2 + 0.01)))


def render(args, scene, extra, out, estimate=True):
    """(render seconds, spp, estimate, low, high); the whole command's wall-clock seconds in args.last_wall."""
    res, integrator, _, _ = SCENES[scene]
    cmd = [args.candela, "render", os.path.join(BITTERLI, scene, "scene-v4.pbrt"), "--resolution", res,
           "--integrator", integrator, "--threads", str(args.threads), "-q", "-o", out] + extra
    start = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True)
    args.last_wall = time.monotonic() - start
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stderr}")
    t = float(re.search(r" in ([\d.]+) s:", p.stdout).group(1))
    spp = re.search(r", (?:min \d+, mean )?([\d.]+)(?: spp)? in ", p.stdout)
    m = re.search(r"estimated error: relMSE ([\d.e+-]+) \(95% interval ([\d.e+-]+)-([\d.e+-]+)", p.stdout)
    if not estimate:
        return t, None, None, None, None
    if not m:
        sys.exit(f"no estimate from: {' '.join(cmd)}\n{p.stdout}")
    return t, float(spp.group(1)) if spp else None, float(m.group(1)), float(m.group(2)), float(m.group(3))


def least_spp_meeting(args, scene, seed, target, ref, out, guess):
    """The least spp (to a step of 2%) whose plain render with this seed has a true relMSE at most `target`."""
    def meets(n):
        render(args, scene, ["--spp", str(n), "--seed", seed], out, estimate=False)
        return relmse(read(out), ref) <= target
    n, step = guess, max(1, round(0.02 * guess))
    if meets(n):
        while n - step >= 1 and meets(n - step):
            n -= step
    else:
        while not meets(n + step):
            n += step
        n += step
    return n


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--skip-targets", action="store_true")
    ap.add_argument("--targets-only", action="store_true")
    ap.add_argument("--repeat", type=int, default=3, help="timings per target render (median)")
    ap.add_argument("--target-seeds", default="11", help="seeds of the target renders, comma-separated")
    ap.add_argument("--loose-only", action="store_true", help="only each scene's looser target")
    args = ap.parse_args()
    args.candela = os.path.join(args.build, "candela")
    scenes = args.scenes.split(",")
    tmp = tempfile.mkdtemp(prefix="candela-error-")
    out = os.path.join(tmp, "image.exr")

    scenes_for_accuracy = [] if args.targets_only else scenes
    print("| scene (integrator) | spp | true relMSE (median) | estimate / truth: median, min, max | truth in 95% interval |")
    print("|---|---|---|---|---|")
    all_ratios, all_covered = [], 0
    for scene in scenes_for_accuracy:
        ref = read(os.path.join(BITTERLI, scene, "pbrt-v4-reference.exr"))
        _, integrator, budgets, _ = SCENES[scene]
        for spp in budgets:
            truths, ratios, covered = [], [], 0
            for seed in range(1, args.seeds + 1):
                t, _, est, low, high = render(args, scene, ["--spp", str(spp), "--seed", str(seed), "--estimate-error"], out)
                truth = relmse(read(out), ref)
                truths.append(truth)
                ratios.append(est / truth)
                covered += low <= truth <= high
            all_ratios += ratios
            all_covered += covered
            print(f"| {scene} ({integrator}) | {spp} | {statistics.median(truths):.4g} | {statistics.median(ratios):.2f}, "
                  f"{min(ratios):.2f}, {max(ratios):.2f} | {covered} of {len(ratios)} |", flush=True)
    if all_ratios:
        print(f"\nAll runs: estimate / truth from {min(all_ratios):.2f} to {max(all_ratios):.2f}; "
              f"{sum(1 for r in all_ratios if 1 / 1.5 <= r <= 1.5)} of {len(all_ratios)} within a factor 1.5; "
              f"truth in the interval in {all_covered} of {len(all_ratios)}.\n")
    if args.skip_targets:
        return
    print("| scene (integrator) | target | seed | stopped at spp | true relMSE | true / target | oracle spp | "
          "render s | oracle s | render / oracle | wall s | oracle wall s | wall / oracle |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    ratios = {}
    for scene in scenes:
        ref = read(os.path.join(BITTERLI, scene, "pbrt-v4-reference.exr"))
        _, integrator, _, targets = SCENES[scene]
        for target in targets[:1] if args.loose_only else targets:
            for seed in args.target_seeds.split(","):
                # The same render `repeat` times (the same image each time), the median time: this
                # machine's speed drifts by 10-20% between runs. Both the render's own time ("in X s",
                # from its first pass to its last) and the whole command's (loading the scene and
                # writing the image too: what the user waits for).
                t, spp, _, _, _ = render(args, scene, ["--target-error", str(target), "--seed", seed], out)
                truth = relmse(read(out), ref)
                # The spp a user who knew it would have asked for: the least at which a plain render (no
                # replicas) meets the target, searched from the 1/spp law's guess in steps of 2%.
                oracle_spp = least_spp_meeting(args, scene, seed, target, ref, out, max(1, round(spp * truth / target)))
                # Timed in turns (target, plain, target, ...) so that the machine's drift falls on both.
                times, walls, oracle_times, oracle_walls = [], [], [], []
                for _ in range(args.repeat):
                    times.append(render(args, scene, ["--target-error", str(target), "--seed", seed], out)[0])
                    walls.append(args.last_wall)
                    oracle_times.append(render(args, scene, ["--spp", str(oracle_spp), "--seed", seed], out, estimate=False)[0])
                    oracle_walls.append(args.last_wall)
                t, wall = statistics.median(times), statistics.median(walls)
                ot, owall = statistics.median(oracle_times), statistics.median(oracle_walls)
                ratios.setdefault((scene, target), []).append((t / ot, wall / owall))
                print(f"| {scene} ({integrator}) | {target} | {seed} | {spp:.0f} | {truth:.4g} | {truth / target:.2f} | "
                      f"{oracle_spp} | {t:.2f} | {ot:.2f} | {t / ot:.2f} | {wall:.2f} | {owall:.2f} | {wall / owall:.2f} |",
                      flush=True)
    if len(args.target_seeds.split(",")) > 1:
        print("\n| scene, target | render / oracle: median (min-max) | wall / oracle: median (min-max) |")
        print("|---|---|---|")
        for (scene, target), r in ratios.items():
            render_r, wall_r = [a for a, _ in r], [b for _, b in r]
            print(f"| {scene} {target} | {statistics.median(render_r):.2f} ({min(render_r):.2f}-{max(render_r):.2f}) | "
                  f"{statistics.median(wall_r):.2f} ({min(wall_r):.2f}-{max(wall_r):.2f}) |")


if __name__ == "__main__":
    main()
