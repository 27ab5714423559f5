"""`whitted.distributed` on a real Dask cluster on 127.0.0.1: a scheduler and three
single-thread workers started as processes, as on a real cluster. Tiles stitched in
memory equal the command line's image byte for byte, a worker killed mid-job costs
only its tasks, and failures are one clear error."""

import os
import signal
import socket
import subprocess
import sys
import time

import distributed
import numpy as np
import pytest

import whitted
from whitted.distributed import default_tiles, render_tiles

from conftest import read_ppm

WORKERS = 3


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start(*args: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "dask", *args],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )


def stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGTERM)
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()


@pytest.fixture(scope="module")
def cluster():
    """The scheduler's address, the worker processes, and a client."""
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    scheduler = start("scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard")
    workers = []
    client = None
    try:
        workers = [
            start("worker", address, "--nthreads", "1", "--nworkers", "1", "--no-nanny", "--no-dashboard")
            for _ in range(WORKERS)
        ]
        client = distributed.Client(address, timeout=60)
        client.wait_for_workers(WORKERS, timeout=60)
        yield address, workers, client
    finally:
        if client is not None:
            client.close()
        for p in workers + [scheduler]:
            stop(p)


def test_sixteen_tiles_equal_the_command_line(cluster, cli):
    _, _, client = cluster
    image = render_tiles(client, whitted.hw3_scene(), tiles=16, width=1280, height=720)
    assert image.dtype == np.uint8 and image.shape == (720, 1280, 3)
    assert np.array_equal(image, cli("--width", "1280", "--height", "720"))


def test_linear_tiles_equal_render_linear(cluster):
    _, _, client = cluster
    scene = whitted.hw3_scene()
    image = render_tiles(client, scene, tiles=5, linear=True, width=200, height=100, spp=4)
    assert image.dtype == np.float32
    assert np.array_equal(image, whitted.render_linear(scene, width=200, height=100, spp=4))


def test_the_default_tile_count_is_eight_a_worker_thread(cluster):
    _, _, client = cluster
    assert default_tiles(client, 1280, 720) == 8 * WORKERS
    assert default_tiles(client, 2, 3) == 6


def test_a_killed_worker_costs_only_its_tasks(cluster, cli):
    address, workers, client = cluster
    scene = whitted.hw3_scene()
    options = dict(width=1920, height=1080, quality="default")
    killed = []

    def kill_one(done, total):
        if done == 3 and not killed:
            victim = workers[-1]
            os.killpg(victim.pid, signal.SIGKILL)
            killed.append(victim.pid)

    image = render_tiles(client, scene, tiles=32, on_tile=kill_one, **options)
    assert killed, "the job ended before a worker could be killed"
    assert np.array_equal(image, cli("--width", "1920", "--height", "1080", "--quality", "default"))
    # The scheduler saw the loss.
    deadline = time.time() + 30
    while len(client.scheduler_info()["workers"]) != WORKERS - 1 and time.time() < deadline:
        time.sleep(0.2)
    assert len(client.scheduler_info()["workers"]) == WORKERS - 1


def test_bad_options_fail_before_anything_is_sent(cluster):
    _, _, client = cluster
    with pytest.raises(ValueError, match="spp 0"):
        render_tiles(client, whitted.hw3_scene(), tiles=4, spp=0)
    with pytest.raises(ValueError, match="does not exist"):
        render_tiles(client, whitted.hw3_scene(), tiles=10, width=3, height=3)
    with pytest.raises(ValueError, match="no region or tile"):
        render_tiles(client, whitted.hw3_scene(), tiles=4, region=(0, 0, 1, 1))


def test_the_command_writes_the_image(cluster, whitted_bin, tmp_path):
    address, _, _ = cluster
    out = tmp_path / "dist.ppm"
    run = subprocess.run(
        [sys.executable, "-m", "whitted.distributed", "--scheduler", address, "hw3", "-o", str(out),
         "--width", "320", "--height", "180", "--spp", "2", "--tiles", "6"],
        capture_output=True, text=True, timeout=120,
    )
    assert run.returncode == 0, run.stderr
    theirs = tmp_path / "cli.ppm"
    subprocess.run([whitted_bin, "render", "--quiet", "--width", "320", "--height", "180", "--spp", "2",
                    "-o", str(theirs)], check=True)
    assert out.read_bytes() == theirs.read_bytes()


def test_an_unreachable_scheduler_is_one_line_and_exit_1(tmp_path):
    out = tmp_path / "never.png"
    start = time.time()
    run = subprocess.run(
        [sys.executable, "-m", "whitted.distributed", "--scheduler", f"tcp://127.0.0.1:{free_port()}",
         "hw3", "-o", str(out), "--timeout", "2"],
        capture_output=True, text=True, timeout=60,
    )
    assert run.returncode == 1
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("whitted: error: cannot reach the Dask scheduler"), run.stderr
    assert not out.exists()
    assert time.time() - start < 30


def test_a_bad_scene_file_is_one_line_and_exit_1(tmp_path):
    scene = tmp_path / "bad.toml"
    scene.write_text("[[sphere]]\ncenter = [0, 0, -1]\nradius = -1\n")
    run = subprocess.run(
        [sys.executable, "-m", "whitted.distributed", "--scheduler", "tcp://127.0.0.1:1", str(scene),
         "-o", str(tmp_path / "x.png")],
        capture_output=True, text=True, timeout=60,
    )
    assert run.returncode == 1
    assert run.stderr.strip() == f"whitted: error: {scene}:3:10: sphere 1: radius must be > 0, got -1"


def test_a_turntable_on_the_cluster_equals_the_command_lines_frames(cluster, whitted_bin, tmp_path):
    from test_render import turntable_text
    from whitted.distributed import render_frames

    _, _, client = cluster
    path = tmp_path / "spin.toml"
    path.write_text(turntable_text(12))
    scene = whitted.load_scene(path)
    ours = tmp_path / "ours"
    ours.mkdir()
    written = render_frames(client, scene, str(ours / "f-%02d.png"), width=320, height=180)
    assert written == [str(ours / f"f-{k:02d}.png") for k in range(12)]
    theirs = tmp_path / "theirs"
    theirs.mkdir()
    subprocess.run([whitted_bin, "render", str(path), "--quiet", "--width", "320", "--height", "180",
                    "-o", str(theirs / "f-%02d.png")], check=True)
    for k in range(12):
        assert (ours / f"f-{k:02d}.png").read_bytes() == (theirs / f"f-{k:02d}.png").read_bytes(), k
    # A slice, as --frame A..B.
    again = render_frames(client, scene, str(ours / "g-%02d.png"), range(4, 6), width=320, height=180)
    assert again == [str(ours / "g-04.png"), str(ours / "g-05.png")]
    assert (ours / "g-05.png").read_bytes() == (theirs / "f-05.png").read_bytes()
    with pytest.raises(ValueError, match="frame 12 does not exist"):
        render_frames(client, scene, str(ours / "h-%02d.png"), 12)
