"""Mesh quality metrics: Chamfer, Hausdorff, normal error, F-score; stroke-to-surface distance.

The metrics follow the SharpNet paper (Niu et al. 2025, Sec. 5, "Metrics"), with one
deliberate change (the project's ``curvenet eval``): distances are
measured from points sampled on one mesh to the *other mesh's triangles*, not to the
other mesh's sample points, so the sampling density sets no floor on the scores (with
100k point-to-point samples a perfect unit sphere would already score a Chamfer distance
of about 2.8e-3).

Both meshes are scaled (about the reference's bounding-box centre) so that the
reference's longest bounding-box side is 1 before anything is measured; all distances
in the results are in those units.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..core.geometry import as_polyline, densify_polyline, face_normals_areas, sample_surface
from ..core.tolerances import DEGENERATE_AREA_REL, DIVISION_GUARD
from ..core.errors import InvalidParameterError, SketchFormatError

__all__ = ["evaluate_mesh", "stroke_distance", "stroke_fidelity", "sketch_fidelity",
           "format_report",
           "load_mesh_arrays", "sample_surface", "point_surface_distance", "stroke_samples"]

#: Stroke polylines are resampled with this spacing relative to the sketch's bbox diagonal.
STROKE_SPACING_REL = 1e-3

#: Stroke fidelity counts stroke length within this fraction of the surface's bbox diagonal.
FIDELITY_TOL_REL = 0.01


# ---------------------------------------------------------------------------
# input handling
# ---------------------------------------------------------------------------
def load_mesh_arrays(mesh, *, name: str = "mesh") -> tuple[np.ndarray, np.ndarray]:
    """Turn a mesh argument into validated ``(vertices, faces)`` arrays.

    Parameters
    ----------
    mesh : trimesh.Trimesh, (vertices, faces) pair, object with ``.vertices`` and
        ``.faces``, or str / os.PathLike
        A path is loaded with ``trimesh.load(path, force="mesh")`` (OBJ, PLY, STL, OFF, ...).
    name : str
        Parameter name used in error messages.

    Returns
    -------
    vertices : (n, 3) float64 ndarray
    faces : (m, 3) int64 ndarray
        ``m >= 1``; degenerate (zero-area) triangles are kept here.

    Raises
    ------
    SketchFormatError
        A file that cannot be read or holds no triangles (the message names the file).
    InvalidParameterError
        Arrays of the wrong shape, NaN/inf coordinates, out-of-range face indices, no
        faces, or zero total area.
    """
    path = None
    if isinstance(mesh, (str, os.PathLike)):
        path = Path(mesh)
        import trimesh

        try:
            # process=False: trimesh's clean-up would drop NaN vertices before the check below
            loaded = trimesh.load(str(path), force="mesh", process=False)
        except Exception as err:  # trimesh raises many types (ValueError, KeyError, ...)
            # an ImportError here is trimesh guessing a text encoding, not a missing feature
            why = "" if isinstance(err, ImportError) else f" ({err})"
            kind = path.suffix.lstrip(".").upper() or "mesh"
            raise SketchFormatError(f"not a readable {kind} mesh{why}", path=path) from None
        if not hasattr(loaded, "faces") or len(loaded.faces) == 0:
            raise SketchFormatError("no triangles in mesh file", path=path)
        vertices, faces = loaded.vertices, loaded.faces
    elif hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        vertices, faces = mesh.vertices, mesh.faces
    elif isinstance(mesh, (tuple, list)) and len(mesh) == 2:
        vertices, faces = mesh
    else:
        raise InvalidParameterError(
            f"{name}: expected a trimesh.Trimesh, a (vertices, faces) pair or a path, "
            f"got {type(mesh).__name__}")

    def fail(message):
        if path is not None:
            raise SketchFormatError(message, path=path)
        raise InvalidParameterError(f"{name}: {message}")

    try:
        v = np.asarray(vertices, dtype=np.float64)
        f = np.asarray(faces)
    except (TypeError, ValueError) as err:
        fail(f"cannot convert to arrays ({err})")
    if v.ndim != 2 or v.shape[1] != 3:
        fail(f"vertices must be (n, 3), got shape {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3 or len(f) == 0:
        fail(f"faces must be (m, 3) with m >= 1, got shape {f.shape}")
    if not np.issubdtype(f.dtype, np.integer):
        fail(f"faces must be integers, got dtype {f.dtype}")
    if not np.isfinite(v).all():
        fail("vertices contain NaN or infinite coordinates")
    f = f.astype(np.int64)
    if f.min() < 0 or f.max() >= len(v):
        fail(f"face indices out of range 0..{len(v) - 1}")
    return np.ascontiguousarray(v), np.ascontiguousarray(f)


def _drop_degenerate(vertices, faces):
    """Faces, unit normals and areas of the non-degenerate triangles only."""
    normals, areas = face_normals_areas(vertices, faces)
    diag2 = float(np.sum(np.ptp(vertices, axis=0) ** 2))
    keep = areas > DEGENERATE_AREA_REL * max(diag2, DIVISION_GUARD)
    return faces[keep], normals[keep], areas[keep]


# ---------------------------------------------------------------------------
# core array functions
# ---------------------------------------------------------------------------
def point_surface_distance(points, vertices, faces, *, closest: bool = False) -> tuple:
    """Unsigned distance from points to a triangle mesh's surface, and the closest triangle.

    Parameters
    ----------
    points : (n, 3) float64
    vertices : (V, 3) float64
    faces : (F, 3) int64

    Returns
    -------
    distance : (n,) float64
    face_index : (n,) int64
        Index (into ``faces``) of a closest triangle; at a point equidistant from several
        triangles (closest point on a shared edge or vertex) one of them.
    closest_points : (n, 3) float64
        Only with ``closest=True``: the closest point of the surface to each point.

    Notes
    -----
    Uses libigl's AABB tree (``igl.point_mesh_squared_distance``), O((n + F) log F).
    """
    import igl

    sq, idx, near = igl.point_mesh_squared_distance(
        np.ascontiguousarray(points, dtype=np.float64),
        np.ascontiguousarray(vertices, dtype=np.float64),
        np.ascontiguousarray(faces, dtype=np.int64))
    out = np.sqrt(np.maximum(sq, 0.0)), np.asarray(idx, dtype=np.int64)
    return out + (np.asarray(near, dtype=np.float64),) if closest else out


def _check_options(n_samples, threshold):
    if isinstance(n_samples, bool) or not isinstance(n_samples, (int, np.integer)) \
            or n_samples < 1:
        raise InvalidParameterError(f"n_samples must be a positive integer, got {n_samples!r}")
    if not (isinstance(threshold, (int, float, np.floating)) and math.isfinite(threshold)
            and threshold > 0):
        raise InvalidParameterError(f"threshold must be a positive number, got {threshold!r}")


def evaluate_mesh(mesh, reference, *, n_samples: int = 100_000, threshold: float = 0.01,
                  seed: int = 0) -> dict:
    """Chamfer, Hausdorff, normal error and F-score of ``mesh`` against ``reference``.

    Parameters
    ----------
    mesh, reference : trimesh.Trimesh, (vertices, faces) pair or path
        Triangle meshes; see :func:`load_mesh_arrays`. Orientation and closedness do not
        matter.
    n_samples : int, default 100000
        Points sampled on *each* mesh (area-weighted, uniform).
    threshold : float, default 0.01
        F-score distance threshold ``r``, in normalised units (reference's longest
        bounding-box side = 1).
    seed : int, default 0
        Seed of the sampling; equal seeds give equal results.

    Returns
    -------
    dict
        ``chamfer`` (float), ``hausdorff`` (float), ``normal_error_deg`` (float, degrees),
        ``fscore`` (float in [0, 1]), ``precision`` (fraction of mesh samples within
        ``threshold`` of the reference surface), ``recall`` (fraction of reference samples
        within ``threshold`` of the mesh surface), ``mean_mesh_to_reference``,
        ``mean_reference_to_mesh``, ``n_samples`` (int, per mesh), ``threshold``, and
        ``scale`` (the factor applied to both meshes' coordinates: one over the reference's
        longest bounding-box side).

    Raises
    ------
    SketchFormatError
        A mesh file that cannot be read or holds no triangles.
    InvalidParameterError
        Bad arrays, a reference of zero extent, or bad options.

    Notes
    -----
    With :math:`P_1` sampled on ``mesh``, :math:`P_2` on ``reference``, :math:`S_1, S_2`
    the two surfaces and :math:`d(p, S)` the Euclidean distance from ``p`` to the closest
    point of the triangles of ``S``:

    * Chamfer: ``CD = mean_{p in P1} d(p, S2) / 2 + mean_{p in P2} d(p, S1) / 2``
      (the mean of the two mean distances, not squared);
    * Hausdorff: ``HD = max(max_{P1} d(p, S2), max_{P2} d(p, S1))``;
    * normal error: ``NE = mean_{P1} arccos|n_p . n_q| / 2 + mean_{P2} arccos|n_p . n_q| / 2``
      in degrees, where ``n_p`` is the normal of the triangle ``p`` was sampled on and
      ``n_q`` the normal of the closest triangle of the other mesh. The absolute value
      makes it orientation-agnostic, as in the paper: a mesh with flipped faces scores 0;
    * F-score: ``FC = 2 R1 R2 / (R1 + R2)`` with ``R1`` (``precision``) and ``R2``
      (``recall``) the fractions of samples at distance ``< threshold`` (strict, as in
      the paper); 0 when both are 0.

    Deviation from the paper: the paper takes nearest neighbours in the other *point set*;
    here the other *surface* is used, so a mesh scored against itself gives 0 whatever
    ``n_samples``. At a point whose closest point is on an edge shared by several
    triangles, the normal of one of them is used (the paper has the same ambiguity with
    sample normals). Zero-area triangles (area below ``1e-14`` times the squared bbox
    diagonal) are ignored: they have no normal and no area to sample.

    References
    ----------
    Niu et al. 2025, "SharpNet", Sec. 5, Metrics (CD, HD, NE, FC definitions).

    Examples
    --------
    >>> import trimesh
    >>> a = trimesh.creation.icosphere(subdivisions=3)
    >>> m = evaluate_mesh(a, a, n_samples=1000)
    >>> m["chamfer"] < 1e-9, m["fscore"]
    (True, 1.0)
    """
    _check_options(n_samples, threshold)
    v1, f1 = load_mesh_arrays(mesh, name="mesh")
    v2, f2 = load_mesh_arrays(reference, name="reference")
    lo, hi = v2[f2.ravel()].min(axis=0), v2[f2.ravel()].max(axis=0)
    longest = float(np.max(hi - lo))
    if not longest > 0:
        raise InvalidParameterError("reference: bounding box has zero extent")
    scale = 1.0 / longest
    centre = 0.5 * (lo + hi)
    size_ratio = _size_ratio(v1[f1.ravel()], longest)
    v1 = (v1 - centre) * scale
    v2 = (v2 - centre) * scale
    f1, n1, a1 = _drop_degenerate(v1, f1)
    f2, n2, a2 = _drop_degenerate(v2, f2)
    for name, f in (("mesh", f1), ("reference", f2)):
        if len(f) == 0:
            raise InvalidParameterError(f"{name}: all triangles have zero area")
    metrics = _evaluate_impl(v1, f1, n1, a1, v2, f2, n2, a2, int(n_samples), float(threshold),
                             np.random.default_rng(seed), scale)
    if not (1 / UNIT_MISMATCH_RATIO <= size_ratio <= UNIT_MISMATCH_RATIO):
        metrics["warnings"] = [f"the mesh is {size_ratio:.3g}x the size of the reference "
                               "(longest bounding-box side): different units?"]
    return metrics


#: ``evaluate_mesh`` warns when the mesh and the reference differ in size by more than this.
UNIT_MISMATCH_RATIO = 10.0


def _size_ratio(points, reference_longest: float) -> float:
    """Longest bounding-box side of ``points (n, 3)`` over the reference's."""
    return float(np.max(points.max(axis=0) - points.min(axis=0))) / reference_longest


