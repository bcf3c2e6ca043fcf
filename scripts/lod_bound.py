#!/usr/bin/env python3
"""The image-space bound of level of detail: how few samples per pixel an *ideal* amalgam
renderer would need to reach full detail's error, from one full-detail render at F times the
resolution.

An amalgam rendered at footprint K stands for what lies within about K pixels of the ray. The
best such a renderer can return for a camera sample at image point x is the full-detail image
averaged over a disc of K pixels' diameter about x (the oracle of bench/oracle.h, in image
space: no bake error, shadows and shading prefiltered too). Its expected pixel is the disc-blurred
image averaged over the pixel (bias: the blur), and its noise comes only from where in the pixel
its n stratified samples fall. This script computes, from a full-detail render at F x F
sub-pixels per pixel:

- the floor: RMSE between the ideal renderer's expected image and the pixel-averaged image;
- its RMSE at n = 1, 2, 4, ... stratified samples per pixel (sub-pixel positions drawn on the
  F x F grid, one per stratum, averaged over --draws draws), and the same for full detail
  (K = 0: the unblurred sub-pixel values), all against the same pixel-averaged image;
- the fewest samples with which each K reaches full detail's error at --target-spp, and so the
  largest speed-up an ideal renderer at K could have at equal cost per sample.

The sub-pixel values are themselves averages over a 1/F^2 pixel, so within-sub-pixel variation
is missing from every curve: the noise is underestimated alike for all K (the bound is
optimistic for level of detail). Needs python3-numpy. Usage (docs/yardstick.md, "An image-space
bound"):

  scripts/lod_bound.py --amalgam build/amalgam --scene scenes/meadow.json \
      --width 256 --height 192 --factor 8 --spp 4
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pfm  # noqa: E402


def read_pfm(path):
    """A colour PFM as an H x W x 3 float64 array, top row first."""
    img = pfm.read_pfm(path)
    if img.shape[2] != 3:
        sys.exit(f"{path}: not a colour PFM")
    return img.astype(np.float64)


def disc_blur(img, diameter):
    """img convolved with a normalised disc of `diameter` sub-pixels (FFT, edges clamped by
    padding with the border)."""
    r = diameter / 2.0
    n = int(np.ceil(r))
    yy, xx = np.mgrid[-n : n + 1, -n : n + 1]
    ker = ((xx**2 + yy**2) <= r * r + 1e-9).astype(np.float64)
    ker /= ker.sum()
    pad = np.pad(img, ((n, n), (n, n), (0, 0)), mode="edge")
    h, w = pad.shape[:2]
    kf = np.fft.rfft2(ker, s=(h, w))
    out = np.empty_like(pad)
    for c in range(3):
        out[..., c] = np.fft.irfft2(np.fft.rfft2(pad[..., c]) * kf, s=(h, w))
    # the kernel's centre sits at (n, n): the full convolution is shifted by n
    return out[2 * n : 2 * n + img.shape[0], 2 * n : 2 * n + img.shape[1]]


def strata(n, f):
    """n strata of the F x F sub-pixel grid as (rows, cols) ranges: a grid of sx by sy."""
    sx = 1 << ((n.bit_length() - 1 + 1) // 2)
    sy = n // sx
    if sx * sy != n or f % sx or f % sy:
        raise ValueError(f"{n} samples do not stratify a {f} x {f} grid")
    return [
        (j * f // sy, (j + 1) * f // sy, i * f // sx, (i + 1) * f // sx)
        for j in range(sy)
        for i in range(sx)
    ]


def rmse_at(sub, ref, n, f, draws, rng):
    """RMSE against `ref` of the mean of n stratified samples per pixel of `sub` (shape
    H, F, W, F, 3), over `draws` independent draws."""
    H, _, W, _, _ = sub.shape
    mse = 0.0
    for _ in range(draws):
        est = np.zeros((H, W, 3))
        for y0, y1, x0, x1 in strata(n, f):
            ys = rng.integers(y0, y1, size=(H, W))
            xs = rng.integers(x0, x1, size=(H, W))
            est += sub[np.arange(H)[:, None], ys, np.arange(W)[None, :], xs]
        est /= n
        mse += np.mean((est - ref) ** 2)
    return float(np.sqrt(mse / draws))


def spp_to_reach(curve, ns, target):
    """The samples per pixel at which `curve` (RMSE at each n of `ns`) reaches `target`: log-log
    between the two measured points that bracket it, as the yardstick reads equal error. (None,
    False) when not reached; (ns[0], True) when already below it at ns[0] (at most that)."""
    for i, n in enumerate(ns):
        if curve[n] <= target:
            if i == 0:
                return float(n), True
            n0, e0, e1 = ns[i - 1], curve[ns[i - 1]], curve[n]
            if e1 <= 0 or e0 <= e1:
                return float(n), False
            x = np.log(e0 / target) / np.log(e0 / e1)  # 0 at n0, 1 at n
            return float(n0 * (n / n0) ** x), False
    return None, False


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--amalgam", default="build/amalgam", help="the amalgam binary")
    ap.add_argument("--scene", required=True)
    ap.add_argument("--view", nargs=argparse.REMAINDER, default=[],
                    help="the rest: options passed to amalgam render (e.g. --eye x,y,z ...)")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--height", type=int, default=192)
    ap.add_argument("--factor", type=int, default=8, help="sub-pixels per pixel side (F)")
    ap.add_argument("--spp", type=int, default=4, help="samples per sub-pixel of the render")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--footprints", default="0.5,1,2,4", help="K values")
    ap.add_argument("--spps", default="1,2,4,8,16", help="n values (powers of two)")
    ap.add_argument("--target-spp", type=int, default=16, help="full detail's n to match")
    ap.add_argument("--target", type=float,
                    help="full detail's measured RMSE at --target-spp (e.g. from the yardstick); "
                    "default: this model's, which lacks the within-sub-pixel noise")
    ap.add_argument("--draws", type=int, default=4)
    ap.add_argument("--image", help="use this full-detail PFM (F x the size) instead of rendering")
    ap.add_argument("--json", help="write the results here too")
    a = ap.parse_args()
    f = a.factor
    ks = [float(k) for k in a.footprints.split(",")]
    ns = [int(n) for n in a.spps.split(",")]
    if a.target_spp not in ns:
        sys.exit(f"--target-spp {a.target_spp} must be one of --spps")

    if a.image:
        hi = read_pfm(a.image)
    else:
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "hi.pfm")
            cmd = [a.amalgam, "render", a.scene, "--renderer", "traditional", "--sampler",
                   "stratified", "--width", str(a.width * f), "--height", str(a.height * f),
                   "--spp", str(a.spp), "--threads", str(a.threads), "--seed", "11", "--quiet",
                   "--out", out] + a.view
            print("rendering:", " ".join(cmd), file=sys.stderr)
            subprocess.run(cmd, check=True)
            hi = read_pfm(out)
    H, W = hi.shape[0] // f, hi.shape[1] // f
    if (H * f, W * f) != hi.shape[:2]:
        sys.exit(f"image {hi.shape[1]}x{hi.shape[0]} is not {f} x a whole number of pixels")
    ref = hi.reshape(H, f, W, f, 3).mean(axis=(1, 3))
    rng = np.random.default_rng(1)

    rows = []
    for k in [0.0] + ks:
        blurred = hi if k == 0 else disc_blur(hi, k * f)
        sub = blurred.reshape(H, f, W, f, 3)
        floor = float(np.sqrt(np.mean((sub.mean(axis=(1, 3)) - ref) ** 2)))
        curve = {n: rmse_at(sub, ref, n, f, a.draws, rng) for n in ns}
        rows.append({"K": k, "floor": floor, "rmse": curve})
    target = a.target if a.target else rows[0]["rmse"][a.target_spp]
    for r in rows:
        r["spp_at_target"], r["at_most"] = spp_to_reach(r["rmse"], ns, target)
        need = r["spp_at_target"]
        r["speedup_bound"] = (a.target_spp / need) if need else None

    print(f"{W} x {H} pixels from {W * f} x {H * f} sub-pixels; full detail's RMSE at "
          f"{a.target_spp} spp ({'given' if a.target else 'this model'}): {target:.4f}")
    head = " | ".join(f"RMSE {n} spp" for n in ns)
    print(f"| K | floor (bias) | {head} | spp to reach {target:.4f} | speed-up bound at equal "
          "cost per sample |")
    print("|---|---|" + "---|" * len(ns) + "---|---|")
    for r in rows:
        name = "0 (full detail)" if r["K"] == 0 else f"{r['K']:g}"
        cells = " | ".join(f"{r['rmse'][n]:.4f}" for n in ns)
        need = r["spp_at_target"]
        le = "<= " if r["at_most"] else ""
        ge = ">= " if r["at_most"] else ""
        spp = f"{le}{need:.1f}" if need else "-"
        bound = f"{ge}{r['speedup_bound']:.1f}x" if need else f"not by {ns[-1]} spp"
        print(f"| {name} | {r['floor']:.4f} | {cells} | {spp} | {bound} |")
    if a.json:
        with open(a.json, "w") as out:
            json.dump({"width": W, "height": H, "factor": f, "target": target, "rows": rows},
                      out, indent=1)


if __name__ == "__main__":
    main()
