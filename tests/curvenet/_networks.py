"""Small curve networks for the cycle tests: random graphs, relabelled copies, face sets."""

from __future__ import annotations

import numpy as np

from curvenet.model.network import CurveNetwork


def random_network(seed, n=9, m=16, *, loops=True, parallel=True) -> CurveNetwork:
    """Random multigraph with straight (or bent, for parallel/loop) curves at random points."""
    rng = np.random.default_rng(seed)
    pos = rng.normal(size=(n, 3))
    net = CurveNetwork(pos)
    for _ in range(m):
        u, v = (int(x) for x in rng.integers(0, n, size=2))
        if u == v and not loops:
            continue
        bend = rng.normal(scale=0.3, size=3)
        if u == v:
            c = [pos[u], pos[u] + bend, pos[u] + np.roll(bend, 1), pos[u]]
        else:
            c = [pos[u], (pos[u] + pos[v]) / 2 + bend, pos[v]]
        net.add_edge(u, v, c)
        if parallel and rng.random() < 0.1 and u != v:
            net.add_edge(v, u, [pos[v], (pos[u] + pos[v]) / 2 - bend, pos[u]])
    return net


def random_simple_network(seed, n=9, m=16) -> CurveNetwork:
    """Random simple graph (no loops, no parallel curves) with straight curves."""
    rng = np.random.default_rng(seed)
    pos = rng.normal(size=(n, 3))
    net = CurveNetwork(pos)
    pairs = [(u, v) for u in range(n) for v in range(u + 1, n)]
    for j in rng.permutation(len(pairs))[:m]:
        u, v = pairs[j]
        net.add_edge(u, v, [pos[u], pos[v]])
    return net


def permuted(net: CurveNetwork, seed):
    """Same network with vertices relabelled and edges reordered (and some reversed)."""
    rng = np.random.default_rng(seed)
    nv, ne = net.number_of_vertices, net.number_of_edges
    vperm = rng.permutation(nv)            # old vertex i -> new vperm[i]
    eorder = rng.permutation(ne)           # new edge j is old edge eorder[j]
    pos = np.empty_like(net.positions)
    pos[vperm] = net.positions
    out = CurveNetwork(pos)
    for old in eorder:
        e = net.edges[old]
        if rng.random() < 0.5:
            out.add_edge(int(vperm[e.v]), int(vperm[e.u]), e.curve[::-1], label=e.label)
        else:
            out.add_edge(int(vperm[e.u]), int(vperm[e.v]), e.curve, label=e.label)
    return out, eorder


def true_faces(shape):
    return {tuple(sorted(e for e, _ in f)) for f in shape.faces}


def found(ps):
    return {p.edges for p in ps.patches}
