"""curvenet: 3D sketches and curve networks to surfaces.

The public API is re-exported here. Submodules are imported on first use, so
``import curvenet`` is fast and never imports torch. Snapping is
``curvenet.snap.snap(sketch)`` (a name shared by a submodule cannot be
re-exported safely: importing the submodule rebinds the package attribute).
"""

from __future__ import annotations

import importlib

from .errors import (CurvenetError, InvalidParameterError, MissingDependencyError,
                     NetworkError, SketchFormatError)
from .network import CurveNetwork, Edge
from .patchset import Patch, PatchSet, load_network_file, save_network, save_patchset
from .sketch import LABELS, Sketch

__version__ = "0.1.0"

# name -> submodule that defines it (imported lazily, see __getattr__)
_LAZY = {
    "read_sketch": "io",
    "write_sketch": "io",
    "write_network_obj": "io",
    "SnapOptions": "snap",
    "find_patches": "cycles",
    "PatchSession": "session",
    "surface": "pipeline",
    "patches": "pipeline",
    "SurfaceResult": "pipeline",
    "evaluate_mesh": "evaluate",
    "render_preview": "preview",
    "MeshResult": "core.result",
    "register_surfacer": "surfacers",
    "unregister_surfacer": "surfacers",
    "surfacer_names": "surfacers",
    "SurfaceInput": "surfacers",
    "RouteDecision": "route",
}

__all__ = [
    "CurvenetError", "SketchFormatError", "InvalidParameterError", "NetworkError",
    "MissingDependencyError", "Sketch", "LABELS", "CurveNetwork", "Edge", "Patch", "PatchSet",
    "load_network_file", "save_network", "save_patchset", *_LAZY,
]


def __getattr__(name):
    if name in _LAZY:
        module = importlib.import_module(f".{_LAZY[name]}", __name__)
        value = getattr(module, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'curvenet' has no attribute {name!r}")


def __dir__():
    """What ``dir(curvenet)`` and tab completion show: the lazy names too."""
    return sorted(set(globals()) | set(__all__))
