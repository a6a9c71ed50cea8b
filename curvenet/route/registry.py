"""One registry of surfacers: the functions that turn patches or strokes into a mesh.

A surfacer is a name, what it needs, and ``run(inp: SurfaceInput, options: dict) ->
MeshResult``:

- ``needs="patches"``: the network's curves and its oriented patch loops
  (``inp.curves``, ``inp.loops``, ``inp.crease_curves``); the pipeline snaps and finds
  patches first.
- ``needs="strokes"``: the labelled strokes (``inp.strokes``, ``inp.labels``) and, when
  it refines an earlier surface, ``inp.init_mesh``.
- ``needs="regions"``: a composite of a patch surfacer and a stroke surfacer (the
  hybrid route): what ``"patches"`` gets and ``inp.regions``, the regions of the
  network with their routes.

An optional ``check(options, settings)`` validates the surfacer's own options before
the pipeline does any work and raises :class:`~curvenet.core.errors.InvalidParameterError`
naming the bad one. Everything else a surfacer raises is an internal error.

Entries name their function as ``"module:function"`` (resolved on first use) or pass
it directly. The built-in entries (:mod:`curvenet.route.builtins`, registered when
:mod:`curvenet.route` is imported) import their backend inside the function, so the
registry imports neither backend, and never torch. Adding a surfacer is one function
and one :func:`register_surfacer` call.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from typing import Callable

from ..core.result import MeshResult
from ..core.errors import InvalidParameterError

__all__ = ["NEEDS", "SurfaceSettings", "SurfaceInput", "Surfacer", "register_surfacer",
           "unregister_surfacer", "get_surfacer", "surfacer_names", "check_option_names"]

#: What a surfacer may need: patch loops on the snapped network, the strokes, or patch
#: loops and the network's regions (a composite).
NEEDS = ("patches", "strokes", "regions")
#: Method names the pipeline reserves for its routes (see :func:`curvenet.surface`).
_RESERVED = ("auto", "classical")


@dataclass(frozen=True)
class SurfaceSettings:
    """Settings every surfacer may read (each uses those that apply to it).

    Attributes
    ----------
    crease_angle : float
        Degrees; a dihedral angle above it makes a shared curve a crease.
    subdiv, resolution : int or None
        Subdivision levels and samples per curve; None: the surfacer's default.
    quality : {"draft", "default", "paper"}
        Preset of the neural fits.
    device : str
        ``"cpu"`` or ``"cuda"`` (``"cuda:1"`` ...).
    seed : int
        Seed of every random choice.
    progress : bool
        Show progress bars.
    """

    crease_angle: float = 30.0
    subdiv: int | None = None
    resolution: int | None = None
    quality: str = "draft"
    device: str = "cpu"
    seed: int = 0
    progress: bool = False


@dataclass
class SurfaceInput:
    """What a surfacer is given (the fields its ``needs`` names are filled).

    Attributes
    ----------
    settings : SurfaceSettings
    curves : list of (m_i, 3) float64
        Network curves (``needs="patches"``).
    loops : list of list of (int, bool)
        Oriented patch loops: (curve index, traversed forward) (``needs="patches"``).
    holes : list of list of list of (int, bool)
        Per loop, the loops of its holes (``[]`` for a disc; an empty list: no
        patch has holes) (``needs="patches"``).
    crease_curves : list of int
        Curves labelled crease (``needs="patches"``).
    strokes : list of (n_i, 3) float64
        Boundary and crease strokes (``needs="strokes"``).
    labels : list of str
        One label per stroke (``needs="strokes"``).
    init_mesh : tuple of ((n, 3) float64, (f, 3) int64) or None
        A surface to refine (``needs="strokes"``, refinement only).
    anchors : tuple of ((m, 3) float64, (m, 3) float64) or None
        Points and unit normals of a surface the result must meet (``needs="strokes"``:
        the classical patches beside a hybrid fill,
        :func:`curvenet.route.hybrid.patch_anchors`).
    regions : list of curvenet.route.Region
        The regions of a per-region route, the patched one first (the composite
        ``"hybrid"`` surfacer; empty otherwise).
    """

    settings: SurfaceSettings = field(default_factory=SurfaceSettings)
    curves: list = field(default_factory=list)
    loops: list = field(default_factory=list)
    holes: list = field(default_factory=list)
    crease_curves: list = field(default_factory=list)
    strokes: list = field(default_factory=list)
    labels: list = field(default_factory=list)
    init_mesh: tuple | None = None
    anchors: tuple | None = None
    regions: list = field(default_factory=list)


def _resolve(ref):
    """A callable, or ``"module:function"`` imported now."""
    if not isinstance(ref, str):
        return ref
    module, _, name = ref.partition(":")
    return getattr(importlib.import_module(module), name)


@dataclass(frozen=True)
class Surfacer:
    """One registry entry (see :func:`register_surfacer`).

    Attributes
    ----------
    name : str
        Registry key; also a ``method`` of :func:`curvenet.surface` and ``--method``.
    run : callable or str
        ``run(inp: SurfaceInput, options: dict) -> MeshResult``, or ``"module:function"``.
    needs : {"patches", "strokes", "regions"}
    label : str
        The method name results carry (``SurfaceResult.method``) and the key of its
        timings and report in the pipeline result.
    check : callable, str or None
        ``check(options: dict, settings: SurfaceSettings) -> None``; raises
        ``InvalidParameterError`` for an unknown option or a value out of range.
    summary : str
        One line for ``--help``.
    """

    name: str
    run: Callable | str
    needs: str
    label: str
    check: Callable | str | None = None
    summary: str = ""

    def validate(self, options: dict | None, settings: SurfaceSettings) -> dict:
        """``options`` checked by the entry's ``check`` (before any work), as a new dict."""
        options = dict(options or {})
        if self.check is not None:
            _resolve(self.check)(options, settings)
        return options

    def __call__(self, inp: SurfaceInput, options: dict | None = None) -> MeshResult:
        """Run the surfacer; its result must be a :class:`~curvenet.core.MeshResult`."""
        res = _resolve(self.run)(inp, dict(options or {}))
        if not isinstance(res, MeshResult):
            raise TypeError(f"surfacer {self.name!r} returned {type(res).__name__}, "
                            f"not a MeshResult")
        return res


