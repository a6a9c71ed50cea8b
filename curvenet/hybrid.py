"""Per-region routes of ``auto``: patches where cycles close, a neural fill, wires.

The curves no patch uses are grouped into *regions*: curves closer to each other than
:data:`REGION_GAP` of the network's diagonal belong together. A region whose curves
span area (seen in the plane of its two main directions, most of its bounding
rectangle lies near a curve, and the rectangle is not a sliver) is *surface-like* and
gets a neural fill when it carries at least :data:`MIN_FILL_LENGTH` of the curve length;
any other region (a single stroke, legs, a stem, a small detail) stays as wires.
:func:`plan_regions` makes that decision as data; :func:`trim_fill` keeps of a
neural surface only the part that fills a region and does not overlap the patches.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .core.geometry import arc_length, densify_polyline

__all__ = ["REGION_GAP", "plan_regions", "region_strokes", "trim_fill", "assemble"]

#: curves closer than this fraction of the network's diagonal form one region
REGION_GAP = 0.08
#: a region is surface-like when at least this share of its 2D bounding rectangle
#: lies within REGION_GAP of one of its curves...
FILL_SHARE = 0.7
#: ...and the rectangle's short side is at least this fraction of its long side
MIN_SPREAD = 0.15
#: grid cells per side of the rectangle probed for the fill share
FILL_GRID = 16
#: a surface-like region gets a neural fill only when it carries at least this share of
#: the network's curve length: a fill costs a whole neural fit, and a smaller region
#: (a detail beside dozens of patches) is represented as wires instead
MIN_FILL_LENGTH = 0.1


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
    """(share of the PCA bounding rectangle within ``gap`` of a point, short/long side)."""
    centred = points - points.mean(axis=0)
    _u, _s, vt = np.linalg.svd(centred, full_matrices=False)
    flat = centred @ vt[:2].T
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    side = hi - lo
    if not side[0] > 0:
        return 0.0, 0.0
    g = np.stack(np.meshgrid(*[np.linspace(lo[k], hi[k], FILL_GRID) for k in (0, 1)]),
                 axis=-1).reshape(-1, 2)
    near = cKDTree(flat).query(g)[0] < gap
    return float(np.mean(near)), float(side[1] / side[0])


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
    from .evaluate import point_surface_distance
    centroids = np.asarray(vertices)[np.asarray(faces)].mean(axis=1)
    dense = np.concatenate([densify_polyline(c, gap / 4) for c in region_curves])
    near = cKDTree(dense).query(centroids)[0] < gap
    if len(patch_faces):
        off = point_surface_distance(centroids, patch_vertices, patch_faces)[0] > gap / 4
        near &= off
    return near


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
    ``out.face_route`` their route (0 classical, 1 neural), ``out.wires`` the curves of
    the wire regions, ``out.method`` ``"hybrid"`` when a fill kept faces.
    """
    import trimesh
    edges = out.network.edges
    used = np.zeros(len(edges), bool)
    used[out.decision.regions[0]["curves"]] = True
    gap = REGION_GAP * _diagonal([e.curve for e in edges])
    verts, faces = [np.asarray(classical.vertices)], [np.asarray(classical.faces)]
    routes = [np.zeros(len(classical.faces), np.uint8)]
    for region in out.decision.regions[1:]:
        if region["route"] == "wires":
            out.wires += [edges[i].curve for i in region["curves"]]
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
