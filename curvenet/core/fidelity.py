"""Stroke fidelity: how much of a sketch's stroke length a surface passes through.

The strokes are resampled by arc length (:func:`stroke_samples`), so every stretch
weighs by its length; a sample counts as on the surface within a fraction of a
diagonal. :func:`sketch_fidelity` is what ``curvenet surface --explain`` reports and
what the neural route's polish guard compares; :func:`stroke_fidelity` measures
against the surface's diagonal (the batch report's column).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from .distance import drop_degenerate, load_mesh_arrays, point_surface_distance
from .errors import InvalidParameterError
from .geometry import as_polyline, bbox_diagonal, densify_polyline
from .tolerances import DIVISION_GUARD

__all__ = ["STROKE_SPACING_REL", "FIDELITY_TOL_REL", "stroke_list", "stroke_samples",
           "stroke_sample_distances", "stroke_fidelity", "sketch_fidelity", "format_fidelity"]

#: Stroke polylines are resampled with this spacing relative to the sketch's bbox diagonal.
STROKE_SPACING_REL = 1e-3

#: Stroke fidelity counts stroke length within this fraction of the surface's bbox diagonal.
FIDELITY_TOL_REL = 0.01


def stroke_list(strokes) -> list:
    """Strokes as a list of (n, 3) arrays; a Sketch drops its 'construction' strokes."""
    if hasattr(strokes, "strokes") and hasattr(strokes, "labels"):  # Sketch
        return [s for s, lab in zip(strokes.strokes, strokes.labels) if lab != "construction"]
    if hasattr(strokes, "edges") and hasattr(strokes, "positions"):  # CurveNetwork
        return [e.curve for e in strokes.edges]
    if isinstance(strokes, np.ndarray) and strokes.ndim == 2:
        return [strokes]
    try:
        return list(strokes)
    except TypeError:
        raise InvalidParameterError(
            f"strokes: expected a Sketch, a CurveNetwork or a list of (n, 3) arrays, "
            f"got {type(strokes).__name__}") from None


def stroke_samples(strokes, spacing):
    """Arc-length samples of the strokes, ``spacing`` of the sketch's diagonal apart.

    Returns ``(lines, diag, samples, counts)``: ``lines`` the strokes as (n, 3) float64
    arrays, ``diag`` the sketch's bounding-box diagonal, ``samples`` (k, 3) float64 the
    samples of every stroke in stroke order, ``counts`` (len(lines),) int64 the samples
    per stroke.
    """
    if not (isinstance(spacing, (int, float, np.floating)) and math.isfinite(spacing)
            and spacing > 0):
        raise InvalidParameterError(f"spacing must be a positive number, got {spacing!r}")
    lines = [as_polyline(s, name=f"strokes[{i}]") for i, s in enumerate(stroke_list(strokes))]
    if not lines:
        raise InvalidParameterError("strokes: no strokes to measure")
    diag = bbox_diagonal(lines)
    if not diag > 0:
        raise InvalidParameterError("strokes: the sketch has zero extent")
    dense = [densify_polyline(pl, spacing * diag) for pl in lines]
    return lines, diag, np.concatenate(dense), np.array([len(p) for p in dense], np.int64)


def stroke_sample_distances(mesh, strokes, spacing):
    """Distances from arc-length stroke samples to the mesh (input units).

    Returns ``(d, diag, vertices, samples)``: ``d`` (k,) float64 per sample, ``diag`` the
    sketch's bounding-box diagonal (samples are ``spacing * diag`` apart), ``vertices``
    (V, 3) float64 of the mesh, ``samples`` (k, 3) float64 the stroke samples
    (:func:`stroke_samples`).
    """
    _lines, diag, pts, _counts = stroke_samples(strokes, spacing)
    v, f = load_mesh_arrays(mesh, name="mesh")
    f, _n, _a = drop_degenerate(v, f)
    if len(f) == 0:
        raise InvalidParameterError("mesh: all triangles have zero area")
    d, _ = point_surface_distance(pts, v, f)
    return d, diag, v, pts


def stroke_fidelity(mesh, strokes, *, tol: float = FIDELITY_TOL_REL,
                    spacing: float = STROKE_SPACING_REL) -> dict:
    """How much of the sketch the surface passes through: the batch report's fidelity.

    Parameters
    ----------
    mesh : trimesh.Trimesh, (vertices, faces) pair or path
    strokes : Sketch, CurveNetwork, list of (n, 3) array_like, or path of a sketch file
        As in :func:`stroke_distance`.
    tol : float, default 0.01
        Distance counted as "on the surface", relative to the *surface's* bounding-box
        diagonal.
    spacing : float, default 1e-3
        Arc-length resampling step relative to the sketch's diagonal (as in
        :func:`stroke_distance`), so the share below is a share of stroke length.

    Returns
    -------
    dict
        ``fidelity`` (share of stroke length within ``tol`` of the surface, in [0, 1]),
        ``median`` and ``p95`` (stroke-to-surface distance, divided by the surface's
        diagonal), ``diagonal`` (the surface's bbox diagonal, input units).

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box()
    >>> stroke_fidelity(box, [[[-0.5, -0.5, 0.5], [0.5, -0.5, 0.5]]])["fidelity"]
    1.0
    """
    if not (isinstance(tol, (int, float, np.floating)) and 0 < tol < 1):
        raise InvalidParameterError(f"tol must be a number in (0, 1), got {tol!r}")
    d, _sketch_diag, v, _pts = stroke_sample_distances(mesh, strokes, spacing)
    diag = bbox_diagonal(v)
    d = d / max(diag, DIVISION_GUARD)
    return {"fidelity": float(np.mean(d < tol)), "median": float(np.median(d)),
            "p95": float(np.percentile(d, 95)), "diagonal": diag}


def sketch_fidelity(mesh, strokes, *, wires=(), tol: float = FIDELITY_TOL_REL,
                    spacing: float = STROKE_SPACING_REL) -> dict:
    """Stroke fidelity against the *sketch's* diagonal, of the surface and of surface + wires.

    A stroke kept as a wire (a polyline written beside the mesh) counts as represented
    where it lies within ``tol`` of a wire.

    Parameters
    ----------
    mesh : trimesh.Trimesh, (vertices, faces) pair or path
    strokes : Sketch, CurveNetwork, list of (n, 3) array_like, or path of a sketch file
        As in :func:`stroke_distance`.
    wires : list of (m, 3) array_like
        Polylines of the output kept as wires (may be empty).
    tol : float, default 0.01
        Distance counted as "represented", relative to the sketch's bounding-box diagonal.
    spacing : float, default 1e-3
        Arc-length resampling step of strokes and wires, relative to the sketch's diagonal.

    Returns
    -------
    dict
        ``surface`` and ``with_wires`` (share of stroke length within ``tol`` of the
        surface, of the surface or a wire), ``wire_share`` (share of stroke length that
        only a wire represents), ``median`` and ``p95`` (stroke-to-surface distance /
        the sketch's diagonal), ``median_with_wires`` and ``p95_with_wires`` (distance to
        the nearer of surface and wires), ``diagonal`` (the sketch's, input units).

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box()
    >>> far = [[2.0, 0, 0], [3.0, 0, 0]]
    >>> f = sketch_fidelity(box, [[[-0.5, -0.5, 0.5], [0.5, -0.5, 0.5]], far], wires=[far])
    >>> round(f["surface"], 2), f["with_wires"], round(f["wire_share"], 2)
    (0.5, 1.0, 0.5)
    """
    if not (isinstance(tol, (int, float, np.floating)) and 0 < tol < 1):
        raise InvalidParameterError(f"tol must be a number in (0, 1), got {tol!r}")
    d, diag, _v, pts = stroke_sample_distances(mesh, strokes, spacing)
    d = d / diag
    both = d
    lines = [as_polyline(w, name=f"wires[{i}]") for i, w in enumerate(wires)]
    if lines:
        dense = np.concatenate([densify_polyline(pl, spacing * diag) for pl in lines])
        both = np.minimum(d, cKDTree(dense).query(pts)[0] / diag)
    return {"surface": float(np.mean(d < tol)), "with_wires": float(np.mean(both < tol)),
            "wire_share": float(np.mean((both < tol) & ~(d < tol))),
            "median": float(np.median(d)), "p95": float(np.percentile(d, 95)),
            "median_with_wires": float(np.median(both)),
            "p95_with_wires": float(np.percentile(both, 95)), "diagonal": diag, "tol": tol}


def format_fidelity(fid: dict) -> str:
    """One line of :func:`sketch_fidelity`'s figures, as ``--explain`` prints it.

    Examples
    --------
    >>> print(format_fidelity({"surface": 0.9, "with_wires": 0.95, "wire_share": 0.05,
    ...                        "median": 1e-3, "p95": 0.02}))  # doctest: +NORMALIZE_WHITESPACE
    fidelity: 90% of stroke length within 1% of the diagonal
    (95% with wires, 5% on wires only); median 0.10%, p95 2.00% of the diagonal
    """
    return (f"fidelity: {fid['surface']:.0%} of stroke length within "
            f"{fid.get('tol', FIDELITY_TOL_REL):.0%} of the diagonal "
            f"({fid['with_wires']:.0%} with wires, {fid['wire_share']:.0%} on wires only); "
            f"median {fid['median']:.2%}, p95 {fid['p95']:.2%} of the diagonal")
