#!/usr/bin/env python3
"""Colour noise per unit time of spectral transport, between builds of candela (issue 28: three
wavelengths per path against four).

  bench/wavelength_count.py --candela OLD/candela NEW/candela [--seeds 8] [--spp 16] [--threads 2]
                            [--scenes white-sky cornell-box veach-mis]

Renders each scene spectrally with every binary at `--spp` for `--seeds` seeds (the binaries
alternate per seed, so the machine's drift falls on both alike) and measures, per pixel, the variance
over the seeds of the error's two parts: its luminance (Rec. 709 Y of the deviation from the pixel's
mean over every render) and its colour (the deviation less that luminance, per channel). Each is
divided by the pixel's squared mean luminance plus 0.01 (relMSE's weighting) and averaged over the
image. Printed per scene and binary: time per render, the two relative variances, and the colour
part's efficiency (1 / (variance x time)) over the first binary's. The image means of the binaries
must agree (both are unbiased): their largest difference in standard errors is printed too.

white-sky is where wavelength noise is all the noise there is: a grey sphere on a grey floor under
a constant white sky (D65 in spectral transport), no light sampling choice to speak of.
"""
import argparse
import json
import pathlib
import subprocess
import time

import numpy as np
import OpenImageIO as oiio

ROOT = pathlib.Path(__file__).resolve().parent.parent
BITTERLI = ROOT.parent / "shared" / "scenes" / "bitterli"
WORK = pathlib.Path("/tmp/candela-wavelength-count")
LUMA = np.array([0.2126, 0.7152, 0.0722])

WHITE_SKY = {
    "camera": {"position": [0, 1.2, -4], "look_at": [0, 0.4, 0], "up": [0, 1, 0], "fov": 40,
               "width": 160, "height": 120},
    "render": {"spp": 16, "max_depth": 8, "integrator": "path", "spectral": True},
    "materials": {"grey": {"type": "diffuse", "reflectance": 0.6},
                  "floor": {"type": "diffuse", "reflectance": 0.4}},
    "shapes": [{"type": "sphere", "center": [0, 0.6, 0], "radius": 0.6, "material": "grey"},
               {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "floor"}],
    "lights": [{"type": "sky", "radiance": 1}],
}


def scenes(names):
    WORK.mkdir(parents=True, exist_ok=True)
    sky = WORK / "white-sky.json"
    sky.write_text(json.dumps(WHITE_SKY))
    table = {
        "white-sky": (sky, []),
        "cornell-box": (ROOT / "scenes" / "cornell-box.json", ["--transport", "spectral", "--resolution", "128x128"]),
        "veach-mis": (BITTERLI / "veach-mis" / "scene-v4.pbrt", ["--resolution", "320x180"]),
    }
    return [(n, *table[n]) for n in names]


def load(path):
    buf = oiio.ImageBuf(str(path))
    if buf.has_error:
        raise SystemExit(f"{path}: {buf.geterror()}")
    return buf.get_pixels(oiio.FLOAT)[..., :3].astype(np.float64)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--candela", nargs="+", required=True)
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--scenes", nargs="+", default=["white-sky", "cornell-box", "veach-mis"])
    args = parser.parse_args()

    print(f"{'scene':12} {'binary':40} {'time s':>7} {'lum var':>10} {'colour var':>11} {'colour eff':>10}")
    for name, scene, extra in scenes(args.scenes):
        images = {b: [] for b in args.candela}
        times = {b: [] for b in args.candela}
        for seed in range(1, args.seeds + 1):
            for b in args.candela:
                out = WORK / f"{name}-{abs(hash(b)) % 10**8}-{seed}.exr"
                cmd = [b, "render", str(scene), "--spp", str(args.spp), "--seed", str(seed), "--threads",
                       str(args.threads), "-o", str(out), "--quiet"] + extra
                start = time.perf_counter()
                subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                times[b].append(time.perf_counter() - start)
                images[b].append(load(out))
        grand = np.mean([img for b in args.candela for img in images[b]], axis=0)
        weight = (grand @ LUMA) ** 2 + 0.01
        base_eff = None
        means = {}
        for b in args.candela:
            stack = np.stack(images[b])              # seeds x H x W x 3
            dev = stack - stack.mean(axis=0)
            lum = dev @ LUMA                          # seeds x H x W
            colour = dev - lum[..., None]
            n = stack.shape[0]
            lum_var = float(((lum ** 2).sum(axis=0) / (n - 1) / weight).mean())
            colour_var = float(((colour ** 2).sum(axis=0).mean(axis=-1) / (n - 1) / weight).mean())
            t = float(np.median(times[b]))
            eff = 1 / (colour_var * t)
            base_eff = base_eff or eff
            means[b] = stack.reshape(n, -1, 3).mean(axis=1)   # per seed image mean per channel
            print(f"{name:12} {b[-40:]:40} {t:7.2f} {lum_var:10.3e} {colour_var:11.3e} {eff / base_eff:10.2f}")
        first = means[args.candela[0]]
        for b in args.candela[1:]:
            other = means[b]
            se = np.sqrt(first.var(axis=0, ddof=1) / len(first) + other.var(axis=0, ddof=1) / len(other))
            z = np.abs(first.mean(axis=0) - other.mean(axis=0)) / np.maximum(se, 1e-12)
            print(f"{'':12} image means of {b[-30:]} against the first: largest |z| over channels {z.max():.2f}")


if __name__ == "__main__":
    main()
