"""Arguments as Python binds them: paths as str or os.PathLike, one-line TypeErrors naming
the function and keyword, one-line ValueErrors naming the keyword and its range, load()'s
messages in Python's words, and signatures that help() and inspect can read."""

import inspect
import os
import pathlib
import subprocess

import numpy as np
import pytest

import amalgam

SCENES = pathlib.Path(__file__).resolve().parents[2] / "scenes"


def one_line(e):
    """The exception's message, checked to be one line."""
    message = str(e.value)
    assert "\n" not in message, message
    assert "incompatible function arguments" not in message
    return message


class FsPath:
    """A path-like object that is not a pathlib.Path: only __fspath__."""

    def __init__(self, path):
        self.path = str(path)

    def __fspath__(self):
        return self.path


def test_paths_accept_str_and_pathlike(demo, tmp_path):
    spheres = SCENES / "spheres.json"
    by_str = amalgam.load(str(spheres)).render(width=16, height=12, spp=1)
    for path in (spheres, FsPath(spheres), os.fsencode(spheres)):
        r = amalgam.load(path).render(width=16, height=12, spp=1)
        assert np.array_equal(r.image, by_str.image)
    r = demo.render(width=8, height=6, spp=1)
    for i, path in enumerate((tmp_path / "a.pfm", FsPath(tmp_path / "b.pfm"), str(tmp_path / "c.pfm"))):
        r.save(path)
        amalgam.save_image(path, r.image)
        amalgam.save_image(path=path, image=r)
    sizes = {p.name: p.stat().st_size for p in tmp_path.iterdir()}
    assert sorted(sizes) == ["a.pfm", "b.pfm", "c.pfm"] and len(set(sizes.values())) == 1
    with pytest.raises(TypeError) as e:
        amalgam.load(42)
    assert one_line(e) == "load() argument 'scene' must be str, os.PathLike or dict, not int"
    with pytest.raises(TypeError) as e:
        r.save(3.5)
    assert one_line(e) == "RenderResult.save() argument 'path' must be str or os.PathLike, not float"
    with pytest.raises(ValueError) as e:
        amalgam.load(tmp_path / "missing.json")
    assert one_line(e) == str(tmp_path / "missing.json") + ": no such file"


def test_unknown_keyword_is_one_line_type_error(demo):
    cases = [
        (lambda: demo.render(width=8, height=8, sed=1), "Scene.render() got an unexpected keyword argument 'sed'"),
        (lambda: demo.trace(widht=8), "Scene.trace() got an unexpected keyword argument 'widht'"),
        (lambda: amalgam.save_image("x.png", np.zeros((2, 2, 3)), quality=9),
         "save_image() got an unexpected keyword argument 'quality'"),
        (lambda: amalgam.compare(a=np.zeros((2, 2, 3)), c=1),
         "compare() got an unexpected keyword argument 'c'"),
        (lambda: amalgam.experiment("expected", quik=True),
         "experiment() got an unexpected keyword argument 'quik'"),
        (lambda: amalgam.to_srgb(img=1), "to_srgb() got an unexpected keyword argument 'img'"),
        (lambda: demo.render(8), "Scene.render() takes 0 positional arguments but 1 was given"),
        (lambda: demo.trace(None, None, 1), "Scene.trace() takes from 0 to 2 positional arguments but 3 were given"),
        (lambda: amalgam.load(), "load() missing 1 required positional argument: 'scene'"),
        (lambda: amalgam.load("builtin:demo", scene="builtin:line"), "load() got multiple values for argument 'scene'"),
        (lambda: amalgam.experiment_names(1), "experiment_names() takes 0 positional arguments but 1 was given"),
    ]
    for call, message in cases:
        with pytest.raises(TypeError) as e:
            call()
        assert one_line(e) == message