def _evaluate_impl(v1, f1, n1, a1, v2, f2, n2, a2, n, r, rng, scale) -> dict:
    p1, i1 = sample_surface(v1, f1, n, rng, areas=a1)  # on mesh
    p2, i2 = sample_surface(v2, f2, n, rng, areas=a2)  # on reference
    d12, j12 = point_surface_distance(p1, v2, f2)  # mesh samples -> reference surface
    d21, j21 = point_surface_distance(p2, v1, f1)  # reference samples -> mesh surface

    def angles(na, nb):
        cos = np.abs(np.einsum("ij,ij->i", na, nb))
        return np.degrees(np.arccos(np.clip(cos, 0.0, 1.0)))

    ne = 0.5 * angles(n1[i1], n2[j12]).mean() + 0.5 * angles(n2[i2], n1[j21]).mean()
    precision = float(np.mean(d12 < r))
    recall = float(np.mean(d21 < r))
    fscore = 0.0 if precision + recall == 0 else 2 * precision * recall / (precision + recall)
    return {
        "chamfer": float(0.5 * d12.mean() + 0.5 * d21.mean()),
        "hausdorff": float(max(d12.max(), d21.max())),
        "normal_error_deg": float(ne),
        "fscore": float(fscore),
        "precision": precision,
        "recall": recall,
        "mean_mesh_to_reference": float(d12.mean()),
        "mean_reference_to_mesh": float(d21.mean()),
        "n_samples": int(n),
        "threshold": float(r),
        "scale": float(scale),
    }


