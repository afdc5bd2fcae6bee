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
    write_frames,
)



def _frames(self, times):
    """Yield the frame at each t of `times` (increasing, after the current one), one mesh carried through."""
    for t in times:
        yield self.advance_to(t)


def _moving_frames(self, coordinates, times=None):
    """Yield the frame of each (n, 3) array of `coordinates` (an MD trajectory's positions), ids kept."""
    for k, centres in enumerate(coordinates):
        yield self.advance_to(centres, float(k if times is None else times[k]))


Morph.frames = _frames
MovingBalls.frames = _moving_frames

__all__ = ["Error", "Frame", "InputError", "Mesh", "Morph", "MovingBalls", "VolumeMesh", "__version__", "complex",
           "grade", "interpolate", "mesh", "volume", "write_frames"]
