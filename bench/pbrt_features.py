#!/usr/bin/python3
"""Renders every pbrt-v4 feature probe of ../shared/scenes/pbrt-v4-features with candela and compares
it with pbrt-v4's own render (refs/NAME.exr) by the probes' agreement rule (issue 47): the image mean
per channel within 3% of the reference's, and at least 9 in 10 of the 8x8-pixel blocks within 10% of
(reference block mean + 0.02) in every channel (R, G, B, and a spectral film's wavelength buckets). The scenes of refused-by-pbrt-v4/ must be refused.

Prints one line per scene (agrees / differs, with the numbers / refused, with candela's message) and a
Markdown table for docs/pbrt-format.md with --markdown.

    /usr/bin/python3 bench/pbrt_features.py [--spp 256] [--only mat_] [--markdown] build/candela

Needs python3-openimageio (Debian) and NumPy; run with Debian's /usr/bin/python3.
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
import OpenImageIO as oiio

HERE = os.path.dirname(os.path.abspath(__file__))
FEATURES = os.path.normpath(os.path.join(HERE, "..", "..", "shared", "scenes", "pbrt-v4-features"))


def read_compared_channels(path):
    image = oiio.ImageBuf(path)
    if image.has_error:
        raise RuntimeError(image.geterror())
    spec = image.spec()
    names = list(spec.channelnames)
    channels = [names.index(c) for c in ("R", "G", "B")] if all(c in names for c in "RGB") else [0, 1, 2]
    # A spectral film's wavelength buckets (the OpenEXR spectral layout's S0.*) are compared too.
    channels += [i for i, name in enumerate(names) if name.startswith("S0.")]
    pixels = image.get_pixels(oiio.FLOAT)  # the data window, [y][x][channel]
    return pixels[:, :, channels], (spec.x, spec.y, spec.width, spec.height)


def compare(candela, reference):
    """(agrees, mean error per channel (max), fraction of blocks that agree)."""
    if candela.shape != reference.shape:
        return False, float("inf"), 0.0
    n = reference.shape[-1]
    mean_c = candela.reshape(-1, n).mean(axis=0)
    mean_r = reference.reshape(-1, n).mean(axis=0)
    mean_error = float(np.max(np.abs(mean_c - mean_r) / np.maximum(mean_r, 1e-6)))
    h, w = (reference.shape[0] // 8) * 8, (reference.shape[1] // 8) * 8
    def blocks(img):
        return img[:h, :w].reshape(h // 8, 8, w // 8, 8, n).mean(axis=(1, 3))
    bc, br = blocks(candela), blocks(reference)
    block_ok = np.all(np.abs(bc - br) <= 0.10 * (br + 0.02), axis=-1)
    fraction = float(block_ok.mean()) if block_ok.size else 0.0
    return mean_error <= 0.03 and fraction >= 0.9, mean_error, fraction


def first_error_line(text):
    for line in text.splitlines():
        if "error" in line.lower() or "not supported" in line or "unknown" in line:
            return line.strip()
    lines = [l for l in text.splitlines() if l.strip()]
    return lines[-1].strip() if lines else "(no message)"


def render(binary, scene, spp, out, timeout):
    cmd = [binary, "render", scene, "--spp", str(spp), "--output", out]
    start = time.time()
    try:
        run = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=os.path.dirname(scene))
    except subprocess.TimeoutExpired:
        return None, f"timed out after {timeout} s", timeout
    seconds = time.time() - start
    if run.returncode != 0:
        return None, first_error_line(run.stderr + run.stdout), seconds
    warnings = [l.strip() for l in run.stderr.splitlines() if "warning" in l]
    return out, "; ".join(warnings[:2]), seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("candela")
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--only", default="", help="only scenes whose name contains this")
    parser.add_argument("--timeout", type=int, default=300)
    parser.add_argument("--markdown", action="store_true")
    args = parser.parse_args()
    binary = os.path.abspath(args.candela)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in sorted(os.listdir(FEATURES)):
            if not name.endswith(".pbrt") or args.only not in name:
                continue
            scene = os.path.join(FEATURES, name)
            stem = name[:-5]
            out, message, seconds = render(binary, scene, args.spp, os.path.join(tmp, stem + ".exr"), args.timeout)
            if out is None:
                rows.append((stem, "refused", message, seconds))
            else:
                candela, _ = read_compared_channels(out)
                reference, _ = read_compared_channels(os.path.join(FEATURES, "refs", stem + ".exr"))
                agrees, mean_error, fraction = compare(candela, reference)
                detail = ("size {} vs {}".format(candela.shape[1::-1], reference.shape[1::-1])
                          if candela.shape != reference.shape
                          else f"mean {100 * mean_error:.1f}%, blocks {100 * fraction:.0f}%")
                if message:
                    detail += f"; {message}"
                rows.append((stem, "agrees" if agrees else "differs", detail, seconds))
            print(f"{rows[-1][0]:40s} {rows[-1][1]:8s} {rows[-1][3]:6.1f} s  {rows[-1][2]}", flush=True)
        refused_dir = os.path.join(FEATURES, "refused-by-pbrt-v4")
        for name in sorted(os.listdir(refused_dir)) if os.path.isdir(refused_dir) else []:
            if not name.endswith(".pbrt") or args.only not in name:
                continue
            out, message, seconds = render(binary, os.path.join(refused_dir, name), 1,
                                           os.path.join(tmp, "refused.exr"), args.timeout)
            state = "refused" if out is None else "rendered (pbrt-v4 refuses it)"
            rows.append(("refused-by-pbrt-v4/" + name[:-5], state, message, seconds))
            print(f"{rows[-1][0]:40s} {rows[-1][1]:8s} {rows[-1][3]:6.1f} s  {rows[-1][2]}", flush=True)
    counts = {}
    for row in rows:
        counts[row[1]] = counts.get(row[1], 0) + 1
    print("totals: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    if args.markdown:
        print("\n| probe | state | detail |\n|---|---|---|")
        for stem, state, detail, _ in rows:
            print(f"| `{stem}` | {state} | {detail.replace('|', '/')} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
