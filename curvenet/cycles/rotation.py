"""Faces of a curve network embedded as a surface: a rotation system from the junctions.

A closed 2-manifold through the curves is fixed, combinatorially, by the cyclic order
of the curves around each junction (a *rotation system*): walking along a curve and
turning, at each junction, onto the next curve in that order traces one face; every
curve bounds two faces (both its sides), and for a surface of genus ``g`` the faces
number ``E - V + 2 - 2 g`` per component. The cycle space has ``2 g`` dimensions more
than the faces span, which is why a minimum cycle basis of a torus holds meridian
circles that are no faces (Zhuang et al. 2013, Sec. 1).

The order at a junction comes from the geometry: the curves leave it along tangents
that lie, for a surface through them, near one tangent plane; among the cyclic orders
of those tangents the one that winds around a normal, the largest vector area
``|sum t_i x t_{i+1}|``, is the order on the surface, and that sum is the normal.
Normals of neighbouring junctions are made consistent (one side of the surface) by
transporting each along the curve between them (projection onto the plane normal to
the curve, step by step: a rotation-minimising frame) over a maximum spanning tree of
the agreement. Curves through junctions of two curves are walked as one; curves that
end in a free end bound no face and are left out.

References
----------
Y. Zhuang, M. Zou, N. Carr, T. Ju. A general and efficient method for finding cycles
in 3D curve networks. ACM Trans. Graph. 32(6) (SIGGRAPH Asia 2013): cycles that
together form a surface, each curve bounding two of them, consistent with an order
of the curves around each junction. Departures: the order at each junction is taken
from its tangents alone (the largest vector area), not searched for over all orders
with a surface-quality cost; where that order is wrong the faces are not simple
cycles, and :func:`curvenet.cycles.find_patches` keeps the cycle-basis patches.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import permutations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..core.polylines import Polylines, row_norms
from ..core.tolerances import DIVISION_GUARD
from ..model.network import CurveNetwork

__all__ = ["EmbeddedFaces", "embedded_faces", "TANGENT_FRAC", "TANGENT_REACH"]

#: A curve's tangent at a junction is the chord to its point at this fraction of its
#: length from the junction...
TANGENT_FRAC = 0.2
#: ...but no farther than this fraction of the network's diagonal.
TANGENT_REACH = 0.05
#: Junctions with at most this many curves get all their cyclic orders compared; more
#: are ordered by angle in the plane of their tangents.
MAX_ENUMERATED = 7
#: Samples per curve of the normal transport between junctions.
TRANSPORT_SAMPLES = 17
#: A junction's other cyclic orders whose vector area is at least this fraction of the
#: best one's are tried too (at most MAX_ALTERNATIVES orders per junction)...
ALTERNATIVE = 0.7
MAX_ALTERNATIVES = 3
#: ...in at most this many passes of coordinate descent over those junctions, and at
#: most this many trial embeddings in all (each costs a pass over the network).
MAX_PASSES = 2
MAX_TRIALS = 64


@dataclass
class EmbeddedFaces:
    """The faces a rotation system traces on a network.

    Attributes
    ----------
    loops : list of list of (int, bool)
        Each face as an oriented loop of ``(edge id, forward)`` (faces walk their
        shared curves in opposite directions).
    simple : (F,) bool
        Whether the face is a simple cycle (no curve or junction met twice): only these
        can be patches.
    genus : list of int or None
        Per connected component (of the curves that bound faces), ``1 - chi / 2`` of the
        closed surface the faces form, ``chi = V - E + F``; None where that is not a
        whole number (no consistent surface).
    core : (E,) bool
        The curves that can bound faces (the others end in a free end).
    report : dict
        ``junctions`` (of three or more curves), ``ambiguous`` (junctions with more
        than one candidate order), ``reordered`` (those whose second or third order
        was taken), ``conflicts`` (chains whose transported normal disagrees with the
        orientation chosen), ``dangling`` (curves left out: they end in a free end).
    """

    loops: list
    simple: np.ndarray
    genus: list
    core: np.ndarray
    report: dict = field(default_factory=dict)

    @property
    def edge_sets(self) -> list:
        """Each face as a sorted tuple of edge ids."""
        return [tuple(sorted(e for e, _ in lp)) for lp in self.loops]


# --------------------------------------------------------------------------- reduction
def _core_edges(network: CurveNetwork) -> np.ndarray:
    """Edges that survive pruning free ends repeatedly: (E,) bool."""
    ends = np.array([(e.u, e.v) for e in network.edges], np.int64).reshape(-1, 2)
    alive = np.ones(len(ends), bool)
    deg = np.bincount(ends.ravel(), minlength=network.number_of_vertices)
    at: dict = {}
    for i, (u, v) in enumerate(ends):
        at.setdefault(u, []).append(i)
        at.setdefault(v, []).append(i)
    stack = [v for v in range(len(deg)) if deg[v] == 1]
    while stack:
        v = stack.pop()
        if deg[v] != 1:
            continue
        for i in at.get(v, ()):
            if alive[i]:
                alive[i] = False
                u, w = ends[i]
                deg[u] -= 1
                deg[w] -= 1
                other = w if u == v else u
                if deg[other] == 1:
                    stack.append(other)
                break
    return alive


def _chains(network: CurveNetwork, alive: np.ndarray):
    """Curves through junctions of two curves joined: ``(nodes, chains)``.

    ``chains[k] = (a, b, [(edge, forward), ...])`` runs from node ``a`` to node ``b``;
    nodes are the junctions of three or more curves, and one junction of each
    component that is a single cycle.
    """
    ends = np.array([(e.u, e.v) for e in network.edges], np.int64).reshape(-1, 2)
    ids = np.flatnonzero(alive)
    deg = np.bincount(ends[ids].ravel(), minlength=network.number_of_vertices)
    at: dict = {}
    for i in ids:
        u, v = ends[i]
        at.setdefault(u, []).append((i, True))
        at.setdefault(v, []).append((i, False))
    node = deg >= 3
    used = np.zeros(len(ends), bool)
    chains = []

    def walk(start, first):
        path, v, (i, fwd) = [], start, first
        while True:
            used[i] = True
            path.append((i, fwd))
            v = ends[i, 1] if fwd else ends[i, 0]
            if node[v]:
                return v, path
            nxt = [h for h in at[v] if not used[h[0]]]
            if not nxt:                 # a cycle of two-curve junctions closed on itself
                return v, path
            i, _ = nxt[0]
            fwd = ends[i, 0] == v

    for v in np.flatnonzero(node):
        for i, fwd in at[v]:
            if not used[i]:
                b, path = walk(v, (i, fwd))
                chains.append((int(v), int(b), path))
    for i in ids:                       # components with no junction of three curves
        if not used[i]:
            v = int(ends[i, 0])
            node[v] = True
            b, path = walk(v, (i, True))
            chains.append((v, int(b), path))
    return np.flatnonzero(node), chains


def _polyline(network: CurveNetwork, path) -> np.ndarray:
    """The points of a chain from its first node to its last, (m, 3) float64."""
    parts = []
    for k, (i, fwd) in enumerate(path):
        c = network.edges[i].curve if fwd else network.edges[i].curve[::-1]
        parts.append(c if k == 0 else c[1:])
    return np.concatenate(parts)


# --------------------------------------------------------------------------- geometry
def _end_tangents(lines: Polylines, start: np.ndarray, reach: float) -> np.ndarray:
    """Unit chords ``(C, 3)`` from each polyline's first point to its point at
    :data:`TANGENT_FRAC` of its length (at most ``reach``) along it."""
    d = np.maximum(np.minimum(TANGENT_FRAC * lines.length, reach), DIVISION_GUARD)
    t = lines.at(d[:, None])[:, 0] - start
    return t / np.maximum(row_norms(t), DIVISION_GUARD)[:, None]


def _cyclic_orders(k: int):
    """Cyclic orders of ``k`` items up to rotation and reversal, as index tuples."""
    if k <= 3:
        return [tuple(range(k))]
    return [(0,) + p for p in permutations(range(1, k)) if p[0] < p[-1]]


def _all_orders(around: dict, tangents: np.ndarray) -> dict:
    """:func:`_orders` of every junction, as lists of half-edges: junction -> options, in
    the order of ``around``.

    Junctions with 3 to :data:`MAX_ENUMERATED` curves are taken in groups of equal
    count, all their cyclic orders compared at once; the others one by one.
    """
    by_k: dict = {}
    for v, hs in around.items():
        by_k.setdefault(len(hs) if 3 <= len(hs) <= MAX_ENUMERATED else 0, []).append(v)
    options = {}
    for v in by_k.pop(0, []):
        hs = around[v]
        options[v] = [([hs[i] for i in o], n, s) for o, n, s in _orders(tangents[hs])]
    for k, vs in by_k.items():
        orders = np.array(_cyclic_orders(k))                             # (o, k)
        hs = np.array([around[v] for v in vs], np.int64)                  # (J, k)
        t = tangents[hs][:, orders]                                       # (J, o, k, 3)
        area = np.cross(t, np.roll(t, -1, axis=2)).sum(axis=2)            # (J, o, 3)
        mag = np.linalg.norm(area, axis=2)                                # (J, o)
        rank = np.argsort(-mag, axis=1, kind="stable")[:, :MAX_ALTERNATIVES]
        top = np.take_along_axis(mag, rank, axis=1)
        keep = top >= ALTERNATIVE * top[:, :1]
        unit = area / np.maximum(mag, DIVISION_GUARD)[..., None]
        ring = hs[:, orders]                                              # (J, o, k)
        for r, v in enumerate(vs):
            options[v] = [(ring[r, j].tolist(), unit[r, j], float(mag[r, j] / k))
                          for j, ok in zip(rank[r].tolist(), keep[r].tolist()) if ok]
    return {v: options[v] for v in around}      # junction order: the descent's order


def _orders(tangents: np.ndarray) -> list:
    """Candidate cyclic orders of unit tangents ``(k, 3)``, best first.

    Returns
    -------
    list of (order, normal, strength)
        ``order`` an index tuple; ``normal`` the unit vector ``sum t_i x t_{i+1}`` over
        it; ``strength`` that sum's length over ``k`` (1 for tangents evenly spread in a
        plane). Orders whose strength is at least :data:`ALTERNATIVE` of the best follow
        it, at most :data:`MAX_ALTERNATIVES` in all.
    """
    k = len(tangents)
    if k == 2:
        n = np.cross(tangents[0], tangents[1])
        s = float(np.linalg.norm(n))
        return [((0, 1), n / max(s, DIVISION_GUARD), s)]
    if k <= MAX_ENUMERATED:
        orders = np.array(_cyclic_orders(k))                             # (o, k)
    else:                 # the order by angle in the plane of the tangents
        _, _, vt = np.linalg.svd(tangents, full_matrices=False)
        orders = np.argsort(np.arctan2(tangents @ vt[1], tangents @ vt[0]))[None]
    t = tangents[orders]                                                  # (o, k, 3)
    area = np.cross(t, np.roll(t, -1, axis=1)).sum(axis=1)                # (o, 3)
    mag = np.linalg.norm(area, axis=1)
    rank = np.argsort(-mag, kind="stable")
    keep = [j for j in rank[:MAX_ALTERNATIVES] if mag[j] >= ALTERNATIVE * mag[rank[0]]]
    return [(tuple(int(i) for i in orders[j]), area[j] / max(mag[j], DIVISION_GUARD),
             float(mag[j] / k)) for j in keep]


def _transports(lines: Polylines) -> np.ndarray:
    """Per polyline, the linear map that carries a normal from its first point to its last,
    up to a positive factor: ``(c, 3, 3)``.

    Each polyline is resampled to :data:`TRANSPORT_SAMPLES` points by arc length; at each
    segment ``t`` the vector is projected onto the plane normal to it, ``I - t t^T`` (a
    discrete rotation-minimising frame). The product of the projections is accumulated
    for all polylines at once, one segment at a time.
    """
    m = TRANSPORT_SAMPLES
    s = np.arange(m)[None, :] * (lines.length / (m - 1))[:, None]     # np.linspace, per row
    s[:, -1] = lines.length
    pts = lines.at(s)                                                     # (c, m, 3)
    seg = np.diff(pts, axis=1)
    seg /= np.maximum(np.linalg.norm(seg, axis=2, keepdims=True), DIVISION_GUARD)
    T = np.broadcast_to(np.eye(3), (len(pts), 3, 3)).copy()
    for j in range(m - 1):
        t = seg[:, j]                                                     # (c, 3)
        T = T - t[:, :, None] * np.einsum("ci,cij->cj", t, T)[:, None, :]
        T /= np.maximum(np.linalg.norm(T, axis=(1, 2), keepdims=True), DIVISION_GUARD)
    return T


@dataclass
class _Junctions:
    """What the embedding of a network's core is chosen from (computed once)."""

    nodes: np.ndarray        # (N,) vertex ids of the junctions
    chains: list             # (a, b, path) per chain
    origin: np.ndarray       # (H,) junction each half-edge leaves (2 per chain)
    around: dict             # junction -> its half-edges
    options: dict            # junction -> candidate orders (:func:`_orders`), of half-edges
    transport: np.ndarray    # (C, 3, 3) per chain (:func:`_transports`)
    votes: "_Votes"          # the chains between two junctions (:func:`_votes`)