# ---------------------------------------------------------------------------
# strokes
# ---------------------------------------------------------------------------
def _stroke_list(strokes) -> list:
    """Strokes as a list of (n, 3) arrays; a Sketch drops its 'construction' strokes."""
    if isinstance(strokes, (str, os.PathLike)):
        from ..io.sketch import read_sketch

        strokes = read_sketch(strokes)
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


def stroke_distance(mesh, strokes, *, spacing: float = STROKE_SPACING_REL) -> dict:
    """How closely a surface passes through the sketch's strokes.

    Parameters
    ----------
    mesh : trimesh.Trimesh, (vertices, faces) pair or path
    strokes : Sketch, CurveNetwork, list of (n, 3) array_like, or path of a sketch file
        A :class:`~curvenet.model.sketch.Sketch` contributes its non-``construction`` strokes;
        a network its edge curves.
    spacing : float, default 1e-3
        Strokes are resampled by arc length at this spacing, relative to the sketch's
        bounding-box diagonal, so every stretch of stroke weighs by its length.

    Returns
    -------
    dict
        ``stroke_mean``, ``stroke_max``, ``stroke_p95`` (mean, maximum and 95th percentile
        of the distance from stroke samples to the surface, divided by the sketch's
        bounding-box diagonal), ``stroke_within_1pct`` (fraction of samples closer than
        1% of the diagonal), ``diagonal`` (the sketch's bbox diagonal, input units) and
        ``n_stroke_samples``.

    Raises
    ------
    InvalidParameterError
        No strokes, a malformed stroke, a sketch of zero extent, or bad ``spacing``.

    Notes
    -----
    Not in the SharpNet paper; this is the project's "stroke distance" column (issue 7):
    the surface should interpolate the curves it was built from.

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box()
    >>> d = stroke_distance(box, [[[-0.5, -0.5, 0.5], [0.5, -0.5, 0.5]]])
    >>> d["stroke_max"] < 1e-12
    True
    """
    d, diag, _v, _pts = _stroke_sample_distances(mesh, strokes, spacing)
    d = d / diag
    return {
        "stroke_mean": float(d.mean()),
        "stroke_max": float(d.max()),
        "stroke_p95": float(np.percentile(d, 95)),
        "stroke_within_1pct": float(np.mean(d < 0.01)),
        "diagonal": diag,
        "n_stroke_samples": int(len(d)),
    }


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
    lines = [as_polyline(s, name=f"strokes[{i}]") for i, s in enumerate(_stroke_list(strokes))]
    if not lines:
        raise InvalidParameterError("strokes: no strokes to measure")
    diag = float(np.linalg.norm(np.ptp(np.concatenate(lines), axis=0)))
    if not diag > 0:
        raise InvalidParameterError("strokes: the sketch has zero extent")
    dense = [densify_polyline(pl, spacing * diag) for pl in lines]
    return lines, diag, np.concatenate(dense), np.array([len(p) for p in dense], np.int64)


