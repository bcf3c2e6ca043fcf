"""RenderResult.__array__: numpy.asarray(result) is the image, without a copy unless asked."""

import numpy as np
import pytest


def test_asarray_is_the_image_without_a_copy(demo):
    r = demo.render(width=12, height=8, spp=1)
    a = np.asarray(r)
    assert a.dtype == np.float32 and a.shape == (8, 12, 3)
    assert np.shares_memory(a, r.image) and np.array_equal(a, r.image)
    assert np.asarray(r, dtype=np.float32) is not None and np.shares_memory(np.asarray(r, dtype=np.float32), r.image)
    # NumPy's functions take a result where they take an array.
    assert np.mean(r) == pytest.approx(float(r.image.mean()))


def test_dtype_and_copy(demo):
    r = demo.render(width=12, height=8, spp=1)
    d = np.asarray(r, dtype=np.float64)
    assert d.dtype == np.float64 and np.array_equal(d, r.image.astype(np.float64))
    assert not np.shares_memory(d, r.image)
    c = np.array(r)  # np.array copies by default
    assert not np.shares_memory(c, r.image) and np.array_equal(c, r.image)
    # The protocol called directly, as NumPy 2 calls it (dtype, copy).
    assert r.__array__() is r.image
    assert r.__array__(None, False) is r.image
    copied = r.__array__(copy=True)
    assert copied is not r.image and np.array_equal(copied, r.image)
    assert not np.shares_memory(copied, r.image)
    assert r.__array__("float16").dtype == np.float16
    with pytest.raises(ValueError) as e:
        r.__array__(np.float64, copy=False)
    assert str(e.value) == "copy=False: the image is float32; dtype=float64 needs a copy"
    with pytest.raises(TypeError) as e:
        r.__array__(copy="yes")
    assert str(e.value) == "RenderResult.__array__() argument 'copy' must be bool or None, not str"
