"""Rendering on a Dask cluster (``dask.distributed``), SPEC §8.

Tiles and frames are deterministic, so the work farms out as plain Dask futures: the
scheduler balances uneven tiles, and a lost worker's tasks run again elsewhere.
Nothing here schedules work itself::

    from dask.distributed import Client
    from whitted.distributed import render_tiles
    client = Client("tcp://scheduler:8786")
    img = render_tiles(client, scene, tiles=64, width=7680, height=4320, quality="high")

Frames: ``render_frames(client, scene, "frames/f-%04d.png")``. From a shell:
``python -m whitted.distributed --scheduler ADDR SCENE -o FILE [--tiles N]
[--frames [K|A..B]] [render options]``.
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any, Callable, Iterable, Optional

import numpy as np

import whitted

#: Tiles per worker thread when ``tiles`` is not given: enough that a thread that drew
#: cheap tiles (sky) takes more while another works through the costly ones, few enough
#: that a tile's fixed cost (a task, a scene parse, the hierarchy build; about 4 ms)
#: stays small. On 2 single-thread workers, a 3840x2160 `quality="default"` render took
#: 1.99 s in 8 tiles, 1.72 s in 16, 1.75 s in 32 and 2.72 s in 256.
TILES_PER_THREAD = 8


def default_tiles(client: Any, width: int, height: int) -> int:
    """``TILES_PER_THREAD`` tiles for each thread of the cluster's workers, at most one
    tile per pixel."""
    threads = sum(client.nthreads().values()) or 1
    return max(1, min(TILES_PER_THREAD * threads, width * height))


def _worker_threads() -> Optional[int]:
    """The threads of the Dask worker this runs on (a render uses as many)."""
    try:
        from distributed import get_worker

        return get_worker().state.nthreads
    except (ImportError, ValueError, AttributeError):
        return None


def _render_tile(scene: whitted.Scene, index: int, count: int, options: dict) -> tuple:
    """One task: tile ``index`` of ``count``, with the worker's threads."""
    opts = dict(options)
    if opts.get("threads") is None:
        opts["threads"] = _worker_threads()
    linear = opts.pop("linear", False)
    draw = whitted.render_linear if linear else whitted.render
    region = whitted.plan(scene, tile=(index, count), **opts)[1]
    return region, draw(scene, tile=(index, count), **opts)


def render_tiles(
    client: Any,
    scene: whitted.Scene,
    tiles: Optional[int] = None,
    *,
    linear: bool = False,
    on_tile: Optional[Callable[[int, int], None]] = None,
    **options: Any,
) -> np.ndarray:
    """Renders ``scene`` in ``tiles`` tiles on the cluster of ``client`` and stitches
    them in memory: exactly ``whitted.render(scene, **options)`` (or ``render_linear``
    with ``linear=True``), byte for byte. ``options`` are ``render``'s keywords (not
    ``region`` or ``tile``). ``on_tile(done, total)`` is called as tiles arrive.
    Bad options raise ``ValueError`` before anything is sent; a failing task raises
    its error here."""
    if "region" in options or "tile" in options:
        raise ValueError("render_tiles renders the whole image: no region or tile")
    (width, height), _ = whitted.plan(scene, **options)
    count = tiles if tiles is not None else default_tiles(client, width, height)
    if count < 1:
        raise ValueError(f"tiles must be at least 1, got {count}")
    whitted.tile_region(count - 1, count, width, height)  # ValueError if they do not fit
    dtype = np.float32 if linear else np.uint8
    image = np.empty((height, width, 3), dtype=dtype)
    task_options = dict(options, linear=linear)
    jobs = [(i, count, task_options) for i in range(count)]
    for done, ((x, y, w, h), part) in enumerate(_as_they_finish(client, _render_tile, scene, jobs), 1):
        image[y : y + h, x : x + w] = part
        if on_tile is not None:
            on_tile(done, count)
    return image


def _as_they_finish(client: Any, task: Callable, scene: whitted.Scene, jobs: list) -> Iterable:
    """The results of ``task(scene, *job)`` for each job on the cluster, in the order
    they finish; a task's error is raised here, and then, or if the caller stops
    early, the tasks still queued are cancelled."""
    from distributed import as_completed

    # A key of its own (hash=False): a scattered value shared by key with an earlier
    # job would be released when that job's future goes, cancelling this job's tasks.
    scene_future = client.scatter(scene, broadcast=False, hash=False)
    futures = [client.submit(task, scene_future, *job, pure=False) for job in jobs]
    try:
        for future in as_completed(futures):
            yield future.result()
    except BaseException:
        client.cancel(futures)
        raise


def _render_frame(scene: whitted.Scene, k: int, options: dict) -> tuple:
    """One task: frame ``k``, with the worker's threads."""
    opts = dict(options)
    if opts.get("threads") is None:
        opts["threads"] = _worker_threads()
    return k, whitted.render(scene, frame=k, **opts)


def frame_numbers(scene: whitted.Scene, frames: Any = None) -> list:
    """The frames asked for: all of the scene's (``None``), one (an int), or any
    iterable of frame numbers (a ``range``, say); each must exist."""
    if frames is None:
        numbers = list(range(scene.frames))
    elif isinstance(frames, int):
        numbers = [frames]
    else:
        numbers = list(frames)
    bad = [k for k in numbers if not 0 <= k < scene.frames]
    if bad:
        raise ValueError(f"frame {bad[0]} does not exist: the scene has {scene.frames} frames")
    return numbers


