"""scripts/lod_bound.py: the image-space bound of level of detail (docs/yardstick.md)."""

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest

SCRIPTS = pathlib.Path(__file__).resolve().parents[2] / "scripts"
sys.path.insert(0, str(SCRIPTS))
import lod_bound  # noqa: E402


def write_pfm(path, img):
    h, w, _ = img.shape
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())


def test_pfm_round_trip(tmp_path):
    img = np.random.default_rng(0).random((6, 10, 3))
    write_pfm(tmp_path / "a.pfm", img)
    np.testing.assert_allclose(lod_bound.read_pfm(tmp_path / "a.pfm"), img, rtol=1e-6)


def test_disc_blur_keeps_a_constant_and_spreads_an_impulse_over_the_disc():
    const = np.full((20, 24, 3), 0.25)
    np.testing.assert_allclose(lod_bound.disc_blur(const, 5), const, atol=1e-12)
    img = np.zeros((21, 21, 3))
    img[10, 10] = 1.0
    out = lod_bound.disc_blur(img, 6)  # radius 3: 29 cells of the grid
    assert out[..., 0].sum() == pytest.approx(1.0)
    ys, xs = np.nonzero(out[..., 0] > 1e-9)
    assert ((ys - 10) ** 2 + (xs - 10) ** 2 <= 9).all()  # within the disc, centred
    assert len(ys) == 29
    np.testing.assert_allclose(out[out[..., 0] > 1e-9][:, 0], 1 / 29)


def test_strata_cover_the_grid_once():
    for n in (1, 2, 4, 8, 16):
        cells = np.zeros((8, 8), int)
        for y0, y1, x0, x1 in lod_bound.strata(n, 8):
            cells[y0:y1, x0:x1] += 1
        assert (cells == 1).all() and len(lod_bound.strata(n, 8)) == n
    with pytest.raises(ValueError):
        lod_bound.strata(16, 2)


def test_sub_pixel_checkerboard_exact_errors():
    # Every pixel holds a 4 x 4 checkerboard of 0 and 1: its mean is 0.5, so one sample is
    # off by exactly 0.5, and 16 stratified samples (one per sub-pixel) are exact.
    f, h, w = 4, 3, 5
    sub = (np.indices((h * f, w * f)).sum(axis=0) % 2).astype(float)
    sub = np.repeat(sub[..., None], 3, axis=2)
    ref = np.full((h, w, 3), 0.5)
    rng = np.random.default_rng(0)
    shaped = sub.reshape(h, f, w, f, 3)
    assert lod_bound.rmse_at(shaped, ref, 1, f, 3, rng) == pytest.approx(0.5)
    assert lod_bound.rmse_at(shaped, ref, 16, f, 3, rng) == pytest.approx(0.0)
    # Two samples, one per half (left, right): each half holds 4 zeros and 4 ones, so the
    # error is 0.5 * (a - b) for two independent fair coins: RMSE sqrt(1/8) on average.
    many = lod_bound.rmse_at(shaped, ref, 2, f, 400, rng)
    assert many == pytest.approx(np.sqrt(1 / 8), rel=0.05)


def test_main_on_a_given_image(tmp_path):
    f, h, w = 4, 8, 8
    rng = np.random.default_rng(3)
    img = rng.random((h * f, w * f, 3))
    write_pfm(tmp_path / "hi.pfm", img)
    out = subprocess.run(
        [sys.executable, str(SCRIPTS / "lod_bound.py"), "--scene", "unused", "--image",
         str(tmp_path / "hi.pfm"), "--factor", str(f), "--footprints", "1,2", "--spps",
         "1,2,4,16", "--json", str(tmp_path / "r.json")],
        check=True, capture_output=True, text=True).stdout
    assert "| 0 (full detail) | 0.0000 |" in out
    r = json.loads((tmp_path / "r.json").read_text())
    assert [row["K"] for row in r["rows"]] == [0.0, 1.0, 2.0]
    full = r["rows"][0]
    # Full detail at F^2 stratified samples is exact here, and is its own target.
    assert full["rmse"]["16"] == pytest.approx(0.0) and full["speedup_bound"] == 1.0
    # Blurring white noise loses contrast: the floor grows with K.
    assert 0 < r["rows"][1]["floor"] < r["rows"][2]["floor"]
