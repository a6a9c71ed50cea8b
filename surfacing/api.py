"""One-call surfacing of curve loops: Coons -> Catmull-Clark control mesh -> limit fit.

:func:`surface_loops` is the classical route of Orbay & Kara 2011 (Sec. 4.2-4.3),
with creases, n-sided loops and a direct least-squares fit added;
:func:`soapfilm_loops` is the soap-film baseline of Abbasinejad et al. 2011, Sec. 7.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from curvenet.core.result import MeshResult
from curvenet.core.errors import InvalidParameterError

from .levels import ControlNet
from .catmull_clark import edge_index, subdivision_step
from .controlmesh import build_control_mesh
from .sharp import DEFAULT_CREASE_ANGLE, sharp_structure
from .curveupdate import fit_cubic_curve
from .fit import (FAIRNESS, LAMBDA, VSPRING_STEP, bending_energy, fairness_matrix,
                  fit_iterative, fit_lsq, swept_rows, variation_matrix)
from .fitcheck import ESCAPE, escape, sweep_check
from .limit import limit_matrix, tangent_matrices
from .polyline import point_polyline_distance
from .sides import DEFAULT_STRAIGHT_ANGLE
from .soap import soapfilm_mesh

__all__ = ["PatchMeshResult", "surface_loops", "soapfilm_loops", "check_loops_options",
           "FITS", "AUTO_FIT_MAX_VERTICES", "AUTO_FIT_MAX_ITER", "AUTO_FIT_MAX_LEVEL_VERTICES",
           "AUTO_FIT_TIE", "AUTO_FIT_PREFERENCE", "DEFAULT_RESOLUTION", "DEFAULT_SUBDIV",
           "DEFAULT_TOL", "DEFAULT_EDGE_LENGTH", "DEFAULT_MAX_FACES", "density_subdiv",
           "explain_fit"]

#: Fits of :func:`surface_loops`: ``auto`` (those below, the fairest kept), ``lsq``,
#: ``sweep``, ``iterative``.
FITS = ("auto", "lsq", "sweep", "iterative")
#: ``fit="auto"`` tries the published iteration on control nets of at most this many
#: vertices (sparse networks, where the fairness energy, not the curves, decides the
#: shape between curves); larger nets take the least-squares fit alone.
AUTO_FIT_MAX_VERTICES = 500
#: Steps ``auto`` gives the iteration: where it was kept it converged in 36-165 steps; one
#: that has not by then is not taken (and would cost up to ``max_iter`` steps per fit).
AUTO_FIT_MAX_ITER = 250
#: Catmull-Clark level of the limit meshes whose bending energies ``auto`` compares ...
#: Level 1: at finer levels the limit surface resolves the wiggle of rough or recovered
#: curves, which every fit interpolates, and that energy drowns the difference between
#: the fits' shapes (a torus from point samples: the swept fit 66.6 / 109.9 / 137.8 at
#: levels 1 / 2 / 3, the flattened least-squares fit 85.9 / 108.3 / 122.6).
AUTO_FIT_LEVEL = 1
#: ... lowered (to 0 at the least) until that mesh has at most this many vertices.
AUTO_FIT_MAX_LEVEL_VERTICES = 100_000
#: Bending energies within this fraction of the least are a tie: the energy of a coarse
#: limit mesh is a few percent off its limit (tori, rough and drawn through: 1-3% at
#: level 1), and two fits' order can flip between levels within such a band.
AUTO_FIT_TIE = 0.01
#: Who wins a tie: the swept shape the drawn sections imply, then the least-squares fit.
AUTO_FIT_PREFERENCE = ("sweep", "lsq", "iterative")
#: Control-polygon segments per curve (the paper's user-set N).
DEFAULT_RESOLUTION = 4
#: Catmull-Clark levels of the output mesh.
DEFAULT_SUBDIV = 3
#: Default output edge length, fraction of the diagonal: sets the Catmull-Clark level
#: when ``subdiv`` is not given.
DEFAULT_EDGE_LENGTH = 0.005
#: Most triangles the level chosen from ``edge_length`` may write (an explicit
#: ``subdiv`` is bounded by :data:`MAX_OUTPUT_FACES` only).
DEFAULT_MAX_FACES = 200_000
#: Curve-interpolation tolerance of the iterative fit, fraction of the diagonal.
DEFAULT_TOL = 1e-4


@dataclass(repr=False, kw_only=True)
class PatchMeshResult(MeshResult):
    """A surfaced patch set: a :class:`~curvenet.core.MeshResult` with per-patch extras.

    Attributes
    ----------
    vertices : (n, 3) float64
        Limit-surface points (subdivided ``subdiv`` times, then pushed to the limit).
    faces : (f, 3) int64
        Triangles, two per limit quad, oriented like the loops.
    report : dict
        ``max_curve_deviation`` / ``mean_curve_deviation`` (limit points along the
        curves to the input polylines, fraction of the diagonal),
        ``max_sample_deviation`` (at the fitted samples), ``iterations``,
        ``timings`` (seconds), ``creases`` (crease curves), ``creases_detected``
        (made creases by the dihedral test), ``n_patches``, ``n_control_vertices``,
        ``patch_kinds``, ``fit``.
    face_patch : (f,) int64
        Loop index of each triangle.
    curves : list of (m_i, 3) float64 or None
        Updated network curves when ``update_curves`` was asked for.
    control_vertices, control_quads : arrays or None
        The fitted control mesh (classical route only).
    control_net : surfacing.levels.ControlNet or None
        The fitted control mesh with its patches, creases and curves, for B-spline
        export (classical route only).
    curve_vertices : list of (k_c,) int64 or None
        Per input curve, the output vertex ids along it from its first point to its
        last (None for a curve no loop uses); None when the route has none.
    """

    face_patch: np.ndarray
    curves: list | None = None
    control_vertices: np.ndarray | None = None
    control_quads: np.ndarray | None = None
    control_net: ControlNet | None = None
    curve_vertices: list | None = None


def _quads_to_tris(q: np.ndarray) -> np.ndarray:
    return np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]]).astype(np.int64)


#: Largest output ``surface_loops`` accepts, in triangles (estimated before any allocation).
MAX_OUTPUT_FACES = 20_000_000


def check_loops_options(*, resolution=DEFAULT_RESOLUTION, subdiv=None,
                        edge_length=DEFAULT_EDGE_LENGTH, fit="auto",
                        straight_angle=DEFAULT_STRAIGHT_ANGLE, tol=DEFAULT_TOL, lam=LAMBDA,
                        curve_weight=None, fairness="variation", n_loops: int = 1,
                        **_other) -> None:
    """Check the scalar options of :func:`surface_loops` before any work.

    Takes the keyword options of :func:`surface_loops` (others are ignored) and the
    number of loops, ``n_loops`` (1 when not known yet: the size check is then a
    weaker lower bound).

    Raises
    ------
    InvalidParameterError
        The first option out of range, the message naming it and its value; or an
        output that would exceed :data:`MAX_OUTPUT_FACES` triangles.
    """
    checks = [
        ("fit", fit, lambda v: v in FITS, f"one of {FITS}"),
        ("subdiv", subdiv, lambda v: v is None or _is_int(v) and v >= 0,
         "an integer >= 0 or None"),
        ("edge_length", edge_length, lambda v: v > 0, "> 0"),
        ("resolution", resolution, lambda v: _is_int(v) and v >= 2, "an integer >= 2"),
        ("fairness", fairness, lambda v: v in FAIRNESS, f"one of {FAIRNESS}"),
        ("tol", tol, lambda v: v > 0, "> 0"),
        ("lam", lam, lambda v: 0 < v <= 1, "in (0, 1]"),
        ("curve_weight", curve_weight, lambda v: v is None or v > 0, "> 0 or None"),
        ("straight_angle", straight_angle, lambda v: 0 <= v < 180, "degrees in [0, 180)"),
    ]
    for name, value, ok, expected in checks:
        try:
            good = bool(ok(value))
        except (TypeError, ValueError):     # not a number at all
            good = False
        if not good:
            raise InvalidParameterError(f"{name}: expected {expected}, got {value!r}")
    _check_output_size(n_loops, resolution, 0 if subdiv is None else int(subdiv))


def density_subdiv(vertices, quads, diagonal, edge_length=DEFAULT_EDGE_LENGTH,
                   max_faces=DEFAULT_MAX_FACES) -> int:
    """Catmull-Clark level giving output edges of about ``edge_length`` of the diagonal.

    Parameters
    ----------
    vertices : (n, 3) float64
        Control-mesh vertices.
    quads : (q, 4) int64
        Control quads.
    diagonal : float
        Bounding-box diagonal of the curves.
    edge_length : float
        Target edge length, fraction of ``diagonal``.
    max_faces : int
        The level is lowered until the output has at most this many triangles
        (``2 * q * 4**level``); never below 0.

    Returns
    -------
    int
        The smallest level whose mean control edge, halved per level, is at most the
        target, capped by ``max_faces``.
    """
    if len(quads) == 0:
        return 0
    q = np.asarray(quads)
    mean = float(np.linalg.norm(vertices[q] - vertices[np.roll(q, -1, axis=1)], axis=2).mean())
    target = edge_length * (diagonal if diagonal > 0 else 1.0)
    want = int(np.ceil(np.log2(mean / target))) if mean > target else 0
    cap = int(np.floor(np.log(max(max_faces / (2 * len(q)), 1.0)) / np.log(4)))
    return max(0, min(want, cap))


def _check_output_size(n_loops: int, resolution: int, subdiv: int) -> None:
    """Refuse settings whose output would not fit in memory, before building anything.

    A four-sided patch with one piece per side gives ``2 * r**2 * 4**subdiv`` triangles
    (``r`` = resolution rounded up to even), so this is a lower bound.
    """
    r = int(resolution) + int(resolution) % 2
    faces = 2 * max(n_loops, 1) * r * r * 4 ** subdiv
    if faces > MAX_OUTPUT_FACES:
        raise InvalidParameterError(
            f"resolution {resolution} with subdiv {subdiv} would write at least {faces:.3g} "
            f"triangles for {n_loops} patches; the limit is {MAX_OUTPUT_FACES:.3g} "
            "(lower --resolution or --subdiv)")


def _is_int(value) -> bool:
    return not isinstance(value, bool) and int(value) == value


def surface_loops(curves, loops, *, crease_curves=(), crease_angle: float | None =
                  DEFAULT_CREASE_ANGLE, resolution: int = DEFAULT_RESOLUTION,
                  subdiv: int | None = None, edge_length: float = DEFAULT_EDGE_LENGTH,
                  fit: str = "auto", update_curves=False,
                  straight_angle: float = DEFAULT_STRAIGHT_ANGLE, tol: float = DEFAULT_TOL,
                  max_iter: int = 500, lam: float = LAMBDA, curve_weight: float | None = None,
                  fairness: str = "variation", vspring_step: float = VSPRING_STEP
                  ) -> PatchMeshResult:
    """Smooth surface through a curve network's loops (Orbay & Kara 2011, Sec. 4.2-4.3).

    Parameters
    ----------
    curves : list of (m_i, 3) float64
        Network curves (polylines); curves meeting at a junction share end points.
    loops : list of list of (int, bool)
        Patches: each a closed loop of (curve index, traversed forward); loops that
        disagree in orientation are flipped to agree with the first one.
    crease_curves, crease_angle : iterable of int, float or None
        Curves labelled crease; shared curves whose patches meet at a dihedral angle
        above ``crease_angle`` degrees become creases too (None: labelled ones only).
    resolution : int
        Control-polygon segments per curve piece (>= 2, odd rounded up to even); long
        or winding curves get several pieces (:func:`surfacing.pieces.piece_counts`).
    subdiv : int or None
        Catmull-Clark levels for the output mesh (>= 0); None chooses the level from
        ``edge_length`` (see :func:`density_subdiv`, at most :data:`DEFAULT_MAX_FACES`
        triangles).
    edge_length : float
        Target output edge length, fraction of the diagonal, when ``subdiv`` is None.
    fit : {"auto", "lsq", "sweep", "iterative"}
        ``lsq``: direct sparse least squares with exact interpolation of the curve
        samples; ``sweep``: the same, its fairness measured from the swept shape of
        the four-sided loops (:mod:`surfacing.sweep`), which it keeps between the
        curves; ``iterative``: the published iteration (Eq. 3 with V-spring, Eq. 4);
        ``auto`` (default): ``lsq`` and ``sweep`` (one factorisation), and on control
        nets of at most :data:`AUTO_FIT_MAX_VERTICES` vertices also ``iterative``
        (when it reaches ``tol`` within :data:`AUTO_FIT_MAX_ITER` steps, then
        corrected to interpolate the samples exactly by the change of least fairness
        energy), keeping the one whose limit surface bends least
        (:func:`surfacing.fit.bending_energy`; within :data:`AUTO_FIT_TIE` of the least,
        the first of :data:`AUTO_FIT_PREFERENCE`); where that is ``lsq`` but it departs
        from the swept shape by more than the shape's two sweeps depart from each other,
        ``sweep`` (:func:`surfacing.fitcheck.sweep_check`; the report's ``sweep_check``).
    update_curves : bool or iterable of int
        Return curves refitted to the surface (Sec. 4.3.3): all when True, else the
        given indices (the others are returned unchanged).
    straight_angle : float
        Degrees; curves turning less at a junction form one patch side, and two sharp
        curves turning more make a corner.
    tol, max_iter, lam, vspring_step : float, int, float, float
        Iterative fit: stop tolerance on curve deviation (fraction of the diagonal),
        iteration cap, damping of Eq. 3, and the fraction of the V-spring displacement
        applied per iteration (1.0 as published; see :data:`surfacing.fit.VSPRING_STEP`).
    curve_weight : float or None
        lsq fit: None interpolates exactly; a positive weight trades interpolation
        for fairness (use with ``update_curves``).
    fairness : {"variation", "thin-plate"}
        lsq fit energy: differences of the control net's umbrella Laplacian across
        edges (linear curvature variation, default) or the Laplacian itself.

    Returns
    -------
    PatchMeshResult
        The last subdivision level pushed to the limit; ``report`` deviations are fractions
        of the diagonal. Bad options raise ``InvalidParameterError`` before any work.

    Examples
    --------
    >>> t = np.linspace(0, 1, 9)[:, None]
    >>> sq = [t * [1, 0, 0], [1, 0, 0] + t * [0, 1, 0], [1, 1, 0] - t * [1, 0, 0],
    ...       [0, 1, 0] - t * [0, 1, 0]]
    >>> res = surface_loops(sq, [[(0, True), (1, True), (2, True), (3, True)]])
    >>> bool(np.abs(res.vertices[:, 2]).max() < 1e-12)
    True

    References
    ----------
    Orbay & Kara 2011, Sec. 4.2, 4.3.1 (Eq. 1-2), 4.3.2 (Eq. 3-4), 4.3.3; Halstead et al. 1993.
    """
    check_loops_options(resolution=resolution, subdiv=subdiv, edge_length=edge_length,
                        fit=fit, tol=tol, lam=lam,
                        straight_angle=straight_angle, curve_weight=curve_weight,
                        fairness=fairness, n_loops=len(loops))
    update = _curve_selection(update_curves, len(curves))
    cm, curves, (crease, detected, *sharp, _), timings = _build(
        curves, loops, resolution, crease_curves, crease_angle, straight_angle)
    P, iters, sample_dev, choice = _fit_control_net(
        cm, sharp, fit=fit, fairness=fairness, curve_weight=curve_weight, lam=lam, tol=tol,
        max_iter=max_iter, vspring_step=vspring_step, timings=timings)
    if subdiv is None:
        subdiv = density_subdiv(cm.vertices, cm.quads, cm.diagonal, edge_length)
    V, faces, face_patch, chains = _limit_surface(P, cm, sharp, int(subdiv), timings)
    dev, new_curves = _curve_fit_report(V, chains, curves, cm, update, timings)
    report = _report(cm, fit=choice, dev=dev, sample_dev=sample_dev, iters=iters, timings=timings,
                     crease=crease, detected=detected, n_faces=len(faces),
                     resolution=resolution, subdiv=int(subdiv))
    net = ControlNet(P, cm.quads, cm.face_patch, *sharp, list(cm.curve_vids), cm.diagonal)
    used = {ci for lp in cm.loops for ci, _ in lp}
    return PatchMeshResult(V, faces, report, face_patch=face_patch, curves=new_curves,
                           control_vertices=P, control_quads=cm.quads, control_net=net,
                           curve_vertices=[ch if c in used else None
                                           for c, ch in enumerate(chains)])


def _build(curves, loops, resolution, crease_curves, crease_angle, straight_angle):
    """Control mesh (Coons patches, Sec. 4.2), float64 curves, sharp structure, timings."""
    t0 = time.perf_counter()
    cm = build_control_mesh(curves, loops, resolution, straight_angle=straight_angle)
    curves = [np.asarray(c, dtype=np.float64) for c in curves]
    sharp = sharp_structure(cm, curves, crease_curves, crease_angle=crease_angle,
                            straight_angle=straight_angle)
    return cm, curves, sharp, {"build": time.perf_counter() - t0}


def _curve_selection(update_curves, n_curves: int):
    """Indices of the curves to refit (``update_curves``), or None; checked up front."""
    if update_curves is False or update_curves is None:
        return None
    sel = range(n_curves) if update_curves is True else [int(i) for i in update_curves]
    for c in sel:
        if not 0 <= c < n_curves:
            raise InvalidParameterError(f"update_curves: index {c} out of range [0, {n_curves})")
    return sel


def _fit_control_net(cm, sharp, *, fit, fairness, curve_weight, lam, tol, max_iter,
                     vspring_step, timings):
    """Control points whose limit interpolates the curve samples (Sec. 4.3.2).

    Returns ``(P (n, 3) float64, iterations, sample deviations (k,) float64, choice)``:
    ``choice`` is the fit used and, for ``auto``, the bending energy of each fit tried
    (``{"fit": ..., "energy": {"lsq": e, "sweep": e or None, "iterative": e or None}}``;
    None: not tried: no swept loop, a control net too large for the iteration, or
    an iteration that did not reach ``tol`` within its steps), and where the energies
    kept ``lsq`` and a swept fit exists, ``"sweep_check"`` (:func:`.fitcheck.sweep_check`);
    where a fit left a loop, ``"escaped"``: per fit its largest :func:`.fitcheck.escape`.
    """
    t0 = time.perf_counter()
    sharp_edges, corners = sharp
    n = len(cm.vertices)
    L = limit_matrix(cm.quads, n, sharp_edges, corners)
    cons = np.flatnonzero(cm.on_curve)
    targets = cm.target[cons]
    diag = cm.diagonal if cm.diagonal > 0 else 1.0
    if fit == "iterative":
        P, iters = _iterate(cm, sharp, L, cons, targets, lam=lam, tol=tol * diag,
                            steps=max_iter, vspring_step=vspring_step)
        return _fitted(P, iters, L, cons, targets, {"fit": fit}, timings, t0)
    F = fairness_matrix(cm.quads, n, sharp_edges, corners)
    if fairness == "variation":
        F = variation_matrix(F)
    goals = {"lsq": None}
    if fit in ("sweep", "auto") and cm.swept is not None and cm.swept.any():
        rows = swept_rows(F, cm.quads, cm.face_patch, cm.swept)
        if rows.any():
            # the limit of a control net lies inside it: one step of the inverse,
            # R + (R - L R), puts the rest net's limit on the swept shape to second order
            rest = 2.0 * cm.rest - L @ cm.rest
            goals["sweep"] = np.where(rows[:, None], F @ rest, 0.0)
    if fit == "lsq":
        goals.pop("sweep", None)
    elif fit == "sweep" and "sweep" in goals:
        goals.pop("lsq")
    fits = dict(zip(goals, fit_lsq(L, F, cm.vertices, cons, targets, curve_weight=curve_weight,
                                   goals=list(goals.values()))))
    if fit != "auto":
        name = next(iter(fits))
        return _fitted(fits[name], 1, L, cons, targets, {"fit": name}, timings, t0)
    iters = {name: 1 for name in fits}
    if curve_weight is None and n <= AUTO_FIT_MAX_VERTICES:
        steps = min(max_iter, AUTO_FIT_MAX_ITER)
        Pi, it_i = _iterate(cm, sharp, L, cons, targets, lam=lam, tol=tol * diag,
                            steps=steps, vspring_step=vspring_step)
        if it_i < steps:            # reached tol; then the least fair change that
            # makes it interpolate the samples exactly, as the lsq fit does
            fits["iterative"] = Pi + fit_lsq(L, F, np.zeros_like(Pi), cons,
                                             targets - (L @ Pi)[cons])
            iters["iterative"] = it_i

    def left_of(Q):         # how far a fit leaves its loops (surfacing.fitcheck)
        return escape(L @ Q, cm.quads, cm.face_patch, cm.on_curve, cm.target).max()

    left = {name: left_of(Q) for name, Q in fits.items()}
    direct = list(fits)
    if min(left.values()) > ESCAPE and "iterative" not in fits:
        # every direct fit left a loop (surfacing.fitcheck): the iteration moves the Coons
        # net locally, and is taken as it ends, without the exact correction
        fits["iterative"], iters["iterative"] = _iterate(
            cm, sharp, L, cons, targets, lam=lam, tol=tol * diag, steps=max_iter,
            vspring_step=vspring_step)
        left["iterative"] = left_of(fits["iterative"])
    energy = {"lsq": None, "sweep": None, "iterative": None}
    if len(fits) > 1:
        level = _energy_level(cm)
        energy.update({name: bending_energy(*_limit_surface(Q, cm, sharp, level, {})[:2])
                       for name, Q in fits.items()})
    ok = [name for name in fits if left[name] <= ESCAPE] or direct  # all left: as if unchecked
    best = ok[0]
    judged = [name for name in AUTO_FIT_PREFERENCE if name in ok
              and energy[name] is not None and np.isfinite(energy[name])]
    if judged:
        least = min(energy[name] for name in judged)
        best = next(name for name in judged if energy[name] <= least * (1.0 + AUTO_FIT_TIE))
    choice = {"fit": best, "energy": energy}
    if max(left.values()) > ESCAPE:
        choice["escaped"] = {name: float(e) for name, e in left.items()}
    if best == "lsq" and "sweep" in fits:
        choice["sweep_check"] = sweep_check(cm.spread, fits["lsq"], fits["sweep"], diag)
        if choice["sweep_check"]["departure"] > choice["sweep_check"]["spread"] and "sweep" in ok:
            best = choice["fit"] = "sweep"
    return _fitted(fits[best], iters[best], L, cons, targets, choice, timings, t0)


def _iterate(cm, sharp, L, cons, targets, *, lam, tol, steps, vspring_step):
    """The published iteration (Eq. 3-4) from the Coons control mesh: ``(P, iterations)``."""
    sharp_edges, corners = sharp
    n = len(cm.vertices)
    T1, T2, has = tangent_matrices(cm.quads, n, sharp_edges, corners)
    P, iters, _ = fit_iterative(L, T1, T2, has, cm.quads, cm.vertices, cons, targets,
                                lam=lam, tol=tol, max_iter=steps, sharp_edges=sharp_edges,
                                corners=corners, vspring_step=vspring_step)
    return P, iters


def _energy_level(cm) -> int:
    """Catmull-Clark level of the meshes whose bending energies ``auto`` compares:
    :data:`AUTO_FIT_LEVEL`, lowered while that mesh would exceed
    :data:`AUTO_FIT_MAX_LEVEL_VERTICES` vertices (about ``4**level`` per control quad)."""
    level = AUTO_FIT_LEVEL
    while level > 0 and len(cm.quads) * 4 ** level > AUTO_FIT_MAX_LEVEL_VERTICES:
        level -= 1
    return level


def _fitted(P, iters, L, cons, targets, choice, timings, t0):
    """``_fit_control_net``'s return value, with the sample deviations and the time."""
    sample_dev = np.linalg.norm((L @ P)[cons] - targets, axis=1)
    timings["fit"] = time.perf_counter() - t0
    return P, iters, sample_dev, choice


def _limit_surface(P, cm, sharp, subdiv: int, timings):
    """Subdivide the control net ``subdiv`` times and push the vertices to the limit.

    Returns ``(vertices (n, 3) float64, faces (f, 3) int64, face_patch (f,) int64,
    chains)``, ``chains[c]`` the output vertex ids along curve ``c``.
    """
    t0 = time.perf_counter()
    V, Q, (se, cr) = P, cm.quads, sharp
    fpatch = cm.face_patch
    chains = list(cm.curve_vids)
    for _ in range(subdiv):
        st = subdivision_step(Q, len(V), se, cr)
        nv = len(V)
        new_chains = []
        for ch in chains:
            mid = nv + edge_index(st.topo, ch[:-1], ch[1:])
            out = np.empty(2 * len(ch) - 1, dtype=np.int64)
            out[0::2], out[1::2] = ch, mid
            new_chains.append(out)
        chains = new_chains
        V, Q, se, cr = st.S @ V, st.quads, st.sharp_edges, st.corners
        fpatch = fpatch[st.face_parent]
    Vout = limit_matrix(Q, len(V), se, cr) @ V
    faces = _quads_to_tris(Q)
    timings["output"] = time.perf_counter() - t0
    return Vout, faces, np.concatenate([fpatch, fpatch]), chains


def _curve_fit_report(V, chains, curves, cm, update, timings):
    """Distances of the limit points along the used curves to the input polylines, and the
    curves refitted to the surface (Sec. 4.3.3) when ``update`` lists some (else None)."""
    t0 = time.perf_counter()
    used = np.zeros(len(curves), bool)
    for lp in cm.loops:
        for ci, _ in lp:
            used[ci] = True
    dev = [point_polyline_distance(V[chains[c]], curves[c]) for c in np.flatnonzero(used)]
    dev = np.concatenate(dev) if dev else np.zeros(1)
    new_curves = None
    if update is not None:
        new_curves = list(curves)
        for c in update:
            if used[c]:
                new_curves[c] = fit_cubic_curve(V[chains[c]], len(curves[c]))
    timings["report"] = time.perf_counter() - t0
    return dev, new_curves


def _report(cm, *, fit, dev, sample_dev, iters, timings, crease, detected, n_faces,
            resolution, subdiv) -> dict:
    """The report of :func:`surface_loops`; deviations become fractions of the diagonal."""
    diag = cm.diagonal if cm.diagonal > 0 else 1.0
    kinds: dict = {}
    for k in cm.patch_kind:
        kinds[k] = kinds.get(k, 0) + 1
    return {
        **fit,
        "max_curve_deviation": float(dev.max() / diag),
        "mean_curve_deviation": float(dev.mean() / diag),
        "max_sample_deviation": float(sample_dev.max() / diag) if len(sample_dev) else 0.0,
        "iterations": int(iters),
        "timings": timings,
        "creases": [int(i) for i in np.flatnonzero(crease)],
        "creases_detected": detected,
        "n_patches": len(cm.loops),
        "n_control_vertices": int(len(cm.vertices)),
        "n_faces": int(n_faces),
        "patch_kinds": kinds,
        "resolution": int(resolution) + int(resolution) % 2,
        "subdiv": subdiv,
    }


def explain_fit(report) -> str | None:
    """The line ``--explain`` prints about the fit of a :func:`surface_loops` report.

    Parameters
    ----------
    report : dict or None
        ``PatchMeshResult.report`` (its ``fit`` and, for ``auto``, ``energy``).

    Returns
    -------
    str or None
        None when the report has no fit (another surfacer's).

    Examples
    --------
    >>> line = explain_fit({"fit": "sweep", "energy": {"lsq": 85.9, "sweep": 66.64,
    ...                                                "iterative": None}})
    >>> line.split("; ")[0]
    'fit: sweep (bending energy lsq 85.9, sweep 66.6, iterative not tried'
    >>> print(explain_fit({"fit": "lsq"}))
    fit: lsq
    >>> explain_fit({"fit": "sweep", "energy": {"lsq": 41.5, "sweep": 42.9, "iterative": None},
    ...              "sweep_check": {"spread": 0.0, "departure": 0.0031}}).split("; ")[-1][:57]
    'lsq departs from the swept shape by 0.31% of the diagonal'
    """
    if not report or report.get("fit") not in FITS:
        return None
    energy = report.get("energy")
    if not energy or all(e is None for e in energy.values()):
        return f"fit: {report['fit']}"
    figures = ", ".join(f"{k} {e:.1f}" if e is not None else f"{k} not tried"
                        for k, e in energy.items())
    line = (f"fit: {report['fit']} (bending energy {figures}; the least kept, ties within "
            f"{AUTO_FIT_TIE:.0%} going to {', then '.join(AUTO_FIT_PREFERENCE[:2])}")
    check = report.get("sweep_check")
    if check:
        kept = report["fit"] == "sweep"
        line += (f"; lsq departs from the swept shape by {check['departure']:.2%} of the "
                 f"diagonal, {'more' if kept else 'no more'} than its two sweeps part "
                 f"({check['spread']:.2%}): {'sweep' if kept else 'lsq'} kept")
    if report.get("escaped"):
        left = ", ".join(f"{k} {e:.2f}" for k, e in report["escaped"].items() if e > ESCAPE)
        line += f"; left a loop's box by more than {ESCAPE:g} times its size, not kept: {left}"
    return line + ")"


def soapfilm_loops(curves, loops, *, resolution: int = 16, **_ignored) -> PatchMeshResult:
    """Soap-film baseline (Abbasinejad et al. 2011, Sec. 7) with the classical API.

    Parameters
    ----------
    curves : list of (m_i, 3) float64
    loops : list of list of (int, bool)
    resolution : int
        Boundary segments per curve.
    **_ignored
        Options of :func:`surface_loops` that do not apply (``subdiv``,
        ``crease_curves``, ...), accepted so the two routes share a call site.

    Returns
    -------
    PatchMeshResult
        ``report`` has ``n_patches``, ``timings`` and ``max_curve_deviation`` (0 by
        construction: the boundary samples are vertices).
    """
    t0 = time.perf_counter()
    V, F, fp = soapfilm_mesh(curves, loops, resolution=resolution)
    return PatchMeshResult(V, F, {"fit": "soapfilm", "n_patches": len(loops),
                                  "max_curve_deviation": 0.0,
                                  "timings": {"total": time.perf_counter() - t0}},
                           face_patch=fp)