def test_wrong_types_are_one_line_type_errors(demo):
    cases = [
        ({"width": 8.0}, "Scene.render() argument 'width' must be int, not float"),
        ({"seed": True}, "Scene.render() argument 'seed' must be int, not bool"),
        ({"level": "2"}, "Scene.render() argument 'level' must be int or None, not str"),
        ({"footprint": "2"}, "Scene.render() argument 'footprint' must be a number or None, not str"),
        ({"renderer": 1}, "Scene.render() argument 'renderer' must be str, not int"),
        ({"progress": 1}, "Scene.render() argument 'progress' must be callable or None, not int"),
    ]
    for kwargs, message in cases:
        with pytest.raises(TypeError) as e:
            demo.render(**{"width": 8, "height": 8, "spp": 1, **kwargs})
        assert one_line(e) == message
    with pytest.raises(TypeError) as e:
        amalgam.load("builtin:demo", volumetric="yes")
    assert one_line(e) == "load() argument 'volumetric' must be bool, not str"
    # NumPy's integers and floats are ints and numbers, as Python's own functions take them.
    r = demo.render(width=np.int64(8), height=np.uint8(6), spp=np.int32(1), footprint=np.float32(2))
    assert r.image.shape == (6, 8, 3)


def test_values_out_of_range_are_one_line_value_errors(demo):
    cases = [
        ({"seed": -1}, "seed=-1: expected an integer in [0, 18446744073709551615]"),
        ({"seed": 2**64}, "seed=18446744073709551616: expected an integer in [0, 18446744073709551615]"),
        ({"width": 2**40}, "width=1099511627776: expected an integer in [1, 2147483647]"),
        ({"spp": 0}, "spp=0: expected an integer in [1, 2147483647]"),
        ({"threads": -2}, "threads=-2: expected an integer in [0, 2147483647]"),
        ({"level": -1}, "level=-1: expected an integer in [0, 2147483647]"),
    ]
    for kwargs, message in cases:
        with pytest.raises(ValueError) as e:
            demo.render(**{"width": 8, "height": 8, "spp": 1, **kwargs})
        assert one_line(e) == message
    with pytest.raises(ValueError) as e:
        demo.trace(seed=-1)
    assert one_line(e) == "seed=-1: expected an integer in [0, 18446744073709551615]"
    with pytest.raises(ValueError) as e:
        amalgam.experiment("expected", threads=-1)
    assert one_line(e) == "threads=-1: expected an integer in [0, 2147483647]"
    # The largest seed renders.
    assert demo.render(width=4, height=4, spp=1, seed=2**64 - 1).spp == 1


def test_load_names_keywords_not_cli_flags(cli, tmp_path):
    # Unknown parameter: a TypeError as for any unexpected keyword, listing the builtin's.
    with pytest.raises(TypeError) as e:
        amalgam.load("builtin:line", bogus=1)
    assert one_line(e) == ("load() got an unexpected keyword argument 'bogus' "
                           "(builtin:line's parameters: alpha, depth, lights, m, n)")
    with pytest.raises(TypeError) as e:
        amalgam.load(SCENES / "spheres.json", n=4)
    assert one_line(e) == ("load() got an unexpected keyword argument 'n' "
                           f"({SCENES / 'spheres.json'} takes no parameters)")
    # A value out of range: the keyword as written, never --set.
    with pytest.raises(ValueError) as e:
        amalgam.load("builtin:line", n=100)
    assert one_line(e) == "builtin:line: n=100: expected an integer in [2, 64]"
    with pytest.raises(ValueError) as e:
        amalgam.load("builtin:prisms", fill="lots")
    assert one_line(e) == "builtin:prisms: fill=lots: expected a number"
    with pytest.raises(ValueError) as e:
        amalgam.load("builtin:prisms", view="top")
    assert one_line(e) == "builtin:prisms: view=top: expected one of corner, front"
    # The CLI keeps its own words.
    p = subprocess.run([cli, "render", "builtin:line", "--set", "n=100", "--out", str(tmp_path / "x.pfm")],
                       capture_output=True, text=True)
    assert p.stderr.strip() == "amalgam: builtin:line: --set n=100: expected an integer in [2, 64]"


def test_signatures_for_help_and_inspect(demo):
    sig = inspect.signature(amalgam.load)
    assert list(sig.parameters)[:2] == ["scene", "camera"]
    assert sig.parameters["params"].kind is inspect.Parameter.VAR_KEYWORD
    render = inspect.signature(demo.render)
    assert render.parameters["seed"].default == 0
    assert render.parameters["seed"].kind is inspect.Parameter.KEYWORD_ONLY
    assert "self" not in render.parameters
    assert list(inspect.signature(amalgam.compare).parameters) == ["a", "b"]
    assert amalgam.load.__doc__.startswith("Loads, builds and bakes a scene")
