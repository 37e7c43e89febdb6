#!/usr/bin/python3
"""Stochastic progressive photon mapping against the path tracer at equal time, on a caustic: the glass
sphere of scenes/caustic.json focusing a small spherical light onto the floor (camera paths find the light
through the glass only by chance; photons find the floor through it at once).

  /usr/bin/python3 bench/sppm_equal_time.py build/candela [--seconds 8] [--reference-spp 1024]
                                            [--resolution 160x120] [--radius 0.05] [--threads 2]

Renders a reference with bdpt (light tracing finds caustics; unbiased) at --reference-spp (a seed of its own,
so that the bdpt render compared is not correlated with it), then the path
tracer, bdpt and sppm each with --time-limit SECONDS, and prints each one's relMSE against the reference (the
project's metric: mean of (x - y)^2 / (y^2 + 0.01)) over the whole image and over the caustic (the
reference's pixels of the floor under the sphere brighter than twice the floor's median around it), with
the iterations or samples each reached. The reference's own noise adds the same amount to both.

Needs python3-openimageio (Debian) and NumPy; run with Debian's /usr/bin/python3.
"""
import argparse
import os
import pathlib
import re
import subprocess
import tempfile

import numpy as np
import OpenImageIO as oiio

ROOT = pathlib.Path(__file__).resolve().parent.parent
SCENE = ROOT / "scenes" / "caustic.json"


def load(path):
    buf = oiio.ImageBuf(str(path))
    if buf.has_error:
        raise RuntimeError(buf.geterror())
    return buf.get_pixels(oiio.FLOAT)[:, :, :3].astype(np.float64)


def render(binary, out, args, extra):
    cmd = [binary, "render", str(SCENE), "--resolution", args.resolution, "--threads", str(args.threads),
           "--output", str(out), *extra]
    run = subprocess.run(cmd, capture_output=True, text=True, check=True)
    summary = [line for line in (run.stderr + run.stdout).splitlines() if " in " in line and "->" in line]
    return summary[-1].strip() if summary else ""


def rel_mse(image, reference, mask=None):
    err = (image - reference) ** 2 / (reference ** 2 + 0.01)
    return float(err[mask].mean() if mask is not None else err.mean())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("candela")
    parser.add_argument("--seconds", type=float, default=8)
    parser.add_argument("--reference-spp", type=int, default=1024)
    parser.add_argument("--resolution", default="160x120")
    parser.add_argument("--radius", type=float, default=0.05)
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    binary = os.path.abspath(args.candela)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        line = render(binary, tmp / "reference.exr", args,
                      ["--integrator", "bdpt", "--spp", str(args.reference_spp), "--seed", "7919"])
        print(f"reference (bdpt): {line}")
        reference = load(tmp / "reference.exr")
        # The caustic: pixels far brighter than the floor's median in the lower half of the image.
        luminance = reference @ np.array([0.2126, 0.7152, 0.0722])
        lower = np.zeros_like(luminance, dtype=bool)
        lower[luminance.shape[0] // 2:, :] = True
        caustic = lower & (luminance > 2 * np.median(luminance[lower]))
        time_limit = ["--time-limit", str(args.seconds), "--spp", "1000000"]
        results = {}
        for name, extra in (("path", ["--integrator", "path"]), ("bdpt", ["--integrator", "bdpt"]),
                            ("sppm", ["--integrator", "sppm", "--sppm-radius", str(args.radius)])):
            line = render(binary, tmp / f"{name}.exr", args, extra + time_limit)
            image = load(tmp / f"{name}.exr")
            results[name] = (rel_mse(image, reference), rel_mse(image, reference, np.broadcast_to(
                caustic[:, :, None], image.shape)))
            print(f"{name}: relMSE {results[name][0]:.4g} (caustic, {int(caustic.sum())} pixels: "
                  f"{results[name][1]:.4g}); {line}")
        print(f"sppm over path at {args.seconds:g} s: relMSE x{results['sppm'][0] / results['path'][0]:.3g}, "
              f"caustic x{results['sppm'][1] / results['path'][1]:.3g}")


if __name__ == "__main__":
    main()
