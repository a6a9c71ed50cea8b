"""The graph of the nodes of point samples: spanning tree, closed cycles, pruned spurs, chains.

Helpers of :mod:`curvenet.io.points` (curves recovered from unordered point samples):
the nodes (cell centroids) are linked into a spanning forest, the cycles the samples
close are added back (:func:`close_cycles`), spurs of noise are pruned (:func:`prune`)
and the rest is cut into chains between junctions (:func:`assemble`). Lengths are in
cells ``c`` of the node grid.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from ..core.geometry import arc_length
from ..core.tolerances import DIVISION_GUARD
from .pointjunctions import bridges

__all__ = ["LINK_R", "SPUR", "close_cycles", "prune", "assemble"]

#: nodes closer than this many cells are linked
LINK_R = 2.5
#: a leaf chain shorter than this many cells is a spur of noise
SPUR = 4.0
_CLOSE_LEAF, _FAR, _MERGE = 6.0, 12.0, 4.0   # in cells (see the functions)


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


def close_cycles(x, tree_e, tree_w, graph_e, c):
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
    return arc_length(x[nodes])


def prune(x, e, c, forks=False):
    """Remove the chains that end in a leaf and are spurs; returns (edges, count).

    A spur is shorter than ``SPUR * c``; with ``forks``, also a chain shorter
    than ``_FAR * c`` whose leaf lies within ``LINK_R * c`` of a node off the
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
        spur = lengths < SPUR * c
        if forks:
            alive = np.flatnonzero(deg > 0)
            near = cKDTree(x[alive]).query_ball_point(x[[ch[-1] for ch in leafy]], LINK_R * c)
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


def assemble(x, e, c):
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