def _stroke_sample_distances(mesh, strokes, spacing):
    """Distances from arc-length stroke samples to the mesh (input units).

    Returns ``(d, diag, vertices, samples)``: ``d`` (k,) float64 per sample, ``diag`` the
    sketch's bounding-box diagonal (samples are ``spacing * diag`` apart), ``vertices``
    (V, 3) float64 of the mesh, ``samples`` (k, 3) float64 the stroke samples
    (:func:`stroke_samples`).
    """
    _lines, diag, pts, _counts = stroke_samples(strokes, spacing)
    v, f = load_mesh_arrays(mesh, name="mesh")
    f, _n, _a = _drop_degenerate(v, f)
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
    d, _sketch_diag, v, _pts = _stroke_sample_distances(mesh, strokes, spacing)
    diag = float(np.linalg.norm(np.ptp(v, axis=0)))
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
    d, diag, _v, pts = _stroke_sample_distances(mesh, strokes, spacing)
    d = d / diag
    both = d
    lines = [as_polyline(w, name=f"wires[{i}]") for i, w in enumerate(wires)]
    if lines:
        from scipy.spatial import cKDTree
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


# ---------------------------------------------------------------------------
# report
# ---------------------------------------------------------------------------
_ROWS = (  # key, label, format
    ("chamfer", "Chamfer distance", "{:.4e}"),
    ("hausdorff", "Hausdorff distance", "{:.4e}"),
    ("normal_error_deg", "normal error (deg)", "{:.3f}"),
    ("fscore", "F-score @ {threshold:g}", "{:.2%}"),
    ("precision", "  precision", "{:.2%}"),
    ("recall", "  recall", "{:.2%}"),
    ("stroke_mean", "stroke distance mean", "{:.4e}"),
    ("stroke_p95", "stroke distance p95", "{:.4e}"),
    ("stroke_max", "stroke distance max", "{:.4e}"),
    ("stroke_within_1pct", "strokes within 1%", "{:.2%}"),
    ("fidelity_surface", "stroke length within 1% (surface)", "{:.2%}"),
    ("fidelity_with_wires", "stroke length within 1% (surface+wires)", "{:.2%}"),
    ("fidelity_wire_share", "stroke length on wires only", "{:.2%}"),
    ("fidelity_median", "stroke distance median", "{:.4e}"),
    ("fidelity_p95", "stroke-surface distance p95", "{:.4e}"),
    ("n_samples", "samples per mesh", "{:d}"),
    ("scale", "scale applied", "{:.6g}"),
)


def format_report(metrics: dict) -> str:
    """A short two-column text table of the metrics in ``metrics``.

    Parameters
    ----------
    metrics : dict
        The result of :func:`evaluate_mesh`, of :func:`stroke_distance`, or both merged.
        Known keys are printed in a fixed order with units; others are skipped.

    Returns
    -------
    str
        Lines ``label  value``, no trailing newline. Distances are in normalised units
        (reference's longest bbox side = 1; strokes: fraction of the sketch diagonal).

    Examples
    --------
    >>> print(format_report({"chamfer": 0.00123, "fscore": 0.9841, "threshold": 0.01}))
    Chamfer distance  1.2300e-03
    F-score @ 0.01    98.41%
    """
    threshold = metrics.get("threshold", 0.01)
    rows = []
    for key, label, fmt in _ROWS:
        if key in metrics and metrics[key] is not None:
            rows.append((label.format(threshold=threshold), fmt.format(metrics[key])))
    if not rows:
        return "(no metrics)"
    width = max(len(label) for label, _ in rows)
    return "\n".join(f"{label:<{width}}  {value}" for label, value in rows)
