#!/usr/bin/env python3
"""candela's benchmark suite, one command, one report (Markdown, ready for docs/performance.md):

1. Renders: scene, resolution, spp, threads, wall time, Msamples/s, Mrays/s (camera + bounce + shadow
   rays, as counted by the renderer), rays per sample, peak memory (max RSS of that process) and relMSE
   (eps 0.01) against a reference: the Cornell box (512 x 512, 256 spp, max depth 16), veach-mis,
   the dragon and Igea on a floor (368,690 triangles), and the 1M-triangle MetalRoughSpheres glTF.
   References: the published ones where they exist; for the mesh scenes a 1024-spp candela render
   made once and kept in BUILD/bench-references/ (so those figures measure noise, not bias).
2. Loading: load + BVH build time, and the peak memory per triangle above a one-quad scene's.
3. The limit (build/bench/candela_ray_replay): candela's Mrays/s against raw Embree on the very
   rays it traced, what Embree's packet and stream APIs gain on them, and the floor: a path tracer
   with no shading, one path at a time and as a wavefront, against raw Embree on its own rays.
4. Thread scaling: the Cornell box with 1 and 2 threads.
5. The peer (--cycles, needs Debian's blender): Cycles and candela on the same Cornell box,
   alternately --cycles-repeat times, median time ratio and each one's relMSE.

Usage: /usr/bin/python3 bench/render_bench.py [--build build] [--threads 2] [--repeat 1] [--quick]
           [--cycles] [--cycles-repeat 3] [--skip-replay]
--quick divides every sample count by 16 (a smoke run). Run it with Debian's /usr/bin/python3
(python3-numpy and python3-openimageio are needed for relMSE).
"""
import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared")
sys.path.insert(0, os.path.join(ROOT, "bench"))

CORNELL = os.path.join(ROOT, "scenes/cornell-box.json")
VEACH_MIS = os.path.join(SHARED, "scenes/bitterli/veach-mis/scene-v4.pbrt")
MESHES = os.path.join(ROOT, "bench/scenes/dragon-igea.json")
MILLION = os.path.join(SHARED, "meshes/gltf-sample-assets/MetalRoughSpheresNoTextures/glTF/MetalRoughSpheresNoTextures.gltf")
ONE_QUAD = os.path.join(ROOT, "bench/scenes/one-quad.json")

# name, scene, resolution, spp, extra args, reference (None: a candela render made once)
SCENES = [
    ("Cornell box", CORNELL, "512x512", 256, ["--max-depth", "16"], os.path.join(SHARED, "scenes/cornell-box/reference.exr")),
    ("veach-mis", VEACH_MIS, "320x180", 256, [], os.path.join(SHARED, "scenes/bitterli/veach-mis/pbrt-v4-reference.exr")),
    ("dragon + Igea (368,690 triangles)", MESHES, "640x360", 64, [], None),
    ("MetalRoughSpheres glTF (1,040,409 triangles)", MILLION, "640x360", 16, [], None),
]
REFERENCE_SPP = 1024


def rel_mse(test_path, ref_path):
    try:
        import numpy as np
        import OpenImageIO as oiio
    except ImportError:
        return None
    a = oiio.ImageBuf(test_path).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)
    b = oiio.ImageBuf(ref_path).get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)
    if a.shape != b.shape:
        return None
    return float(np.mean((a - b) ** 2 / (b * b + 0.01)))


def run_measured(cmd):
    """Runs cmd; returns (wall seconds, stdout, max RSS of that process in MiB); exits on failure.

    The peak memory comes from GNU time (Debian's package `time`), which starts the program from a
    small process: a child started straight from this Python would report Python's own RSS as its
    high-water mark (the mark survives fork and exec)."""
    with tempfile.NamedTemporaryFile("r", suffix=".txt") as rss:
        timed = ["/usr/bin/time", "-f", "%M", "-o", rss.name] + cmd if os.path.exists("/usr/bin/time") else cmd
        start = time.monotonic()
        proc = subprocess.run(timed, capture_output=True, text=True)
        wall = time.monotonic() - start
        if proc.returncode != 0:
            sys.exit(f"benchmark failed: {' '.join(cmd)}\n{proc.stderr[-3000:]}")
        lines = rss.read().strip().splitlines()
        peak = float(lines[-1]) / 1024.0 if timed is not cmd and lines else float("nan")
    return wall, proc.stdout, peak


def render_line(out):
    m = re.search(r"in ([\d.]+) s: ([\d.]+) Msamples/s, ([\d.]+) Mrays/s \(([\d.]+) rays/sample\)", out)
    if not m:
        sys.exit(f"no statistics line in candela's output:\n{out[-2000:]}")
    return tuple(float(x) for x in m.groups())


def candela_render(candela, scene, resolution, spp, extra, threads, out, seed=0):
    cmd = [candela, "render", scene, "-o", out, "--threads", str(threads), "-q", "--resolution", resolution,
           "--spp", str(spp), "--seed", str(seed)] + extra
    wall, stdout, rss = run_measured(cmd)
    render_s, msps, mrps, rays_per_sample = render_line(stdout)
    return {"wall": wall, "render": render_s, "msps": msps, "mrps": mrps, "rps": rays_per_sample, "rss": rss}


def reference_for(candela, build, name, scene, resolution, extra, threads, ref):
    if ref:
        return ref if os.path.exists(ref) else None
    folder = os.path.join(build, "bench-references")
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-") + f"-{resolution}.exr")
    if not os.path.exists(path):
        print(f"(making the {REFERENCE_SPP}-spp reference of {name}: {path})", file=sys.stderr)
        candela_render(candela, scene, resolution, REFERENCE_SPP, extra, threads, path, seed=12345)
    return path


