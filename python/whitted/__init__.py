"""whitted: a Whitted-style CPU ray tracer for scenes of spheres.

The same numbers as the ``whitted`` command line, as numpy arrays::

    import whitted
    scene = whitted.load_scene("assets/scenes/hw3.toml")  # or parse_scene(text), hw3_scene()
    img = whitted.render(scene, width=640, height=360)     # uint8 (H, W, 3), top row first
    lin = whitted.render_linear(scene, width=640, height=360)  # float32 (H, W, 3), linear

Renders release the GIL and stop on Ctrl-C (``KeyboardInterrupt``). A ``Scene`` pickles
as its TOML text. ``whitted.distributed`` renders tiles and frames on a Dask cluster.
"""

from ._whitted import (
    Scene,
    SceneError,
    hw3_scene,
    load_scene,
    parse_scene,
    plan,
    render,
    render_linear,
    tile_region,
    write_image,
)

__all__ = [
    "Scene",
    "SceneError",
    "hw3_scene",
    "load_scene",
    "parse_scene",
    "plan",
    "render",
    "render_linear",
    "tile_region",
    "write_image",
]
