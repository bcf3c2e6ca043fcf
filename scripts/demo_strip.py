#!/usr/bin/python3
"""Composes the demo strip (out/demo.png) from the renders scripts/demo.sh makes.

Columns: each scene size rendered traditionally and scale-sensitively. Rows: the image; its exact
cost (intersection tests per pixel, all rays of the pixel, per sample) on one log scale shared by
every column, with its colour bar; and, for the scale-sensitive columns, the level of the amalgam
rendered at each pixel (a traditional renderer never renders one). Under each cost image: the
mean tests per primary ray (shadow rays included) and the render time, from the stats JSON.

Usage: demo_strip.py DIR OUT.png   (DIR holds NAME.png, NAME-cost.pfm, NAME-level.pfm and
NAME.json for every NAME listed in DIR/strip.json)
"""

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import BoundaryNorm, LogNorm  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import pfm  # noqa: E402


def read_pfm(path):
    """A PFM image as a float32 array (rows from the top), one channel if it is grey."""
    img = pfm.read_pfm(path)
    return img[:, :, 0] if img.shape[2] == 3 and np.all(img[:, :, 0] == img[:, :, 1]) else img


def main():
    src, out = Path(sys.argv[1]), Path(sys.argv[2])
    strip = json.loads((src / "strip.json").read_text())
    columns = strip["columns"]
    costs = [read_pfm(src / f"{c['name']}-cost.pfm") for c in columns]
    lo = max(1.0, min(float(c[c > 0].min()) for c in costs))
    hi = max(float(c.max()) for c in costs)
    cost_norm = LogNorm(vmin=lo, vmax=hi)
    has_level = [(src / f"{c['name']}-level.pfm").exists() for c in columns]
    rows = 3 if any(has_level) else 2
    fig, axes = plt.subplots(rows, len(columns), figsize=(3.1 * len(columns) + 1.3, 2.42 * rows + 0.7),
                             squeeze=False, constrained_layout=True)
    # Level images: amalgam levels (rounded: a pixel's samples may have rendered several) on
    # one colour scale over every column, primitives grey, nothing hit white.
    levels = [read_pfm(src / f"{c['name']}-level.pfm") if ok else None
              for c, ok in zip(columns, has_level)]
    rendered = [np.rint(lv[lv >= 0]) for lv in levels if lv is not None]
    rendered = [r for r in rendered if r.size]
    lmin = int(min(r.min() for r in rendered)) if rendered else 0
    lmax = int(max(r.max() for r in rendered)) if rendered else 0
    level_cmap = plt.get_cmap("plasma", lmax - lmin + 1)
    level_norm = BoundaryNorm(np.arange(lmin - 0.5, lmax + 1.5), level_cmap.N)
    cost_im = level_im = None
    for j, c in enumerate(columns):
        stats = json.loads((src / f"{c['name']}.json").read_text())
        per_ray = stats["per_primary_ray"]["mean"]
        t = stats["time_s"]
        axes[0][j].imshow(mpimg.imread(src / f"{c['name']}.png"))
        axes[0][j].set_title(c["title"], fontsize=9)
        cost_im = axes[1][j].imshow(costs[j], cmap="viridis", norm=cost_norm)
        axes[1][j].set_xlabel(f"{per_ray:.1f} tests per ray\nrender {t['render']:.2f} s, "
                              f"load+build+bake {t['load'] + t['build'] + t.get('bake', 0):.2f} s",
                              fontsize=9)
        if rows == 3:
            lv = levels[j]
            if lv is not None and c["renderer"] == "scale-sensitive":
                rgb = np.ones(lv.shape + (3,))
                rgb[lv <= -1.5] = 0.6  # primitives
                mask = lv >= 0
                rgb[mask] = level_cmap(level_norm(np.rint(lv[mask])))[:, :3]
                axes[2][j].imshow(rgb, interpolation="nearest")
                level_im = plt.cm.ScalarMappable(norm=level_norm, cmap=level_cmap)
                axes[2][j].set_xlabel(f"an amalgam rendered in {100.0 * mask.mean():.0f} % of "
                                      "pixels\n(grey: a primitive)", fontsize=9)
            else:
                axes[2][j].text(0.5, 0.5, "traditional:\nevery bounding volume\nis traversed,\n"
                                "none is rendered", ha="center", va="center", fontsize=9,
                                transform=axes[2][j].transAxes)
                axes[2][j].axis("off")
        for ax in axes[:, j]:
            ax.set_xticks([])
            ax.set_yticks([])
    fig.colorbar(cost_im, ax=list(axes[1]), shrink=0.9,
                 label="intersection tests per pixel (log)")
    if level_im is not None:
        fig.colorbar(level_im, ax=list(axes[2]), shrink=0.9, label="level rendered",
                     ticks=range(lmin, lmax + 1, max(1, (lmax - lmin + 1) // 8)))
    fig.suptitle(strip["title"], fontsize=11)
    tmp = out.with_suffix(".tmp.png")
    fig.savefig(tmp, dpi=110)
    tmp.replace(out)


if __name__ == "__main__":
    main()
