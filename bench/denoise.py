#!/usr/bin/env python3
"""What `candela render --denoise` (src/candela/denoise/, docs/denoising.md) buys, against converged references;
relMSE = mean over pixels and channels of (x - ref)^2 / (ref^2 + 0.01).

1. Quality: each scene denoised at 16 and 64 spp (median over seeds): the relMSE of the denoised image (the .exr's
   RGB) and of the raw one (its layer Noisy, the same samples), and the equal-quality spp: the spp at which a plain
   render (no --denoise, no --estimate-error: the scene's own sampler, as a user would render without the
   denoiser) reaches the denoised relMSE, interpolated in log-log between plain renders at 16, 64, 256, ... spp
   (seed 1) and past the last one by the 1/spp law (marked ~; a floor of bias would only raise it). Speed-up in
   samples = that spp / the denoised spp; speed-up in time = the plain render's time at that spp (the last plain
   render's seconds per spp) / (the denoised render's time + the denoiser's seconds). Goal of issue 46: >= 8x on
   the Cornell box at 16 spp, and no scene worse than raw.
2. Error estimate: at 16, 32 and 64 spp and each seed, the denoiser's own estimate (the "denoised:" line) over the
   true relMSE of the denoised image, and whether the truth lies in its 95% interval (target: within a factor 1.5).
   (The --denoise renders also pass --estimate-error, which --denoise implies, for the raw image's estimate. The
   zsobol sampler splits samples into halves in blocks of 8, so its scenes have no halves, and no estimate, below
   16 spp: "n/a".)
3. Time and memory at 1920 x 1080: the Cornell box (scenes/cornell-box.json) at 16 spp with --denoise (the
   denoiser's seconds), and peak memory (max RSS, /usr/bin/time -v) of a plain render, one with --estimate-error
   and one with --denoise.
4. Cycles: the Cornell box at 512 x 512 (../shared/scenes/cornell-box/reference.exr, Cycles at 4096 spp) rendered
   by Cycles (bench/cycles/cornell_box.py) at 16 and 64 spp without denoising, and with OpenImageDenoise (albedo
   and normal passes) if this Blender has it (the check: `_cycles.with_openimagedenoise`; Debian 12's Blender
   3.4.1 is built without it), beside candela with --denoise at the same spp.

Scenes (the references' resolution): cornell-box, veach-mis, veach-ajar (Bitterli's, pbrt-v4 references at 4096
spp), shapes-checker (Mitsuba's test_various_shapes: checkerboard-textured shapes, 480 x 480), wood-sphere
(Mitsuba's test_textured_diffuse: a bitmap-textured sphere, 48 x 48), fog-cornell (the Cornell box filled with
bench/cycles_fog_vs_candela.py's homogeneous fog, volpath, 128 x 128; reference: candela volpath at
--fog-reference-spp, made once and kept in --cache with its own estimated relMSE, which is subtracted from every
truth measured against it), fog-sphere (Mitsuba's test_homo_obj_inside_medium:
homogeneous media in glass spheres over a checkerboard, 48 x 48). Mitsuba's references are means of 32,000 spp.

Usage: /usr/bin/python3 bench/denoise.py [--build build] [--threads 2] [--seeds 3] [--scenes a,b,...] [--quick]
       [--markdown] [--max-raw-spp 256] [--skip-hd | --hd-only] [--skip-cycles] [--estimates-only] [--cache DIR]
       [--fog-reference-spp 4096]
--estimates-only: part 2 alone (no plain renders; with --skip-hd --skip-cycles, about 5 minutes).
--quick: cornell-box and fog-sphere, one seed, 16 spp, plain renders up to 64 spp, the error estimate at 16 and 32
spp, part 3, no Cycles (a smoke run of about a minute). A full run took 13 minutes on 2 threads (a busy 2-core machine), plus 3 to 5
minutes for fog-cornell's reference the first time.
Run it with Debian's /usr/bin/python3 (python3-numpy and python3-openimageio); part 4 needs Blender
(apt-get install blender).
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared")
BITTERLI = os.path.join(SHARED, "scenes", "bitterli")
MITSUBA = os.path.join(SHARED, "scenes", "mitsuba-tests", "tests", "scenes")
CORNELL_JSON = os.path.join(ROOT, "scenes", "cornell-box.json")
CORNELL_REFERENCE = os.path.join(SHARED, "scenes", "cornell-box", "reference.exr")
FOG = (0.0016, 0.0004, 0.3)  # sigma_s, sigma_a per mm, g: bench/cycles_fog_vs_candela.py's fog
EPS = 0.01

# name: (scene file or None for the generated fog box, resolution, extra render arguments, reference file)
SCENES = {
    "cornell-box": (os.path.join(BITTERLI, "cornell-box", "scene-v4.pbrt"), "256x256", ["--integrator", "path"],
                    os.path.join(BITTERLI, "cornell-box", "pbrt-v4-reference.exr")),
    "veach-mis": (os.path.join(BITTERLI, "veach-mis", "scene-v4.pbrt"), "320x180", ["--integrator", "path"],
                  os.path.join(BITTERLI, "veach-mis", "pbrt-v4-reference.exr")),
    "veach-ajar": (os.path.join(BITTERLI, "veach-ajar", "scene-v4.pbrt"), "320x180", ["--integrator", "path"],
                   os.path.join(BITTERLI, "veach-ajar", "pbrt-v4-reference.exr")),
    "shapes-checker": (os.path.join(MITSUBA, "various_shapes", "test_various_shapes_path.xml"), "480x480", [],
                       os.path.join(MITSUBA, "various_shapes", "refs", "test_various_shapes_ref_rgb.exr")),
    "wood-sphere": (os.path.join(MITSUBA, "bsdf_spheres", "test_textured_diffuse_path.xml"), "48x48", [],
                    os.path.join(MITSUBA, "bsdf_spheres", "refs", "test_textured_diffuse_ref_rgb.exr")),
    "fog-cornell": (None, "128x128", ["--integrator", "volpath", "--max-depth", "16", "--filter", "box"], None),
    "fog-sphere": (os.path.join(MITSUBA, "participating_media", "test_homo_obj_inside_medium_volpath.xml"), "48x48",
                   [], os.path.join(MITSUBA, "participating_media", "refs", "test_homo_obj_inside_medium_ref_rgb.exr")),
}
QUICK_SCENES = ["cornell-box", "fog-sphere"]

NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
RENDER_TIME = re.compile(rf" in ({NUM}) s:")
ESTIMATE = re.compile(rf"estimated error: relMSE ({NUM}) \(95% interval ({NUM})-({NUM})")
DENOISED = re.compile(rf"denoised: relMSE ({NUM}) \(95% interval ({NUM})-({NUM})[^)]*\) in ({NUM}) s")
DENOISE_SECONDS = re.compile(rf"denoised: .* in ({NUM}) s")


def denoise_seconds(text):
    m = DENOISE_SECONDS.search(text)
    if not m:
        sys.exit(f"no 'denoised: ... in S s' line in:\n{text[-2000:]}")
    return float(m.group(1))


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def channels(path, names):
    """The named channels of an image file, as an (h, w, len(names)) float64 array. Read by ImageInput, not
    ImageBuf: ImageBuf goes through OpenImageIO's image cache, which can hand back the pixels of an earlier file of
    the same name (seen here with small images rewritten in quick succession)."""
    inp = oiio.ImageInput.open(path)
    if inp is None:
        sys.exit(f"cannot read {path}: {oiio.geterror()}")
    spec = inp.spec()
    have = list(spec.channelnames)
    missing = [n for n in names if n not in have]
    if missing:
        sys.exit(f"{path} has no channel {', '.join(missing)} (it has {', '.join(have)})")
    pixels = inp.read_image(0, 0, 0, spec.nchannels, oiio.FLOAT)
    inp.close()
    return pixels.reshape(spec.height, spec.width, spec.nchannels)[:, :, [have.index(n) for n in names]].astype(np.float64)


def rgb(path):
    return channels(path, ["R", "G", "B"])


def relmse(test, ref):
    return float(np.mean((test - ref) ** 2 / (ref ** 2 + EPS)))


def run(cmd, timed=False):
    """stdout + stderr of cmd (exits on failure); with timed, under /usr/bin/time -v: (output, max RSS in MiB)."""
    full = ["/usr/bin/time", "-v"] + cmd if timed else cmd
    p = subprocess.run(full, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}")
    if timed:
        rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr)
        return p.stdout + p.stderr, int(rss.group(1)) / 1024
    return p.stdout + p.stderr


class Bench:
    def __init__(self, args):
        self.args = args
        self.candela = os.path.join(args.build, "candela")
        # A copy of the build (candela and libcandela.so, e.g. a snapshot taken while others rebuild) finds its
        # own library first.
        if os.path.exists(os.path.join(args.build, "libcandela.so")):
            os.environ["LD_LIBRARY_PATH"] = args.build + os.pathsep + os.environ.get("LD_LIBRARY_PATH", "")
        self.tmp = tempfile.mkdtemp(prefix="candela-denoise-")
        self.out = os.path.join(self.tmp, "image.exr")
        self.fog_scene = None
        self.refs = {}
        self.ref_noise = {}  # a reference's own estimated relMSE, where it is known (candela's own references)

    # --- scenes and references ---------------------------------------------------------------------------------

    def scene_file(self, name):
        path = SCENES[name][0]
        if path is not None:
            return path
        if self.fog_scene is None:
            # The Cornell box filled with homogeneous fog (a box just inside the walls), as in
            # bench/cycles_fog_vs_candela.py.
            scene = json.load(open(CORNELL_JSON))
            scene["media"] = {"fog": {"type": "homogeneous", "sigma_s": FOG[0], "sigma_a": FOG[1], "g": FOG[2]}}
            scene["materials"]["fog boundary"] = {"type": "interface"}
            scene["shapes"].append({"type": "box", "min": [1, 1, 1], "max": [555, 547, 558],
                                    "material": "fog boundary", "interior": "fog"})
            self.fog_scene = os.path.join(self.tmp, "foggy-cornell-box.json")
            json.dump(scene, open(self.fog_scene, "w"))
        return self.fog_scene

    def reference(self, name):
        if name in self.refs:
            return self.refs[name]
        path = SCENES[name][3]
        if path is None:
            # fog-cornell: a long candela render with a seed no test render uses, kept in the cache.
            spp = self.args.fog_reference_spp
            os.makedirs(self.args.cache, exist_ok=True)
            path = os.path.join(self.args.cache, f"fog-cornell-{SCENES[name][1]}-{spp}spp.exr")
            # Its own error, estimated from its halves (docs/error-estimates.md), kept beside it: a truth
            # measured against it holds that error too (the two are independent), which is subtracted.
            noise_file = path + ".relmse"
            if not os.path.exists(path) or not os.path.exists(noise_file):
                log(f"fog-cornell reference: candela volpath at {spp} spp (once; kept as {path})")
                partial = path + ".partial.exr"
                text, _ = self.render(name, ["--spp", str(spp), "--seed", "1000", "--estimate-error"], partial)
                with open(noise_file, "w") as f:
                    f.write(ESTIMATE.search(text).group(1))
                os.replace(partial, path)
            with open(noise_file) as f:
                self.ref_noise[name] = float(f.read())
            log(f"fog-cornell reference: its own estimated relMSE {self.ref_noise[name]:.3g}, subtracted from each truth")
        self.refs[name] = rgb(path)
        return self.refs[name]

    def truth(self, name, image):
        """relMSE of `image` against the scene's reference, less the reference's own (where known)."""
        return relmse(image, self.reference(name)) - self.ref_noise.get(name, 0.0)

    def render(self, name, extra, out=None, timed=False, resolution=None):
        """Renders scene `name`: (output text, render seconds from the closing line[, max RSS MiB])."""
        _, res, scene_args, _ = SCENES[name]
        cmd = [self.candela, "render", self.scene_file(name), "--resolution", resolution or res,
               "--threads", str(self.args.threads), "-q", "-o", out or self.out] + scene_args + extra
        text = run(cmd, timed)
        rss = None
        if timed:
            text, rss = text
        m = RENDER_TIME.search(text)
        if not m:
            sys.exit(f"no render time in the output of {' '.join(cmd)}\n{text[-2000:]}")
        return (text, float(m.group(1)), rss) if timed else (text, float(m.group(1)))

    def denoised_render(self, name, spp, seed):
        """One --denoise render: a dict of its times, estimates and true relMSEs (denoised and raw)."""
        text, t = self.render(name, ["--spp", str(spp), "--seed", str(seed), "--denoise", "--estimate-error"])
        d, e = DENOISED.search(text), ESTIMATE.search(text)
        # Without both halves in every pixel (the zsobol sampler below 16 spp: its halves are blocks of 8
        # samples) the estimates are missing: "not available: ...", or from the raw line's absence.
        halves = e is not None
        return {
            "render_s": t, "denoise_s": denoise_seconds(text),
            "estimate": float(d.group(1)) if d and halves else None,
            "low": float(d.group(2)) if d and halves else None, "high": float(d.group(3)) if d and halves else None,
            "raw_estimate": float(e.group(1)) if halves else None,
            "denoised": self.truth(name, rgb(self.out)),
            "raw": self.truth(name, channels(self.out, ["Noisy.R", "Noisy.G", "Noisy.B"])),
        }

    # --- part 1: quality and equal-quality spp ----------------------------------------------------------------

    def plain_ladder(self, name, targets):
        """Plain renders (seed 1) at 16, 64, 256, ... spp, up to --max-raw-spp or until one reaches the smallest
        target: a list of (spp, relMSE, seconds)."""
        ladder, spp = [], 16
        while spp <= self.args.max_raw_spp:
            _, t = self.render(name, ["--spp", str(spp), "--seed", "1"])
            ladder.append((spp, self.truth(name, rgb(self.out)), t))
            log(f"  {name} plain {spp} spp: relMSE {ladder[-1][1]:.4g} in {t:.2f} s")
            if ladder[-1][1] <= min(targets):
                break
            spp *= 4
        return ladder

    @staticmethod
    def equal_quality_spp(ladder, target):
        """(spp, extrapolated) at which the plain renders reach relMSE `target`: log-log interpolation between the
        bracketing renders, the 1/spp law beyond them."""
        for (s0, e0, _), (s1, e1, _) in zip(ladder, ladder[1:]):
            if e1 <= target <= e0 and e0 > e1:
                f = (np.log(target) - np.log(e0)) / (np.log(e1) - np.log(e0))
                return float(np.exp(np.log(s0) + f * (np.log(s1) - np.log(s0)))), False
        if target > ladder[0][1]:
            return ladder[0][0] * ladder[0][1] / target, True
        # Below the last render (or the renders do not decrease): the 1/spp law from the last one.
        return ladder[-1][0] * ladder[-1][1] / target, True

    # --- the parts ---------------------------------------------------------------------------------------------

    def quality_and_estimates(self, scenes):
        """Parts 1 and 2 share their --denoise renders."""
        a = self.args
        seeds = range(1, a.seeds + 1)
        spps = sorted(set(a.estimate_spp) | set(a.quality_spp))
        runs = {}
        for name in scenes:
            for spp in spps:
                for seed in seeds:
                    r = self.denoised_render(name, spp, seed)
                    runs.setdefault((name, spp), []).append(r)
                    log(f"  {name} {spp} spp seed {seed}: denoised {r['denoised']:.4g} (estimate {r['estimate']}), "
                        f"raw {r['raw']:.4g}; {r['render_s']:.2f} + {r['denoise_s']:.2f} s")
        quality_rows, verdicts = [], []
        for name in scenes if a.quality else []:
            targets = [statistics.median(r["denoised"] for r in runs[(name, spp)]) for spp in a.quality_spp]
            ladder = self.plain_ladder(name, targets)
            per_spp_s = ladder[-1][2] / ladder[-1][0]
            for spp, target in zip(a.quality_spp, targets):
                rs = runs[(name, spp)]
                raw = statistics.median(r["raw"] for r in rs)
                eq, extrapolated = self.equal_quality_spp(ladder, target)
                t_denoised = statistics.median(r["render_s"] + r["denoise_s"] for r in rs)
                t_denoise = statistics.median(r["denoise_s"] for r in rs)
                t_plain = per_spp_s * eq
                mark = "~" if extrapolated else ""
                quality_rows.append([name, SCENES[name][1], spp, f"{raw:.4g}", f"{target:.4g}", f"{raw / target:.2f}",
                                     f"{mark}{eq:.0f}", f"{mark}{eq / spp:.1f}", f"{t_denoised:.2f}",
                                     f"{t_denoise:.2f}", f"{mark}{t_plain:.2f}", f"{mark}{t_plain / t_denoised:.1f}"])
                worse = sum(r["denoised"] > r["raw"] for r in rs)
                if worse:
                    verdicts.append(f"{name} at {spp} spp: denoised WORSE than raw in {worse} of {len(rs)} seeds "
                                    f"(median relMSE {target:.4g} against {raw:.4g})")
            if "cornell-box" == name and 16 in a.quality_spp:
                eq, _ = self.equal_quality_spp(ladder, targets[a.quality_spp.index(16)])
                verdicts.append(f"cornell-box at 16 spp: speed-up in samples {eq / 16:.1f}x "
                                f"({'meets' if eq / 16 >= 8 else 'MISSES'} the goal of 8x)")
        estimate_rows, ratios, covered, missing, off = [], [], 0, 0, []
        for name in scenes:
            for spp in a.estimate_spp:
                rs = runs[(name, spp)]
                truth = f"{statistics.median(r['denoised'] for r in rs):.4g}"
                with_estimate = [r for r in rs if r["estimate"] is not None]
                if not with_estimate:
                    estimate_rows.append([name, spp, truth, "n/a (no halves)", "-", "-", "-"])
                    missing += len(rs)
                    continue
                missing += len(rs) - len(with_estimate)
                rr = [r["estimate"] / r["denoised"] for r in with_estimate]
                raw_rr = [r["raw_estimate"] / r["raw"] for r in with_estimate]
                c = sum(r["low"] <= r["denoised"] <= r["high"] for r in with_estimate)
                ratios += rr
                covered += c
                if not 1 / 1.5 <= statistics.median(rr) <= 1.5:
                    off.append(f"{name} {spp} spp ({statistics.median(rr):.2f})")
                estimate_rows.append([name, spp, truth, f"{statistics.median(rr):.2f}, {min(rr):.2f}, {max(rr):.2f}",
                                      f"{sum(1 / 1.5 <= x <= 1.5 for x in rr)} of {len(rr)}", f"{c} of {len(rr)}",
                                      f"{statistics.median(raw_rr):.2f}"])
        summary = "No run had an estimate." if not ratios else (
            f"All runs with an estimate: denoised estimate / truth from {min(ratios):.2f} to {max(ratios):.2f}; "
            f"{sum(1 / 1.5 <= x <= 1.5 for x in ratios)} of {len(ratios)} within a factor 1.5; "
            f"truth in the 95% interval in {covered} of {len(ratios)}.")
        if off:
            summary += f" Median estimate / truth outside a factor 1.5: {', '.join(off)}."
        if missing:
            summary += (f" {missing} runs had no estimate (pixels without both halves: the zsobol sampler needs "
                        f"16 spp for them).")
        return quality_rows, estimate_rows, summary, verdicts

    def hd(self):
        """Part 3: the denoiser's time at 1920 x 1080, and the peak memory with and without it."""
        a = self.args
        rows = []
        for label, extra in [("plain", []), ("--estimate-error", ["--estimate-error"]), ("--denoise", ["--denoise", "--estimate-error"])]:
            cmd = [self.candela, "render", CORNELL_JSON, "--resolution", "1920x1080", "--spp", str(a.hd_spp),
                   "--seed", "1", "--threads", str(a.threads), "-q", "-o", self.out] + extra
            start = time.monotonic()
            text, rss = run(cmd, timed=True)
            wall = time.monotonic() - start
            t = float(RENDER_TIME.search(text).group(1))
            denoise_s = f"{denoise_seconds(text):.2f}" if "--denoise" in extra else "-"
            halves = "-" if label == "plain" else ("yes" if ESTIMATE.search(text) else "no")
            rows.append([label, f"{t:.2f}", denoise_s, halves, f"{wall:.2f}", f"{rss:.0f}"])
            log(f"  1920x1080 {label}: render {t:.2f} s, wall {wall:.2f} s, max RSS {rss:.0f} MiB")
        # The denoiser alone: `candela denoise` on the render's halves, three times (median).
        halves_exr = os.path.join(self.tmp, "hd-halves.exr")
        run([self.candela, "render", CORNELL_JSON, "--resolution", "1920x1080", "--spp", str(a.hd_spp), "--seed", "1",
             "--threads", str(a.threads), "-q", "--aov", "halves", "-o", halves_exr])
        runs = []
        for _ in range(3):
            start = time.monotonic()
            text, rss = run([self.candela, "denoise", halves_exr, "-o", self.out], timed=True)  # every core
            runs.append((denoise_seconds(text), time.monotonic() - start, rss))
        d, wall, rss = sorted(runs)[1]
        rows.append(["candela denoise (median of 3)", "-", f"{d:.2f}", "yes", f"{wall:.2f}", f"{rss:.0f}"])
        log(f"  1920x1080 candela denoise: denoise {d:.2f} s, wall {wall:.2f} s, max RSS {rss:.0f} MiB")
        return rows

    def cycles(self):
        """Part 4: Cycles (with OIDN if it has it) beside candela --denoise on the Cornell box, 512 x 512."""
        a = self.args
        if shutil.which("blender") is None:
            return None, "Blender is not installed (apt-get install blender): part 4 skipped."
        check = "import _cycles; print('with_openimagedenoise', _cycles.with_openimagedenoise)"
        text = run(["blender", "-b", "--factory-startup", "--python-expr", check])
        version = re.search(r"Blender (\S+)", text)
        has_oidn = "with_openimagedenoise True" in text
        note = (f"Blender {version.group(1) if version else '?'}: `_cycles.with_openimagedenoise` is {has_oidn}"
                f"{'' if has_oidn else ': no OpenImageDenoise, so Cycles is compared without denoising'}.")
        ref = rgb(CORNELL_REFERENCE)
        script = os.path.join(ROOT, "bench", "cycles", "cornell_box.py")
        rows = []
        for spp in a.quality_spp:
            results = {}
            for seed in range(1, a.seeds + 1):
                variants = [("Cycles", [])] + ([("Cycles + OIDN (albedo, normal)", ["--oidn"])] if has_oidn else [])
                for label, extra in variants:
                    text = run(["blender", "-b", "--factory-startup", "--python", script, "--", "--spp", str(spp),
                                "--threads", str(a.threads), "--seed", str(seed), "--resolution", "512",
                                "--out", self.out] + extra)
                    t = float(re.search(rf"cycles render seconds: ({NUM})", text).group(1))
                    results.setdefault(label, []).append((relmse(rgb(self.out), ref), t))
                text = run([self.candela, "render", CORNELL_JSON, "--spp", str(spp), "--max-depth", "16",
                            "--resolution", "512x512", "--threads", str(a.threads), "--seed", str(seed), "-q",
                            "-o", self.out, "--denoise", "--estimate-error"])
                t = float(RENDER_TIME.search(text).group(1)) + denoise_seconds(text)
                results.setdefault("candela --denoise", []).append((relmse(rgb(self.out), ref), t))
                results.setdefault("candela raw (its layer Noisy)", []).append(
                    (relmse(channels(self.out, ["Noisy.R", "Noisy.G", "Noisy.B"]), ref), None))
                log(f"  cycles comparison {spp} spp seed {seed}: " +
                    ", ".join(f"{k} {v[-1][0]:.4g}" for k, v in results.items()))
            for label, r in results.items():
                times = [x[1] for x in r if x[1] is not None]
                rows.append([label, spp, f"{statistics.median(x[0] for x in r):.4g}",
                             f"{statistics.median(times):.2f}" if times else "-"])
        return rows, note


