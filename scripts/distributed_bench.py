#!/usr/bin/env python3
"""Measures the Python package and whitted.distributed against the command line, in
one sitting (run with the virtual environment of scripts/test.sh):

    target/python-env/bin/python scripts/distributed_bench.py [--runs 5]

1. `whitted.render` against `whitted time` (both warm, in one process, render only) on
   hw3 at 1280x720, on 1 and 2 threads: the binding's cost.
2. A 3840x2160 `--quality default` render: `whitted render --threads 2` (a fresh
   process, as users run it) against `render_tiles` on a local cluster of 2 workers
   with 1 thread each, for 4, 16, 64 and 256 tiles: parallel efficiency (command-line
   time / cluster time) and the overhead per tile.
3. The same cluster job with one of 3 workers killed after the first tiles arrive: the
   extra seconds against the job without the kill.
Medians of --runs runs; prints one line per figure.
"""

import argparse
import os
import pathlib
import re
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time

import whitted
from whitted.distributed import render_tiles

REPO = pathlib.Path(__file__).resolve().parents[1]
BIN = os.environ.get("WHITTED_BIN", str(REPO / "target" / "release" / "whitted"))


def median_time(fn, runs):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def binding(runs):
    scene = whitted.hw3_scene()
    for threads in (1, 2):
        whitted.render(scene, threads=threads)  # warm-up: pools, pages
        py = median_time(lambda: whitted.render(scene, threads=threads), runs)
        line = subprocess.run(
            [BIN, "time", "--runs", str(runs), "--threads", str(threads)],
            capture_output=True, text=True, check=True,
        ).stdout
        cli = float(re.search(r"render_s=([0-9.]+)", line).group(1))
        print(f"binding threads={threads} python_s={py:.4f} cli_s={cli:.4f} ratio={py / cli:.3f}")


def start(*args):
    return subprocess.Popen([sys.executable, "-m", "dask", *args], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, start_new_session=True)


class Cluster:
    def __init__(self, workers):
        from distributed import Client

        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        self.address = f"tcp://127.0.0.1:{port}"
        self.processes = [start("scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard")]
        self.workers = [start("worker", self.address, "--nthreads", "1", "--no-nanny", "--no-dashboard")
                        for _ in range(workers)]
        self.processes += self.workers
        self.client = Client(self.address, timeout=60)
        self.client.wait_for_workers(workers, timeout=60)

    def close(self):
        self.client.close()
        for p in self.processes:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
                p.wait()


def distributed(runs):
    options = dict(width=3840, height=2160, quality="default")
    args = ["--width", "3840", "--height", "2160", "--quality", "default"]
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "x.png")
        cli = median_time(lambda: subprocess.run([BIN, "render", "--quiet", "--threads", "2", "-o", out, *args],
                                                 check=True), runs)
    print(f"cli threads=2 size=3840x2160 quality=default seconds={cli:.3f}")
    scene = whitted.hw3_scene()
    cluster = Cluster(2)
    try:
        render_tiles(cluster.client, scene, tiles=4, width=64, height=36)  # warm the workers
        for tiles in (4, 16, 64, 256):
            t = median_time(lambda: render_tiles(cluster.client, scene, tiles=tiles, **options), runs)
            print(f"cluster workers=2x1 tiles={tiles} seconds={t:.3f} efficiency={cli / t:.3f} "
                  f"overhead_per_tile_ms={(t - cli) / tiles * 1000:.1f}")
    finally:
        cluster.close()


def recovery(runs):
    options = dict(width=3840, height=2160, quality="default")
    scene = whitted.hw3_scene()
    plain, killed = [], []
    for _ in range(runs):
        for kill in (False, True):
            cluster = Cluster(3)
            try:
                render_tiles(cluster.client, scene, tiles=3, width=64, height=36)

                def on_tile(done, total, cluster=cluster, kill=kill):
                    if kill and done == 6:
                        os.killpg(cluster.workers[-1].pid, signal.SIGKILL)

                start = time.perf_counter()
                render_tiles(cluster.client, scene, tiles=48, on_tile=on_tile, **options)
                (killed if kill else plain).append(time.perf_counter() - start)
            finally:
                cluster.close()
    p, k = statistics.median(plain), statistics.median(killed)
    print(f"recovery workers=3x1 tiles=48 plain_s={p:.3f} killed_s={k:.3f} extra_s={k - p:.3f} "
          f"(3 workers doing the work of 2 after the kill: ideal extra about {p / 2:.3f} s at the kill's moment)")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--only", choices=["binding", "distributed", "recovery"])
    args = parser.parse_args()
    for name, fn in [("binding", binding), ("distributed", distributed), ("recovery", recovery)]:
        if args.only in (None, name):
            fn(args.runs)


if __name__ == "__main__":
    main()
