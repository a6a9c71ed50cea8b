"""The built-in surfacers: Catmull-Clark limit fitting, the soap-film baseline, the neural
fit, and the hybrid composite.

Each entry imports its backend inside its function, so importing this module imports
neither backend (and never torch). :mod:`curvenet.route` imports it, which registers
the entries.
"""

from __future__ import annotations

import inspect

from ..core.errors import InvalidParameterError
from ..core.result import MeshResult
from .hybrid import check_hybrid, surface_hybrid
from .registry import SurfaceInput, SurfaceSettings, check_option_names, register_surfacer

__all__: list = []


#: surface_loops arguments the pipeline fills from the network and the settings
_FROM_PIPELINE = ("crease_curves", "crease_angle")
#: surface_boundaries' own options beside those of surface_loops
_BOUNDARY_OPTIONS = ("analytic_tol", "denoise")


def _loops_kwargs(options: dict, settings: SurfaceSettings) -> dict:
    """Options with the explicit ``subdiv`` / ``resolution`` settings on top."""
    kw = dict(options)
    if settings.subdiv is not None:
        kw["subdiv"] = settings.subdiv
    if settings.resolution is not None:
        kw["resolution"] = settings.resolution
    return kw


def _check_catmull_clark(options: dict, settings: SurfaceSettings) -> None:
    from ..surfacing import check_loops_options, surface_loops
    params = inspect.signature(surface_loops).parameters.values()
    check_option_names("catmull-clark", options, [p.name for p in params if p.kind is p.KEYWORD_ONLY
                                            and p.name not in _FROM_PIPELINE]
                       + list(_BOUNDARY_OPTIONS))
    tol = options.get("analytic_tol", 0.0)
    if tol is not None and not (isinstance(tol, (int, float)) and 0 <= tol < 1):
        raise InvalidParameterError(f"analytic_tol: expected a fraction in [0, 1) or None, "
                                    f"got {tol!r}")
    check_loops_options(**_loops_kwargs(options, settings))


def _boundaries(inp: SurfaceInput) -> list:
    """Per patch ``[outer loop, hole loops...]``."""
    holes = inp.holes or [[] for _ in inp.loops]
    return [[lp, *h] for lp, h in zip(inp.loops, holes)]


def _catmull_clark(inp: SurfaceInput, options: dict) -> MeshResult:
    from ..surfacing.sectors import surface_boundaries
    return surface_boundaries(inp.curves, _boundaries(inp), crease_curves=inp.crease_curves,
                              crease_angle=inp.settings.crease_angle,
                              **_loops_kwargs(options, inp.settings))


def _check_soapfilm(options: dict, settings: SurfaceSettings) -> None:
    check_option_names("soapfilm", options, ["resolution"])
    res = options.get("resolution", 1)
    try:
        good = int(res) >= 1
    except (TypeError, ValueError):     # not a number at all
        good = False
    if not good:
        raise InvalidParameterError(f"resolution: expected >= 1, got {res!r}")


def _soapfilm(inp: SurfaceInput, options: dict) -> MeshResult:
    from ..surfacing import soapfilm_loops
    from ..surfacing.sectors import split_boundaries
    curves, loops, _, _ = split_boundaries(inp.curves, _boundaries(inp))
    return soapfilm_loops(curves, loops, **options)


def _check_neural(options: dict, settings: SurfaceSettings) -> None:
    """Flow settings (:class:`neural.presets.FlowConfig` fields) and, under ``"creases"``,
    the crease refit's (:class:`neural.crease_refit.CreaseConfig` fields)."""
    from ..neural.presets import get_config
    flow = dict(options)
    creases = flow.pop("creases", None)
    try:
        get_config(settings.quality, **flow)
    except ValueError as err:
        raise InvalidParameterError(f"neural_options: {err}") from err
    if creases:
        from ..neural.crease_refit import crease_config
        try:
            crease_config(settings.quality, creases)
        except ValueError as err:
            raise InvalidParameterError(f"crease_options: {err}") from err


def _neural(inp: SurfaceInput, options: dict) -> MeshResult:
    """Flow-aligned implicit fit (part by part, :mod:`neural.parts`), then the crease refit
    when some strokes are creases."""
    from ..neural import crease_refit, parts
    s = inp.settings
    _check_device(s.device)
    flow_options = dict(options)
    crease_options = flow_options.pop("creases", None) or {}
    res = parts.fit_parts(inp.strokes, labels=inp.labels, quality=s.quality,
                          device=s.device, seed=s.seed, init_mesh=inp.init_mesh,
                          anchors=inp.anchors, progress=s.progress, **flow_options)
    verts, faces, report = res.vertices, res.faces, dict(res.report)
    if "crease" in inp.labels and not report.get("interrupted"):
        cres = crease_refit.crease_refine(verts, faces, inp.strokes, inp.labels, quality=s.quality,
                                     device=s.device, seed=s.seed, progress=s.progress,
                                     **crease_options)
        verts, faces = cres.vertices, cres.faces
        report["creases"] = dict(cres.report)
    return MeshResult(verts, faces, report)


def _check_device(device: str) -> None:
    """A CUDA device asked for on a machine without one is bad input, not a failure."""
    if str(device).startswith("cuda"):
        import torch
        if not torch.cuda.is_available():
            raise InvalidParameterError(f"device: {device!r} requested but CUDA is not "
                                        f"available")


register_surfacer("catmull-clark", _catmull_clark, needs="patches", label="classical",
                  check=_check_catmull_clark,
                  summary="Coons patches -> Catmull-Clark limit surface fitted to the curves")
register_surfacer("soapfilm", _soapfilm, needs="patches", check=_check_soapfilm,
                  summary="soap-film baseline, a minimal surface per patch")
register_surfacer("neural", _neural, needs="strokes", check=_check_neural,
                  summary="flow-aligned implicit surface fitted to the strokes, with torch")
register_surfacer("hybrid", surface_hybrid, needs="regions", check=check_hybrid,
                  summary="patches, and a neural fill for each surface-like region no patch "
                          "covers (auto's per-region route)")
