"""Shared by the Python package's tests: the command-line binary they compare with."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def whitted_bin() -> str:
    """The `whitted` binary of this checkout (built by `cargo test --release`, or
    named by WHITTED_BIN)."""
    path = os.environ.get("WHITTED_BIN", str(REPO / "target" / "release" / "whitted"))
    if not os.access(path, os.X_OK):
        pytest.fail(f"no whitted binary at {path}: run `cargo build --release` first")
    return path


def read_ppm(path) -> np.ndarray:
    """A binary PPM (P6) as a uint8 array (H, W, 3), top row first."""
    data = pathlib.Path(path).read_bytes()
    magic, width, height, maxval, pixels = data.split(maxsplit=4)
    assert magic == b"P6" and maxval == b"255"
    w, h = int(width), int(height)
    return np.frombuffer(pixels, dtype=np.uint8).reshape(h, w, 3)


@pytest.fixture
def cli(whitted_bin, tmp_path):
    """Renders with the command line into a binary PPM and returns its pixels."""

    def run(*args: str, scene=None) -> np.ndarray:
        out = tmp_path / "cli.ppm"
        cmd = [whitted_bin, "render"] + ([str(scene)] if scene else [])
        cmd += ["--quiet", "--ppm-binary", "-o", str(out), *args]
        subprocess.run(cmd, check=True)
        return read_ppm(out)

    return run
