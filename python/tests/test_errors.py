"""Errors: ValueError for bad input with the CLI's one-line message; KeyboardInterrupt."""

import os
import pydoc
import signal
import subprocess
import threading

import numpy as np
import pytest

import amalgam


def cli_message(cli, *args):
    """The CLI's one-line error message (after "amalgam: ") and its exit status."""
    p = subprocess.run([cli, *args], capture_output=True, text=True)
    return p.stderr.strip().removeprefix("amalgam: "), p.returncode


def test_unknown_builtin_is_value_error(cli, tmp_path):
    message, status = cli_message(cli, "render", "builtin:nope", "--out", str(tmp_path / "x.pfm"))
    assert status == 2
    with pytest.raises(ValueError) as e:
        amalgam.load("builtin:nope")
    assert str(e.value) == message


def test_unknown_parameter_is_type_error(cli, tmp_path):
    # The CLI names its --set; Python raises what it raises for any unexpected keyword
    # argument, listing the parameters the builtin has.
    message, status = cli_message(cli, "render", "builtin:demo", "--set", "bogus=1", "--out",
                                  str(tmp_path / "x.pfm"))
    assert status == 2 and message == "builtin:demo: unknown parameter 'bogus' in --set"
    with pytest.raises(TypeError) as e:
        amalgam.load("builtin:demo", bogus=1)
    assert str(e.value) == ("load() got an unexpected keyword argument 'bogus' "
                            "(builtin:demo's parameters: depth, fill, leaf, lights, split, view)")


def test_level_beyond_lmax_is_value_error(cli, demo, tmp_path):
    message, status = cli_message(cli, "render", "builtin:demo", "--level", "99", "--out",
                                  str(tmp_path / "x.pfm"))
    assert status == 2
    with pytest.raises(ValueError) as e:
        demo.render(width=8, height=8, spp=1, level=99)
    # The same check and words; Python names the keyword where the CLI names the flag.
    assert "--level 99" in message
    assert str(e.value) == message.replace("--level 99", "level=99")


def test_booleans_are_not_integers(demo):
    # Python's bool is an int: width=True used to render one pixel wide. Refused as a float is.
    for keyword in ("width", "height", "spp", "seed", "threads", "level"):
        with pytest.raises(TypeError):
            demo.render(**{"width": 8, "height": 8, "spp": 1, keyword: True})
        with pytest.raises(TypeError):
            demo.render(**{"width": 8, "height": 8, "spp": 1, keyword: 1.0})
    for keyword in ("width", "height", "seed", "level"):
        with pytest.raises(TypeError):
            demo.trace(**{keyword: False})
    with pytest.raises(TypeError):
        amalgam.experiment("noise", threads=True)
    assert demo.render(width=8, height=8, spp=1, seed=1, threads=1, level=1).image.shape == (8, 8, 3)


def test_bad_options_are_value_errors(demo, tmp_path):
    with pytest.raises(ValueError, match="give one"):
        demo.render(width=8, height=8, level=1, footprint=2.0)
    with pytest.raises(ValueError, match="^renderer=fast: expected"):
        demo.render(width=8, height=8, renderer="fast")
    with pytest.raises(ValueError, match="^spp=0: expected"):
        demo.render(width=8, height=8, spp=0)
    with pytest.raises(ValueError, match="^renderer=traditional renders no amalgam: level="):
        demo.render(width=8, height=8, renderer="traditional", level=2)
    with pytest.raises(ValueError, match="^direction=: must not be the zero vector"):
        demo.trace(direction=[0, 0, 0])
    with pytest.raises(ValueError, match="^tracer=fast: expected amalgam or embree"):
        demo.render(width=8, height=8, tracer="fast")
    with pytest.raises(ValueError, match="same size"):
        amalgam.compare(np.zeros((2, 2, 3)), np.zeros((3, 2, 3)))
    with pytest.raises(ValueError, match="unknown"):
        amalgam.experiment("nope")
    missing = tmp_path / "missing.json"
    with pytest.raises(ValueError, match="missing.json"):
        amalgam.load(str(missing))


