"""Type stubs of the native module (see ``whitted``'s docstrings for the whole story)."""

import os
from typing import Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

Rect = Tuple[int, int, int, int]
PathLike = Union[str, "os.PathLike[str]"]

class SceneError(ValueError):
    """A scene that cannot be loaded, with where: ``path``, ``line``, ``column``
    (``None`` when the error concerns the whole file) and ``message``."""

    path: str
    line: Optional[int]
    column: Optional[int]
    message: str

class Scene:
    """A validated scene. Pickles as its TOML text."""

    @property
    def name(self) -> str:
        """A short name: the file's stem, or "hw3"."""
    @property
    def spheres(self) -> int:
        """How many spheres the scene holds."""
    @property
    def frames(self) -> int:
        """Frames of the scene's animation (1 for a still scene)."""
    @property
    def fps(self) -> float:
        """Frames a second of the scene's animation."""
    @property
    def lights(self) -> int:
        """How many point lights the scene holds."""
    def to_toml(self) -> str:
        """The scene as a scene file; ``parse_scene`` of it gives the scene back."""

def load_scene(path: PathLike) -> Scene:
    """Reads, parses and validates a scene file. Raises ``SceneError``."""

def parse_scene(text: str, path: str = "<string>") -> Scene:
    """Parses and validates scene text; ``path`` names it in errors."""

def hw3_scene(seed: int = 2020) -> Scene:
    """The built-in scene of the assignment, its 48 small balls drawn from ``seed``."""

def render(
    scene: Scene,
    *,
    width: Optional[int] = None,
    height: Optional[int] = None,
    spp: Optional[int] = None,
    depth: Optional[int] = None,
    seed: Optional[int] = None,
    quality: Optional[str] = None,
    encoding: Optional[str] = None,
    region: Optional[Rect] = None,
    tile: Optional[Tuple[int, int]] = None,
    frame: Optional[int] = None,
    threads: Optional[int] = None,
    reference: bool = False,
) -> npt.NDArray[np.uint8]:
    """Renders to 8-bit RGB, shape (height, width, 3), top row first: the bytes
    ``whitted render -o x.png`` writes with the same options. With ``region`` or
    ``tile``, only that rectangle; with ``frame``, that frame of the scene's
    animation; ``encoding`` "srgb" applies the sRGB curve to the bytes. Bad options
    raise ``ValueError``; the GIL is released while rendering and Ctrl-C raises
    ``KeyboardInterrupt``."""

def render_linear(
    scene: Scene,
    *,
    width: Optional[int] = None,
    height: Optional[int] = None,
    spp: Optional[int] = None,
    depth: Optional[int] = None,
    seed: Optional[int] = None,
    quality: Optional[str] = None,
    encoding: Optional[str] = None,
    region: Optional[Rect] = None,
    tile: Optional[Tuple[int, int]] = None,
    frame: Optional[int] = None,
    threads: Optional[int] = None,
    reference: bool = False,
) -> npt.NDArray[np.float32]:
    """Renders to linear RGB floats, shape (height, width, 3), top row first: the
    values an EXR file of ``whitted render`` holds."""

def plan(
    scene: Scene,
    *,
    width: Optional[int] = None,
    height: Optional[int] = None,
    spp: Optional[int] = None,
    depth: Optional[int] = None,
    seed: Optional[int] = None,
    quality: Optional[str] = None,
    encoding: Optional[str] = None,
    region: Optional[Rect] = None,
    tile: Optional[Tuple[int, int]] = None,
    frame: Optional[int] = None,
    threads: Optional[int] = None,
    reference: bool = False,
) -> Tuple[Tuple[int, int], Rect]:
    """``((width, height), (x, y, w, h))``: the whole image's size and the rectangle
    ``render`` with these options gives. Checks the options without rendering."""

def write_image(
    path: PathLike, image: npt.NDArray, *, ppm_binary: bool = False, encoding: str = "linear"
) -> None:
    """Writes a uint8 (8-bit formats) or float32 (linear; any format, .exr too) array
    of shape (height, width, 3) atomically, format by extension, as the command line;
    a float32 array's bytes are made in ``encoding``."""

def tile_region(index: int, count: int, width: int, height: int) -> Rect:
    """The rectangle of tile ``index`` of ``count`` over a width×height image."""
