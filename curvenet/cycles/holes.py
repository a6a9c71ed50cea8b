"""Faces with holes: nested coplanar loops chosen as holes of the face around them.

A GF(2) cycle basis (Abbasinejad et al. 2011) only holds simple cycles, so a
planar face with a hole comes out as two patches: its outer loop filled over
the hole, and the hole's loop filled as a disc. In the cycle space the face
is the sum of its boundary cycles; geometry decides which sum is meant:

* an *inner* patch whose loop lies in the plane of a planar *outer* patch,
  strictly inside its outline and sharing no junction with it, is a hole of
  the innermost such outer patch (the outer patch becomes a
  :class:`~curvenet.model.patchset.Patch` with ``holes``), provided the outer patch
  lies on a manifold stretch of the surface (none of its curves is shared by
  three or more patches): a flat fin or plate attached where other surfaces
  meet is a sheet, with no solid behind it for a hole to open into, and a
  loop drawn on it (the base of a fin standing on it) stays a disc;
* the inner patch itself is dropped when a wall continues through its loop
  (every one of its curves is also used by another patch: a bore, a boss),
  and kept as a disc when nothing does (a face drawn inside a face);
* a loop inside a hole that was dropped (the bore of a tube standing on a plate,
  drawn where the tube meets the plate) has no face around it in that plane: it
  is no hole. Its disc is dropped when walls continue through it on both sides
  (every one of its curves is also used by two other patches: the tube's bore and
  the plate's), and kept otherwise (the floor of a blind bore).

A loop that no planar face surrounds (a boss's end cap, a blind hole's
bottom) is left a disc.

The search is linear in the network's size: only outer patches whose bounding box
holds an inner patch's bounding box (an R-tree of the planar patches' boxes) are
tested, the plane and shared-junction tests run on all those pairs at once, and the
outline test runs once per outer patch on all its candidates' points.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import csr_matrix

from ..core.geometry import fit_plane
from .loops import cycle_to_loop, loop_points
from ..model.network import CurveNetwork
from ..model.patchset import Patch

__all__ = ["hole_patches", "PLANE_TOL"]

#: Largest distance of a loop's points to its plane, fraction of the network diagonal,
#: for the loop to count as planar (and an inner loop as lying in an outer loop's plane).
PLANE_TOL = 1e-4


def hole_patches(network: CurveNetwork, patches, *, plane_tol: float = PLANE_TOL):
    """Turn nested coplanar patches into faces with holes (see the module docstring).

    Parameters
    ----------
    network : CurveNetwork
    patches : list of Patch
        Simple-cycle patches (``holes`` empty), e.g. from the basis.
    plane_tol : float
        Planarity / coplanarity tolerance, fraction of ``network.diagonal``.

    Returns
    -------
    patches : list of Patch
        Same order, each outer patch carrying its holes, dropped inner patches removed.
    report : list of dict
        One entry per hole, in the order of the inner patches: ``face`` (index in the
        returned list), ``loop`` (edge ids), ``disc_kept`` (whether the loop's own
        patch stays as a disc), ``source`` (that patch's source).

    Notes
    -----
    An outer patch is the smallest (in area) that holds the inner one, the first in
    ``patches`` among equal areas. Nesting is resolved from the outside in: a loop
    whose innermost surrounding patch is itself a dropped hole is no hole.
    """
    tol = plane_tol * max(network.diagonal, 1e-300)
    n = len(patches)
    if n == 0:
        return [], []
    planes = _Planes(network, patches, tol)
    edges = [np.asarray(p.edges, np.int64) for p in patches]
    sizes = np.array([len(e) for e in edges], np.int64)
    flat = np.concatenate(edges)
    owner = np.repeat(np.arange(n), sizes)
    uses = np.bincount(flat, minlength=network.number_of_edges)
    # per patch: whether every curve is used at most twice / at least twice
    manifold = np.bincount(owner, weights=uses[flat] > 2, minlength=n) == 0
    walled = np.bincount(owner, weights=uses[flat] < 2, minlength=n) == 0
    ends = np.array([(e.u, e.v) for e in network.edges], np.int64).reshape(-1, 2)
    junctions = csr_matrix((np.ones(2 * len(flat)), (np.repeat(owner, 2), ends[flat].ravel())),
                           shape=(n, network.number_of_vertices))
    nearest = _nearest_outer(planes, junctions, manifold, tol)
    through = np.bincount(owner, weights=uses[flat] < 3, minlength=n) == 0
    parent, dropped = {}, set()
    for i in _outside_in(nearest):
        j = nearest[i]
        if j in dropped:        # in the opening of a hole: no face around it in this plane
            if through[i]:      # walls on both sides: a ring where two walls meet
                dropped.add(i)
            continue
        parent[i] = j
        if walled[i]:
            dropped.add(i)
    holes: dict = {}
    for i, j in sorted(parent.items()):
        holes.setdefault(j, []).append(i)
    out, index = [], {}
    for k, p in enumerate(patches):
        if k in dropped:
            continue
        index[k] = len(out)
        hs = tuple(patches[i].edges for i in holes.get(k, ()))
        out.append(Patch(p.edges, p.source, hs) if hs else p)
    report = [{"face": index[j], "loop": list(patches[i].edges), "disc_kept": i not in dropped,
               "source": patches[i].source} for i, j in sorted(parent.items())]
    return out, report


class _Planes:
    """Every patch's loop polyline, least-squares plane, bounding box and area.

    Attributes
    ----------
    points : (m, 3) float64
        The loops' points (:func:`~curvenet.cycles.loops.loop_points`), patch after patch.
    start : (n + 1,) int64
        Patch ``k``'s points are ``points[start[k]:start[k + 1]]``.
    centre, normal : (n, 3) float64
    axes : (n, 2, 3) float64
        The frames of :func:`~curvenet.core.geometry.fit_plane`.
    planar : (n,) bool
        Simple loops within ``tol`` of their plane.
    lo, hi : (n, 3) float64
        Bounding boxes.
    area : (n,) float64
        Unsigned area of the loop projected on its plane.
    """

    def __init__(self, network: CurveNetwork, patches, tol: float):
        pts = [loop_points(network, cycle_to_loop(network, p.edges)) for p in patches]
        n = len(pts)
        sizes = np.array([len(q) for q in pts], np.int64)
        self.start = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
        self.points = np.concatenate(pts)
        self.centre = np.empty((n, 3))
        self.normal = np.empty((n, 3))
        self.axes = np.empty((n, 2, 3))
        dev = np.empty(n)
        order = np.argsort(sizes, kind="stable")
        for ids in np.split(order, np.flatnonzero(np.diff(sizes[order])) + 1):
            if len(ids) == 0:
                continue
            q = np.stack([pts[k] for k in ids])                            # (g, m, 3)
            if q.shape[1] < 3:       # fit_plane completes the frame of one or two points
                frames = [fit_plane(x) for x in q]
                c = np.array([f[0] for f in frames])
                nrm = np.array([f[1] for f in frames])
                axes = np.array([f[2] for f in frames])
            else:                    # fit_plane, loop by loop in the stacked SVD
                c = q.mean(axis=1)
                vt = np.linalg.svd(q - c[:, None], full_matrices=False)[2]
                nrm, axes = vt[:, 2], vt[:, :2]
            self.centre[ids], self.normal[ids], self.axes[ids] = c, nrm, axes
            dev[ids] = np.abs(np.matmul(q - c[:, None], nrm[:, :, None])[..., 0]).max(axis=1)
        self.planar = (dev <= tol) & np.array([not p.holes for p in patches], bool)
        self.area = np.zeros(n)
        for k in np.flatnonzero(self.planar):
            self.area[k] = abs(_area2d((pts[k] - self.centre[k]) @ self.axes[k].T))
        self.lo = np.minimum.reduceat(self.points, self.start[:-1])
        self.hi = np.maximum.reduceat(self.points, self.start[:-1])

    def of(self, k: int) -> np.ndarray:
        """Patch ``k``'s loop points, ``(m_k, 3) float64``."""
        return self.points[self.start[k]:self.start[k + 1]]


def _nearest_outer(planes: _Planes, junctions, manifold, tol: float) -> dict:
    """Inner patch -> the smallest planar manifold patch that holds it in its plane.

    ``junctions`` is the ``(n, V)`` sparse incidence of patches and their loops'
    junctions. Candidates are the pairs whose boxes nest (an R-tree query with the inner
    box's centre, then box containment); the shared-junction and plane tests run on all
    pairs at once, the outline test once per outer patch.
    """
    inner = np.flatnonzero(planes.planar)
    outer = np.flatnonzero(planes.planar & manifold)
    if len(inner) == 0 or len(outer) == 0:
        return {}
    i, j = _nesting_boxes(planes, inner, outer, 3 * tol)
    apart = np.asarray(junctions[i].multiply(junctions[j]).sum(axis=1)).ravel() == 0
    i, j = i[apart], j[apart]
    i, j = _coplanar(planes, i, j, tol)
    i, j = _inside(planes, i, j)
    if len(i) == 0:
        return {}
    # smallest area first, then the first in ``patches``
    order = np.lexsort((j, planes.area[j], i))
    i, j = i[order], j[order]
    first = np.r_[True, i[1:] != i[:-1]]
    return dict(zip(i[first].tolist(), j[first].tolist()))


def _nesting_boxes(planes: _Planes, inner, outer, margin: float):
    """Pairs ``(i, j)``, ``i != j``, whose inner box lies in the outer box grown by ``margin``.

    A loop within ``tol`` of a plane and inside the outline of a loop in that plane lies
    within ``2 tol`` of that loop's box, so ``margin = 3 tol`` loses no hole.
    """
    from rtree import index
    prop = index.Property()
    prop.dimension = 3
    tree = index.Index((outer.astype(np.int64), planes.lo[outer] - margin,
                        planes.hi[outer] + margin), properties=prop)
    mid = 0.5 * (planes.lo[inner] + planes.hi[inner])
    hits, counts = tree.intersection_v(mid, mid)
    i = np.repeat(inner, counts.astype(np.int64))
    j = hits.astype(np.int64)
    keep = ((i != j) & (planes.lo[j] - margin <= planes.lo[i]).all(axis=1)
            & (planes.hi[i] <= planes.hi[j] + margin).all(axis=1))
    return i[keep], j[keep]


def _coplanar(planes: _Planes, i, j, tol: float):
    """The pairs whose inner loop lies within ``tol`` of the outer loop's plane."""
    if len(i) == 0:
        return i, j
    counts = planes.start[i + 1] - planes.start[i]
    pair = np.repeat(np.arange(len(i)), counts)
    offsets = np.concatenate([[0], np.cumsum(counts)[:-1]])
    point = planes.start[i][pair] + np.arange(len(pair)) - offsets[pair]
    jj = j[pair]
    dist = np.abs(np.einsum("ij,ij->i", planes.points[point] - planes.centre[jj],
                            planes.normal[jj]))
    keep = np.maximum.reduceat(dist, offsets) <= tol
    return i[keep], j[keep]


def _inside(planes: _Planes, i, j):
    """The pairs whose inner loop's points all lie inside the outer outline, in its plane.

    One point-in-polygon call per outer patch, on all its candidates' points.
    """
    if len(i) == 0:
        return i, j
    from matplotlib.path import Path
    keep = np.zeros(len(i), bool)
    order = np.argsort(j, kind="stable")
    bounds = np.flatnonzero(np.r_[True, j[order][1:] != j[order][:-1], True])
    for a, b in zip(bounds[:-1], bounds[1:]):
        sel = order[a:b]
        k = int(j[sel[0]])
        c, axes = planes.centre[k], planes.axes[k]
        outline = Path((planes.of(k) - c) @ axes.T)
        pts = [planes.of(int(m)) for m in i[sel]]
        inside = outline.contains_points((np.concatenate(pts) - c) @ axes.T)
        starts = np.concatenate([[0], np.cumsum([len(q) for q in pts])[:-1]])
        keep[sel] = np.logical_and.reduceat(inside, starts)
    return i[keep], j[keep]


def _outside_in(nearest: dict) -> list:
    """The inner patches ordered so that each comes after the patch around it."""
    depth: dict = {}
    for start in nearest:
        chain, k = [], start
        while k in nearest and k not in depth and k not in chain:
            chain.append(k)
            k = nearest[k]
        d = depth.get(k, -1)
        for m in reversed(chain):
            d += 1
            depth[m] = d
    return sorted(nearest, key=lambda k: (depth[k], k))


def _area2d(xy) -> float:
    x, y = xy[:, 0], xy[:, 1]
    xn, yn = np.concatenate([x[1:], x[:1]]), np.concatenate([y[1:], y[:1]])   # np.roll(., -1)
    return 0.5 * float(np.dot(x, yn) - np.dot(y, xn))
