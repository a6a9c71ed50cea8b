"""curvenet: 3D sketches and curve networks to surfaces.

The public API is re-exported here. The stages live in subpackages, imported on
first use so that ``import curvenet`` is fast and never imports torch:

* :mod:`curvenet.core` primitives, tolerances, errors, the mesh result;
* :mod:`curvenet.model` sketches, curve networks, patch sets;
* :mod:`curvenet.io` readers and writers of every format;
* :mod:`curvenet.snap` strokes to a curve network;
* :mod:`curvenet.cycles` curve network to patches, the review session;
* :mod:`curvenet.route` the route decision and the surfacer registry;
* :mod:`curvenet.evaluate` scores against references and strokes;
* :mod:`curvenet.cad`, :mod:`curvenet.view`, :mod:`curvenet.batch`,
  :mod:`curvenet.datasets` CAD output, pictures, batches, known-truth inputs;
* :mod:`curvenet.surfacing`, :mod:`curvenet.neural` the two surfacing backends;
* :mod:`curvenet.pipeline` and :mod:`curvenet.cli` on top.

Snapping is ``curvenet.snap.snap(sketch)`` (a name shared by a subpackage cannot be
re-exported safely: importing the subpackage rebinds the package attribute).
"""

from importlib import import_module as _import_module

from .core.errors import (CurvenetError, InvalidParameterError, MissingDependencyError,
                          NetworkError, SketchFormatError)
from .model import LABELS, CurveNetwork, Edge, Patch, PatchSet, Sketch

__version__ = "0.1.0"

# name -> module that defines it (imported lazily, see __getattr__)
_LAZY = {
    "read_sketch": "io",
    "write_sketch": "io",
    "write_network_obj": "io",
    "SnapOptions": "snap",
    "find_patches": "cycles",
    "PatchSession": "cycles.session",
    "surface": "pipeline",
    "patches": "pipeline",
    "SurfaceResult": "pipeline",
    "evaluate_mesh": "evaluate",
    "render_preview": "view",
    "MeshResult": "core.result",
    "register_surfacer": "route",
    "unregister_surfacer": "route",
    "surfacer_names": "route",
    "SurfaceInput": "route",
    "RouteDecision": "route",
    "read_patches": "io",
    "write_patches": "io",
    "write_network": "io",
}
#: earlier names of public functions: alias -> (module, name)
_ALIASES = {"load_network_file": ("io", "read_patches"), "save_network": ("io", "write_network"),
            "save_patchset": ("io", "write_patches")}
#: the stages, imported on first use (``curvenet.snap`` is the subpackage; its function is
#: ``curvenet.snap.snap``)
_SUBPACKAGES = ("core", "model", "io", "snap", "cycles", "route", "evaluate", "cad", "view",
                "review", "batch", "datasets", "surfacing", "neural", "pipeline", "cli")
#: modules that moved into a subpackage, reachable under their old name
_MOVED_MODULES = {"shapes": "datasets.shapes", "redraw": "datasets.redraw"}

__all__ = [
    "CurvenetError", "SketchFormatError", "InvalidParameterError", "NetworkError",
    "MissingDependencyError", "Sketch", "LABELS", "CurveNetwork", "Edge", "Patch", "PatchSet",
    *_LAZY,
]


def __getattr__(name):
    if name in _LAZY:
        value = getattr(_import_module(f".{_LAZY[name]}", __name__), name)
    elif name in _ALIASES:
        module, new = _ALIASES[name]
        value = getattr(_import_module(f".{module}", __name__), new)
    elif name in _MOVED_MODULES:
        value = _import_module(f".{_MOVED_MODULES[name]}", __name__)
    elif name in _SUBPACKAGES:
        value = _import_module(f".{name}", __name__)
    else:
        raise AttributeError(f"module 'curvenet' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    """What ``dir(curvenet)`` and tab completion show: the public names and the subpackages."""
    return sorted(__all__ + ["__version__", *_SUBPACKAGES])
