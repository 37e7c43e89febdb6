#!/usr/bin/env python3
"""Per-sample variance of candela's render of a Mitsuba test scene against the reference's own
variance image (Mitsuba's per-sample variance at 32,000 spp), both in CIE XYZ where Mitsuba computed
it (docs/conformance.md): the ratio the conformance protocol silently assumes to be at most 1.

Usage (from the repository root, after building build/):
  bench/media_variance.py SCENE.xml REF_rgb.exr [extra candela flags, e.g. --sampler independent]
Renders 24 independent 64-spp images (seeds 1..24), prints the mean ratio, the ratio of summed and the
median of per-pixel variances, the fraction of |z| > 3 of the mean of all runs, and the median ratio
per 12 x 12 block (where candela is noisier).
"""
import os
import sys, subprocess, numpy as np, OpenImageIO as oiio

CANDELA = os.environ.get("CANDELA", "build/candela")
os.makedirs("/tmp/candela-media-variance", exist_ok=True)
scene, ref, extra = sys.argv[1], sys.argv[2], sys.argv[3:]
spp=64; runs=24
# Linear sRGB -> XYZ, the matrix of Mitsuba's Bitmap conversions.
M=np.array([[0.412453,0.357580,0.180423],[0.212671,0.715160,0.072169],[0.019334,0.119193,0.950227]])
def xyz(filename):
    return oiio.ImageBuf(filename).get_pixels(oiio.FLOAT)[:,:,:3].astype(np.float64)@M.T
imgs=[]
for s in range(runs):
    out=f"/tmp/candela-media-variance/run{s}.exr"
    subprocess.run([CANDELA,"render",scene,"-o",out,"--spp",str(spp),"--seed",str(s+1)]+extra,check=True,capture_output=True)
    imgs.append(xyz(out))
a=np.array(imgs)
var=a.var(axis=0,ddof=1)*spp
rv=xyz(ref.replace("_ref_rgb.exr","_ref_rgb_var.exr"))
m=xyz(ref)
print("mean ratio", a.mean()/m.mean(), "per-sample var candela/mitsuba (sum)", var.sum()/np.abs(rv).sum(), "median ratio", np.median(var/np.maximum(rv,1e-6)))
z=(a.mean(axis=0)-m)/np.sqrt(np.maximum(rv,1e-4)/(spp*runs))
print("frac |z|>3", (np.abs(z)>3).mean(), "mean z", z.mean(), "per XYZ channel mean z", z.mean(axis=(0,1)))
r=var/np.maximum(rv,1e-6)
h,w=r.shape[:2]
for y0 in range(0,h,12):
    print(" ".join(f"{np.median(r[y0:y0+12,x0:x0+12]):5.2f}" for x0 in range(0,w,12)))
