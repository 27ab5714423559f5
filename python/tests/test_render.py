"""The module `whitted` (SPEC §7) against the command line and against its contract:
the same bytes as `whitted render`, errors with positions, pickling, the GIL released,
Ctrl-C honoured."""

import os
import pickle
import signal
import subprocess
import threading
import time

import numpy as np
import pytest

import whitted

from conftest import REPO


@pytest.mark.parametrize(
    "options, args",
    [
        ({}, []),
        ({"spp": 4}, ["--spp", "4"]),
        ({"width": 320, "height": 200, "seed": 7, "spp": 2}, ["--width", "320", "--height", "200", "--seed", "7", "--spp", "2"]),
        ({"region": (100, 50, 300, 200)}, ["--region", "100,50,300,200"]),
        ({"tile": (5, 16)}, ["--tile", "5/16"]),
        ({"width": 160, "height": 90, "reference": True}, ["--width", "160", "--height", "90", "--reference"]),
        ({"width": 320, "height": 180, "quality": "default"}, ["--width", "320", "--height", "180", "--quality", "default"]),
        ({"depth": 0, "width": 64, "height": 36}, ["--depth", "0", "--width", "64", "--height", "36"]),
    ],
)
def test_render_gives_the_bytes_of_the_command_line(cli, options, args):
    ours = whitted.render(whitted.hw3_scene(), **options)
    theirs = cli(*args)
    assert ours.dtype == np.uint8 and ours.shape == theirs.shape
    assert np.array_equal(ours, theirs)


def test_scene_files_render_as_on_the_command_line(cli):
    path = REPO / "assets" / "scenes" / "stress" / "camera-in-glass.toml"
    scene = whitted.load_scene(path)
    assert scene.name == "camera-in-glass"
    assert np.array_equal(whitted.render(scene, width=200, height=120), cli("--width", "200", "--height", "120", scene=path))


def test_render_linear_holds_what_exr_holds(whitted_bin, tmp_path):
    scene = whitted.hw3_scene()
    lin = whitted.render_linear(scene, width=160, height=90, spp=4)
    assert lin.dtype == np.float32 and lin.shape == (90, 160, 3)
    ours = tmp_path / "ours.exr"
    whitted.write_image(ours, lin)
    theirs = tmp_path / "theirs.exr"
    subprocess.run([whitted_bin, "render", "--quiet", "--width", "160", "--height", "90", "--spp", "4", "-o", str(theirs)], check=True)
    assert ours.read_bytes() == theirs.read_bytes()
    # And the 8-bit image is its rounding: round(clamp(c) * 255).
    expected = np.rint(np.clip(lin, 0.0, 1.0) * 255.0).astype(np.uint8)
    assert np.array_equal(whitted.render(scene, width=160, height=90, spp=4), expected)


def test_write_image_writes_what_the_command_line_writes(whitted_bin, tmp_path):
    img = whitted.render(whitted.hw3_scene(), width=64, height=36)
    for ext in ["png", "ppm", "bmp", "jpg"]:
        ours = tmp_path / f"ours.{ext}"
        whitted.write_image(ours, img)
        theirs = tmp_path / f"theirs.{ext}"
        subprocess.run([whitted_bin, "render", "--quiet", "--width", "64", "--height", "36", "-o", str(theirs)], check=True)
        assert ours.read_bytes() == theirs.read_bytes(), ext
    with pytest.raises(ValueError, match="unknown image format"):
        whitted.write_image(tmp_path / "x.gif", img)
    with pytest.raises(ValueError, match="shape"):
        whitted.write_image(tmp_path / "x.png", img[:, :, :2].copy())


def test_scene_errors_say_where():
    with pytest.raises(whitted.SceneError) as info:
        whitted.parse_scene("[image]\nwidth = -1\n", "bad.toml")
    e = info.value
    assert isinstance(e, ValueError)
    assert (e.path, e.line, e.column) == ("bad.toml", 2, 9)
    assert str(e).startswith("bad.toml:2:9: ")
    with pytest.raises(whitted.SceneError) as info:
        whitted.parse_scene("[[sphere]]\ncenter = [0, 0, -1]\nradius = 0\n")
    assert (info.value.path, info.value.line) == ("<string>", 3)
    assert "radius must be > 0" in info.value.message
    with pytest.raises(whitted.SceneError) as info:
        whitted.load_scene("/nonexistent/scene.toml")
    assert (info.value.line, info.value.column) == (None, None)
    assert "cannot read scene file" in str(info.value)


@pytest.mark.parametrize(
    "options, needle",
    [
        ({"spp": 0}, "spp 0 is out of range"),
        ({"depth": 65}, "max_depth 65 is out of range"),
        ({"quality": "ultra"}, 'unknown quality "ultra"'),
        ({"region": (1200, 700, 200, 200)}, "does not fit in the 1280x720 image"),
        ({"tile": (4, 4)}, "tile 4/4 does not exist"),
        ({"tile": (0, 2), "region": (0, 0, 1, 1)}, "not both"),
        ({"threads": 0}, "threads must be at least 1"),
        ({"width": 0}, "is empty"),
    ],
)
def test_bad_options_raise_value_error(options, needle):
    with pytest.raises(ValueError, match=needle):
        whitted.render(whitted.hw3_scene(), **options)


