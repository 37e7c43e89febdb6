#!/usr/bin/env python3
"""Compare MLT settings by their error over seeds, where no converged reference can be rendered.

  mlt_seed_variance.py 'DIR/mlt-NAME-[0-9]*.exr' off lens ... [--crop X0 X1 Y0 Y1] [--also IMAGE ...]

For each setting NAME, the images matching the pattern (one per seed) are scaled to the common image
mean (MLT's normalisation is estimated by a bootstrap that does not depend on the mutations: every
setting of a seed shares it, so its error is the same for all and is factored out here) and then:
  - relvar: the per-pixel variance over seeds, relative (over mean^2 + 0.01, the eps of imgcmp.py),
    averaged over the image: the expected relMSE of one render of that setting;
  - relMSE: each render against the pooled mean of the *other* settings' renders, averaged over seeds
    (adds the pooled mean's own, smaller, noise and any bias between settings);
  - mean: the setting's unscaled image mean over the pooled one (all settings share each seed's
    normalisation, so these agree with each other; what they say about absolute brightness is limited
    by the bootstrap).
--crop X0 X1 Y0 Y1: also report relvar within those pixels (x in [X0, X1), y in [Y0, Y1)).
--also: other renders (path, bdpt at equal time), reported as plain relMSE against the pooled mean of all
settings' renders (unscaled: their brightness is their own).
"""
import argparse
import glob

import numpy as np
import OpenImageIO as oiio

EPS = 0.01


def load(path):
    buf = oiio.ImageBuf(path)
    if buf.has_error:
        raise SystemExit(f"{path}: {buf.geterror()}")
    return buf.get_pixels(oiio.FLOAT)[..., :3].astype(np.float64)


def relmse(image, reference):
    return float(np.mean((image - reference) ** 2 / (reference ** 2 + EPS)))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("pattern", help="glob with NAME where the setting's name goes")
    parser.add_argument("names", nargs="+")
    parser.add_argument("--also", nargs="*", default=[])
    parser.add_argument("--crop", nargs=4, type=int, metavar=("X0", "X1", "Y0", "Y1"))
    args = parser.parse_args()

    renders = {}
    for name in args.names:
        paths = sorted(glob.glob(args.pattern.replace("NAME", name)))
        if len(paths) < 2:
            raise SystemExit(f"{args.pattern.replace('NAME', name)}: need renders of at least 2 seeds, found {len(paths)}")
        renders[name] = [load(p) for p in paths]
    common_mean = np.mean([image.mean() for images in renders.values() for image in images])
    scaled = {name: np.array([image * common_mean / image.mean() for image in images])
              for name, images in renders.items()}
    pooled_sum = sum(s.sum(0) for s in scaled.values())
    pooled_count = sum(len(s) for s in scaled.values())
    pooled_raw = np.mean([image for images in renders.values() for image in images], 0)

    crop_column = " relvar in the crop |" if args.crop else ""
    print(f"| setting | seeds | relvar over seeds | relMSE against the other settings | mean / pooled mean |{crop_column}")
    print("|---|---|---|---|---|" + ("---|" if args.crop else ""))
    for name, s in scaled.items():
        others = (pooled_sum - s.sum(0)) / (pooled_count - len(s))
        relative_variance = s.var(0, ddof=1) / (others ** 2 + EPS)
        errors = [relmse(image, others) for image in s]
        mean = np.mean([image.mean() for image in renders[name]]) / pooled_raw.mean()
        crop = ""
        if args.crop:
            x0, x1, y0, y1 = args.crop
            crop = f" {relative_variance[y0:y1, x0:x1].mean():.4f} |"
        print(f"| {name} | {len(s)} | {relative_variance.mean():.4f} | {np.mean(errors):.4f} | {mean:.4f} |{crop}")
    for path in args.also:
        image = load(path)
        print(f"| {path} (unscaled) | 1 | | {relmse(image, pooled_raw):.4f} | {image.mean() / pooled_raw.mean():.4f} |" +
              (" |" if args.crop else ""))


if __name__ == "__main__":
    main()
