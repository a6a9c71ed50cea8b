"""Per-region routes of ``auto``: patches where cycles close, a neural fill, wires.

The curves no patch uses are grouped into *regions*: curves closer to each other than
:data:`REGION_GAP` of the network's diagonal belong together. A region whose curves
span area (seen in the plane of its two main directions, most of its convex hull
lies near a curve, and its bounding rectangle is not a sliver) is *surface-like* and
gets a neural fill when it carries at least :data:`MIN_FILL_LENGTH` of the curve length;
any other region (a single stroke, legs, a stem, a small detail) stays as wires.
:func:`plan_regions` makes that decision as data. A fill is fitted to the region's
strokes, the patch curves beside them and, as oriented points, samples of the patches
along those curves (:func:`patch_anchors`), so that fill and patches meet there;
:func:`trim_fill` keeps of it only the part that fills the region and does not lie
over the patches, and :func:`fill_seam` measures how well the two meet.
:func:`stroke_wires` keeps what the surface leaves out of the sketch: every stretch of a
stroke farther from the surface than the fidelity tolerance (the strokes of wire regions,
overshoots trimmed by the snapping, the second stroke of an overdrawn curve), with the
stroke's own geometry.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..core.geometry import (arc_length, boundary_edges, cumulative_length, densify_polyline,
                            face_normals_areas, interpolate_polyline, sample_surface)
from ..core.distance import point_surface_distance
from ..core.fidelity import FIDELITY_TOL_REL, STROKE_SPACING_REL, stroke_samples

__all__ = ["REGION_GAP", "plan_regions", "region_strokes", "patch_anchors", "trim_fill",
           "close_seam", "fill_seam", "assemble", "stroke_wires"]

#: curves closer than this fraction of the network's diagonal form one region
REGION_GAP = 0.08
#: a region is surface-like when at least this share of its 2D convex hull
#: lies within REGION_GAP / 2 of one of its curves...
FILL_SHARE = 0.7
#: ...and its bounding rectangle's short side is at least this fraction of its long side
MIN_SPREAD = 0.15
#: grid points per side of the bounding rectangle probed (inside the hull) for the fill share
FILL_GRID = 16
#: a surface-like region gets a neural fill only when it carries at least this share of
#: the network's curve length: a fill costs a whole neural fit, and a smaller region
#: (a detail beside dozens of patches) is represented as wires instead
MIN_FILL_LENGTH = 0.1
#: a stretch of stroke off the surface becomes a wire when it is at least this long,
#: as a fraction of the sketch's diagonal (shorter ones are the surface's wobble)
MIN_WIRE_LENGTH = 0.01
#: a fill's anchors are samples of the patch faces within this fraction of REGION_GAP of
#: the patch curves beside the region...
ANCHOR_BAND = 0.5
#: ...at most this many (area-weighted)
MAX_ANCHORS = 2000
#: ...on the patches the fill continues (:func:`patch_anchors`), in degrees
CONTINUE_ANGLE = 135.0


def _diagonal(curves) -> float:
    pts = np.concatenate(curves)
    return float(np.linalg.norm(np.ptp(pts, axis=0)))


def _groups(curves, ids, gap: float) -> list:
    """Connected groups of the curves ``ids`` (closer than ``gap``), as lists of ids."""
    pts = [densify_polyline(curves[i], gap / 2) for i in ids]
    owner = np.repeat(np.arange(len(ids)), [len(p) for p in pts])
    pairs = cKDTree(np.concatenate(pts)).query_pairs(gap, output_type="ndarray")
    a, b = owner[pairs[:, 0]], owner[pairs[:, 1]]
    adj = coo_matrix((np.ones(len(a)), (a, b)), shape=(len(ids), len(ids)))
    n, comp = connected_components(adj, directed=False)
    return [[ids[k] for k in np.flatnonzero(comp == c)] for c in range(n)]


def _fill_share(points: np.ndarray, gap: float) -> tuple[float, float]:
    """(share of the 2D convex hull within ``gap`` of a point, short/long side).

    The points are seen in the plane of their two main directions; the hull (not the
    bounding rectangle, whose corners a round region never reaches) is probed on a
    grid. The side ratio is that of the PCA bounding rectangle; below
    :data:`MIN_SPREAD` the share is not measured (0).
    """
    from scipy.spatial import ConvexHull, Delaunay
    centred = points - points.mean(axis=0)
    _u, _s, vt = np.linalg.svd(centred, full_matrices=False)
    flat = centred @ vt[:2].T
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    side = hi - lo
    if not side[0] > 0 or side[1] < MIN_SPREAD * side[0]:
        return 0.0, float(side[1] / side[0]) if side[0] > 0 else 0.0
    g = np.stack(np.meshgrid(*[np.linspace(lo[k], hi[k], FILL_GRID) for k in (0, 1)]),
                 axis=-1).reshape(-1, 2)
    g = g[Delaunay(flat[ConvexHull(flat).vertices]).find_simplex(g) >= 0]
    near = cKDTree(flat).query(g)[0] < gap
    return float(np.mean(near)) if len(g) else 0.0, float(side[1] / side[0])


def plan_regions(curves, used, *, gap_rel: float = REGION_GAP) -> list:
    """Regions of the curves no patch uses, each with its route.

    A region is filled when it is surface-like and carries at least
    :data:`MIN_FILL_LENGTH` of the total curve length; otherwise it is kept as wires.

    Parameters
    ----------
    curves : list of (m_i, 3) float64
        The network's curves.
    used : (n,) bool
        Whether some patch uses curve ``i``.
    gap_rel : float
        Curves closer than this fraction of the diagonal of all curves form one region.

    Returns
    -------
    list of dict
        One per region: ``route`` (``"neural"`` for a surface-like region, else
        ``"wires"``), ``curves`` (curve ids), ``length`` (its curve length),
        ``fill`` and ``spread`` (the figures of the decision).

    Examples
    --------
    >>> t = np.linspace(0, 1, 20)[:, None]
    >>> ribbon = [np.hstack([t, 0 * t + y, 0 * t]) for y in np.linspace(0, 0.5, 6)]
    >>> leg = np.hstack([0 * t + 3, 0 * t, -t])
    >>> [r["route"] for r in plan_regions(ribbon + [leg], np.zeros(7, bool))]
    ['neural', 'wires']
    """
    ids = [int(i) for i in np.flatnonzero(~np.asarray(used, bool))]
    if not ids:
        return []
    gap = gap_rel * _diagonal(curves)
    lengths = [arc_length(c) for c in curves]
    total = sum(lengths)
    regions = []
    for group in _groups(curves, ids, gap):
        pts = np.concatenate([densify_polyline(curves[i], gap / 4) for i in group])
        fill, spread = _fill_share(pts, gap / 2)
        length = sum(lengths[i] for i in group)
        surface = (len(group) > 1 and fill >= FILL_SHARE and spread >= MIN_SPREAD
                   and length >= MIN_FILL_LENGTH * total)
        regions.append({"route": "neural" if surface else "wires", "curves": group,
                        "length": length, "fill": fill, "spread": spread})
    return regions


def region_strokes(curves, region: dict, used, *, gap_rel: float = REGION_GAP) -> list:
    """Curve ids of a region's neural fit: its curves and the patch curves beside it.

    Patch curves within the region's gap are the constraints through which the fill
    meets the patches (they are data of the fit, like the region's own curves).
    """
    gap = gap_rel * _diagonal(curves)
    own = list(region["curves"])
    tree = cKDTree(np.concatenate([densify_polyline(curves[i], gap / 2) for i in own]))
    beside = [int(i) for i in np.flatnonzero(np.asarray(used, bool))
              if np.min(tree.query(densify_polyline(curves[i], gap / 2))[0]) < gap]
    return own + beside


def _dense(curves, step: float) -> np.ndarray:
    """The curves' points, densified to ``step``, as one (n, 3) array."""
    return np.concatenate([densify_polyline(c, step) for c in curves])


def _region_frame(points, region_pts, gap: float):
    """Where the region lies from each point: unit direction and normal, each (n, 3).

    From the (up to 32) nearest region points within ``gap``: the direction is their
    mean offset, normalised; the normal is the least-variance direction of them (the
    normal of the sheet they span). Both are zero where no region point is that near.
    """
    dist, idx = cKDTree(region_pts).query(points, k=32, distance_upper_bound=gap)
    w = np.isfinite(dist)[..., None].astype(np.float64)                    # (n, k, 1)
    near = np.concatenate([region_pts, np.zeros((1, 3))])[np.where(w[..., 0] > 0, idx,
                                                                    len(region_pts))]
    offset = ((near - points[:, None]) * w).sum(axis=1)
    length = np.linalg.norm(offset, axis=1, keepdims=True)
    direction = np.where(length > 0, offset / np.where(length > 0, length, 1.0), 0.0)
    centred = (near - (near * w).sum(axis=1, keepdims=True)
               / np.maximum(w.sum(axis=1, keepdims=True), 1.0)) * w
    normal = np.linalg.eigh(np.einsum("nki,nkj->nij", centred, centred))[1][:, :, 0]
    return direction, normal * (length > 0)


def patch_anchors(vertices, faces, shared_curves, region_curves, *, gap: float,
                  band_rel: float = ANCHOR_BAND, n: int = MAX_ANCHORS, seed=0):
    """Oriented samples of the patches a fill continues across their shared curves.

    A patch face is sampled when its centroid lies within ``band_rel * gap`` of a point
    of a shared curve that is within ``gap`` of the region, on the far side of that
    point from the region, and roughly parallel to the region there: the direction
    from the point to the face and the one into the region make more than
    :data:`CONTINUE_ANGLE` degrees, and its normal and the normal of the sheet the
    region's nearby points span make less than 180 degrees minus that (either sign).
    The fill continues those patches. The other patches at the curve meet the fill at
    an angle (a box's side below an awning that continues its top); asking the fill to
    pass through them too would ask one implicit surface to branch.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64
        The classical surface.
    shared_curves : list of (m, 3) float64
        The patch curves beside the region (:func:`region_strokes`).
    region_curves : list of (m, 3) float64
        The region's own curves.
    gap : float
        The region gap, input units.
    band_rel : float
        Width of the band sampled, as a fraction of ``gap``.
    n : int
        Number of samples, area-weighted.
    seed : int or numpy.random.Generator

    Returns
    -------
    (points (n, 3) float64, normals (n, 3) float64) or None
        The samples and their faces' unit normals (as the faces are oriented); None when
        no face qualifies.
    """
    if not shared_curves or not len(faces):
        return None
    region_pts = _dense(region_curves, gap / 8)
    pts = _dense(shared_curves, gap / 8)
    pts = pts[cKDTree(region_pts).query(pts)[0] < gap]
    if not len(pts):
        return None
    vertices, faces = np.asarray(vertices, np.float64), np.asarray(faces)
    normals, areas = face_normals_areas(vertices, faces)
    centroids = vertices[faces].mean(axis=1)
    dist, at = cKDTree(pts).query(centroids)
    away = centroids - pts[at]
    away /= np.maximum(np.linalg.norm(away, axis=1, keepdims=True), np.finfo(float).tiny)
    into, sheet = _region_frame(pts, region_pts, gap)
    cos = np.cos(np.radians(CONTINUE_ANGLE))
    beyond = ((away * into[at]).sum(axis=1) < cos) \
        & (np.abs((normals * sheet[at]).sum(axis=1)) > -cos)
    areas = np.where((dist < band_rel * gap) & beyond, areas, 0.0)
    if not areas.sum() > 0:
        return None
    points, face = sample_surface(vertices, faces, n, seed, areas=areas)
    return points, normals[face]


def trim_fill(vertices, faces, region_curves, patch_vertices, patch_faces, *,
              gap: float, patch_curves=(), on_curve: float = 0.0) -> np.ndarray:
    """Faces of a neural surface that fill a region: near its curves, not over the patches.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64
        The neural surface.
    region_curves : list of (m, 3) float64
        The region's own curves.
    patch_vertices, patch_faces : arrays
        The classical surface.
    gap : float
        Input units: kept faces have their centroid within ``gap`` of a region curve.
    patch_curves : list of (m, 3) float64
        The curves the patches are bounded by.
    on_curve : float
        A face whose centroid lies within ``gap / 4`` of the classical surface is over a
        patch and dropped, unless its closest point there lies within ``on_curve`` of a
        patch curve: then it lies beyond the patch, across the curve where the two meet
        (``on_curve = 0``: every face that near is dropped).

    Returns
    -------
    (F,) bool
        The faces kept.
    """
    centroids = np.asarray(vertices)[np.asarray(faces)].mean(axis=1)
    near = cKDTree(_dense(region_curves, gap / 4)).query(centroids)[0] < gap
    if len(patch_faces):
        d, _, closest = point_surface_distance(centroids, patch_vertices, patch_faces,
                                               closest=True)
        over = d <= gap / 4
        if len(patch_curves) and on_curve > 0:
            tree = cKDTree(_dense(patch_curves, on_curve / 2))
            over[over] = tree.query(closest[over])[0] >= on_curve
        near &= ~over
    return near


def close_seam(vertices, faces, patch_vertices, patch_faces, *, reach: float):
    """The fill with its boundary vertices near the patches moved onto them.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64
        The kept fill.
    patch_vertices, patch_faces : arrays
        The classical surface.
    reach : float
        Boundary vertices closer than this to the classical surface (input units) move
        to their closest point there; no other vertex moves.

    Returns
    -------
    vertices : (V, 3) float64
        A new array.
    moved : float
        The longest move (0 when none).
    """
    vertices = np.array(vertices, dtype=np.float64)
    ids = np.unique(boundary_edges(faces))
    if not len(ids) or not len(patch_faces):
        return vertices, 0.0
    d, _, closest = point_surface_distance(vertices[ids], patch_vertices, patch_faces,
                                           closest=True)
    near = d < reach
    vertices[ids[near]] = closest[near]
    return vertices, float(d[near].max()) if near.any() else 0.0


def fill_seam(vertices, faces, shared_curves, *, gap: float, tol: float) -> dict:
    """How a kept fill meets the patches along the curves they share.

    The shared curves are sampled (step ``tol / 2``); the samples within ``gap / 2`` of
    the fill are where the fill reaches them. There, the seam is met where the fill's
    boundary (its edges used by one face) passes within ``tol``.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64
        The kept fill.
    shared_curves : list of (m, 3) float64
        The patch curves beside the region.
    gap, tol : float
        Input units.

    Returns
    -------
    dict
        ``seam``: share of the reached shared-curve length where the fill's boundary is
        within ``tol`` (None when the fill reaches no shared curve); ``seam_p95``: the
        95th percentile of the distance there, input units (None likewise).
    """
    none = {"seam": None, "seam_p95": None}
    faces = np.asarray(faces)
    if not shared_curves or not len(faces):
        return none
    q = _dense(shared_curves, tol / 2)
    q = q[point_surface_distance(q, vertices, faces)[0] < gap / 2]
    rim = boundary_edges(faces)
    if not len(q) or not len(rim):
        return none
    ends = np.asarray(vertices, np.float64)[rim]                        # (E, 2, 3)
    k = max(2, int(np.ceil(np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1).max() / (tol / 4))))
    t = np.linspace(0.0, 1.0, k)[None, :, None]
    rim_pts = (ends[:, :1] + t * (ends[:, 1:] - ends[:, :1])).reshape(-1, 3)
    d = cKDTree(rim_pts).query(q)[0]   # q is evenly spaced: its share is a length share
    return {"seam": float(np.mean(d <= tol)), "seam_p95": float(np.percentile(d, 95))}