@dataclass
class _Votes:
    """The chains that join two different junctions, as :func:`_orient` weighs them."""

    at: np.ndarray           # (N,) node index of each junction of ``options``, in its order
    transport: np.ndarray    # (P, 3, 3) of each such chain
    ia: np.ndarray           # (P,) node index of its first junction
    ib: np.ndarray           # (P,) ... and of its last
    group: np.ndarray        # (P,) one id per pair of junctions, in order of first chain
    key: np.ndarray          # (G,) sorted ``min * N + max`` of the pairs' node indices
    key_group: np.ndarray    # (G,) the group of each key


def _votes(nodes, chains, transport, options) -> _Votes:
    index = {int(v): i for i, v in enumerate(nodes)}
    at = np.array([index[v] for v in options], np.int64)
    pairs = [(k, index[a], index[b]) for k, (a, b, _) in enumerate(chains) if a != b]
    k, ia, ib = (np.array(x, np.int64).reshape(-1) for x in (zip(*pairs) if pairs
                                                             else ([], [], [])))
    code = np.minimum(ia, ib) * len(nodes) + np.maximum(ia, ib)
    key, first, group = np.unique(code, return_index=True, return_inverse=True)
    rank = np.empty(len(key), np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(len(key))
    return _Votes(at, transport[k], ia, ib, rank[group.reshape(-1)], key, rank)


def _junctions(network: CurveNetwork, alive: np.ndarray) -> _Junctions:
    nodes, chains = _chains(network, alive)
    reach = TANGENT_REACH * max(network.diagonal, DIVISION_GUARD)
    polys = [_polyline(network, path) for _, _, path in chains]
    lines = Polylines(polys)
    # half-edge 2 k leaves node a of chain k, 2 k + 1 leaves node b (backwards)
    tangents = np.stack([
        _end_tangents(lines, np.array([p[0] for p in polys]), reach),
        _end_tangents(Polylines(polys, reverse=True), np.array([p[-1] for p in polys]), reach),
    ], axis=1).reshape(-1, 3)
    origin = np.array([[a, b] for a, b, _ in chains], np.int64).ravel()
    around: dict = {}
    for h, v in enumerate(origin.tolist()):
        around.setdefault(v, []).append(h)
    options = _all_orders(around, tangents)
    transport = _transports(lines)
    return _Junctions(nodes, chains, origin, around, options, transport,
                      _votes(nodes, chains, transport, options))


# --------------------------------------------------------------------------- faces
def embedded_faces(network: CurveNetwork) -> EmbeddedFaces:
    """Faces traced by the rotation system the junctions' tangents imply.

    Each junction takes its best cyclic order; where another order comes close
    (:data:`ALTERNATIVE`), the orders are chosen by coordinate descent so that as few
    curves as possible lie on faces that are no simple cycle, then with as few
    orientation conflicts as possible.

    Parameters
    ----------
    network : CurveNetwork

    Returns
    -------
    EmbeddedFaces

    Examples
    --------
    >>> from curvenet.datasets.shapes import torus
    >>> f = embedded_faces(torus(n_u=4, n_v=2).network)
    >>> len(f.loops), bool(f.simple.all()), f.genus
    (8, True, [1])
    """
    alive = _core_edges(network)
    report = {"dangling": int(np.count_nonzero(~alive)), "junctions": 0, "ambiguous": 0,
              "reordered": 0, "conflicts": 0}
    if not alive.any():
        return EmbeddedFaces([], np.zeros(0, bool), [], alive, report)
    J = _junctions(network, alive)
    choice = {v: 0 for v in J.options}
    doubtful = [v for v, opts in J.options.items() if len(opts) > 1]
    report.update(junctions=sum(len(hs) >= 3 for hs in J.around.values()),
                  ambiguous=len(doubtful))
    best = _embed(network, J, choice)
    trials = 0
    for _ in range(MAX_PASSES):
        improved = False
        # only a junction on a face that is no simple cycle can make it one
        bad = {int(x) for lp, ok in zip(best[0], best[1]) if not ok
               for x in _loop_vertices(network, lp)}
        for v in [v for v in doubtful if v in bad or best[2]]:
            if (not _badness(*best)[0] and not best[2]) or trials >= MAX_TRIALS:
                break
            for j in range(1, len(J.options[v])):
                trials += 1
                trial = {**choice, v: (choice[v] + j) % len(J.options[v])}
                got = _embed(network, J, trial)
                if _badness(*got) < _badness(*best):
                    choice, best, improved = trial, got, True
        if not improved:
            break
    loops, simple, report["conflicts"] = best
    report["reordered"] = sum(1 for v in doubtful if choice[v])
    return EmbeddedFaces(loops, simple, _genus(J.nodes, J.chains, loops), alive, report)


def _embed(network: CurveNetwork, J: _Junctions, choice: dict):
    """Faces of the rotation system with order ``choice[v]`` at junction ``v``:
    ``(loops, simple, conflicts)`` (see :func:`_orient`, :func:`_trace`)."""
    order = [J.options[v][choice[v]] for v in J.options]
    normal = np.empty((len(J.nodes), 3))
    strength = np.empty(len(J.nodes))
    normal[J.votes.at] = [o[1] for o in order]
    strength[J.votes.at] = [o[2] for o in order]
    sign, conflicts = _orient(J, normal, strength)
    succ = np.empty(len(J.origin), np.int64)
    for (hs, _, _), positive in zip(order, (sign[J.votes.at] > 0).tolist()):
        hs = hs if positive else hs[::-1]
        succ[hs] = hs[1:] + hs[:1]
    loops, simple = _trace(network, J.chains, succ)
    return loops, simple, conflicts


def _loop_vertices(network: CurveNetwork, loop) -> list:
    """The vertices an oriented loop of ``(edge, forward)`` passes, in order."""
    return [network.edges[i].u if f else network.edges[i].v for i, f in loop]


def _badness(loops, simple, conflicts) -> tuple:
    """Embeddings in order, best first: curves on faces that are no simple cycle, then
    orientation conflicts."""
    return (sum(len(lp) for lp, ok in zip(loops, simple) if not ok), conflicts)


def _orient(J: _Junctions, normal: np.ndarray, strength: np.ndarray):
    """+-1 per junction (the side of its normal that agrees with its neighbours), and the
    number of conflicts: chains of weight over 0.1 whose vote the signs overrule.

    ``normal`` ``(N, 3)`` and ``strength`` ``(N,)`` are the junctions' (node order). A
    chain ``a -> b`` votes ``sign(n_b . T n_a)`` (``T`` its transport), weighed by the
    cosine's magnitude and the junctions' smaller strength; the signs follow a maximum
    spanning tree of the strongest vote between each two junctions (the first of equals).
    Returns ``(sign, conflicts)``, ``sign`` ``(N,) int64``.
    """
    V, n = J.votes, len(J.nodes)
    s = np.ones(n, np.int64)
    if len(V.ia) == 0:
        return s, 0
    ia, ib = V.ia, V.ib
    carried = np.einsum("cij,cj->ci", V.transport, normal[ia])
    carried /= np.maximum(np.linalg.norm(carried, axis=1, keepdims=True), DIVISION_GUARD)
    dot = np.einsum("ij,ij->i", carried, normal[ib])
    weight = np.abs(dot) * np.minimum(strength[ia], strength[ib])
    by = np.lexsort((np.arange(len(weight)), -weight, V.group))     # group, best first
    best = by[np.r_[True, V.group[by][1:] != V.group[by][:-1]]]     # one per group, in order
    lo, hi = np.minimum(ia[best], ib[best]), np.maximum(ia[best], ib[best])
    r, c = _spanning_tree(lo, hi, 2.0 - weight[best], n)
    code = r * n + c
    flip = (dot[best[V.key_group[np.searchsorted(V.key, code)]]] < 0).tolist()
    nbrs: list = [[] for _ in range(n)]
    for x, y, f in zip(r.tolist(), c.tolist(), flip):
        nbrs[x].append((y, f))
        nbrs[y].append((x, f))
    # each component from its first junction (sign +1), along the tree
    seen = [False] * n
    for root in range(n):
        if seen[root]:
            continue
        seen[root] = True
        stack = [root]
        while stack:
            x = stack.pop()
            for y, f in nbrs[x]:
                if not seen[y]:
                    seen[y] = True
                    s[y] = -s[x] if f else s[x]
                    stack.append(y)
    conflicts = int(np.count_nonzero((s[ia] * s[ib] * np.sign(dot) < 0) & (weight > 0.1)))
    return s, conflicts


def _spanning_tree(lo, hi, cost, n: int):
    """Minimum spanning forest of the graph on ``n`` nodes with edges ``lo < hi`` (unique
    pairs) of ``cost`` (positive): ``(lo, hi)`` of its edges.

    Kruskal's algorithm as :func:`scipy.sparse.csgraph.minimum_spanning_tree` runs it (the
    edges in row-major order, then stably sorted by cost), so the same forest where costs
    tie; without building sparse matrices, which costs more than the search on the few
    junctions of a network.
    """
    rows = np.argsort(lo * n + hi)
    lo, hi, cost = lo[rows], hi[rows], cost[rows]
    parent = list(range(n))

    def root(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    kept = []
    order = np.argsort(cost, kind="stable")
    for j, a, b in zip(order.tolist(), lo[order].tolist(), hi[order].tolist()):
        ra, rb = root(a), root(b)
        if ra != rb:
            parent[ra] = rb
            kept.append(j)
    kept = np.array(kept, np.int64)
    return lo[kept], hi[kept]


def _trace(network: CurveNetwork, chains, succ: np.ndarray):
    """Orbits of ``h -> succ[twin(h)]``: the faces, as oriented loops of the network's edges."""
    seen = np.zeros(len(succ), bool)
    loops, simple = [], []
    ends = [(e.u, e.v) for e in network.edges]
    for h0 in range(len(succ)):
        if seen[h0]:
            continue
        loop, h = [], h0
        while not seen[h]:
            seen[h] = True
            path = chains[h // 2][2]
            loop.extend(path if h % 2 == 0 else [(i, not f) for i, f in reversed(path)])
            h = succ[h ^ 1]
        edges = [i for i, _ in loop]
        verts = [ends[i][0] if f else ends[i][1] for i, f in loop]
        loops.append(loop)
        simple.append(len(set(edges)) == len(edges) and len(set(verts)) == len(verts))
    return loops, np.array(simple, bool)


def _genus(nodes, chains, loops) -> list:
    """Per component of the chains, ``1 - (V - E + F) / 2``, or None if not whole."""
    index = {int(v): i for i, v in enumerate(nodes)}
    a = np.array([index[x] for x, _, _ in chains])
    b = np.array([index[y] for _, y, _ in chains])
    n = len(nodes)
    _, comp = connected_components(coo_matrix((np.ones(len(a)), (a, b)), shape=(n, n)),
                                   directed=False)
    chain_of = {}
    for k, (_, _, path) in enumerate(chains):
        for i, _ in path:
            chain_of[i] = k
    m = comp.max() + 1
    faces = np.bincount([comp[a[chain_of[lp[0][0]]]] for lp in loops], minlength=m)
    chi = np.bincount(comp, minlength=m) - np.bincount(comp[a], minlength=m) + faces
    return [1 - int(x) // 2 if x % 2 == 0 else None for x in chi]