def table(markdown, header, rows):
    rows = [[str(c) for c in r] for r in rows]
    if markdown:
        lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        lines += ["| " + " | ".join(r) + " |" for r in rows]
    else:
        widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(header)]
        lines = ["  ".join(h.ljust(w) for h, w in zip(header, widths))]
        lines += ["  ".join(c.ljust(w) for c, w in zip(r, widths)) for r in rows]
    print("\n".join(lines) + "\n", flush=True)


def heading(markdown, text):
    print(f"### {text}\n" if markdown else f"== {text}\n", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--scenes", default=",".join(SCENES), help="comma-separated, of: " + ", ".join(SCENES))
    ap.add_argument("--quick", action="store_true", help="a smoke run: two small scenes, one seed, no Cycles")
    ap.add_argument("--markdown", action="store_true", help="Markdown tables (for docs/denoising.md)")
    ap.add_argument("--max-raw-spp", type=int, default=256, help="the most spp of a plain render for part 1")
    ap.add_argument("--hd-spp", type=int, default=16)
    ap.add_argument("--skip-hd", action="store_true")
    ap.add_argument("--hd-only", action="store_true", help="part 3 alone")
    ap.add_argument("--estimates-only", action="store_true", help="part 2 alone (with --skip-hd --skip-cycles)")
    ap.add_argument("--skip-cycles", action="store_true")
    ap.add_argument("--fog-reference-spp", type=int, default=4096)
    ap.add_argument("--cache", default=os.path.join(os.path.expanduser("~"), ".cache", "candela-bench"),
                    help="where fog-cornell's reference is kept")
    a = ap.parse_args()
    a.quality_spp, a.estimate_spp = [16, 64], [16, 32, 64]
    a.quality = not a.estimates_only
    scenes = a.scenes.split(",")
    if a.quick:
        a.seeds, a.max_raw_spp, a.skip_cycles, a.estimate_spp = 1, min(a.max_raw_spp, 64), True, [16, 32]
        a.quality_spp = [16]
        if a.scenes == ",".join(SCENES):
            scenes = QUICK_SCENES
    unknown = [s for s in scenes if s not in SCENES]
    if unknown:
        sys.exit(f"unknown scene {', '.join(unknown)}; the scenes: {', '.join(SCENES)}")
    bench = Bench(a)
    if "--denoise" not in run([bench.candela, "render", "--help"]):
        sys.exit(f"{bench.candela} has no --denoise")
    start = time.monotonic()
    m = a.markdown
    print(f"candela {a.build}, {a.threads} threads, seeds 1-{a.seeds}; relMSE with eps {EPS}; medians over seeds.\n")

    if a.hd_only:
        heading(m, f"1920 x 1080: time and memory (scenes/cornell-box.json, {a.hd_spp} spp)")
        table(m, ["render", "render s", "denoise s", "both halves (an estimate)", "wall s", "max RSS MiB"], bench.hd())
        return
    quality, estimates, summary, verdicts = bench.quality_and_estimates(scenes)
    if a.quality:
        quality_table(m, a, quality, verdicts)
    heading(m, "The denoiser's error estimate")
    table(m, ["scene", "spp", "true relMSE of the denoised image (median)", "estimate / truth: median, min, max",
              "within 1.5x", "truth in the 95% interval", "raw estimate / raw truth (median)"], estimates)
    print(summary + "\n")

    if not a.skip_hd:
        heading(m, f"1920 x 1080: time and memory (scenes/cornell-box.json, {a.hd_spp} spp)")
        table(m, ["render", "render s", "denoise s", "both halves (an estimate)", "wall s", "max RSS MiB"], bench.hd())

    if not a.skip_cycles:
        heading(m, "Cycles and candela on the Cornell box, 512 x 512 (against Cycles at 4096 spp)")
        rows, note = bench.cycles()
        print(note + "\n")
        if rows:
            table(m, ["renderer", "spp", "relMSE (median)", "time s (render + denoise, median)"], rows)
    log(f"done in {time.monotonic() - start:.0f} s")
    shutil.rmtree(bench.tmp, ignore_errors=True)


def quality_table(m, a, quality, verdicts):
    heading(m, "Denoised against raw, and the equal-quality spp")
    print("raw: the same render's layer Noisy (the same samples, in two halves); equal-quality spp: where plain renders "
          f"(the scene's sampler, seed 1, 16-{a.max_raw_spp} spp) reach the denoised relMSE, ~ = beyond them by "
          "the 1/spp law; time: render + denoise s (median), plain s = plain seconds per spp x that spp.\n")
    table(m, ["scene", "resolution", "spp", "raw relMSE", "denoised relMSE", "raw / denoised", "equal-quality spp",
              "speed-up (spp)", "denoised s", "of which denoise s", "plain s at equal quality", "speed-up (time)"],
          quality)
    if not any("WORSE" in v for v in verdicts):
        verdicts.append("No denoised image was worse than its raw one (every scene, spp and seed).")
    print("\n".join(verdicts) + "\n")


if __name__ == "__main__":
    main()