def stroke_wires(strokes, vertices, faces, *, tol_rel: float = FIDELITY_TOL_REL,
                 spacing_rel: float = STROKE_SPACING_REL,
                 min_length_rel: float = MIN_WIRE_LENGTH) -> list:
    """Stretches of the strokes that the surface does not pass through, as wires.

    Parameters
    ----------
    strokes : Sketch, CurveNetwork or list of (n, 3) array_like
        As in :func:`curvenet.evaluate.sketch_fidelity`; the diagonal of their points is
        the scale of the relative lengths below.
    vertices : (V, 3) float64
    faces : (F, 3) int64
        The surface.
    tol_rel : float
        A stroke sample farther than this from the surface is off it (the fidelity
        tolerance).
    spacing_rel : float
        Arc-length step of the stroke samples.
    min_length_rel : float
        Stretches shorter than this are left out.

    Returns
    -------
    list of (m, 3) float64
        One piece of one stroke each (m >= 2), in stroke order: the stroke's own points
        from the sample before its first sample off the surface to the sample after its
        last (so a wire starts and ends at the surface when it leaves it), the two ends
        interpolated on the stroke.

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box()
    >>> stroke = [[-0.5, -0.5, 0.5], [0.5, -0.5, 0.5], [1.5, -0.5, 0.5]]
    >>> [w.round(3).tolist() for w in stroke_wires([stroke], box.vertices, box.faces)]
    [[[0.518, -0.5, 0.5], [1.5, -0.5, 0.5]]]
    """
    lines, diag, pts, counts = stroke_samples(strokes, spacing_rel)
    off = point_surface_distance(pts, vertices, faces)[0] >= tol_rel * diag
    sid = np.repeat(np.arange(len(lines)), counts)
    first = np.r_[0, np.cumsum(counts)[:-1]]
    step = np.r_[0.0, np.linalg.norm(np.diff(pts, axis=0), axis=1)]
    step[first] = 0.0
    cum = np.cumsum(step) - np.cumsum(step)[first][sid]   # arc length along each stroke
    same = sid[1:] == sid[:-1]
    starts = np.flatnonzero(off & ~np.r_[False, off[:-1] & same])
    ends = np.flatnonzero(off & ~np.r_[off[1:] & same, False])
    last = first + counts - 1
    lo = np.maximum(starts - 1, first[sid[starts]])
    hi = np.minimum(ends + 1, last[sid[ends]])
    wires = []
    for a, b in zip(lo, hi):
        s0, s1, line = cum[a], cum[b], lines[sid[a]]
        if s1 - s0 < min_length_rel * diag:
            continue
        c = cumulative_length(line)
        eps = 1e-3 * spacing_rel * diag   # float noise of the two arc lengths
        inner = line[(c > s0 + eps) & (c < s1 - eps)]
        wires.append(np.concatenate([interpolate_polyline(line, [s0], cum=c), inner,
                                     interpolate_polyline(line, [s1], cum=c)]))
    return wires


