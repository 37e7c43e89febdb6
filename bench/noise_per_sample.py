#!/usr/bin/env python3
"""Noise per sample and per second against pbrt-v4, scene by scene (issue 28's table).

  bench/noise_per_sample.py [--candela build/candela] [--seeds 3 5 6] [--selections power bvh]
                            [--threads 2] [--city] [--road] [--rows NAME ...]

Renders each row's scene at 64 spp with each light selection and seed, and prints per row and
selection the medians over seeds of: render time, relMSE (eps 0.01) against pbrt-v4's converged
reference, and the median per-pixel error (the same quantity per pixel, averaged over channels; robust
to the fireflies that make one seed's relMSE swing), then the efficiency ratio against pbrt-v4's
figures (candela time x relMSE over pbrt-v4 time x relMSE, below 1 = candela better; pbrt-v4 was
measured on another machine, so only candela's own before/after ratios on this machine compare like
with like) and candela's efficiency under each selection relative to the first one.

--city adds the generated many-light scene (scenes/make_city.py, about 23,000 emissive triangles) at
240x135, 64 spp, with its own reference (1024 spp with the light BVH, rendered once into the work
directory). --road adds scenes/lamp-road.json (5,200 street lamps along a 65 km road, 10,400 emissive
triangles) the same way.
"""
import argparse
import pathlib
import re
import statistics
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

ROOT = pathlib.Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "scenes" / "bitterli"
WORK = pathlib.Path("/tmp/candela-noise-per-sample")
EPS = 0.01

# name, scene, integrator, resolution, pbrt-v4's time (s) and relMSE at 64 spp (issue 28: pbrt-v4 CPU
# built from source, 2 threads, seed 3).
ROWS = [
    ("veach-bidir", "veach-bidir", "bdpt", "192x192", 177.6, 0.0083),
    ("veach-bidir", "veach-bidir", "mlt", "192x192", 22.6, 0.049),
    ("cornell-box", "cornell-box", "path", "256x256", 19.6, 0.0047),
    ("veach-ajar", "veach-ajar", "path", "320x180", 24.8, 2.98),
    ("veach-ajar", "veach-ajar", "mlt", "320x180", 39.7, 0.305),
    ("veach-mis", "veach-mis", "path", "320x180", 13.6, 0.154),
]
# pbrt-v4's median per-pixel error on veach-mis (seeds 3, 5, 6: 0.0005-0.0006).
PBRT_MEDIAN_ERROR = {("veach-mis", "path"): 0.00055}


def load(path):
    buf = oiio.ImageBuf(str(path))
    if buf.has_error:
        raise SystemExit(f"{path}: {buf.geterror()}")
    return buf.get_pixels(oiio.FLOAT)[..., :3].astype(np.float64)


def errors(image, reference):
    per_channel = (image - reference) ** 2 / (reference ** 2 + EPS)
    return float(per_channel.mean()), float(np.median(per_channel.mean(axis=2)))


def render(candela, scene, integrator, resolution, spp, seed, selection, threads, out):
    cmd = [candela, "render", str(scene), "--integrator", integrator, "--resolution", resolution, "--spp", str(spp),
           "--seed", str(seed), "--light-selection", selection, "--threads", str(threads), "-o", str(out)]
    result = subprocess.run(cmd, capture_output=True, text=True)
    if result.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{result.stderr}")
    seconds = re.search(r" in ([0-9.]+) s", result.stdout + result.stderr)
    if not seconds:
        raise SystemExit(f"no render time in the output of {' '.join(cmd)}:\n{result.stdout}")
    return float(seconds.group(1))


def generated_scene(candela, threads, name, scene_file, make_args):
    """A many-light scene whose meshes scenes/make_city.py writes, and its reference (1024 spp, light BVH)."""
    WORK.mkdir(parents=True, exist_ok=True)
    scene = WORK / name / scene_file
    if not scene.exists():
        subprocess.run([sys.executable, str(ROOT / "scenes/make_city.py"), str(WORK / name)] + make_args, check=True)
        scene.write_text((ROOT / "scenes" / scene_file).read_text())
    reference = WORK / f"{name}-reference.exr"
    if not reference.exists():
        print(f"rendering the reference of {scene_file} (1024 spp)...", flush=True)
        render(candela, scene, "path", "240x135", 1024, 1, "bvh", threads, reference)
    return scene, reference


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--candela", default=str(ROOT / "build" / "candela"))
    parser.add_argument("--seeds", nargs="+", type=int, default=[3, 5, 6])
    parser.add_argument("--selections", nargs="+", default=["power", "bvh"])
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--city", action="store_true")
    parser.add_argument("--road", action="store_true")
    parser.add_argument("--rows", nargs="*", help="only these rows (scene or scene/integrator)")
    args = parser.parse_args()
    WORK.mkdir(parents=True, exist_ok=True)

    jobs = []
    for name, scene, integrator, resolution, pbrt_time, pbrt_relmse in ROWS:
        if args.rows and name not in args.rows and f"{name}/{integrator}" not in args.rows:
            continue
        jobs.append((name, SHARED / scene / "scene-v4.pbrt", integrator, resolution,
                     SHARED / scene / "pbrt-v4-reference.exr", pbrt_time, pbrt_relmse))
    if args.city:
        scene, reference = generated_scene(args.candela, args.threads, "city", "city-night.json", [])
        jobs.append(("city-night", scene, "path", "240x135", reference, None, None))
    if args.road:
        scene, reference = generated_scene(args.candela, args.threads, "road", "lamp-road.json", ["--road"])
        jobs.append(("lamp-road", scene, "path", "240x135", reference, None, None))

    print(f"{args.spp} spp, seeds {args.seeds}, {args.threads} threads; medians over seeds")
    print(f"{'scene':<12} {'integ':<5} {'selection':<9} {'time s':>7} {'relMSE':>9} {'median err':>10} "
          f"{'eff. vs pbrt-v4':>15} {'eff. vs ' + args.selections[0]:>14}")
    for name, scene, integrator, resolution, reference_path, pbrt_time, pbrt_relmse in jobs:
        reference = load(reference_path)
        first_cost = None
        for selection in args.selections:
            times, relmses, medians = [], [], []
            for seed in args.seeds:
                out = WORK / f"{name}-{integrator}-{selection}-{seed}.exr"
                times.append(render(args.candela, scene, integrator, resolution, args.spp, seed, selection,
                                    args.threads, out))
                relmse, median = errors(load(out), reference)
                relmses.append(relmse)
                medians.append(median)
            t, r, m = statistics.median(times), statistics.median(relmses), statistics.median(medians)
            # Cost = time x error: its inverse is the efficiency.
            cost = t * r
            first_cost = first_cost or cost
            vs_pbrt = f"{cost / (pbrt_time * pbrt_relmse):.2f}" if pbrt_time else "-"
            print(f"{name:<12} {integrator:<5} {selection:<9} {t:7.2f} {r:9.4g} {m:10.3g} {vs_pbrt:>15} "
                  f"{first_cost / cost:14.2f}", flush=True)
        if (name, integrator) in PBRT_MEDIAN_ERROR:
            print(f"{'':<12} {'':<5} {'pbrt-v4':<9} {pbrt_time:7.1f} {pbrt_relmse:9.4g} "
                  f"{PBRT_MEDIAN_ERROR[(name, integrator)]:10.3g}")


if __name__ == "__main__":
    main()
