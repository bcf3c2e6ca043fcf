#!/usr/bin/python3
"""Quality against cost: renders builtin:demo at full detail (the reference), then with the
scale-sensitive renderer at several ray footprints, and plots the error of each image against
the exact intersection tests it cost. Run after the build (docs/python.md):
    PYTHONPATH=build/python /usr/bin/python3 examples/quality_vs_cost.py [OUT.png]"""
import sys

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt

import amalgam

out = sys.argv[1] if len(sys.argv) > 1 else "quality_vs_cost.png"
scene = amalgam.load("builtin:demo")  # built and baked once, reused by every render
size = dict(width=160, height=120, spp=16, seed=1)
reference = scene.render(renderer="traditional", **size)
print(f"full detail    : {reference.cost.mean():8.1f} tests/sample")
points = []
for footprint in [0.5, 1, 2, 4, 8, 16, 32]:
    r = scene.render(footprint=footprint, **size)
    m = amalgam.compare(r, reference)
    points.append((r.cost.mean(), m["rmse"], m["ssim"], footprint))
    print(f"footprint {footprint:5}: {r.cost.mean():8.1f} tests/sample, "
          f"RMSE {m['rmse']:.4f}, SSIM {m['ssim']:.4f}")
fig, ax = plt.subplots(1, 2, figsize=(9, 3.5))
for i, name in [(1, "RMSE"), (2, "SSIM")]:
    ax[i - 1].plot([p[0] for p in points], [p[i] for p in points], "o-", label="scale-sensitive")
    for p in points:
        ax[i - 1].annotate(f"{p[3]:g} px", (p[0], p[i]), fontsize=7)
    ax[i - 1].set(xscale="log", xlabel="intersection tests per sample", ylabel=name,
                  title=f"{name} against full detail ({reference.cost.mean():.0f} tests)")
fig.tight_layout()
fig.savefig(out, dpi=120)
print("wrote", out)