def add_wires(out) -> None:
    """Keep as ``out.wires`` the stretches of strokes ``out.mesh`` leaves out, in place.

    The strokes are the sketch's (the network's curves without a sketch); see
    :func:`stroke_wires`. A result with wires but no face routes gets one route, the
    decision's, for every face.
    """
    ref = out.sketch if out.sketch is not None else out.network
    out.wires = stroke_wires(ref, out.mesh.vertices, out.mesh.faces)
    if out.wires and not out.routes:
        out.routes = (out.decision.method,)
        out.face_route = np.zeros(len(out.mesh.faces), np.uint8)


def _fill(out, classical, region, used, gap, plan, settings, run):
    """One region's neural fill, trimmed: ``(vertices, faces)`` of the kept part.

    The fit gets the region's strokes, the patch curves beside them and the patches'
    samples along those curves (:func:`patch_anchors`); the kept part's boundary is
    moved onto the patches where it lies within ``gap / 4`` of them (:func:`close_seam`).
    ``region`` gets ``faces``, ``anchors``, the :func:`fill_seam` figures of the fit
    (``seam_fit``, ``seam_fit_p95``) and of the result (``seam``, ``seam_p95``) and the
    longest move ``seam_moved`` (lengths as fractions of the network's diagonal).
    """
    from .registry import SurfaceInput
    curves = [e.curve for e in out.network.edges]
    ids = region_strokes(curves, region, used)
    own = [curves[i] for i in region["curves"]]
    shared = [curves[i] for i in ids[len(own):]]
    anchors = patch_anchors(classical.vertices, classical.faces, shared, own, gap=gap,
                            seed=settings.seed)
    # every stroke of a fill is a boundary: the fill needs no crease refit of its own
    inp = SurfaceInput(settings, strokes=[curves[i] for i in ids],
                       labels=["boundary"] * len(ids), anchors=anchors)
    fill = run(plan.stroke, inp, plan.options[plan.stroke.name], out.timings, out.diagnostics)
    tol = FIDELITY_TOL_REL * _diagonal(curves)
    keep = trim_fill(fill.vertices, fill.faces, own, classical.vertices, classical.faces,
                     gap=gap, patch_curves=[curves[i] for i in np.flatnonzero(used)],
                     on_curve=tol / 2)
    faces = np.asarray(fill.faces)[keep]
    kept, inverse = np.unique(faces, return_inverse=True)
    verts, faces = np.asarray(fill.vertices)[kept], inverse.reshape(-1, 3)
    fitted = fill_seam(verts, faces, shared, gap=gap, tol=tol)
    verts, moved = close_seam(verts, faces, classical.vertices, classical.faces, reach=gap / 4)
    closed = fill_seam(verts, faces, shared, gap=gap, tol=tol)
    rel = FIDELITY_TOL_REL / tol       # input units -> fractions of the diagonal
    region.update(faces=int(len(faces)), anchors=0 if anchors is None else len(anchors[0]),
                  seam_fit=fitted["seam"], seam=closed["seam"], seam_moved=moved * rel,
                  **{k: None if v is None else v * rel for k, v in
                     (("seam_fit_p95", fitted["seam_p95"]), ("seam_p95", closed["seam_p95"]))})
    return verts, faces


