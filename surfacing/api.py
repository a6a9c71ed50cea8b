"""One-call surfacing of curve loops: Coons -> Catmull-Clark control mesh -> limit fit.

:func:`surface_loops` is the classical route of Orbay & Kara 2011 (Sec. 4.2-4.3),
with creases, n-sided loops and a direct least-squares fit added;
:func:`soapfilm_loops` is the soap-film baseline of Abbasinejad et al. 2011, Sec. 7.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .catmull_clark import edge_index, subdivision_step
from .controlmesh import build_control_mesh
from .creases import DEFAULT_CREASE_ANGLE, sharp_structure
from .curveupdate import fit_cubic_curve
from .fit import (FAIRNESS, LAMBDA, VSPRING_STEP, fairness_matrix, fit_iterative, fit_lsq,
                  variation_matrix)
from .limit import limit_matrix, tangent_matrices
from .polyline import point_polyline_distance
from .sides import DEFAULT_STRAIGHT_ANGLE
from .soap import soapfilm_mesh

__all__ = ["SurfaceResult", "surface_loops", "soapfilm_loops", "DEFAULT_RESOLUTION",
           "DEFAULT_SUBDIV", "DEFAULT_TOL"]

#: Control-polygon segments per curve (the paper's user-set N).
DEFAULT_RESOLUTION = 4
#: Catmull-Clark levels of the output mesh.
DEFAULT_SUBDIV = 3
#: Curve-interpolation tolerance of the iterative fit, fraction of the diagonal.
DEFAULT_TOL = 1e-4


@dataclass
class SurfaceResult:
    """A surfaced patch set.

    Attributes
    ----------
    vertices : (n, 3) float64
        Limit-surface points (subdivided ``subdiv`` times, then pushed to the limit).
    faces : (f, 3) int64
        Triangles, two per limit quad, oriented like the loops.
    face_patch : (f,) int64
        Loop index of each triangle.
    report : dict
        ``max_curve_deviation`` / ``mean_curve_deviation`` (limit points along the
        curves to the input polylines, fraction of the diagonal),
        ``max_sample_deviation`` (at the fitted samples), ``iterations``,
        ``timings`` (seconds), ``creases`` (crease curves), ``creases_detected``
        (made creases by the dihedral test), ``n_patches``, ``n_control_vertices``,
        ``patch_kinds``, ``fit``.
    curves : list of (m_i, 3) float64 or None
        Updated network curves when ``update_curves`` was asked for.
    control_vertices, control_quads : arrays or None
        The fitted control mesh (classical route only).
    """

    vertices: np.ndarray
    faces: np.ndarray
    face_patch: np.ndarray
    report: dict = field(default_factory=dict)
    curves: list | None = None
    control_vertices: np.ndarray | None = None
    control_quads: np.ndarray | None = None


def _quads_to_tris(q: np.ndarray) -> np.ndarray:
    return np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]]).astype(np.int64)


#: Largest output ``surface_loops`` accepts, in triangles (estimated before any allocation).
MAX_OUTPUT_FACES = 20_000_000


def _check_output_size(n_loops: int, resolution: int, subdiv: int) -> None:
    """Refuse settings whose output would not fit in memory, before building anything.

    A four-sided patch with one piece per side gives ``2 * r**2 * 4**subdiv`` triangles
    (``r`` = resolution rounded up to even), so this is a lower bound.
    """
    r = int(resolution) + int(resolution) % 2
    faces = 2 * max(n_loops, 1) * r * r * 4 ** subdiv
    if faces > MAX_OUTPUT_FACES:
        raise ValueError(f"resolution {resolution} with subdiv {subdiv} would write at least "
                         f"{faces:.3g} triangles for {n_loops} patches; the limit is "
                         f"{MAX_OUTPUT_FACES:.3g} (lower --resolution or --subdiv)")


def surface_loops(curves, loops, *, crease_curves=(), crease_angle: float | None =
                  DEFAULT_CREASE_ANGLE, resolution: int = DEFAULT_RESOLUTION,
                  subdiv: int = DEFAULT_SUBDIV, fit: str = "lsq", update_curves=False,
                  straight_angle: float = DEFAULT_STRAIGHT_ANGLE, tol: float = DEFAULT_TOL,
                  max_iter: int = 500, lam: float = LAMBDA,
                  curve_weight: float | None = None,
                  fairness: str = "variation",
                  vspring_step: float = VSPRING_STEP) -> SurfaceResult:
    """Smooth surface through a curve network's loops (Orbay & Kara 2011, Sec. 4.2-4.3).

    Parameters
    ----------
    curves : list of (m_i, 3) float64
        Network curves (polylines); curves meeting at a junction share end points.
    loops : list of list of (int, bool)
        Patches: each a closed loop of (curve index, traversed forward). Loops that
        traverse shared curves in opposite directions give a consistently oriented
        mesh; inconsistent loops are flipped to agree (first loop wins).
    crease_curves : iterable of int
        Curves labelled crease.
    crease_angle : float or None
        Degrees; shared curves whose patches meet at a larger dihedral angle become
        creases too. None: labelled creases only.
    resolution : int
        Control-polygon segments per curve piece (>= 2; odd values are rounded up to
        even). Long or winding curves get several pieces (see
        :func:`surfacing.controlmesh.curve_pieces`).
    subdiv : int
        Catmull-Clark levels for the output mesh (>= 0).
    fit : {"lsq", "iterative"}
        Direct sparse least squares with exact interpolation of the curve samples
        (default), or the published iteration (Eq. 3 with V-spring, Eq. 4).
    update_curves : bool or iterable of int
        Return curves refitted to the surface (Sec. 4.3.3): all when True, else the
        given indices (the others are returned unchanged).
    straight_angle : float
        Degrees; curves turning less at a junction form one patch side, and two sharp
        curves turning more make a corner.
    tol : float
        Iterative fit: stop tolerance on curve deviation, fraction of the diagonal.
    max_iter : int
        Iterative fit: iteration cap.
    lam : float
        Iterative fit: damping of Eq. 3.
    curve_weight : float or None
        lsq fit: None interpolates exactly; a positive weight trades interpolation
        for fairness (use with ``update_curves``).
    vspring_step : float
        Iterative fit: fraction of the V-spring displacement applied per iteration
        (1.0 as published; 0.5 by default, see :data:`surfacing.fit.VSPRING_STEP`).
    fairness : {"variation", "thin-plate"}
        lsq fit energy: differences of the control net's umbrella Laplacian across
        edges (linear curvature variation, default) or the Laplacian itself.

    Returns
    -------
    SurfaceResult

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0, 1, 9)[:, None]
    >>> sq = [t * [1, 0, 0], [1, 0, 0] + t * [0, 1, 0], [1, 1, 0] - t * [1, 0, 0],
    ...       [0, 1, 0] - t * [0, 1, 0]]
    >>> res = surface_loops(sq, [[(0, True), (1, True), (2, True), (3, True)]])
    >>> bool(np.abs(res.vertices[:, 2]).max() < 1e-12)
    True

    Notes
    -----
    Output vertex order: the vertices of the last subdivision level, pushed to their
    limit positions with :func:`surfacing.limit.limit_matrix`. ``report`` deviations
    are fractions of the curves' bounding-box diagonal.

    References
    ----------
    Orbay & Kara 2011, Sec. 4.2 (Coons patches), 4.3.1 (limit masks, Eq. 1-2),
    4.3.2 (Eq. 3-4), 4.3.3 (curve update); Halstead, Kass & DeRose 1993.
    """
    if fit not in ("lsq", "iterative"):
        raise ValueError(f"fit: expected 'lsq' or 'iterative', got {fit!r}")
    if int(subdiv) != subdiv or subdiv < 0:
        raise ValueError(f"subdiv: expected an integer >= 0, got {subdiv!r}")
    _check_output_size(len(loops), resolution, int(subdiv))
    if fairness not in FAIRNESS:
        raise ValueError(f"fairness: expected one of {FAIRNESS}, got {fairness!r}")
    if not tol > 0:
        raise ValueError(f"tol: expected > 0, got {tol!r}")
    subdiv = int(subdiv)
    timings = {}
    t0 = time.perf_counter()
    cm = build_control_mesh(curves, loops, resolution, straight_angle=straight_angle)
    curves = [np.asarray(c, dtype=np.float64) for c in curves]
    diag = cm.diagonal if cm.diagonal > 0 else 1.0
    crease, detected, sharp_edges, corners, dih = sharp_structure(
        cm, curves, crease_curves, crease_angle=crease_angle, straight_angle=straight_angle)
    timings["build"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    n = len(cm.vertices)
    L = limit_matrix(cm.quads, n, sharp_edges, corners)
    cons = np.flatnonzero(cm.on_curve)
    targets = cm.target[cons]
    if fit == "lsq":
        F = fairness_matrix(cm.quads, n, sharp_edges, corners)
        if fairness == "variation":
            F = variation_matrix(F)
        P = fit_lsq(L, F, cm.vertices, cons, targets, curve_weight=curve_weight)
        iters = 1
    else:
        T1, T2, has = tangent_matrices(cm.quads, n, sharp_edges, corners)
        P, iters, _ = fit_iterative(L, T1, T2, has, cm.quads, cm.vertices, cons, targets,
                                    lam=lam, tol=tol * diag, max_iter=max_iter,
                                    sharp_edges=sharp_edges, corners=corners,
                                    vspring_step=vspring_step)
    sample_dev = np.linalg.norm((L @ P)[cons] - targets, axis=1)
    timings["fit"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    V, Q, se, cr = P, cm.quads, sharp_edges, corners
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
    Lk = limit_matrix(Q, len(V), se, cr)
    Vout = Lk @ V
    faces = _quads_to_tris(Q)
    face_patch = np.concatenate([fpatch, fpatch])
    timings["output"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    used = np.zeros(len(curves), bool)
    for lp in cm.loops:
        for ci, _ in lp:
            used[ci] = True
    dev = [point_polyline_distance(Vout[chains[c]], curves[c]) for c in np.flatnonzero(used)]
    dev = np.concatenate(dev) if dev else np.zeros(1)
    new_curves = None
    if update_curves is not False and update_curves is not None:
        sel = range(len(curves)) if update_curves is True else [int(i) for i in update_curves]
        new_curves = list(curves)
        for c in sel:
            if not 0 <= c < len(curves):
                raise ValueError(f"update_curves: index {c} out of range [0, {len(curves)})")
            if used[c]:
                new_curves[c] = fit_cubic_curve(Vout[chains[c]], len(curves[c]))
    timings["report"] = time.perf_counter() - t0
    kinds: dict = {}
    for k in cm.patch_kind:
        kinds[k] = kinds.get(k, 0) + 1
    report = {
        "fit": fit,
        "max_curve_deviation": float(dev.max() / diag),
        "mean_curve_deviation": float(dev.mean() / diag),
        "max_sample_deviation": float(sample_dev.max() / diag) if len(sample_dev) else 0.0,
        "iterations": int(iters),
        "timings": timings,
        "creases": [int(i) for i in np.flatnonzero(crease)],
        "creases_detected": detected,
        "n_patches": len(cm.loops),
        "n_control_vertices": int(n),
        "n_faces": int(len(faces)),
        "patch_kinds": kinds,
        "resolution": int(resolution) + int(resolution) % 2,
        "subdiv": subdiv,
    }
    return SurfaceResult(Vout, faces, face_patch, report, new_curves, P, cm.quads)


def soapfilm_loops(curves, loops, *, resolution: int = 16, **_ignored) -> SurfaceResult:
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
    SurfaceResult
        ``report`` has ``n_patches``, ``timings`` and ``max_curve_deviation`` (0 by
        construction: the boundary samples are vertices).
    """
    t0 = time.perf_counter()
    V, F, fp = soapfilm_mesh(curves, loops, resolution=resolution)
    return SurfaceResult(V, F, fp, {"fit": "soapfilm", "n_patches": len(loops),
                                    "max_curve_deviation": 0.0,
                                    "timings": {"total": time.perf_counter() - t0}})