def render_frames(
    client: Any,
    scene: whitted.Scene,
    pattern: str,
    frames: Any = None,
    *,
    on_frame: Optional[Callable[[int, int], None]] = None,
    **options: Any,
) -> list:
    """Renders frames of ``scene``'s animation on the cluster of ``client``, one task a
    frame, and writes each to ``pattern % k`` (e.g. ``"frames/f-%04d.png"``: the frame
    number in the whole sequence) as it arrives, atomically, the bytes of
    ``whitted render -o PATTERN --frame K``. ``frames``: all (``None``), one, or an
    iterable of frame numbers. Returns the paths in frame order. ``on_frame(done,
    total)`` is called as frames are written."""
    numbers = frame_numbers(scene, frames)
    if "frame" in options:
        raise ValueError("render_frames takes the frames as `frames`")
    whitted.plan(scene, **options)  # ValueError before anything is sent
    paths = {k: pattern % k for k in numbers}
    jobs = [(k, options) for k in numbers]
    for done, (k, image) in enumerate(_as_they_finish(client, _render_frame, scene, jobs), 1):
        whitted.write_image(paths[k], image)
        if on_frame is not None:
            on_frame(done, len(numbers))
    return [paths[k] for k in numbers]


def _parse_frames(text: str) -> range:
    """``K`` or ``A..B`` (end excluded), as the command line's ``--frame``."""
    start, sep, end = text.partition("..")
    try:
        return range(int(start), int(end)) if sep else range(int(start), int(start) + 1)
    except ValueError:
        raise argparse.ArgumentTypeError("expected a frame K or a range A..B") from None


def main(argv: Optional[Iterable[str]] = None) -> int:
    """``python -m whitted.distributed``: render a scene on a Dask cluster into a file."""
    parser = argparse.ArgumentParser(
        prog="python -m whitted.distributed",
        description="Render a whitted scene on a Dask cluster (tiles stitched in memory).",
    )
    parser.add_argument("--scheduler", required=True, help="the scheduler, e.g. tcp://host:8786")
    parser.add_argument("scene", help="a scene file (TOML), or 'hw3' for the built-in scene")
    parser.add_argument("-o", "--output", required=True, help="the image file (.png .ppm .bmp .jpg .exr)")
    parser.add_argument("--tiles", type=int, help="tiles (default: 8 per worker thread)")
    parser.add_argument(
        "--frames",
        nargs="?",
        const="all",
        metavar="K|A..B",
        help="render the animation's frames (all, or K, or A..B), one task a frame: "
        "-o is then a pattern such as f-%%04d.png",
    )
    parser.add_argument("--width", type=int)
    parser.add_argument("--height", type=int)
    parser.add_argument("--spp", type=int)
    parser.add_argument("--depth", type=int)
    parser.add_argument("--seed", type=int)
    parser.add_argument("--quality", choices=["draft", "default", "high", "reference"])
    parser.add_argument("--encoding", choices=["linear", "srgb"])
    parser.add_argument("--reference", action="store_true", help="the f64 reference tracer")
    parser.add_argument("--timeout", type=float, default=10.0, help="seconds to reach the scheduler")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    args = parser.parse_args(None if argv is None else list(argv))

    def fail(message: str) -> int:
        print(f"whitted: error: {message}", file=sys.stderr)
        return 1

    try:
        scene = whitted.hw3_scene() if args.scene == "hw3" else whitted.load_scene(args.scene)
        options = {
            k: v
            for k, v in vars(args).items()
            if k in ("width", "height", "spp", "depth", "seed", "quality", "encoding") and v is not None
        }
        if args.reference:
            options["reference"] = True
        whitted.plan(scene, **options)
        linear = os.path.splitext(args.output)[1].lower() == ".exr"
        frames = None
        if args.frames is not None:
            frames = frame_numbers(scene, None if args.frames == "all" else _parse_frames(args.frames))
            if "%" not in args.output:
                return fail(f"{args.output}: frames need a numbered pattern such as f-%04d.png")
    except (ValueError, argparse.ArgumentTypeError) as e:  # SceneError is a ValueError
        return fail(str(e))

    from distributed import Client

    try:
        client = Client(args.scheduler, timeout=args.timeout)
    except (OSError, TimeoutError) as e:
        return fail(f"cannot reach the Dask scheduler at {args.scheduler}: {e}")
    bar = None
    try:
        if not args.quiet and sys.stderr.isatty():
            from tqdm import tqdm

            unit = "frame" if frames is not None else "tile"
            bar = tqdm(total=len(frames) if frames is not None else args.tiles, unit=unit, file=sys.stderr)

        def progress(done: int, total: int) -> None:
            if bar is not None:
                bar.total = total
                bar.update(1)

        if frames is not None:
            render_frames(client, scene, args.output, frames, on_frame=progress, **options)
        else:
            image = render_tiles(client, scene, args.tiles, linear=linear, on_tile=progress, **options)
            whitted.write_image(args.output, image)
    except KeyboardInterrupt:
        return fail("interrupted: no file was written")
    except (ValueError, OSError) as e:
        return fail(str(e))
    finally:
        if bar is not None:
            bar.close()
        client.close()
    if not args.quiet:
        print(f"wrote {args.output}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
