"""amalgam.load(dict): a scene file's structure as a dict, read by the scene-file parser."""

import json
import pathlib

import numpy as np
import pytest

import amalgam

SCENES = pathlib.Path(__file__).resolve().parents[2] / "scenes"

SMALL = {
    "camera": {"position": [0, 1, 5], "look_at": [0, 0.5, 0], "vfov": 40},
    "lights": [{"type": "point", "position": [3, 4, 5], "intensity": [10, 10, 10]}],
    "materials": {"red": {"colour": [0.8, 0.1, 0.1]}},
    "spheres": [{"centre": [0, 0.5, 0], "radius": 0.5, "material": "red"}],
    "boxes": [{"min": [-2, -0.1, -2], "max": [2, 0, 2]}],
}

TRIANGLE_OBJ = "v -1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"


def test_dict_renders_as_the_file_does():
    # The same bits as the scene file: the dict goes through the same parser.
    doc = json.loads((SCENES / "spheres.json").read_text())
    from_file = amalgam.load(SCENES / "spheres.json").render(width=24, height=16, spp=2, seed=3)
    scene = amalgam.load(doc)
    from_dict = scene.render(width=24, height=16, spp=2, seed=3)
    assert np.array_equal(from_dict.image.view(np.uint32), from_file.image.view(np.uint32))
    assert from_dict.stats["tests"] == from_file.stats["tests"]
    assert scene.name == "the dict"
    # Tuples and NumPy values are JSON's lists and numbers; the keywords apply as for a file.
    small = dict(SMALL, spheres=[{"centre": np.array([0, 0.5, 0]), "radius": np.float32(0.5),
                                  "material": "red"}])
    small["camera"] = dict(SMALL["camera"], position=(0, 1, 5))
    a = amalgam.load(small, fov=30).render(width=8, height=8, spp=1)
    b = amalgam.load(SMALL, fov=30).render(width=8, height=8, spp=1)
    assert np.array_equal(a.image, b.image)


def test_dict_errors_name_the_dict():
    bad = dict(SMALL, spheres=[{"centre": [0, 0, 0], "radius": "big"}])
    with pytest.raises(ValueError) as e:
        amalgam.load(bad)
    assert str(e.value) == "the dict: /spheres/0/radius: expected a number, found a string"
    with pytest.raises(ValueError) as e:
        amalgam.load(dict(SMALL, colour=[1, 1, 1]))
    assert str(e.value) == ("the dict: /colour: unknown key (expected one of: camera, lights, "
                            "background, materials, meshes, spheres, boxes, triangles, instances)")
    with pytest.raises(ValueError) as e:
        amalgam.load(dict(SMALL, background=[float("nan"), 0, 0]))
    assert str(e.value) == "the dict: Out of range float values are not JSON compliant"
    with pytest.raises(TypeError) as e:
        amalgam.load(dict(SMALL, background={1, 2, 3}))
    assert str(e.value) == ("the dict: Object of type set is not JSON serializable "
                            "(a scene dict holds what a scene file does)")
    with pytest.raises(TypeError) as e:
        amalgam.load(SMALL, n=3)
    assert str(e.value) == "load() got an unexpected keyword argument 'n' (the dict takes no parameters)"
    with pytest.raises(ValueError) as e:
        amalgam.load(SMALL, volumetric=True)
    assert str(e.value).startswith("volumetric=True: the dict has no meshes")


def test_dict_mesh_paths_are_relative_to_the_current_directory(tmp_path, monkeypatch):
    (tmp_path / "tri.obj").write_text(TRIANGLE_OBJ)
    doc = dict(SMALL, meshes=[{"file": "tri.obj"}])
    monkeypatch.chdir(tmp_path)
    scene = amalgam.load(doc)
    assert scene.render(width=8, height=8, spp=1).stats["tests"]["total"] > 0
    # A pathlib.Path in the dict is its path.
    amalgam.load(dict(SMALL, meshes=[{"file": pathlib.Path("tri.obj")}]))
    monkeypatch.chdir(tmp_path.parent)
    with pytest.raises(ValueError) as e:
        amalgam.load(doc)
    assert str(e.value) == "the dict: /meshes/0/file: tri.obj: no such file"
    # The absolute path loads from anywhere.
    amalgam.load(dict(SMALL, meshes=[{"file": str(tmp_path / "tri.obj")}]))