def test_wrong_types_raise_type_error():
    with pytest.raises(TypeError):
        whitted.render(whitted.hw3_scene(), width="wide")
    with pytest.raises(OverflowError):
        whitted.render(whitted.hw3_scene(), width=-5)
    with pytest.raises(TypeError, match="unexpected keyword argument 'sppp'"):
        whitted.render(whitted.hw3_scene(), sppp=4)
    # None means "not given", as in the signatures.
    assert whitted.plan(whitted.hw3_scene(), width=None, region=None) == ((1280, 720), (0, 0, 1280, 720))


def test_scenes_pickle_as_their_text():
    scene = whitted.parse_scene(
        "[camera]\nlook_from = [0, 1, 2]\nlook_at = [0, 0, -1]\n[image]\nwidth = 96\nheight = 64\n"
        "[[sphere]]\ncenter = [0, 0, -1]\nradius = 0.5\nreflect = 0.3\n",
        "mine.toml",
    )
    again = pickle.loads(pickle.dumps(scene))
    assert isinstance(again, whitted.Scene)
    assert (again.name, again.spheres, again.to_toml()) == (scene.name, 1, scene.to_toml())
    assert np.array_equal(whitted.render(again), whitted.render(scene))
    assert whitted.render(again).shape == (64, 96, 3)


def test_the_gil_is_released_while_rendering():
    ticks = 0
    stop = threading.Event()

    def count():
        nonlocal ticks
        while not stop.is_set():
            ticks += 1
            time.sleep(0.001)

    counter = threading.Thread(target=count)
    counter.start()
    start = time.perf_counter()
    whitted.render(whitted.hw3_scene(), width=1280, height=720, spp=16, threads=1)
    elapsed = time.perf_counter() - start
    stop.set()
    counter.join()
    # With the GIL held the counter could not run at all during the render.
    assert elapsed > 0.2, "the render is too short to tell"
    assert ticks > 0.3 * elapsed / 0.001 * 0.5, (ticks, elapsed)


def test_ctrl_c_stops_a_render_within_a_fraction_of_a_second():
    # Python's own Ctrl-C handler, whatever an earlier test's library left installed:
    # one that does not raise would let the render run to its end.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        ctrl_c_stops_a_render()
    finally:
        signal.signal(signal.SIGINT, previous)


def ctrl_c_stops_a_render():
    scene = whitted.hw3_scene()
    start = time.perf_counter()
    whitted.render(scene, width=320, height=180, spp=64, threads=1)
    per_pixel = (time.perf_counter() - start) / (320 * 180)
    # A render of about 20 s, interrupted after 0.3 s.
    pixels = int(20.0 / per_pixel)
    side = int((pixels * 16 / 9) ** 0.5)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        whitted.render(scene, width=side, height=side * 9 // 16, spp=64, threads=1)
    stopped = time.perf_counter() - start
    timer.join()
    assert stopped < 0.3 + 0.5, f"the render went on for {stopped - 0.3:.2f} s after Ctrl-C"


def turntable_text(frames: int) -> str:
    body = (REPO / "assets" / "scenes" / "hw3.toml").read_text()
    camera = '[camera]\nlook_from = [0, 0.5, 1]\nlook_at = [0, -0.2, -2]\nup = [0, 1, 0]\nvfov = 50\n\n'
    return camera + body + f"\n[animation]\nframes = {frames}\norbit = 360\n"


def test_frames_render_as_the_command_line_renders_them(cli, tmp_path):
    path = tmp_path / "spin.toml"
    path.write_text(turntable_text(8))
    scene = whitted.load_scene(path)
    assert (scene.frames, scene.fps) == (8, 24.0)
    for k in (0, 3, 7):
        ours = whitted.render(scene, frame=k, width=160, height=90)
        assert np.array_equal(ours, cli("--width", "160", "--height", "90", "--frame", str(k), scene=path)), k
    assert not np.array_equal(whitted.render(scene, frame=3, width=160, height=90),
                              whitted.render(scene, frame=0, width=160, height=90))
    with pytest.raises(ValueError, match="frame 8 does not exist"):
        whitted.render(scene, frame=8)
    # A still scene has one frame: frame 0 is the image.
    assert np.array_equal(whitted.render(whitted.hw3_scene(), frame=0, width=64, height=36),
                          whitted.render(whitted.hw3_scene(), width=64, height=36))


def test_srgb_bytes_are_the_command_line_srgb_bytes(cli):
    ours = whitted.render(whitted.hw3_scene(), width=160, height=90, encoding="srgb")
    assert np.array_equal(ours, cli("--width", "160", "--height", "90", "--encoding", "srgb"))
    linear = whitted.render_linear(whitted.hw3_scene(), width=160, height=90)
    c = np.clip(linear.astype(np.float64), 0.0, 1.0)
    curve = np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)
    assert np.array_equal(ours, np.rint(curve * 255.0).astype(np.uint8))
    with pytest.raises(ValueError, match='unknown encoding "gamma"'):
        whitted.render(whitted.hw3_scene(), encoding="gamma")
