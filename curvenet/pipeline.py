"""One pipeline from a sketch file to a surface: snap, find patches, surface.

``surface(...)`` decides by itself (``method="auto"``) whether the classical
patch route (Coons -> Catmull-Clark limit fit, :mod:`curvenet.surfacing`), the neural
route (flow-aligned implicit, :mod:`curvenet.neural`) or the hybrid route (patches and
a neural fill per region) serves the sketch better, and says why in
``SurfaceResult.decision`` (a :class:`~curvenet.route.RouteDecision`; its sentence is
``SurfaceResult.diagnostics["decision"]``). The surfacers themselves come from the
registry of :mod:`curvenet.route`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .cad.export import CAD_FORMATS
from .core.errors import CurvenetError, InvalidParameterError
from .core.fidelity import sketch_fidelity, stroke_fidelity
from .core.result import MeshResult
from .evaluate.topology import surface_topology
from .io.source import check_patches_match, load_source
from .io.meshes import MESH_FORMATS, write_mesh, write_routed
from .model.network import CurveNetwork
from .model.patchset import PatchSet
from .model.sketch import Sketch
from .route import (AUTO_MIN_COVERAGE, Region, Route, RouteDecision, SurfaceInput,
                    SurfaceSettings, Surfacer, coverage, get_surfacer, region_route,
                    surfacer_names)
from .route.check import judge_patches, wall_area
from .route.regions import plan_regions
from .route.wires import stroke_wires

__all__ = ["SurfaceResult", "surface", "patches", "load_source", "MESH_FORMATS", "CAD_FORMATS",
           "AUTO_MIN_COVERAGE", "write_mesh", "export_cad"]

#: methods that name a route; every registered surfacer name is a method too
METHODS = ("auto", "classical")
QUALITIES = ("draft", "default", "paper")
#: the surfacer of the neural route (auto's fallback, and ``refine``)
STROKE_SURFACER = "neural"
#: the composite surfacer of the hybrid route (patches, and a neural fill per region)
REGION_SURFACER = "hybrid"


@dataclass
class SurfaceResult:
    """What :func:`surface` produced.

    Attributes
    ----------
    mesh : trimesh.Trimesh
        The surface, in the sketch's coordinates.
    method : str
        The label of the surfacer that ran (``"classical"``, ``"soapfilm"``,
        ``"neural"`` ...), with ``"+refine"`` when the neural refinement followed.
    sketch : Sketch or None
    network : CurveNetwork or None
    patchset : PatchSet or None
    timings : dict
        Seconds per stage (``snap``, ``patches``, then one per surfacer label:
        ``classical``, ``neural`` ...).
    diagnostics : dict
        ``decision`` (why this route, one sentence), ``coverage``, ``unused_edges``
        (curves no patch uses: dangling details, reported not lost), ``fidelity``
        (:func:`curvenet.core.fidelity.sketch_fidelity`), ``topology``
        (:func:`curvenet.evaluate.topology.surface_topology`: pieces, closure, boundary
        loops, genus) and each surfacer's report under its label.
    decision : RouteDecision or None
        The route decision as data (``dataclasses.asdict`` makes it JSON).
    wires : list of (m, 3) float64
        Stretches of strokes the surface does not pass through (strokes that bound
        nothing, trimmed overshoots, overdrawn strokes), with the strokes' own geometry,
        kept as polylines beside the mesh (``auto`` only;
        :func:`curvenet.route.wires.stroke_wires`).
    face_route : (F,) uint8 or None
        Per face, an index into ``routes``: the route that made it.
    routes : tuple of Route
        Routes of ``face_route`` (``(Route.CLASSICAL, Route.NEURAL)``).
    control_net : surfacing.bspline.ControlNet or None
        The Catmull-Clark route's fitted control mesh (what :func:`export_cad` reads);
        ``diagnostics["cad"]`` holds the export report after a STEP / 3DM save.
    """

    mesh: object
    method: str
    sketch: Sketch | None = None
    network: CurveNetwork | None = None
    patchset: PatchSet | None = None
    timings: dict = field(default_factory=dict)
    diagnostics: dict = field(default_factory=dict)
    decision: RouteDecision | None = None
    wires: list = field(default_factory=list)
    face_route: np.ndarray | None = None
    routes: tuple = ()
    control_net: object = None

    @property
    def interrupted(self) -> bool:
        """True when a fit was stopped with Ctrl-C: the mesh is the best surface so far."""
        neural = self.diagnostics.get("neural", {})
        return bool(neural.get("interrupted")
                    or neural.get("creases", {}).get("interrupted"))

    def save(self, path, *, schema: str = "AP214") -> Path:
        """Write the mesh atomically; the format follows the extension.

        With wires or several routes, OBJ gets one group per route and the wires as
        ``l`` records, PLY a ``route`` face property (:func:`curvenet.io.meshes.write_routed`).
        ``.step`` / ``.stp`` (``schema`` AP214 or AP242) and ``.3dm`` write B-spline
        faces (:func:`export_cad`, needs ``pip install 'curvenet[cad]'``).
        """
        if Path(path).suffix.lower() in CAD_FORMATS:
            self.diagnostics["cad"] = export_cad(path, self, schema=schema)
            return Path(path)
        if not self.wires and len(self.routes) < 2:
            return write_mesh(path, self.mesh)
        return write_routed(path, self.mesh, self.face_route, self.routes, self.wires)

    def __repr__(self) -> str:
        return (f"<SurfaceResult(method={self.method!r}, "
                f"vertices={len(self.mesh.vertices)}, faces={len(self.mesh.faces)})>")


def export_cad(path, result: SurfaceResult, *, schema: str = "AP214",
               level: int | None = None) -> dict:
    """Write the classical surface of ``result`` as a B-rep (STEP or 3DM).

    Patches the surfacer found to lie on a plane, cylinder, cone, sphere or torus
    (``diagnostics["classical"]["analytic"]``, and the patches of a region that shares
    one within the drawing's noise, ``["shared"]``) become that surface trimmed by their
    curves, the others the B-spline pieces of the fitted control mesh
    (:func:`surfacing.bspline.extract_bsplines`); see :func:`curvenet.cad.write_cad`.

    Returns
    -------
    dict
        ``pieces`` (B-spline report), ``seams`` (G0 gap, G1 angle and deviation per
        seam between pieces), ``faces`` (per face its patch, kind and residual),
        ``file`` (what the writer reports: faces, shells, solids, free edges,
        validity), the B-rep figures of :func:`curvenet.cad.brep.brep_shape` and
        ``pieced_for_trims`` (patches written as their B-spline pieces because
        OpenCascade's wire check refused their trimmed face, :class:`curvenet.cad.
        TrimCheckError`; absent when none).
    """
    from . import cad
    suffix = Path(path).suffix.lower()
    cad.require_cad(suffix)
    if result.control_net is None:
        raise InvalidParameterError(
            f"output {path}: CAD export needs the classical Catmull-Clark route "
            f"(this surface came from {result.method})")
    foreign = (np.asarray(result.routes)[result.face_route] != Route.CLASSICAL
               if result.face_route is not None and len(result.routes) else np.zeros(0, bool))
    if foreign.any():
        raise InvalidParameterError(
            f"output {path}: {int(foreign.sum())} faces came from the "
            f"neural fill (a mesh, no B-spline form) and cannot be written as CAD faces; "
            f"save a mesh format or surface with --method classical")
    from curvenet.surfacing.analytic import AnalyticSurface
    from curvenet.surfacing.bspline import DEFAULT_LEVEL
    rep = result.diagnostics.get("classical", {})
    ps = result.patchset
    surfaces = [None if a is None else AnalyticSurface.from_dict(a)
                for a in rep.get("analytic", [None] * len(ps.patches))]
    for region in rep.get("shared", []):        # trimmed by the strokes, off it by the noise
        for k in region["patches"]:
            surfaces[k] = AnalyticSurface.from_dict(region["surface"])
    holed_flat = [k for k, p in enumerate(ps.patches) if p.holes and surfaces[k] is None
                  and rep.get("flat_meshed", 0)]
    if holed_flat:
        raise InvalidParameterError(
            f"output {path}: {len(holed_flat)} faces with holes among flat faces meshed in "
            f"their plane, and analytic faces are off (classical_options analytic_tol=None): "
            f"their control mesh covers the outer loop only; save a mesh format")
    loop_patch = rep.get("loop_patch", list(range(len(ps.patches))))
    lv = DEFAULT_LEVEL if level is None else level
    refused: list = []
    while True:
        model, bset = cad.cad_model(result.network, ps, result.control_net, surfaces,
                                    loop_patch, level=lv,
                                    curve_deviation=rep.get("max_curve_deviation", 0.0))
        try:
            out = cad.write_cad(path, model, schema=schema, wires=result.wires)
        except cad.TrimCheckError as err:
            # OpenCascade refused a trimmed face the samples do not show crossing
            # itself: that patch as its B-spline pieces, unless it is one already or
            # has holes (its pieces cover the outer loop only)
            if surfaces[err.patch] is None or ps.patches[err.patch].holes:
                raise
            surfaces[err.patch] = None
            refused.append(err.patch)
            continue
        break
    if refused:
        out["pieced_for_trims"] = refused
    return {"pieces": bset.report, "seams": bset.seams, **out}


def _network(sketch, patchset, *, snap_tol, timings):
    if patchset is not None:
        return patchset.network
    from .snap.graph import snap
    t = time.perf_counter()
    net = snap(sketch, snap_tol=snap_tol)
    timings["snap"] = time.perf_counter() - t
    if "reading" in sketch.metadata:
        net.report["reading"] = sketch.metadata["reading"]
    return net


def patches(source, *, snap_tol: float | str | None = "auto", close: str = "auto",
            points="auto",
            **options) -> PatchSet:
    """Snap (when given a sketch) and find patches.

    Parameters
    ----------
    source : Sketch, CurveNetwork, str or os.PathLike
        A sketch or a ``NETWORK.json`` / ``PATCHES.json`` file (its patches are
        recomputed).
    snap_tol : float or "auto"
        Snapping tolerance as a fraction of the bounding-box diagonal, or
        ``"auto"`` (default; ``None`` means the same): see :func:`curvenet.snap.snap`.
    close : {"auto", "none"}
        Accept closing patches automatically (see :func:`curvenet.cycles.find_patches`).
    points : {"auto", True, False}
        Reading of unordered point samples (see :func:`load_source`).
    **options
        Passed to :func:`curvenet.cycles.find_patches`.

    Returns
    -------
    PatchSet
        ``report["timings"]`` has the snapping and patch-finding seconds.

    Examples
    --------
    >>> from curvenet import shapes
    >>> ps = patches(shapes.box().sketch())
    >>> len(ps.patches)
    6
    """
    from .cycles.find import find_patches
    sketch, given = load_source(source, points=points)
    timings: dict = {}
    net = _network(sketch, given, snap_tol=snap_tol, timings=timings)
    t = time.perf_counter()
    ps = find_patches(net, close=close, **options)
    timings["patches"] = time.perf_counter() - t
    ps.report.setdefault("timings", {}).update(timings)
    return ps


def _load(source, patchset: PatchSet | None, points, diag: dict):
    """``(sketch, patch set)`` of the input; a given ``patchset`` must match the sketch."""
    sketch, given = load_source(source, points=points)
    if sketch is not None:
        diag["reading"] = sketch.metadata.get("reading", "polylines: no stroke is a block of "
                                              "unordered points" if points is not False else
                                              "polylines: point reading off")
    if patchset is not None:
        given = patchset
        if sketch is not None:
            check_patches_match(sketch, patchset)
    if sketch is not None and len(sketch.select(("boundary", "crease"))) == 0:
        raise InvalidParameterError(f"{sketch.source or 'sketch'}: no boundary or crease strokes")
    return sketch, given


def _check_settings(method: str, s: SurfaceSettings) -> None:
    """The pipeline's own settings (each surfacer checks its options)."""
    methods = METHODS + surfacer_names()
    if method not in methods:
        raise InvalidParameterError(f"method: {method!r} is not one of {methods}")
    if s.quality not in QUALITIES:
        raise InvalidParameterError(f"quality: {s.quality!r} is not one of {QUALITIES}")
    if not (0.0 < s.crease_angle < 180.0):
        raise InvalidParameterError(f"crease_angle: {s.crease_angle!r} is not in (0, 180)")
    if s.device not in ("cpu", "cuda") and not str(s.device).startswith("cuda:"):
        raise InvalidParameterError(f"device: {s.device!r} is not cpu or cuda")


@dataclass
class _Plan:
    """The surfacers a call may run and their checked options (name -> dict)."""

    patch: Surfacer | None      # the classical route
    stroke: Surfacer | None     # the neural route, or the refinement after the classical one
    regions: Surfacer | None    # the hybrid route: patches, and a fill per region
    options: dict
    refine: bool                # run ``stroke`` on the result of ``patch``


def _plan(method: str, surfacer: str, refine: bool, settings: SurfaceSettings, *,
          classical_options, neural_options, crease_options) -> _Plan:
    """Choose the candidate surfacers and validate their options, before any work."""
    _check_settings(method, settings)
    patch = get_surfacer(surfacer, "patches")
    stroke = get_surfacer(STROKE_SURFACER, "strokes")
    regions = get_surfacer(REGION_SURFACER, "regions")
    if method not in METHODS:
        chosen = get_surfacer(method)
        if chosen.needs == "regions":
            regions = chosen
        elif chosen.needs == "patches":
            patch = chosen
        else:
            patch, stroke = None, chosen
    refine = bool(refine) and patch is not None
    checked = [s for s in (patch, stroke) if s]
    per_region = method in ("auto", regions.name)
    if not per_region:
        regions = None
        if patch is not None and not refine:
            stroke = None
    stroke_options = dict(neural_options or {})
    if crease_options:
        stroke_options["creases"] = crease_options
    given = {"patches": classical_options, "strokes": stroke_options}
    # options given are checked even for a surfacer this route will not run
    options = {s.name: s.validate(given[s.needs], settings) for s in checked
               if s in (patch, stroke) or given[s.needs]}
    if regions is not None:
        options[regions.name] = regions.validate(
            {"patch": patch.name, "fill": stroke.name, "patch_options": options[patch.name],
             "fill_options": options[stroke.name]}, settings)
    return _Plan(patch, stroke, regions, options, refine)


def _find_patches(sketch, given, *, snap_tol, close, timings, diag):
    """Snap (unless given a network) and find patches (unless given some)."""
    from .cycles.find import find_patches
    net = _network(sketch, given, snap_tol=snap_tol, timings=timings)
    diag["snap"] = dict(net.report)
    if given is not None and given.patches:
        ps = given
    else:
        t = time.perf_counter()
        ps = find_patches(net, close=close)
        timings["patches"] = time.perf_counter() - t
    cov, unused = coverage(ps)
    diag.update(coverage=cov, unused_edges=unused, patches=len(ps.patches))
    return net, ps


def _regions(ps) -> list:
    """The patched region, then :func:`~curvenet.route.regions.plan_regions`' regions."""
    curves = [e.curve for e in ps.network.edges]
    used = np.zeros(len(curves), bool)
    used[sorted({i for p in ps.patches for i in p.edges})] = True
    covered = Region(Route.CLASSICAL, [int(i) for i in np.flatnonzero(used)],
                     float(sum(ps.network.edges[i].length() for i in np.flatnonzero(used))),
                     patches=len(ps.patches))
    return [covered, *plan_regions(curves, used)] if ps.patches else [covered]


def _decide(method: str, plan: _Plan, diag: dict, ps) -> RouteDecision:
    """The route: auto's rule per region, or what was requested (with the coverage)."""
    if method == "auto":
        covered, *regions = _regions(ps)
        return region_route(diag["patches"], diag["coverage"], regions, covered,
                            patch_surfacer=plan.patch.name, stroke_surfacer=plan.stroke.name,
                            hybrid_surfacer=plan.regions.name)
    sought = {k: diag[k] for k in ("coverage", "patches") if k in diag}
    if plan.regions is not None:
        return RouteDecision(method, plan.regions.name, "requested", regions=_regions(ps),
                             **sought)
    first = plan.patch or plan.stroke
    return RouteDecision(method, first.name, "requested", **sought)


def _classical(plan: _Plan, decision: RouteDecision) -> bool:
    """Whether the decision takes a route that needs patches (alone or per region)."""
    return plan.patch is not None and decision.surfacer in (
        plan.patch.name, plan.regions.name if plan.regions is not None else None)


def _strokes(sketch: Sketch | None, net: CurveNetwork | None):
    if sketch is not None:
        sub = sketch.select(("boundary", "crease"))
        return sub.strokes, sub.labels
    return [e.curve for e in net.edges], [e.label for e in net.edges]


def _run(surfacer: Surfacer, inp: SurfaceInput, options: dict, timings, diag) -> MeshResult:
    """Run one surfacer; its seconds and report are filed under its label, and those of
    the parts of a composite (its report's ``parts`` and ``timings``) under theirs."""
    t = time.perf_counter()
    res = surfacer(inp, options)
    timings[surfacer.label] = time.perf_counter() - t
    diag[surfacer.label] = dict(res.report)
    if "parts" in res.report:
        diag.update(res.report["parts"])
        timings.update(res.report["timings"])
    return res


def _surface_route(plan: _Plan, decision: RouteDecision, settings: SurfaceSettings, *,
                   sketch, net, ps, timings, diag):
    """Run the decided surfacer (and the refinement); returns ``(MeshResult, name)``."""
    res, name, init = None, None, None
    if _classical(plan, decision):
        from .cycles.loops import orient_boundaries
        edges = net.edges
        bounds = orient_boundaries(net, ps.patches)
        inp = SurfaceInput(settings, curves=[e.curve for e in edges],
                           loops=[b[0] for b in bounds], holes=[b[1:] for b in bounds],
                           crease_curves=[i for i, e in enumerate(edges) if e.label == "crease"],
                           regions=decision.regions)
        run = plan.patch if decision.surfacer == plan.patch.name else plan.regions
        res = _run(run, inp, plan.options[run.name], timings, diag)
        name = run.label if len(res.routes) > 1 else plan.patch.label
        init = (res.vertices, res.faces)
    if res is None or plan.refine:
        strokes, labels = _strokes(sketch, net)
        inp = SurfaceInput(settings, strokes=strokes, labels=labels, init_mesh=init)
        res = _run(plan.stroke, inp, plan.options[plan.stroke.name], timings, diag)
        name = plan.stroke.label if init is None else name + "+refine"
    return res, name


#: Walls on less than this share of the classical surface's area are reported and kept:
#: a sliver is not worth a neural fit that would lose strokes elsewhere.
JUDGE_WALL_AREA = 0.01
#: The neural surface replaces a judged classical one only when its stroke fidelity is
#: at most this much below the classical surface's (a share of stroke length).
JUDGE_FIDELITY_MARGIN = 0.02


def _judge(plan: _Plan, decision: RouteDecision, settings: SurfaceSettings, close: str, *,
           sketch, net, ps, res, name, timings, diag):
    """``auto``'s check of the classical surface, and what it takes when the check fails.

    The surface passes when no patch is a wall inside the shape the others bound
    (:func:`~curvenet.route.check.judge_patches`). When it does not, the other patch
    selection (:func:`~curvenet.cycles.find_patches` ``mode="faces"`` or ``"basis"``)
    is surfaced and kept if it covers at least the curve length the first covers and
    has no walls. A surface whose walls hold at least :data:`JUDGE_WALL_AREA` of its area and
    that has no such replacement goes to the neural route, which is kept if its
    stroke fidelity is at most :data:`JUDGE_FIDELITY_MARGIN` below the classical
    surface's; else the classical surface stays, walls and all (a wrong shape through
    the strokes is not traded for a surface that misses them). Returns ``(result,
    patch set, decision with its check, name)``.
    """
    if getattr(res, "face_patch", None) is None:
        return res, ps, decision, name
    creases = [i for i, e in enumerate(net.edges) if e.label == "crease"]

    def judge(r, p):
        return judge_patches(r.vertices, r.faces, r.face_patch, [q.all_edges for q in p.patches],
                             net.number_of_edges, creases=creases)

    first = judge(res, ps)
    mode = ps.report.get("mode", "basis")
    check = {"walls": {mode: len(first["walls"])}, "nonmanifold": first["nonmanifold"],
             "coverage": {mode: diag["coverage"]}, "taken": mode}
    if first["passes"]:
        return res, ps, replace(decision, check=check), name
    from .cycles.find import find_patches
    other = "faces" if mode == "basis" else "basis"
    alt = find_patches(net, close=close, mode=other)
    check["coverage"][other], alt_unused = coverage(alt)
    if alt.patches and check["coverage"][other] >= diag["coverage"] - 1e-9:
        alt_res, alt_name = _surface_route(plan, decision, settings, sketch=sketch, net=net,
                                           ps=alt, timings=timings, diag=diag)
        verdict = judge(alt_res, alt)
        check["walls"][other] = len(verdict["walls"])
        if verdict["passes"]:
            check.update(taken=other, nonmanifold=verdict["nonmanifold"])
            diag.update(patches=len(alt.patches), coverage=check["coverage"][other],
                        unused_edges=alt_unused)
            return alt_res, alt, replace(decision, patches=len(alt.patches), check=check), alt_name
    check["wall_area"] = wall_area(res.vertices, res.faces, res.face_patch, first["walls"])
    if check["wall_area"] < JUDGE_WALL_AREA:
        return res, ps, replace(decision, check=check), name
    strokes, labels = _strokes(sketch, net)
    neural = _run(plan.stroke, SurfaceInput(settings, strokes=strokes, labels=labels),
                  plan.options[plan.stroke.name], timings, diag)
    ref = sketch if sketch is not None else net
    check["fidelity"] = {
        "classical": stroke_fidelity((res.vertices, res.faces), ref)["fidelity"],
        "neural": stroke_fidelity((neural.vertices, neural.faces), ref)["fidelity"]}
    if check["fidelity"]["neural"] < check["fidelity"]["classical"] - JUDGE_FIDELITY_MARGIN:
        return res, ps, replace(decision, check=check), name
    check["taken"] = "neural"
    decision = replace(decision, route=Route.NEURAL, surfacer=plan.stroke.name, reason="judged",
                       check=check)
    diag["decision"] = decision.explain()
    return neural, ps, decision, plan.stroke.label


def surface(source, *, method: str = "auto", patchset: PatchSet | None = None,
            snap_tol: float | str | None = "auto", close: str = "auto",
            surfacer: str = "catmull-clark",
            subdiv: int | None = None, resolution: int | None = None,
            crease_angle: float = 30.0, refine: bool = False, quality: str = "draft",
            device: str = "cpu", seed: int = 0, progress: bool = False,
            classical_options: dict | None = None,
            neural_options: dict | None = None,
            crease_options: dict | None = None, points="auto") -> SurfaceResult:
    """Sketch (or network, or patch set) to surface.

    Parameters
    ----------
    source : Sketch, CurveNetwork, PatchSet, str or os.PathLike
        A sketch, a sketch file in any supported format, or a ``NETWORK.json`` /
        ``PATCHES.json`` file.
    method : str
        ``"auto"`` snaps, finds patches and takes the classical route when they cover at
        least :data:`AUTO_MIN_COVERAGE` of the curve length, else the neural route;
        ``"classical"`` (the ``surfacer``), or any name of :func:`curvenet.route.surfacer_names`.
    patchset : PatchSet, optional
        Use these patches (e.g. an edited ``PATCHES.json``) instead of finding them.
    snap_tol : float or "auto"
        Snapping tolerance (fraction of the bounding-box diagonal), or ``"auto"``
        (default): see :func:`curvenet.snap.snap`.
    close : {"auto", "none"}
        Closing-patch policy of the patch finder.
    surfacer : str
        Surfacer of the classical route: ``"catmull-clark"`` (Orbay-Kara limit fitting),
        ``"soapfilm"`` (the baseline) or another that needs patches.
    subdiv, resolution : int, optional
        Subdivision levels, samples per curve of the classical surfacer; its defaults.
    crease_angle : float
        Dihedral angle (degrees) above which a curve becomes a crease.
    refine : bool
        Continue the classical result with the neural flow-alignment fit.
    quality, device, seed, progress
        Neural preset (``"draft"``, ``"default"``, ``"paper"``), ``"cpu"`` or ``"cuda"``,
        the seed of every random choice, progress bars.
    classical_options, neural_options : dict, optional
        Options of the classical surfacer (:func:`surfacing.surface_loops` keywords) and
        of the neural one (:class:`neural.presets.FlowConfig` fields).
    crease_options : dict, optional
        Settings of the neural crease refit (:class:`neural.crease_refit.CreaseConfig`).
    points : {"auto", True, False}
        Reading of unordered point samples (see :func:`load_source`); the reading taken
        is in ``diagnostics["reading"]``.

    Every option is checked before any work (``InvalidParameterError`` names it); a
    failure inside a surfacer is an internal error and propagates as it is.

    Returns
    -------
    SurfaceResult

    Examples
    --------
    >>> from curvenet import shapes
    >>> res = surface(shapes.box().sketch(), method="classical")
    >>> res.method, res.mesh.is_watertight, res.decision.explain()
    ('classical', True, 'classical: requested')
    """
    settings = SurfaceSettings(crease_angle, subdiv, resolution, quality, device, seed, progress)
    plan = _plan(method, surfacer, refine, settings, classical_options=classical_options,
                 neural_options=neural_options, crease_options=crease_options)
    timings, diag = {}, {}
    sketch, given = _load(source, patchset, points, diag)
    net, ps = (given.network if given is not None else None), None
    if plan.patch is not None:
        net, ps = _find_patches(sketch, given, snap_tol=snap_tol, close=close, timings=timings,
                                diag=diag)
    decision = _decide(method, plan, diag, ps)
    diag["decision"] = decision.explain()
    if _classical(plan, decision) and not ps.patches:
        raise CurvenetError("no patches found: the curves form no cycles; try --method neural")
    res, name = _surface_route(plan, decision, settings, sketch=sketch, net=net, ps=ps,
                               timings=timings, diag=diag)
    if (method == "auto" and decision.route is Route.CLASSICAL and not plan.refine
            and (given is None or not given.patches)):      # patches given are the user's
        res, ps, decision, name = _judge(plan, decision, settings, close, sketch=sketch, net=net,
                                         ps=ps, res=res, name=name, timings=timings, diag=diag)
    if len(res.faces) == 0:
        raise CurvenetError(f"the {name} route produced an empty surface")
    if "regions" in res.report:        # a composite filled in its regions' figures
        decision = replace(decision, regions=[
            replace(r, **figures) for r, figures in zip(decision.regions, res.report["regions"])])
    mesh = res.to_trimesh()
    ref = sketch if sketch is not None else net
    face_route, routes = res.face_route, tuple(res.routes)
    wires = stroke_wires(ref, mesh.vertices, mesh.faces) if method == "auto" else []
    if wires and not routes:
        face_route, routes = np.zeros(len(mesh.faces), np.uint8), (decision.route,)
    t = time.perf_counter()
    diag["fidelity"] = sketch_fidelity(mesh, ref, wires=wires)
    timings["fidelity"] = time.perf_counter() - t
    diag["topology"] = surface_topology(mesh.vertices, mesh.faces)
    for key in ("open_at_box", "rims_closed"):    # the field left the box, was closed
        if diag.get("neural", {}).get(key):
            diag["topology"][key] = int(diag["neural"][key])
    return SurfaceResult(mesh, name, sketch, net, ps, timings, diag, decision, wires,
                         face_route, routes, control_net=getattr(res, "control_net", None))