def assemble(out, classical, plan, settings, run) -> None:
    """Add the neural fills and the wires of ``out.decision.regions`` to ``out``, in place.

    Parameters
    ----------
    out : curvenet.pipeline.SurfaceResult
        The classical result; its ``decision.regions[0]`` is the patched region.
    classical : curvenet.core.MeshResult
        The classical surface.
    plan : curvenet.pipeline._Plan
        Gives the stroke surfacer and its options.
    settings : curvenet.route.registry.SurfaceSettings
    run : callable
        ``run(surfacer, inp, options, timings, diagnostics) -> MeshResult``.

    ``out.mesh`` becomes the classical faces followed by the kept neural faces,
    ``out.face_route`` their route (0 classical, 1 neural), ``out.method`` ``"hybrid"``
    when a fill kept faces. The wire regions get no surface: :func:`add_wires` keeps
    their strokes.
    """
    import trimesh
    edges = out.network.edges
    used = np.zeros(len(edges), bool)
    used[out.decision.regions[0]["curves"]] = True
    gap = REGION_GAP * _diagonal([e.curve for e in edges])
    verts, faces = [np.asarray(classical.vertices)], [np.asarray(classical.faces)]
    routes = [np.zeros(len(classical.faces), np.uint8)]
    for region in out.decision.regions[1:]:
        if region["route"] == "wires":   # its strokes become wires (:func:`add_wires`)
            continue
        v, f = _fill(out, classical, region, used, gap, plan, settings, run)
        faces.append(f + sum(len(x) for x in verts))
        verts.append(v)
        routes.append(np.ones(len(f), np.uint8))
    out.face_route = np.concatenate(routes)
    out.routes = ("classical", "neural") if len(out.face_route) > len(classical.faces) \
        else ("classical",)
    if len(out.routes) > 1:
        out.mesh = trimesh.Trimesh(np.concatenate(verts), np.concatenate(faces), process=False)
        out.method = "hybrid"
