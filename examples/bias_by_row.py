"""Where an amalgam image is biased: per band of rows, the amalgam render's mean luminance,
albedo and visible normal against a full-detail render of the same view.

    PYTHONPATH=build/python /usr/bin/python3 examples/bias_by_row.py scenes/field.json

Luminance off while albedo (what was hit) agrees means the shading of what was hit is wrong,
not its coverage; the normal columns show which way the surfaces each render shaded face.
"""

import argparse

import numpy as np

import amalgam


def lum(x):
    return x[..., 0] * 0.2126 + x[..., 1] * 0.7152 + x[..., 2] * 0.0722


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--height", type=int, default=192)
    ap.add_argument("--footprint", type=float, default=1.0)
    ap.add_argument("--spp", type=int, default=64, help="samples of the amalgam render")
    ap.add_argument("--ref-spp", type=int, default=128, help="samples of the full-detail one")
    ap.add_argument("--band", type=int, default=4, help="rows per band")
    ap.add_argument("--threads", type=int, default=0)
    a = ap.parse_args()
    scene = amalgam.load(a.scene)
    ref = scene.render(width=a.width, height=a.height, spp=a.ref_spp, renderer="traditional",
                       seed=11, threads=a.threads)
    lod = scene.render(width=a.width, height=a.height, spp=a.spp, footprint=a.footprint, seed=3,
                       threads=a.threads)
    print(f"# {a.scene}, {a.width}x{a.height}, footprint {a.footprint}: RMSE "
          f"{amalgam.compare(lod, ref)['rmse']:.4f}; rows where the reference hits something")
    print("| rows | in amalgams | luminance | albedo | visible normal, full detail | "
          "visible normal, amalgams |")
    print("|---|---|---|---|---|---|")
    for y0 in range(0, a.height, a.band):
        rows = slice(y0, y0 + a.band)
        hit = np.isfinite(ref.depth[rows]).mean()
        if hit < 0.5:
            continue
        l_ref, l_lod = lum(ref.image[rows]).mean(), lum(lod.image[rows]).mean()
        a_ref, a_lod = lum(ref.albedo[rows]).mean(), lum(lod.albedo[rows]).mean()
        amal = (lod.level[rows] >= 0).mean()
        n_ref = ref.normal[rows].reshape(-1, 3).mean(0)
        n_lod = lod.normal[rows].reshape(-1, 3).mean(0)
        fmt = lambda n: "(" + ", ".join(f"{v:.2f}" for v in n) + ")"
        print(f"| {y0}-{y0 + a.band - 1} | {amal:.0%} | {l_lod / l_ref - 1:+.1%} | "
              f"{a_lod / a_ref - 1:+.1%} | {fmt(n_ref)} | {fmt(n_lod)} |")


if __name__ == "__main__":
    main()
