#!/usr/bin/env python3
"""docs/python.md as a script: load the Cornell box (pbrt-v4 format), render it, change a material,
and plot how the error falls with the sample count, measured against a reference and as candela
estimates it from the render itself.

    PYTHONPATH=build/python python3 examples/convergence.py OUTPUT_DIR

Writes OUTPUT_DIR/cornell.exr, cornell-blue.png and convergence.png. The test suite runs it with
CANDELA_EXAMPLE_QUICK=1 (a smaller image and fewer samples).
"""
import os
import pathlib
import sys

import matplotlib

matplotlib.use(os.environ.get("MPLBACKEND", "Agg"))
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import candela  # noqa: E402

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
out.mkdir(parents=True, exist_ok=True)
quick = os.environ.get("CANDELA_EXAMPLE_QUICK") == "1"
size = (64, 64) if quick else (256, 256)
reference_spp = 256 if quick else 4096

# Load a scene in any format candela reads; the render settings are keywords, as on the command line.
scene = candela.load_file(pathlib.Path(__file__).resolve().parents[1] / "scenes/cornell-box.pbrt")
image = candela.render(scene, spp=16, resolution=size, seed=1)
image.write(out / "cornell.exr")
print(f"{image.shape[1]}x{image.shape[0]}, {image.metadata['candela:spp']} spp "
      f"in {image.metadata['candela:render_time_seconds']} s")

# Change a material and render again: no file is read a second time.
params = candela.traverse(scene)
red = next(name for name in params if name.startswith("materials.") and name.endswith("reflectance")
           and params[name][0] > 2 * params[name][2])
print(f"{red}: {params[red]} -> blue")
params[red] = (0.05, 0.1, 0.6)
candela.render(scene, spp=16, resolution=size, seed=1).write(out / "cornell-blue.png")
params[red] = (0.63, 0.065, 0.05)

# A convergence curve: relMSE (epsilon 0.01, the project's metric) against a reference render, and
# candela's own estimate of it from two independent halves of the samples (--estimate-error).
reference = candela.render(scene, spp=reference_spp, resolution=size, seed=1000)


def relmse(test):
    return float(np.mean((test - reference) ** 2 / (reference ** 2 + 0.01)))


counts = [4, 8, 16, 32, 64] if quick else [4, 8, 16, 32, 64, 128, 256]
measured, estimated = [], []
for spp in counts:
    test = candela.render(scene, spp=spp, resolution=size, seed=spp, estimate_error=True)
    measured.append(relmse(test))
    estimated.append(float(test.metadata["candela:relmse_estimate"]))
    print(f"{spp:5d} spp: relMSE {measured[-1]:.5f}, estimated {estimated[-1]:.5f}")

plt.figure(figsize=(5, 4))
plt.loglog(counts, measured, "o-", label="against the reference")
plt.loglog(counts, estimated, "s--", label="candela's own estimate")
plt.loglog(counts, [measured[0] * counts[0] / n for n in counts], ":", color="grey", label="1 / spp")
plt.xlabel("samples per pixel")
plt.ylabel("relMSE")
plt.title("Cornell box, path tracer")
plt.legend()
plt.tight_layout()
plt.savefig(out / "convergence.png", dpi=100)
print(f"wrote {out / 'convergence.png'}")
