"""Regions of the curves no patch uses, and the route each gets.

The curves no patch uses are grouped into *regions*: curves closer to each other than
:data:`REGION_GAP` of the network's diagonal belong together. A region whose curves
span area (seen in the plane of its two main directions, most of its convex hull
lies near a curve, and its bounding rectangle is not a sliver) is *surface-like* and
gets a neural fill (:mod:`curvenet.route.hybrid`) when it carries at least
:data:`MIN_FILL_LENGTH` of the curve length; any other region (a single stroke, legs, a
stem, a small detail) stays as wires. :func:`plan_regions` makes that decision as data.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ..core.geometry import arc_length, bbox_diagonal, densify_polyline
from .decision import Region, Route

__all__ = ["REGION_GAP", "FILL_SHARE", "MIN_SPREAD", "MIN_FILL_LENGTH", "plan_regions",
           "region_strokes", "dense"]

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


def dense(curves, step: float) -> np.ndarray:
    """The curves' points, densified to ``step``, as one (n, 3) array."""
    return np.concatenate([densify_polyline(c, step) for c in curves])


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
    list of Region
        One per region: ``route`` (``NEURAL`` for a surface-like region, else
        ``WIRES``), ``curves`` (curve ids), ``length`` (its curve length), ``fill`` and
        ``spread`` (the figures of the decision).

    Examples
    --------
    >>> t = np.linspace(0, 1, 20)[:, None]
    >>> ribbon = [np.hstack([t, 0 * t + y, 0 * t]) for y in np.linspace(0, 0.5, 6)]
    >>> leg = np.hstack([0 * t + 3, 0 * t, -t])
    >>> [r.route.value for r in plan_regions(ribbon + [leg], np.zeros(7, bool))]
    ['neural', 'wires']
    """
    ids = [int(i) for i in np.flatnonzero(~np.asarray(used, bool))]
    if not ids:
        return []
    gap = gap_rel * bbox_diagonal(curves)
    lengths = [arc_length(c) for c in curves]
    total = sum(lengths)
    regions = []
    for group in _groups(curves, ids, gap):
        pts = np.concatenate([densify_polyline(curves[i], gap / 4) for i in group])
        fill, spread = _fill_share(pts, gap / 2)
        length = sum(lengths[i] for i in group)
        surface = (len(group) > 1 and fill >= FILL_SHARE and spread >= MIN_SPREAD
                   and length >= MIN_FILL_LENGTH * total)
        regions.append(Region(Route.NEURAL if surface else Route.WIRES, group, length,
                              fill=fill, spread=spread))
    return regions


def region_strokes(curves, region: Region, used, *, gap_rel: float = REGION_GAP) -> list:
    """Curve ids of a region's neural fit: its curves and the patch curves beside it.

    Patch curves within the region's gap are the constraints through which the fill
    meets the patches (they are data of the fit, like the region's own curves).
    """
    gap = gap_rel * bbox_diagonal(curves)
    own = list(region.curves)
    tree = cKDTree(np.concatenate([densify_polyline(curves[i], gap / 2) for i in own]))
    beside = [int(i) for i in np.flatnonzero(np.asarray(used, bool))
              if np.min(tree.query(densify_polyline(curves[i], gap / 2))[0]) < gap]
    return own + beside