_REGISTRY: dict[str, Surfacer] = {}


def register_surfacer(name: str, run: Callable | str | None = None, *, needs: str,
                      label: str | None = None, check: Callable | str | None = None,
                      summary: str = "", replace: bool = False):
    """Add a surfacer to the registry.

    Parameters
    ----------
    name : str
        Registry key and ``method`` name (not ``"auto"`` or ``"classical"``).
    run : callable or str, optional
        ``run(inp: SurfaceInput, options: dict) -> MeshResult`` or ``"module:function"``
        (imported on first use). Omitted: returns a decorator that registers the
        function it decorates.
    needs : {"patches", "strokes", "regions"}
        What the pipeline prepares for it.
    label : str, optional
        Method name of its results (default ``name``).
    check : callable or str, optional
        ``check(options, settings)``: validates its options before any work.
    summary : str
        One line for ``--help``.
    replace : bool
        Allow replacing an entry of the same name.

    Returns
    -------
    Surfacer, or a decorator when ``run`` is omitted.

    Examples
    --------
    >>> @register_surfacer("hull", needs="strokes", summary="convex hull of the strokes")
    ... def hull(inp, options):
    ...     import numpy as np, trimesh
    ...     h = trimesh.convex.convex_hull(np.concatenate(inp.strokes))
    ...     return MeshResult(h.vertices, h.faces)
    >>> "hull" in surfacer_names("strokes")
    True
    >>> unregister_surfacer("hull").summary
    'convex hull of the strokes'
    """
    if run is None:
        def decorator(func):
            register_surfacer(name, func, needs=needs, label=label, check=check,
                              summary=summary, replace=replace)
            return func
        return decorator
    if needs not in NEEDS:
        raise InvalidParameterError(f"needs: {needs!r} is not one of {NEEDS}")
    if name in _RESERVED or not name:
        raise InvalidParameterError(f"name: {name!r} is reserved for a route of the pipeline")
    if name in _REGISTRY and not replace:
        raise InvalidParameterError(f"name: a surfacer {name!r} is already registered")
    entry = Surfacer(name, run, needs, label or name, check, summary)
    _REGISTRY[name] = entry
    return entry


def unregister_surfacer(name: str) -> Surfacer:
    """Remove a surfacer from the registry and return its entry."""
    entry = get_surfacer(name)
    del _REGISTRY[name]
    return entry


def get_surfacer(name: str, needs: str | None = None) -> Surfacer:
    """The entry called ``name`` (that needs ``needs``, when given).

    Raises
    ------
    InvalidParameterError
        No such surfacer, or one that needs something else.
    """
    entry = _REGISTRY.get(name)
    if entry is None or (needs is not None and entry.needs != needs):
        raise InvalidParameterError(f"surfacer: {name!r} is not one of {surfacer_names(needs)}")
    return entry


def surfacer_names(needs: str | None = None) -> tuple:
    """Registered names in registration order (only those that need ``needs``, if given)."""
    return tuple(n for n, s in _REGISTRY.items() if needs is None or s.needs == needs)


def check_option_names(surfacer: str, options: dict, valid) -> None:
    """Refuse options of ``surfacer`` that are not in ``valid`` (one line naming them)."""
    unknown = sorted(set(options) - set(valid))
    if unknown:
        raise InvalidParameterError(f"{surfacer}: unknown option(s) {unknown}; "
                                    f"valid: {sorted(valid)}")
