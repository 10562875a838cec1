"""lidarloop: loop closure detection in sequences of 3-D LiDAR scans.

The C++ library through pybind11 (the extension lidarloop._lidarloop); docs/python.md describes
the API. Every name is importable from `lidarloop` directly; the area modules below only group
them (python/README.md).
"""

from ._lidarloop import __version__
from . import app, descriptors, errors, eval, io, pipeline, posegraph, registration, sim
from .app import *  # noqa: F401,F403
from .descriptors import *  # noqa: F401,F403
from .errors import *  # noqa: F401,F403
from .eval import *  # noqa: F401,F403
from .io import *  # noqa: F401,F403
from .pipeline import *  # noqa: F401,F403
from .posegraph import *  # noqa: F401,F403
from .registration import *  # noqa: F401,F403
from .sim import *  # noqa: F401,F403

__all__ = ["__version__"] + [
    name
    for area in (app, descriptors, errors, eval, io, pipeline, posegraph, registration, sim)
    for name in area.__all__
]
