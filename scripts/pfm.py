"""Reading PFM images (what `amalgam render --out X.pfm` writes) with NumPy."""

import numpy as np


def read_pfm(path):
    """A PFM image ("PF" colour or "Pf" grey) as an H x W x C float32 array, top row first
    (PFM stores its rows bottom to top). Exits with one line naming the file if it is not one."""
    with open(path, "rb") as f:
        kind = f.readline().strip()
        if kind not in (b"PF", b"Pf"):
            raise SystemExit(f"{path}: not a PFM image")
        width, height = (int(v) for v in f.readline().split())
        scale = float(f.readline())
        channels = 3 if kind == b"PF" else 1
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(height, width, channels)[::-1]


def write_pfm(path, img):
    """Writes an H x W x 3 array (top row first) as a little-endian colour PFM."""
    h, w, _ = img.shape
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())
