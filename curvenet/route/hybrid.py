"""The hybrid route: patches where cycles close, a neural fill for each surface-like region.

A registered composite surfacer (``"hybrid"``, :func:`surface_hybrid`): it runs the
patch surfacer, then for each region :func:`curvenet.route.regions.plan_regions`
routed ``NEURAL`` a fill fitted to the region's strokes, the patch curves beside them
and, as oriented points, samples of the patches along those curves
(:func:`patch_anchors`), so that fill and patches meet there. :func:`trim_fill` keeps
of a fill only the part that fills the region and does not lie over the patches,
:func:`close_seam` moves its boundary onto the patches where it lies near them, and
:func:`fill_seam` measures how well the two meet.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.spatial import cKDTree

from ..core.distance import point_surface_distance
from ..core.fidelity import FIDELITY_TOL_REL
from ..core.geometry import (arc_length, bbox_diagonal, boundary_edges, face_normals_areas,
                             sample_surface)
from ..core.result import MeshResult
from .decision import Region, Route
from .regions import REGION_GAP, dense, plan_regions, region_strokes
from .registry import SurfaceInput, SurfaceSettings, check_option_names, get_surfacer

__all__ = ["patch_anchors", "trim_fill", "close_seam", "fill_seam", "check_hybrid",
           "surface_hybrid"]

#: a fill's anchors are samples of the patch faces within this fraction of REGION_GAP of
#: the patch curves beside the region...
ANCHOR_BAND = 0.5
#: ...at most this many (area-weighted)
MAX_ANCHORS = 2000
#: ...on the patches the fill continues (:func:`patch_anchors`), in degrees
CONTINUE_ANGLE = 135.0


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
    region_pts = dense(region_curves, gap / 8)
    pts = dense(shared_curves, gap / 8)
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
    near = cKDTree(dense(region_curves, gap / 4)).query(centroids)[0] < gap
    if len(patch_faces):
        d, _, closest = point_surface_distance(centroids, patch_vertices, patch_faces,
                                               closest=True)
        over = d <= gap / 4
        if len(patch_curves) and on_curve > 0:
            tree = cKDTree(dense(patch_curves, on_curve / 2))
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
    q = dense(shared_curves, tol / 2)
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


def _fill(fill, options, inp, classical, region, used, gap):
    """One region's neural fill, trimmed.

    The fit gets the region's strokes, the patch curves beside them and the patches'
    samples along those curves (:func:`patch_anchors`); the kept part's boundary is
    moved onto the patches where it lies within ``gap / 4`` of them (:func:`close_seam`).

    Returns
    -------
    vertices : (V, 3) float64
    faces : (F, 3) int64
        The kept part.
    report : dict
        The fill surfacer's report.
    figures : dict
        ``faces``, ``anchors``, the :func:`fill_seam` figures of the fit (``seam_fit``,
        ``seam_fit_p95``) and of the result (``seam``, ``seam_p95``) and the longest
        move ``seam_moved`` (lengths as fractions of the network's diagonal): the fields
        of the region's :class:`~curvenet.route.Region` they fill in.
    """
    curves = inp.curves
    ids = region_strokes(curves, region, used)
    own = [curves[i] for i in region.curves]
    shared = [curves[i] for i in ids[len(own):]]
    anchors = patch_anchors(classical.vertices, classical.faces, shared, own, gap=gap,
                            seed=inp.settings.seed)
    # every stroke of a fill is a boundary: the fill needs no crease refit of its own
    sub = SurfaceInput(inp.settings, strokes=[curves[i] for i in ids],
                       labels=["boundary"] * len(ids), anchors=anchors)
    res = fill(sub, options)
    tol = FIDELITY_TOL_REL * bbox_diagonal(curves)
    keep = trim_fill(res.vertices, res.faces, own, classical.vertices, classical.faces,
                     gap=gap, patch_curves=[curves[i] for i in np.flatnonzero(used)],
                     on_curve=tol / 2)
    faces = np.asarray(res.faces)[keep]
    kept, inverse = np.unique(faces, return_inverse=True)
    verts, faces = np.asarray(res.vertices)[kept], inverse.reshape(-1, 3)
    fitted = fill_seam(verts, faces, shared, gap=gap, tol=tol)
    verts, moved = close_seam(verts, faces, classical.vertices, classical.faces, reach=gap / 4)
    closed = fill_seam(verts, faces, shared, gap=gap, tol=tol)
    rel = FIDELITY_TOL_REL / tol       # input units -> fractions of the diagonal
    figures = dict(faces=int(len(faces)), anchors=0 if anchors is None else len(anchors[0]),
                   seam_fit=fitted["seam"], seam=closed["seam"], seam_moved=moved * rel,
                   **{k: None if v is None else v * rel for k, v in
                      (("seam_fit_p95", fitted["seam_p95"]), ("seam_p95", closed["seam_p95"]))})
    return verts, faces, dict(res.report), figures


def _parts(options: dict):
    """The patch and fill surfacers a hybrid's options name."""
    return (get_surfacer(options.get("patch", "catmull-clark"), "patches"),
            get_surfacer(options.get("fill", "neural"), "strokes"))


def check_hybrid(options: dict, settings: SurfaceSettings) -> None:
    """Options of the hybrid surfacer: ``patch`` and ``fill`` (surfacer names, default
    ``"catmull-clark"`` and ``"neural"``) and their options ``patch_options``,
    ``fill_options``, each checked by its surfacer."""
    check_option_names("hybrid", options, ["patch", "fill", "patch_options", "fill_options"])
    patch, fill = _parts(options)
    patch.validate(options.get("patch_options"), settings)
    fill.validate(options.get("fill_options"), settings)


def surface_hybrid(inp: SurfaceInput, options: dict) -> MeshResult:
    """Patches, and a neural fill for each region ``inp.regions`` routes ``NEURAL``.

    Parameters
    ----------
    inp : SurfaceInput
        The patch surfacer's input (``curves``, ``loops``, ``holes``, ``crease_curves``)
        and ``regions``, the classical region first (:func:`curvenet.route.region_route`);
        without regions they are planned here from the curves the loops use
        (:func:`curvenet.route.regions.plan_regions`).
    options : dict
        See :func:`check_hybrid`.

    Returns
    -------
    MeshResult
        The classical faces followed by the kept fill faces; ``face_route`` says which
        (``routes`` is ``(CLASSICAL, NEURAL)``, or ``(CLASSICAL,)`` when no fill kept a
        face). ``report``: ``parts`` (the patch surfacer's report under its label, and the
        fills' under theirs: ``fills``, one report per fill, and ``interrupted``),
        ``timings`` (seconds per part), ``regions`` (per region, the figures of its fill:
        the :class:`~curvenet.route.Region` fields to fill in; ``{}`` for the others).
    """
    patch, fill = _parts(options)
    curves = inp.curves
    t = time.perf_counter()
    classical = patch(inp, options.get("patch_options"))
    timings = {patch.label: time.perf_counter() - t}
    regions = inp.regions or _plan(curves, inp.loops, inp.holes)
    used = np.zeros(len(curves), bool)
    used[regions[0].curves] = True
    gap = REGION_GAP * bbox_diagonal(curves)
    verts, faces = [np.asarray(classical.vertices)], [np.asarray(classical.faces)]
    routes = [np.zeros(len(classical.faces), np.uint8)]
    reports, figures = [], [{} for _ in regions]
    t = time.perf_counter()
    for k, region in enumerate(regions):
        if region.route is not Route.NEURAL:   # wires get no surface
            continue
        v, f, report, figures[k] = _fill(fill, options.get("fill_options"), inp, classical,
                                         region, used, gap)
        faces.append(f + sum(len(x) for x in verts))
        verts.append(v)
        routes.append(np.ones(len(f), np.uint8))
        reports.append(report)
    face_route = np.concatenate(routes)
    parts = {patch.label: dict(classical.report)}
    if reports:
        timings[fill.label] = time.perf_counter() - t
        parts[fill.label] = {"fills": reports,
                             "interrupted": any(r.get("interrupted") for r in reports)}
    report = {"parts": parts, "timings": timings, "regions": figures}
    if len(face_route) == len(classical.faces):
        return MeshResult(classical.vertices, classical.faces, report,
                          face_route=face_route, routes=(Route.CLASSICAL,))
    return MeshResult(np.concatenate(verts), np.concatenate(faces), report,
                      face_route=face_route, routes=(Route.CLASSICAL, Route.NEURAL))


def _plan(curves, loops, holes) -> list:
    """Regions of a hybrid asked for directly: the loops' curves, then plan_regions'."""
    used = np.zeros(len(curves), bool)
    for loop in [*loops, *(h for hs in holes for h in hs)]:
        used[[i for i, _ in loop]] = True
    covered = Region(Route.CLASSICAL, [int(i) for i in np.flatnonzero(used)],
                     float(sum(arc_length(curves[i]) for i in np.flatnonzero(used))),
                     patches=len(loops))
    return [covered, *plan_regions(curves, used)]
