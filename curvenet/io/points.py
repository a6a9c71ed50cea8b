"""Curves given as unordered point samples: tell them from polylines, recover the curves.

A block of points read as one stroke is a *drawn polyline* when consecutive
points are neighbours, and *unordered samples of curves* (wireframe samples,
scanner edge points, point-set exports) when consecutive points jump far
beyond the sampling spacing. :func:`read_point_blocks` decides block by block
(:func:`jump_ratio` against :data:`JUMP_RATIO`) and replaces each unordered
block by the curves :func:`recover_curves` finds in it, so that the usual
snapping, patch finding and surfacing follow.

Recovery (:func:`recover_curves`)
---------------------------------
1. Scale. Box counting over half-octave cell sizes gives the local dimension
   ``log2(N(c) / N(2c))`` of the samples; curves are one-dimensional from
   above their spacing and noise up to the gaps between distinct curves. The
   finest run of :data:`MIN_RUN` consecutive scales with dimension in
   ``[0.7, 1.4]`` sets the cell size ``c``. No such run (a 2D scatter, a
   surface scan, a blob): :class:`NotCurvesError`.
2. Nodes. Points are averaged per grid cell of size ``c`` (noise averages
   out), then each node is projected onto the principal line of its
   neighbours within ``2 c`` where they are linear, collapsing the noisy tube
   onto its axis.
3. Thinning. Minimum spanning tree of the node graph (pairs within
   ``2.5 c``); spurs shorter than ``4 c`` are pruned; cycles the tree cut are
   closed again by the shortest node-graph edges (or leaf-to-curve links
   within ``6 c``) whose ends are more than ``12 c`` apart along the tree.
4. Curves. The graph splits into chains between nodes of degree other than
   two; junction nodes joined by chains shorter than ``3 c`` merge into one
   junction, placed at the least-squares intersection of the incoming chain
   ends' tangent lines (fitted from ``2 c`` to ``10 c`` out; quadratic where
   an end is curved); short chains that noise laid across curves converging at a
   junction (a loop back to it, or a bridge closing a triangle of short
   chains with it) are dropped; a chain closing on itself with no junction
   stays a closed loop; sharp turns (over 45 degrees within ``3 c``) split a chain into two
   curves meeting at a degree-2 vertex.

Every chain comes back as an ordered polyline whose ends are exactly the
junction points, so snapping in exact mode rebuilds the same graph. Work on
points is vectorised (grids, KD-trees, sparse graphs); Python loops run over
scales and chains only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from .pointjunctions import bridges, junction_point
from ..core.geometry import cumulative_length, interpolate_polyline
from ..core.tolerances import DIVISION_GUARD
from ..core.errors import InvalidParameterError, SketchFormatError
from ..model.sketch import Sketch

__all__ = ["JUMP_RATIO", "MIN_BLOCK_POINTS", "NotCurvesError", "PointCurves", "jump_ratio",
           "dimension_profile",
           "recover_curves", "read_point_blocks"]

#: A block is unordered when the median step between consecutive points exceeds
#: this many times the median nearest-neighbour spacing (drawn polylines: about 1).
JUMP_RATIO = 8.0

_PROBES = 200_000            # largest sample that neighbour statistics are taken on

#: Blocks with fewer points are always read as polylines (too few to tell).
MIN_BLOCK_POINTS = 20

_MAX_DIM = 1.45             # highest correlation dimension read as curves
_DIM_SLACK = 0.2            # radii this close to the lowest dimension are "one-dimensional"
_CELL_FACTOR = 1.0         # cell size over the finest one-dimensional radius
_MIN_CELL = 1.0 / 600.0     # smallest cell size, fraction of the diagonal (bounds node count)
_SMOOTH_R, _LINK_R, _SPUR, _CLOSE_LEAF, _FAR, _MERGE, _CORNER_W = 2.0, 2.5, 4.0, 6.0, 12.0, 4.0, 4.0
_CORNER_ANGLE = 45.0


class NotCurvesError(SketchFormatError):
    """The points do not lie along curves (a surface scan, a scatter): nothing to recover."""


@dataclass
class PointCurves:
    """Curves recovered from unordered samples.

    Attributes
    ----------
    strokes : list of (n_i, 3) float64 ndarray
        Ordered polylines; ends shared exactly at junctions; a closed loop
        repeats its first point at the end.
    junctions : (J, 3) float64 ndarray
        Points where three or more curves meet (and sharp-turn vertices).
    cell : float
        Sampling scale ``c`` used (absolute length).
    dimension : (S, 2) float64 ndarray
        Box-counting profile: cell size, local dimension.
    report : dict
        Counters: ``points``, ``nodes``, ``curves``, ``loops``, ``junctions``,
        ``corners``, ``spurs_pruned``, ``cycles_closed``.
    """

    strokes: list
    junctions: np.ndarray
    cell: float
    dimension: np.ndarray
    report: dict = field(default_factory=dict)


# --------------------------------------------------------------------------- detection
def jump_ratio(points) -> float:
    """Median step between consecutive points over the median nearest-neighbour spacing.

    Parameters
    ----------
    points : (n, 3) array_like

    Returns
    -------
    float
        About 1 for a drawn polyline, about ``n / 3`` for points in random order.
        Nearest neighbours are taken for at most :data:`_PROBES` points (seeded).
    """
    p = np.asarray(points, dtype=np.float64)
    if len(p) < 3:
        return 1.0
    steps = np.linalg.norm(np.diff(p, axis=0), axis=1)
    probe = p if len(p) <= _PROBES else p[np.random.default_rng(0).choice(len(p), _PROBES,
                                                                          replace=False)]
    d, _ = cKDTree(p).query(probe, k=2)
    nn, steps = d[:, 1][d[:, 1] > 0], steps[steps > 0]
    if nn.size == 0 or steps.size == 0:
        return 1.0
    return float(np.median(steps) / np.median(nn))


# --------------------------------------------------------------------------- scale
def _cell_keys(p, lo, c):
    q = np.floor((p - lo) / c).astype(np.int64)
    m = q.max(axis=0) + 1
    return (q[:, 0] * m[1] + q[:, 1]) * m[2] + q[:, 2]


def dimension_profile(points, *, probes: int = 2000, seed: int = 0) -> np.ndarray:
    """Correlation dimension of a point set over half-octave radii.

    Parameters
    ----------
    points : (n, 3) array_like
    probes : int
        Number of points (drawn at random, seeded) whose neighbour counts are
        taken, among at most :data:`_PROBES` points (a seeded subsample).
    seed : int

    Returns
    -------
    (S, 2) float64 ndarray
        Rows ``(r, log2(C(2 r) / C(r)))`` from coarse to fine radii, ``C(r)``
        the mean number of other points within ``r`` of a probe; radii go down
        from a quarter of the diagonal until probes have about one neighbour.
    """
    p = np.asarray(points, dtype=np.float64)
    diag = float(np.linalg.norm(np.ptp(p, axis=0))) or 1.0
    rng = np.random.default_rng(seed)
    other = p if len(p) <= _PROBES else p[rng.choice(len(p), _PROBES, replace=False)]
    probe = other if len(other) <= probes else other[rng.choice(len(other), probes,
                                                                replace=False)]
    radii = diag * 2.0 ** (-np.arange(2, 44) / 2)
    counts = cKDTree(probe).count_neighbors(cKDTree(other), radii).astype(np.float64)
    counts = (counts - len(probe)) / len(probe)
    keep = np.flatnonzero(counts >= 1.0)
    if len(keep) < 3:
        return np.zeros((0, 2))
    c = counts[: keep[-1] + 1]
    return np.column_stack([radii[2: len(c)], np.log2(c[:-2] / c[2:]) / 1.0])


def _pick_cell(profile, diag):
    """Cell size: twice the finest radius of the one-dimensional regime, or None.

    The regime is the run of radii whose dimension is within :data:`_DIM_SLACK`
    of the profile's lowest value, which must itself be at most
    :data:`_MAX_DIM` (curves; a surface is about 2).
    """
    if len(profile) == 0 or profile[:, 1].min() > _MAX_DIM:
        return None
    ok = profile[:, 1] <= profile[:, 1].min() + _DIM_SLACK
    lowest = int(np.argmin(profile[:, 1]))
    fine = lowest
    while fine + 1 < len(ok) and ok[fine + 1]:
        fine += 1
    return max(_CELL_FACTOR * float(profile[fine, 0]), _MIN_CELL * diag)


# --------------------------------------------------------------------------- nodes
def _nodes(p, c):
    """Cell centroids ``(N, 3)`` and point counts ``(N,)`` at cell size ``c``."""
    key = _cell_keys(p, p.min(axis=0), c)
    _, inv, cnt = np.unique(key, return_inverse=True, return_counts=True)
    inv = inv.ravel()
    cen = np.column_stack([np.bincount(inv, weights=p[:, k]) for k in range(3)]) / cnt[:, None]
    return cen, cnt.astype(np.float64)


def _project_lines(x, w, r, rounds=2):
    """Move each node onto the principal line of its neighbours within ``r`` (where linear)."""
    for _ in range(rounds):
        pairs = cKDTree(x).query_pairs(r, output_type="ndarray")
        i = np.concatenate([pairs[:, 0], pairs[:, 1], np.arange(len(x))])
        j = np.concatenate([pairs[:, 1], pairs[:, 0], np.arange(len(x))])
        wj = w[j]
        sw = np.bincount(i, weights=wj, minlength=len(x))
        mu = np.column_stack([np.bincount(i, weights=wj * x[j, k], minlength=len(x))
                              for k in range(3)]) / sw[:, None]
        d = x[j] - mu[i]
        outer = (d[:, :, None] * d[:, None, :]).reshape(-1, 9)
        cov = np.column_stack([np.bincount(i, weights=wj * outer[:, k], minlength=len(x))
                               for k in range(9)]).reshape(-1, 3, 3) / sw[:, None, None]
        lam, vec = np.linalg.eigh(cov)
        axis = vec[:, :, 2]
        linear = lam[:, 2] > 0.85 * lam.sum(axis=1)
        rel = x - mu
        proj = mu + np.einsum("ij,ij->i", rel, axis)[:, None] * axis
        x = np.where(linear[:, None], proj, x)
    return x


# --------------------------------------------------------------------------- graphs
def _sym(n, e, w):
    a = sparse.coo_matrix((np.concatenate([w, w]), (np.concatenate([e[:, 0], e[:, 1]]),
                                                     np.concatenate([e[:, 1], e[:, 0]]))),
                          shape=(n, n))
    return a.tocsr()


def _tree_distance(n, tree_e, tree_w, a, b):
    """Path lengths in a forest between node pairs ``a[k], b[k]`` (binary-lifting LCA)."""
    _, lab = csgraph.connected_components(_sym(n, tree_e, tree_w), directed=False)
    roots = np.unique(lab, return_index=True)[1]
    e = np.vstack([tree_e, np.column_stack([np.full(len(roots), n), roots])])
    w = np.concatenate([tree_w, np.full(len(roots), 1e-300)])  # local: > 0 keeps the edge stored
    g = _sym(n + 1, e, w)
    depth = csgraph.dijkstra(g, indices=n)
    hop = csgraph.dijkstra(g, indices=n, unweighted=True).astype(np.int64)
    _, pred = csgraph.breadth_first_order(g, n, directed=False)
    pred[n] = n
    up = [pred]
    for _ in range(int(hop.max()).bit_length()):
        up.append(up[-1][up[-1]])
    a, b = np.asarray(a).copy(), np.asarray(b).copy()
    a0, b0 = a.copy(), b.copy()
    swap = hop[a] < hop[b]
    a[swap], b[swap] = b[swap], a[swap]
    diff = hop[a] - hop[b]
    for k, u in enumerate(up):
        a = np.where((diff >> k) & 1, u[a], a)
    for u in reversed(up):
        ua, ub = u[a], u[b]
        m = ua != ub
        a, b = np.where(m, ua, a), np.where(m, ub, b)
    lca = np.where(a == b, a, pred[a])
    return depth[a0] + depth[b0] - 2 * depth[lca]


def _walk_back(n, e, start, hops):
    """Node reached from each leaf in ``start`` after ``hops`` steps along its chain
    (stopping early at a junction or an end)."""
    g = _sym(n, e, np.ones(len(e)))
    ptr, nbr = g.indptr, g.indices
    deg = np.diff(ptr)
    prev, cur = start.copy(), start.copy()
    for _ in range(hops):  # loop over hops; every leaf walks at once
        go = (deg[cur] == 1) & (cur == start) | (deg[cur] == 2)
        first = nbr[ptr[cur]]
        second = nbr[np.minimum(ptr[cur] + 1, len(nbr) - 1)]
        nxt = np.where((first == prev) & (deg[cur] == 2), second, first)
        prev, cur = np.where(go, cur, prev), np.where(go, nxt, cur)
    return cur


def _close_cycles(x, tree_e, tree_w, graph_e, c):
    """Edges that close the cycles the spanning tree cut (cheapest first, one per gap).

    Candidates join nodes more than ``_FAR * c`` apart along the tree: node-graph
    edges between two non-leaf nodes (cost: length), and links from a leaf to a
    node within ``_CLOSE_LEAF * c`` ahead of it, within 60 degrees of the
    direction the leaf points in (cost: length over the cosine), so a curve cut
    near a junction rejoins the junction, not a curve beside it.
    """
    n = len(x)
    deg = np.bincount(tree_e.ravel(), minlength=n)
    leaf = deg == 1
    ok = (deg[graph_e[:, 0]] > 1) & (deg[graph_e[:, 1]] > 1)
    cand, cost = [graph_e[ok]], [np.linalg.norm(x[graph_e[ok, 0]] - x[graph_e[ok, 1]], axis=1)]
    leaves = np.flatnonzero(leaf)
    if len(leaves):
        idx = np.flatnonzero(deg > 0)
        tree = cKDTree(x[idx])
        k = min(24, len(idx))
        dist, nb = tree.query(x[leaves], k=k, distance_upper_bound=_CLOSE_LEAF * c)
        nb = idx[np.minimum(nb, len(idx) - 1)]
        ahead = x[leaves] - x[_walk_back(n, tree_e, leaves, hops=4)]
        ahead /= np.maximum(np.linalg.norm(ahead, axis=1, keepdims=True), DIVISION_GUARD)
        to = x[nb] - x[leaves][:, None, :]
        cos = np.einsum("ijk,ik->ij", to, ahead) / np.maximum(dist, DIVISION_GUARD)
        good = np.isfinite(dist) & (cos >= 0.5)
        cand.append(np.column_stack([np.broadcast_to(leaves[:, None], good.shape)[good],
                                     nb[good]]))
        cost.append(dist[good] / cos[good])
    cand, cost = np.vstack(cand), np.concatenate(cost)
    keep = cand[:, 0] != cand[:, 1]
    cand, cost = cand[keep], cost[keep]
    if len(cand) == 0:
        return np.zeros((0, 2), np.int64)
    far = _tree_distance(n, tree_e, tree_w, cand[:, 0], cand[:, 1]) > _FAR * c
    cand, cost = cand[far], cost[far]
    cand = cand[np.argsort(cost, kind="stable")]
    added_e, added_w = [], []
    g = _sym(n, tree_e, tree_w)
    for a, b in cand:  # loop over gap candidates, not points
        if csgraph.dijkstra(g, indices=a, limit=_FAR * c)[b] > _FAR * c:
            added_e.append((a, b))
            added_w.append(float(np.linalg.norm(x[a] - x[b])) + 1e-9 * c)
            g = _sym(n, np.vstack([tree_e, added_e]), np.concatenate([tree_w, added_w]))
    return np.asarray(added_e, np.int64).reshape(-1, 2)


def _edge_keys(n, e):
    return np.minimum(e[:, 0], e[:, 1]) * n + np.maximum(e[:, 0], e[:, 1])


def _chains(n, e):
    """Split a simple graph into chains between nodes of degree other than two.

    Parameters
    ----------
    n : int
    e : (E, 2) int64 ndarray
        Undirected edges, no duplicates, no self-loops.

    Returns
    -------
    list of (k,) int64 ndarray
        Node sequences, ends included; a cycle of degree-2 nodes repeats its
        first node at the end.
    """
    deg = np.bincount(e.ravel(), minlength=n)
    inner = deg == 2
    both = inner[e[:, 0]] & inner[e[:, 1]]
    ie = e[both]
    _, comp = csgraph.connected_components(_sym(n, ie, np.ones(len(ie))), directed=False)
    ids = np.flatnonzero(inner)
    n_in = np.bincount(comp[ids], minlength=n)
    e_in = np.bincount(comp[ie[:, 0]], minlength=n)
    cyc = (e_in == n_in) & (n_in > 0)
    indeg = np.bincount(ie.ravel(), minlength=n)
    # start of each inner path: its smallest end node; of each inner cycle: its smallest node
    is_start = inner & ((indeg < 2) | cyc[comp])
    starts = ids[is_start[ids]]
    starts = starts[np.unique(comp[starts], return_index=True)[1]]
    cut = cyc[comp[ie[:, 0]]] & np.isin(ie, starts).any(axis=1)
    first_cut = np.unique(comp[ie[cut, 0]], return_index=True)[1]
    drop = np.zeros(len(ie), bool)
    drop[np.flatnonzero(cut)[first_cut]] = True
    pe = np.vstack([ie[~drop], np.column_stack([np.full(len(starts), n), starts])])
    order = csgraph.breadth_first_order(_sym(n + 1, pe, np.ones(len(pe))), n,
                                        directed=False, return_predecessors=False)
    rank = np.empty(n + 1, np.int64)
    rank[order] = np.arange(len(order))
    seq = ids[np.lexsort((rank[ids], comp[ids]))]
    bounds = np.flatnonzero(np.diff(comp[seq])) + 1
    mixed = e[inner[e[:, 0]] != inner[e[:, 1]]]
    att = np.where(inner[mixed[:, 0]][:, None], mixed, mixed[:, ::-1])  # (inner, outer)
    att = att[np.argsort(att[:, 0], kind="stable")]
    where = np.searchsorted(att[:, 0], np.arange(n))
    out = []
    for run in np.split(seq, bounds) if len(seq) else []:
        if cyc[comp[run[0]]]:
            out.append(np.append(run, run[0]))
            continue
        a = att[where[run[0]], 1]
        b = att[where[run[-1]] + (1 if len(run) == 1 else 0), 1]
        out.append(np.concatenate([[a], run, [b]]))
    out.extend(e[~inner[e[:, 0]] & ~inner[e[:, 1]]])
    return out


def _length(x, nodes):
    return float(np.linalg.norm(np.diff(x[nodes], axis=0), axis=1).sum())


def _prune(x, e, c, forks=False):
    """Remove the chains that end in a leaf and are spurs; returns (edges, count).

    A spur is shorter than ``_SPUR * c``; with ``forks``, also a chain shorter
    than ``_FAR * c`` whose leaf lies within ``_LINK_R * c`` of a node off the
    chain (a branch running alongside a curve). Where fewer than two other
    chains meet a spur's junction (the spur may be the curve's own end), the
    longest of its spurs stays, so a curve is never eaten from its end.
    """
    n = len(x)
    pruned = 0
    while len(e):
        deg = np.bincount(e.ravel(), minlength=n)
        chains = _chains(n, e)
        leafy = [ch if deg[ch[-1]] == 1 else ch[::-1] for ch in chains
                 if deg[ch[0]] == 1 or deg[ch[-1]] == 1]
        if not leafy:
            break
        lengths = np.array([_length(x, ch) for ch in leafy])
        spur = lengths < _SPUR * c
        if forks:
            alive = np.flatnonzero(deg > 0)
            near = cKDTree(x[alive]).query_ball_point(x[[ch[-1] for ch in leafy]], _LINK_R * c)
            spur |= (lengths < _FAR * c) & np.array(
                [np.isin(alive[nb], ch, invert=True).any() for nb, ch in zip(near, leafy)])
        root = np.array([ch[0] for ch in leafy])
        ends = np.array([v for ch in chains if deg[ch[0]] != 1 and deg[ch[-1]] != 1
                         for v in (ch[0], ch[-1])], np.int64)
        others = np.bincount(ends, minlength=n)[root]
        order = np.lexsort((-lengths, root))
        first = np.zeros(len(leafy), bool)
        first[order[np.r_[True, root[order][1:] != root[order][:-1]]]] = True
        spur &= ~(first & (others < 2) & (deg[root] != 1))
        gone = [np.stack([ch[:-1], ch[1:]], axis=1) for ch, s in zip(leafy, spur) if s]
        if not gone:
            break
        pruned += len(gone)
        e = e[~np.isin(_edge_keys(n, e), _edge_keys(n, np.vstack(gone)))]
    return e, pruned


def _assemble(x, e, c):
    """Chains of the thinned graph -> (polylines, closed flags, junction points)."""
    n = len(x)
    chains = _chains(n, e)
    deg = np.bincount(e.ravel(), minlength=n)
    lengths = np.array([_length(x, ch) for ch in chains])
    hub = np.array([deg[ch[0]] >= 3 and deg[ch[-1]] >= 3 for ch in chains], bool)
    short = hub & (lengths < _MERGE * c)
    pairs = np.array([[ch[0], ch[-1]] for ch, s in zip(chains, short) if s], np.int64)
    _, cluster = csgraph.connected_components(_sym(n, pairs.reshape(-1, 2),
                                                   np.ones(len(pairs))), directed=False)
    short |= bridges(chains, lengths, cluster, hub & ~short, c)
    closed = [ch[0] == ch[-1] and deg[ch[0]] == 2 for ch in chains]
    # curves: [nodes, start vertex, end vertex]; vertex = cluster label (-1: closed loop)
    curves = [[ch, -1 if cl else cluster[ch[0]], -1 if cl else cluster[ch[-1]]]
              for ch, s, cl in zip(chains, short, closed) if not s]
    while True:  # a junction left with two curves is no junction: join them
        ends = np.array([v for cv in curves for v in cv[1:] if v >= 0], np.int64)
        cnt = np.bincount(ends) if len(ends) else np.zeros(0, np.int64)
        twos = np.flatnonzero(cnt == 2)
        if not len(twos):
            break
        v = twos[0]
        inc = [i for i, cv in enumerate(curves) if v in cv[1:]]
        if len(inc) == 1:
            nodes = curves[inc[0]][0]
            curves[inc[0]] = [nodes if nodes[0] == nodes[-1] else np.append(nodes, nodes[0]),
                              -1, -1]
            continue
        i, j = inc
        ci, cj = curves[i], curves[j]
        ni = ci[0] if ci[2] == v else ci[0][::-1]
        nj = cj[0] if cj[1] == v else cj[0][::-1]
        ai = ci[1] if ci[2] == v else ci[2]
        bj = cj[2] if cj[1] == v else cj[1]
        curves[i] = [np.concatenate([ni, nj]), ai, bj]
        del curves[j]
    return curves, cluster, deg


def _corners(poly, w):
    """Indices of the corners of a polyline.

    A corner turns by more than :data:`_CORNER_ANGLE` between the directions
    over ``[2 w / 3, 2 w]`` before and after it, and by less than 1.5 times the
    turn over ``[w / 3, w]``: a corner's turn does not grow with the window
    (rounding by the sampling scale aside), a smooth bend's grows in proportion.
    """
    s = cumulative_length(poly)
    inside = np.flatnonzero((s > 2 * w) & (s < s[-1] - 2 * w))
    if len(inside) == 0:
        return inside

    def at(t):
        return interpolate_polyline(poly, t, cum=s)

    def turn(r):
        u, v = at(s[inside] - r / 3) - at(s[inside] - r), at(s[inside] + r) - at(s[inside] + r / 3)
        cos = np.einsum("ij,ij->i", u, v) / np.maximum(
            np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1), DIVISION_GUARD)
        return np.degrees(np.arccos(np.clip(cos, -1, 1)))

    turn, wide = turn(w), turn(2 * w)
    turn = np.where(wide < 1.5 * turn, wide, 0.0)
    sharp = inside[turn > _CORNER_ANGLE]
    if len(sharp) == 0:
        return sharp
    # one corner per run of sharp samples: the sharpest
    run = np.concatenate([[0], np.cumsum(np.diff(s[sharp]) > w)])
    t = turn[np.searchsorted(inside, sharp)]
    best = np.lexsort((-t, run))
    return np.sort(sharp[best[np.concatenate([[True], np.diff(run[best]) > 0])]])


def _smooth(p, closed, rounds=4):
    """Binomial smoothing along a polyline (ends fixed unless closed)."""
    for _ in range(rounds):
        if closed and len(p) > 3:
            q = p[:-1]
            q = 0.5 * q + 0.25 * (np.roll(q, 1, axis=0) + np.roll(q, -1, axis=0))
            p = np.vstack([q, q[:1]])
        elif len(p) > 2:
            p = np.vstack([p[:1], 0.5 * p[1:-1] + 0.25 * (p[:-2] + p[2:]), p[-1:]])
    return p


def _polylines(x, curves, cluster, c):
    """Ordered polylines whose ends are exactly the junction points; sharp turns split."""
    labels = sorted({v for cv in curves for v in cv[1:] if v >= 0})
    where = {}
    for v in labels:
        members = np.flatnonzero(cluster == v)
        ends = [cv[0] if k == 1 else cv[0][::-1] for cv in curves for k in (1, 2)
                if cv[k] == v]
        where[v] = junction_point(x, members, ends, c)
    strokes, corners = [], 0
    for nodes, a, b in curves:
        p = x[nodes]
        closed = a < 0
        if not closed:
            ja, jb = where[a], where[b]
            keep = ((np.linalg.norm(p - ja, axis=1) > c) & (np.linalg.norm(p - jb, axis=1) > c))
            keep[[0, -1]] = False
            p = np.vstack([ja, p[keep], jb])
        cut = _corners(p, _CORNER_W * c)
        if closed and len(cut):  # closed loop with corners: start it at one
            p = np.vstack([p[cut[0]:-1], p[:cut[0] + 1]])
            cut, closed = _corners(p, _CORNER_W * c), False
        corners += len(cut)
        strokes.extend(_smooth(p[i:j + 1], closed)
                       for i, j in zip(np.r_[0, cut], np.r_[cut, len(p) - 1]))
    return strokes, np.array([where[v] for v in labels]).reshape(-1, 3), corners


def recover_curves(points, *, cell: float | None = None, name: str = "points",
                   path=None) -> PointCurves:
    """Recover the curve network sampled by unordered points.

    Parameters
    ----------
    points : (n, 3) array_like
        Samples along curves, any order, any density, with noise well below
        the distance between distinct curves.
    cell : float, optional
        Sampling scale (absolute length); estimated by box counting when omitted.
    name : str
        Names the input in error messages.
    path : str, optional
        The file the points came from (named in error messages).

    Returns
    -------
    PointCurves

    Raises
    ------
    NotCurvesError
        The points are not one-dimensional at any scale (a surface scan, a 2D
        scatter), or no curve survives thinning.

    Examples
    --------
    >>> t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    >>> ring = np.column_stack([np.cos(t), np.sin(t), 0 * t])
    >>> rc = recover_curves(np.random.default_rng(0).permutation(ring))
    >>> len(rc.strokes), rc.report["loops"], bool((rc.strokes[0][0] == rc.strokes[0][-1]).all())
    (1, 1, True)
    """
    p = np.asarray(points, dtype=np.float64)
    diag = float(np.linalg.norm(np.ptp(p, axis=0))) if len(p) else 0.0
    if len(p) < MIN_BLOCK_POINTS or diag == 0.0:
        raise NotCurvesError(f"{name}: {len(p)} points spanning {diag:.3g}: too few to "
                             "recover curves from", path=path)
    profile = dimension_profile(p)
    if cell is None:
        cell = _pick_cell(profile, diag)
        if cell is None:
            dims = profile[:, 1]
            raise NotCurvesError(
                f"{name}: the {len(p)} points do not lie along curves (their dimension is "
                f"{dims.min() if len(dims) else 0:.1f} at best, curves have 1): a surface scan "
                "or a scatter, not curve samples", path=path)
    x, w = _nodes(p, cell)
    x = _project_lines(x, w, _SMOOTH_R * cell)
    pairs = cKDTree(x).query_pairs(_LINK_R * cell, output_type="ndarray")
    length = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1) + 1e-9 * cell  # local: > 0
    mst = csgraph.minimum_spanning_tree(
        sparse.coo_matrix((length, (pairs[:, 0], pairs[:, 1])), shape=(len(x),) * 2)).tocoo()
    tree = np.column_stack([mst.row, mst.col]).astype(np.int64)
    tree, spurs = _prune(x, tree, cell)
    closing = _close_cycles(x, tree, np.linalg.norm(x[tree[:, 0]] - x[tree[:, 1]], axis=1)
                            + 1e-9 * cell, pairs, cell)
    e, more = _prune(x, np.vstack([tree, closing]), cell, forks=True)
    curves, cluster, _ = _assemble(x, e, cell)
    strokes, junctions, corners = _polylines(x, curves, cluster, cell)
    if not strokes:
        raise NotCurvesError(f"{name}: no curve longer than {_SPUR * cell:.3g} found in "
                             f"{len(p)} points: not curve samples", path=path)
    report = {"points": len(p), "nodes": len(x), "curves": len(strokes),
              "loops": sum(cv[1] < 0 for cv in curves), "junctions": len(junctions),
              "corners": corners, "spurs_pruned": spurs + more, "cycles_closed": len(closing),
              "cell": cell, "cell_rel": cell / diag}
    return PointCurves(strokes, junctions, cell, profile, report)


# --------------------------------------------------------------------------- sketches
def read_point_blocks(sketch: Sketch, points="auto") -> Sketch:
    """Replace the strokes that are unordered point samples by the curves they sample.

    Parameters
    ----------
    sketch : Sketch
        As read from a file: each block of points is one stroke.
    points : {"auto", True, False}
        ``auto`` reads a stroke of at least :data:`MIN_BLOCK_POINTS` points as
        unordered samples when :func:`jump_ratio` exceeds :data:`JUMP_RATIO`;
        ``True`` reads every stroke so; ``False`` none.

    Returns
    -------
    Sketch
        Strokes in file order, each unordered block replaced by its recovered
        curves (with the block's label). When a block was read as points,
        ``metadata["reading"]`` says so in one line and why, and
        ``metadata["point_blocks"]`` has the :attr:`PointCurves.report` of
        each; otherwise the sketch comes back unchanged.

    Raises
    ------
    NotCurvesError
        An unordered block that does not sample curves (named, with the file).
    """
    if points not in ("auto", True, False):
        raise InvalidParameterError(f"points: {points!r} is not 'auto', True or False")
    src = sketch.source
    strokes, labels, blocks = [], [], []
    for i, (s, lab) in enumerate(zip(sketch.strokes, sketch.labels)):
        ratio = jump_ratio(s) if points is True or (points == "auto" and
                                                    len(s) >= MIN_BLOCK_POINTS) else 1.0
        if points is True or (points == "auto" and len(s) >= MIN_BLOCK_POINTS
                              and ratio > JUMP_RATIO):
            rc = recover_curves(s, name=f"stroke {i + 1} ({len(s)} points, consecutive points "
                                f"{ratio:.0f}x the spacing apart)", path=src)
            strokes.extend(rc.strokes)
            labels.extend([lab] * len(rc.strokes))
            blocks.append((i, len(s), ratio, rc.report))
        else:
            strokes.append(s)
            labels.append(lab)
    if not blocks:
        return sketch
    why = "forced by points=True" if points is True else (
        f"consecutive points jump more than {JUMP_RATIO:g}x the spacing")
    parts = [f"stroke {i + 1} ({n} points, steps {r:.0f}x the spacing) -> {rep['curves']} "
             f"curves, {rep['junctions']} junctions" for i, n, r, rep in blocks]
    n_poly = len(sketch) - len(blocks)
    meta = dict(sketch.metadata)
    meta["reading"] = (f"point samples ({why}): " + "; ".join(parts)
                       + (f"; {n_poly} stroke(s) read as polylines" if n_poly else ""))
    meta["point_blocks"] = [dict(r, stroke=i) for i, _, _, r in blocks]
    return Sketch(strokes, labels, meta, src)
