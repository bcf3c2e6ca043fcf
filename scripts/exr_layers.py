#!/usr/bin/env python3
"""Reads the layers of an OpenEXR file that amalgam wrote (`render --out x.exr`: scanline,
ZIP compression, FLOAT channels; docs/outputs.md) into numpy arrays, with no OpenEXR module:
zlib, the byte predictor and the byte interleave of the ZIP codec, by hand. Other files
(tiled, multi-part, other compressions or HALF channels) are refused.

    from exr_layers import read_exr
    layers = read_exr("x.exr")   # {"R": H x W float32, "G": ..., "albedo.R": ..., "Z": ...}

    python3 scripts/exr_layers.py x.exr   # prints the channels and their ranges
"""
import struct
import sys
import zlib

import numpy as np

_FLOAT, _ZIP, _ZIPS = 2, 3, 2


def _undo_zip(raw, size):
    t = np.frombuffer(zlib.decompress(raw), dtype=np.uint8)
    if t.size != size:
        raise ValueError(f"chunk inflates to {t.size} bytes, expected {size}")
    # The predictor: byte i is stored as b[i] - b[i - 1] + 128 (the first one as is).
    t = np.cumsum(t.astype(np.int64) - 128, dtype=np.int64) + 128
    t = (t & 0xFF).astype(np.uint8)
    out = np.empty_like(t)
    half = (t.size + 1) // 2
    out[0::2] = t[:half]
    out[1::2] = t[half:]
    return out


def read_exr(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(f"{path}: not an OpenEXR file")
    version = struct.unpack_from("<I", data, 4)[0]
    if version & 0xFF != 2 or version & 0x1600:
        raise ValueError(f"{path}: only single-part scanline files (version flags {version:#x})")
    pos, header = 8, {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        end2 = data.index(b"\0", end + 1)
        typ = data[end + 1:end2].decode()
        size = struct.unpack_from("<i", data, end2 + 1)[0]
        header[name] = (typ, data[end2 + 5:end2 + 5 + size])
        pos = end2 + 5 + size
    pos += 1
    channels, cl = [], header["channels"][1]
    p = 0
    while cl[p] != 0:
        end = cl.index(b"\0", p)
        name = cl[p:end].decode()
        # pixel type (int32), pLinear (1 byte), 3 reserved bytes, x and y sampling (int32)
        ptype = struct.unpack_from("<i", cl, end + 1)[0]
        xs, ys = struct.unpack_from("<ii", cl, end + 9)
        if ptype != _FLOAT or xs != 1 or ys != 1:
            raise ValueError(f"{path}: channel {name} is not FLOAT at full resolution")
        channels.append(name)
        p = end + 1 + 16
    comp = header["compression"][1][0]
    if comp not in (_ZIP, _ZIPS):
        raise ValueError(f"{path}: compression {comp}, only ZIP (3) and ZIPS (2) are read")
    x0, y0, x1, y1 = struct.unpack("<iiii", header["dataWindow"][1])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    lines = 16 if comp == _ZIP else 1
    chunks = (h + lines - 1) // lines
    offsets = struct.unpack_from(f"<{chunks}Q", data, pos)
    out = {c: np.empty((h, w), dtype=np.float32) for c in channels}
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, off)
        raw = data[off + 8:off + 8 + size]
        n = min(lines, y1 + 1 - y)
        full = n * len(channels) * w * 4
        block = np.frombuffer(raw if size == full else _undo_zip(raw, full).tobytes(),
                              dtype="<f4").reshape(n, len(channels), w)
        for i, c in enumerate(channels):
            out[c][y - y0:y - y0 + n] = block[:, i, :]
    return out


if __name__ == "__main__":
    for name, a in read_exr(sys.argv[1]).items():
        fin = a[np.isfinite(a)]
        print(f"{name}: {a.shape[1]} x {a.shape[0]}, finite {fin.size}, "
              f"range {fin.min() if fin.size else 0:g} .. {fin.max() if fin.size else 0:g}")
