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


def bored_prism(sides=6, *, seam=True, through=True, radius=0.5, height=0.8, samples=33):
    """A regular prism (a hex nut for ``sides=6``) with a round bore drawn as a CAD B-rep
    has it: two circles, each one closed curve on one junction, and one seam line
    between them (``seam=False``: no seam). ``through=False``: a blind hole, its
    bottom circle half way down; nothing closes it but its disc."""
    ang = 2 * np.pi * np.arange(sides) / sides
    ring = np.c_[np.cos(ang), np.sin(ang)]
    bottom = 0.0 if through else height / 2
    pos = np.array([(x, y, z) for z in (0.0, height) for x, y in ring]
                   + [(radius, 0, bottom), (radius, 0, height)], float)
    net = CurveNetwork(pos)
    s = np.linspace(0, 1, samples)[:, None]
    for k in (0, sides):
        for i in range(sides):
            a, b = k + i, k + (i + 1) % sides
            net.add_edge(a, b, (1 - s) * pos[a] + s * pos[b])
    for i in range(sides):
        net.add_edge(i, i + sides, (1 - s) * pos[i] + s * pos[i + sides])
    t = np.linspace(0, 2 * np.pi, 2 * samples - 1)
    for vid in (2 * sides, 2 * sides + 1):
        z = pos[vid, 2]
        net.add_edge(vid, vid, np.c_[radius * np.cos(t), radius * np.sin(t), np.full_like(t, z)])
    if seam:
        a, b = 2 * sides, 2 * sides + 1
        net.add_edge(a, b, (1 - s) * pos[a] + s * pos[b])
    return net


def seam_cylinder(radius=0.5, height=1.0, samples=33):
    """A capped cylinder as a CAD B-rep draws it: two circles and one seam line."""
    pos = np.array([(radius, 0, 0), (radius, 0, height)], float)
    net = CurveNetwork(pos)
    t = np.linspace(0, 2 * np.pi, 2 * samples - 1)
    for vid in (0, 1):
        net.add_edge(vid, vid, np.c_[radius * np.cos(t), radius * np.sin(t),
                                     np.full_like(t, pos[vid, 2])])
    s = np.linspace(0, 1, samples)[:, None]
    net.add_edge(0, 1, (1 - s) * pos[0] + s * pos[1])
    return net