def test_keyboard_interrupt_stops_render(demo):
    # A render of minutes, interrupted by SIGINT after half a second. Meanwhile another Python
    # thread ticks every 10 ms: it can only run if the render released the GIL.
    ticks = []
    rendering = threading.Event()
    stop = threading.Event()

    def tick():
        while not stop.wait(0.01):
            if rendering.is_set():
                ticks.append(1)

    ticker = threading.Thread(target=tick)
    ticker.start()
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as e:
            rendering.set()
            demo.render(width=256, height=256, spp=5000, seed=1)
    finally:
        rendering.clear()
        stop.set()
        timer.cancel()
        ticker.join()
    assert len(ticks) >= 10  # about 50 in the half second: the GIL was free
    partial = e.value.partial
    assert partial is demo.last_result
    # Stopped early: 5000 samples would take minutes.
    assert partial.interrupted and partial.spp < partial.spp_requested == 5000
    if partial.spp > 0:
        assert partial.image.shape == (256, 256, 3)
        assert int(partial.tests.sum()) == partial.stats["tests"]["total"]
        # The completed samples are exactly those of an uninterrupted render of that many.
        again = demo.render(width=256, height=256, spp=partial.spp, seed=1)
        assert np.array_equal(again.image, partial.image)
    # The scene still renders afterwards.
    assert demo.render(width=8, height=8, spp=1).spp == 1


def test_help_shows_the_api():
    doc = amalgam.__doc__
    assert "load" in doc and "render" in doc
    assert "KeyboardInterrupt" in amalgam.Scene.render.__doc__
    # help() shows each function's signature (its text signature) above its docstring.
    assert pydoc.render_doc(amalgam.load, renderer=pydoc.plaintext).count("load(scene, *, camera=None") == 1
    assert "render(self, /, *, width=512" in pydoc.render_doc(amalgam.Scene, renderer=pydoc.plaintext)


def test_bad_view_keywords_are_value_errors(cli, tmp_path):
    message, status = cli_message(cli, "render", "builtin:demo", "--fov", "200", "--out",
                                  str(tmp_path / "x.pfm"))
    assert status == 2
    with pytest.raises(ValueError) as e:
        amalgam.load("builtin:demo", fov=200)
    # The CLI's check and words; Python names the keyword where the CLI names the flag.
    assert "--fov 200" in message
    message = message.replace("--fov 200", "fov=200")
    assert str(e.value) == message
    with pytest.raises(ValueError, match="^eye='"):
        amalgam.load("builtin:demo", eye=(1, 2))
    # The loader's view messages name keywords too, with the CLI's words.
    camera_message, _ = cli_message(cli, "render", "builtin:demo", "--camera", "nope", "--out",
                                    str(tmp_path / "x.pfm"))
    assert camera_message.startswith("--camera nope: ")
    with pytest.raises(ValueError) as e:
        amalgam.load("builtin:demo", camera="nope")
    expected = camera_message.replace("--camera nope", "camera=nope")
    for flag in ("eye", "look-at", "up", "fov"):
        expected = expected.replace("--" + flag, flag.replace("-", "_") + "=")
    assert str(e.value) == expected
    assert "--" not in str(e.value)
    scene = amalgam.load("builtin:demo")
    with pytest.raises(ValueError) as e:
        scene.render(width=4, height=4, spp=1, fov=200)
    assert str(e.value) == message
    with pytest.raises(ValueError, match="^up=: the up vector"):
        scene.render(width=4, height=4, spp=1, up=(0, 0, 1), eye=(0, 0, 3), look_at=(0, 0, 0))
    with pytest.raises(ValueError, match="^eye=/look_at=: the eye is at the look-at point"):
        scene.render(width=4, height=4, spp=1, eye=(1, 1, 1), look_at=(1, 1, 1))


def test_python_refuses_what_the_cli_refuses(cli, tmp_path):
    # Non-finite images: NaN compares false with everything, so an all-NaN pair came out as
    # SSIM 1 and max error 0; refused as by `amalgam compare`.
    nan = np.full((4, 4, 3), np.nan, dtype=np.float32)
    with pytest.raises(ValueError, match="^a: 16 of 16 pixels are not finite"):
        amalgam.compare(nan, nan)
    good = np.zeros((4, 4, 3), dtype=np.float32)
    with pytest.raises(ValueError, match="^b: 16 of 16 pixels are not finite"):
        amalgam.compare(good, nan)
    # A view vector beyond the range of scene coordinates, with the CLI's words.
    message, status = cli_message(cli, "render", "builtin:demo", "--eye", "1e13,0,0", "--out",
                                  str(tmp_path / "x.pfm"))
    assert status == 2 and "must be within [-1e12, 1e12]" in message
    with pytest.raises(ValueError, match=r"^eye='.*': each coordinate must be within \[-1e12"):
        amalgam.load("builtin:demo", eye=(1e13, 0, 0))
    # volumetric=True on a scene without meshes (a builtin): refused when loading, as the CLI
    # refuses --renderer volumetric on it.
    with pytest.raises(ValueError, match="^volumetric=True: builtin:demo has no meshes"):
        amalgam.load("builtin:demo", volumetric=True)
