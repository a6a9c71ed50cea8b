"""Per-region routes of ``auto``: patches where cycles close, a neural fill, wires.

The curves no patch uses are grouped into *regions*: curves closer to each other than
:data:`REGION_GAP` of the network's diagonal belong together. A region whose curves
span area (seen in the plane of its two main directions, most of its convex hull
lies near a curve, and its bounding rectangle is not a sliver) is *surface-like* and
gets a neural fill when it carries at least :data:`MIN_FILL_LENGTH` of the curve length;
any other region (a single stroke, legs, a stem, a small detail) stays as wires.
:func:`plan_regions` makes that decision as data; :func:`trim_fill` keeps of a
neural surface only the part that fills a region and does not overlap the patches.
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

from .core.geometry import arc_length, cumulative_length, densify_polyline, interpolate_polyline
from .evaluate import FIDELITY_TOL_REL, STROKE_SPACING_REL, point_surface_distance, stroke_samples

__all__ = ["REGION_GAP", "plan_regions", "region_strokes", "trim_fill", "assemble",
           "stroke_wires"]

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


def trim_fill(vertices, faces, region_curves, patch_vertices, patch_faces, *,
              gap: float) -> np.ndarray:
    """Faces of a neural surface that fill a region: near its curves, off the patches.

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
        Input units: kept faces have their centroid within ``gap`` of a region curve
        and farther than ``gap / 4`` from the classical surface.

    Returns
    -------
    (F,) bool
        The faces kept.
    """
    centroids = np.asarray(vertices)[np.asarray(faces)].mean(axis=1)
    dense = np.concatenate([densify_polyline(c, gap / 4) for c in region_curves])
    near = cKDTree(dense).query(centroids)[0] < gap
    if len(patch_faces):
        off = point_surface_distance(centroids, patch_vertices, patch_faces)[0] > gap / 4
        near &= off
    return near


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
    """One region's neural fill, trimmed: ``(vertices, faces)`` of the kept part."""
    from .surfacers import SurfaceInput
    edges = out.network.edges
    ids = region_strokes([e.curve for e in edges], region, used)
    # every stroke of a fill is a boundary: the fill needs no crease refit of its own
    inp = SurfaceInput(settings, strokes=[edges[i].curve for i in ids],
                       labels=["boundary"] * len(ids))
    fill = run(plan.stroke, inp, plan.options[plan.stroke.name], out.timings, out.diagnostics)
    keep = trim_fill(fill.vertices, fill.faces, [edges[i].curve for i in region["curves"]],
                     classical.vertices, classical.faces, gap=gap)
    faces = np.asarray(fill.faces)[keep]
    kept, inverse = np.unique(faces, return_inverse=True)
    region["faces"] = int(len(faces))
    return np.asarray(fill.vertices)[kept], inverse.reshape(-1, 3)


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
    settings : curvenet.surfacers.SurfaceSettings
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
