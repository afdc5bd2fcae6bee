"""skinmesh: quality meshes of molecular skin surfaces, and morphs.

numpy in and out: vertices (n, 3) float64, triangles (m, 3) int64,
per-vertex attributes in a dict of arrays, reports as dicts. See
docs/python.md in the repository.
"""
import numpy as np

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
    """Yield the frame of each (n, 3) array of `coordinates` (an MD trajectory's positions), ids kept.

    Each call is told the next centres, so the engine prepares that frame beside this one; each array is
    copied first, as a trajectory reader may refill one array in place.
    """
    frames = (np.array(c, dtype=np.float64) for c in coordinates)
    current = next(frames, None)
    k = 0
    while current is not None:
        following = next(frames, None)
        yield self.advance_to(current, float(k if times is None else times[k]), next=following)
        current = following
        k += 1


Morph.frames = _frames
MovingBalls.frames = _moving_frames

__all__ = ["Error", "Frame", "InputError", "Mesh", "Morph", "MovingBalls", "VolumeMesh", "__version__", "complex",
           "grade", "interpolate", "mesh", "volume", "write_frames"]
