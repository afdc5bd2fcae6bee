"""skinmesh: quality meshes of molecular skin surfaces, and morphs.

numpy in and out: vertices (n, 3) float64, triangles (m, 3) int64,
per-vertex attributes in a dict of arrays, reports as dicts. See
docs/python.md in the repository.
"""
from ._skinmesh import (  # noqa: F401
    Error,
    Frame,
    InputError,
    Mesh,
    Morph,
    MovingBalls,
    VolumeMesh,
    __version__,
    complex,
    grade,
    interpolate,
    mesh,
    volume,
)

__all__ = ["Error", "Frame", "InputError", "Mesh", "Morph", "MovingBalls", "VolumeMesh", "__version__", "complex",
           "grade", "interpolate", "mesh", "volume"]