def section_renders(a, candela, tmp):
    print(f"## Renders ({a.threads} threads, the median of {a.repeat} run(s))\n")
    print("| scene | resolution | spp | threads | wall s | render s | Msamples/s | Mrays/s | rays/sample | peak MiB | relMSE |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, scene, resolution, spp, extra, ref in SCENES:
        if not os.path.exists(scene):
            print(f"| {name} | missing: {scene} |")
            continue
        spp = max(1, spp // 16) if a.quick else spp
        out = os.path.join(tmp, "bench.exr")
        runs = sorted((candela_render(candela, scene, resolution, spp, extra, a.threads, out) for _ in range(a.repeat)),
                      key=lambda r: r["render"])
        r = runs[len(runs) // 2]
        reference = reference_for(candela, a.build, name, scene, resolution, extra, a.threads, ref)
        err = rel_mse(out, reference) if reference else None
        print(f"| {name} | {resolution} | {spp} | {a.threads} | {r['wall']:.2f} | {r['render']:.2f} | {r['msps']:.3f} | "
              f"{r['mrps']:.2f} | {r['rps']:.2f} | {r['rss']:.0f} | {'' if err is None else f'{err:.5f}'} |")
    print()


def section_loading(a, candela, tmp):
    print("## Loading: parse + BVH build, and memory per triangle (1 spp at 8 x 8: the render is negligible)\n")
    print("| scene | triangles | wall s | peak MiB | bytes/triangle above the one-quad scene |")
    print("|---|---|---|---|---|")
    out = os.path.join(tmp, "load.exr")
    base = None
    for name, scene, tris, extra in [("one quad", ONE_QUAD, 2, []), ("dragon + Igea", MESHES, 368690, []),
                                     ("MetalRoughSpheres glTF", MILLION, 1040409, []),
                                     ("MetalRoughSpheres glTF, `--bvh compact`", MILLION, 1040409, ["--bvh", "compact"])]:
        if not os.path.exists(scene):
            continue
        runs = [run_measured([candela, "render", scene, "-o", out, "-q", "--threads", str(a.threads), "--spp", "1",
                              "--resolution", "8x8"] + extra) for _ in range(max(1, a.repeat))]
        wall = statistics.median(r[0] for r in runs)
        rss = statistics.median(r[2] for r in runs)
        if base is None:
            base = rss
        per_tri = (rss - base) * 1024 * 1024 / tris if tris > 2 else 0
        print(f"| {name} | {tris:,} | {wall:.2f} | {rss:.0f} | {'' if tris <= 2 else f'{per_tri:.0f}'} |")
    print()


def section_replay(a, tmp):
    replay = os.path.join(a.build, "bench", "candela_ray_replay")
    if not os.path.exists(replay):
        print("## The limit: build/bench/candela_ray_replay is not built (configure with -DCANDELA_BUILD_BENCH=ON)\n")
        return
    print("## The limit: candela against raw Embree on the same rays (`candela_ray_replay`)\n")
    for scene, args in [(CORNELL, ["--resolution", "256x256", "--spp", "16"]),
                        (MESHES, ["--resolution", "640x360", "--spp", "4"]),
                        (MILLION, ["--resolution", "640x360", "--spp", "4"])]:
        if not os.path.exists(scene):
            continue
        _, out, _ = run_measured([replay, scene, "--threads", str(a.threads), "--repeat", "3"] + args)
        print(out)


def section_threads(a, candela, tmp):
    print("## Thread scaling (Cornell box, 512 x 512, 32 spp)\n")
    out = os.path.join(tmp, "threads.exr")
    times = {}
    for threads in (1, 2):
        runs = [candela_render(candela, CORNELL, "512x512", 8 if a.quick else 32, [], threads, out)["render"]
                for _ in range(max(1, a.repeat))]
        times[threads] = min(runs)
    print(f"1 thread {times[1]:.2f} s, 2 threads {times[2]:.2f} s: speed-up {times[1] / times[2]:.2f}x\n")


def section_cycles(a):
    if not shutil.which("blender"):
        print("## Cycles: blender is not installed (apt-get install blender)\n")
        return
    import cycles_vs_candela
    print(f"## Against Cycles (`bench/cycles_vs_candela.py`, {a.cycles_repeat} alternating runs)\n")
    spp = 16 if a.quick else 256
    cycles_vs_candela.compare(a.build, a.cycles_repeat, spp, a.threads, "")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", default=os.path.join(ROOT, "build"))
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--repeat", type=int, default=1, help="runs per render; the median is reported")
    p.add_argument("--quick", action="store_true", help="a sixteenth of the sample counts")
    p.add_argument("--cycles", action="store_true", help="also run Blender's Cycles on the Cornell box")
    p.add_argument("--cycles-repeat", type=int, default=3)
    p.add_argument("--skip-replay", action="store_true")
    a = p.parse_args()
    candela = os.path.join(a.build, "candela")
    print(f"# candela benchmark suite ({time.strftime('%Y-%m-%d')}, {os.cpu_count()} cores)\n")
    with tempfile.TemporaryDirectory() as tmp:
        section_renders(a, candela, tmp)
        section_loading(a, candela, tmp)
        if not a.skip_replay:
            section_replay(a, tmp)
        section_threads(a, candela, tmp)
        if a.cycles:
            section_cycles(a)


if __name__ == "__main__":
    main()
