#!/usr/bin/python3
"""Why Mitsuba's test_spot_direct fails its own protocol: its reference variance is impossible.

The camera and the spot light of ../shared/scenes/mitsuba-tests/.../spot_light/test_spot_direct.xml
share their origin and look down +z at a white diffuse plane at z = 1, so a sample at film position
(px, py) sees, without noise, g = 0.1 + I falloff(theta) tex(uv) cos^3(theta) / pi (the constant
emitter's 0.1 plus the spot's irradiance over pi). Mitsuba's independent sampler puts each sample
uniformly in its pixel, so by the law of total variance its per-sample variance is at least the
spread of g over the pixel. This script integrates g over every pixel (supersampled), compares the
reference's variance image with that lower bound, and reruns the protocol with valid variances.

usage: bench/spot_variance_bound.py CANDELA_RENDER.exr [SHARED_DIR]
  CANDELA_RENDER.exr: the conformance test's render (CANDELA_CONFORMANCE_OUT=DIR, 868 spp)
"""
import math
import sys

import numpy as np
import OpenImageIO as oiio

render = sys.argv[1]
shared = sys.argv[2] if len(sys.argv) > 2 else "../shared"
scene = f"{shared}/scenes/mitsuba-tests/tests/scenes/spot_light"


def load(path):
    return oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[..., :3].astype(np.float64)


ref = load(f"{scene}/refs/test_spot_ref_rgb.exr")
var = load(f"{scene}/refs/test_spot_ref_rgb_var.exr")
image = load(render)
texture_row = oiio.ImageBuf(f"{scene}/textures/de_bruijn_pattern.png").get_pixels(oiio.FLOAT)[0, :, :3]
texels = texture_row.shape[0]  # the stripes are vertical: every row of the texture is the same

W = 48                                   # film width = height
tan_half_fov = math.tan(math.radians(25))  # fov 50 along x
uv_factor = math.tan(math.radians(20))     # cutoff angle
beam, cutoff = math.radians(15), math.radians(20)
SX, SY = 512, 16                          # samples per pixel along x (across the stripes) and y

mean_g = np.zeros((W, W, 3))
spread_g = np.zeros((W, W, 3))
for row in range(W):
    py = row + (np.arange(SY) + 0.5) / SY
    px = (np.arange(W * SX) + 0.5) / SX
    # Mitsuba's film x runs towards the camera's -x, which the spot's lookat makes world +x.
    X, Y = np.meshgrid(tan_half_fov * (1 - 2 * px / W), tan_half_fov * (1 - 2 * py / W))
    theta = np.arctan(np.hypot(X, Y))
    falloff = np.where(theta < cutoff, np.clip((cutoff - theta) / (cutoff - beam), 0, 1), 0)
    c = (0.5 + 0.5 * X / uv_factor) * texels - 0.5  # Mitsuba's bilinear lookup, u * width - 1/2
    i0 = np.floor(c).astype(int)
    w = (c - i0)[..., None]
    tex = (1 - w) * texture_row[i0 % texels] + w * texture_row[(i0 + 1) % texels]
    g = 0.1 + 5 * falloff[..., None] * tex / np.pi / ((1 + X * X + Y * Y) ** 1.5)[..., None]
    g = g.reshape(SY, W, SX, 3).transpose(1, 0, 2, 3).reshape(W, SY * SX, 3)
    mean_g[row] = g.mean(axis=1)
    spread_g[row] = g.var(axis=1)

print(f"model against the reference: mean |difference| {np.abs(mean_g - ref).mean() / ref.mean():.2%} per pixel-channel")
print(f"model against candela:       mean |difference| {np.abs(mean_g - image).mean() / image.mean():.2%} per pixel-channel")
textured = spread_g > 1e-3
ratio = var[textured] / spread_g[textured]
print(f"{textured.sum()} pixel-channels on the stripes; reference variance / its lower bound there:")
print("  percentiles 1, 5, 25, 50, 75, 95, 99:", np.round(np.percentile(ratio, [1, 5, 25, 50, 75, 95, 99]), 3))
print(f"  below a quarter of the bound: {(ratio < 0.25).mean():.1%} (negative: {(var[textured] < 0).mean():.1%})")

spp = 2000000 // (W * W)
alpha = 1 - 0.99 ** (1 / (W * W))
erfc = np.vectorize(math.erfc)


def protocol(variance, label):
    z = np.abs(image - ref) * np.sqrt(spp / np.maximum(variance, 1e-4))
    failing = erfc(z / math.sqrt(2)) <= alpha
    print(f"{label}: {1 - failing.mean():.5f} pass ({failing.sum()} pixel-channels fail, "
          f"{int(0.0025 * failing.size)} may)")
    return failing


protocol(var, "protocol (reference variance)")
failing = protocol(np.abs(var), "with |var|")
for r, c, ch in np.argwhere(failing):
    print(f"  pixel ({c}, {r}) channel {ch}: reference variance {var[r, c, ch]:.3g}, lower bound {spread_g[r, c, ch]:.3g}")
protocol(np.maximum(var, spread_g), "with the variance raised to its lower bound")
