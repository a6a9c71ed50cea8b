"""Cycles as closed loops: walking a cycle's edges, orienting patches, loop geometry.

A patch is stored as a set of edge ids; surfacing needs it as one closed walk
``[(edge_id, forward), ...]``. :func:`cycle_to_loop` walks one cycle,
:func:`orient_patches` orients a whole patch set consistently (outward on
closed surfaces), :func:`newell_normal` and :func:`signed_volume` measure loops.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from ..core.tolerances import DIVISION_GUARD
from ..core.errors import NetworkError
from ..model.network import CurveNetwork
from ..model.patchset import Patch

__all__ = ["cycle_to_loop", "orient_patches", "orient_boundaries", "loop_points", "newell_normal",
           "signed_volume", "edge_components"]


def cycle_to_loop(network: CurveNetwork, edge_ids) -> list:
    """Order a cycle's edges into one closed, oriented loop.

    Parameters
    ----------
    network : CurveNetwork
    edge_ids : iterable of int
        The cycle's edges, in any order.

    Returns
    -------
    loop : list of (int, bool)
        ``(edge_id, forward)`` in walking order; ``forward`` means the edge is
        walked ``u -> v``. The walk starts with the smallest edge id, forward.

    Raises
    ------
    NetworkError
        Empty, repeated or out-of-range ids, or edges that are not one simple
        closed loop (a vertex of degree other than 2, or several loops).

    Examples
    --------
    >>> from curvenet.datasets.shapes import box
    >>> net = box().network
    >>> loop = cycle_to_loop(net, [2, 0, 1, 3])
    >>> sorted(e for e, _ in loop)
    [0, 1, 2, 3]

    Notes
    -----
    Edges listed twice are the *seam* of a periodic face (a bore wall bounded by two
    circles and one seam line): the walk is the first loop from the seam's end on it,
    the seam, the second loop walked against the first (opposite Newell normals, as
    the two borders of a band are), and the seam back (:func:`_seam_walk`).
    """
    ids = [int(e) for e in edge_ids]
    ne = network.number_of_edges
    if not ids:
        raise NetworkError("cycle_to_loop: empty edge list")
    bad = [e for e in ids if not 0 <= e < ne]
    if bad:
        raise NetworkError(f"cycle_to_loop: edge ids {bad} out of range 0..{ne - 1}")
    if len(set(ids)) != len(ids):
        return _seam_walk(network, ids)
    ends = {e: (network.edges[e].u, network.edges[e].v) for e in ids}
    if len(ids) == 1:
        u, v = ends[ids[0]]
        if u != v:
            raise NetworkError(f"cycle_to_loop: edge {ids[0]} alone is not closed")
        return [(ids[0], True)]
    inc: dict = {}
    for e, (u, v) in ends.items():
        if u == v:
            raise NetworkError(f"cycle_to_loop: loop edge {e} inside a longer cycle")
        inc.setdefault(u, []).append(e)
        inc.setdefault(v, []).append(e)
    odd = {x: len(es) for x, es in inc.items() if len(es) != 2}
    if odd:
        raise NetworkError(f"cycle_to_loop: edges {sorted(ids)} are not a simple loop "
                           f"(vertex degrees {odd})")
    start = min(ids)
    loop = [(start, True)]
    used = {start}
    x = ends[start][1]
    while len(loop) < len(ids):
        nxt = [e for e in inc[x] if e not in used]
        if not nxt:
            raise NetworkError(f"cycle_to_loop: edges {sorted(ids)} form several loops")
        e = nxt[0]
        u, v = ends[e]
        fwd = u == x
        loop.append((e, fwd))
        used.add(e)
        x = v if fwd else u
    if x != ends[start][0]:
        raise NetworkError(f"cycle_to_loop: edges {sorted(ids)} do not close")
    return loop


def _seam_walk(network: CurveNetwork, ids: list) -> list:
    """The closed walk of a periodic face: ``L1, seam, L2, seam reversed``.

    ``ids`` holds the seam's edges twice and the edges of one or two simple loops
    once; the seam is a path from a junction of the first loop (the one with the
    smallest edge id) to one of the second, or to a free end (an apex: the walk is then
    ``L1, seam, seam reversed``).

    Raises
    ------
    NetworkError
        An edge listed more than twice, a seam that is no path between the loops,
        or loops that are not simple.
    """
    count: dict = {}
    for e in ids:
        count[e] = count.get(e, 0) + 1
    if max(count.values()) > 2:
        raise NetworkError(f"cycle_to_loop: an edge listed more than twice in {sorted(ids)}")
    seam = sorted(e for e, c in count.items() if c == 2)
    rest = sorted(e for e, c in count.items() if c == 1)
    ends = {e: (network.edges[e].u, network.edges[e].v) for e in count}
    groups = edge_components(rest, ends)
    if not 1 <= len(groups) <= 2:
        raise NetworkError(f"cycle_to_loop: edges {sorted(ids)} are no seam face "
                           f"({len(groups)} loops beside the seam)")
    loops = [cycle_to_loop(network, g) for g in groups]
    on = [{ends[e][0] if f else ends[e][1] for e, f in lp} for lp in loops]
    deg: dict = {}
    for e in seam:
        for x in ends[e]:
            deg[x] = deg.get(x, 0) + 1
    tips = sorted(x for x, d in deg.items() if d == 1)
    start = [x for x in tips if x in on[0]]
    if len(tips) != 2 or len(start) != 1 or any(ends[e][0] == ends[e][1] for e in seam):
        raise NetworkError(f"cycle_to_loop: the seam {seam} of {sorted(ids)} is no path "
                           f"from a loop")
    a = start[0]
    b = tips[1] if tips[0] == a else tips[0]
    if len(loops) == 2 and b not in on[1] or len(loops) == 1 and b in on[0]:
        raise NetworkError(f"cycle_to_loop: the seam {seam} of {sorted(ids)} does not join "
                           f"its loops")
    path, x, left = [], a, set(seam)
    while left:
        e = next(e for e in sorted(left) if x in ends[e])
        fwd = ends[e][0] == x
        path.append((e, fwd))
        left.discard(e)
        x = ends[e][1] if fwd else ends[e][0]
    walk = _rotated(network, loops[0], a) + path
    if len(loops) == 2:
        second = _rotated(network, loops[1], b)
        if float(newell_normal(network, second) @ newell_normal(network, loops[0])) > 0:
            second = _rotated(network, [(e, not f) for e, f in reversed(second)], b)
        walk += second
    return walk + [(e, not f) for e, f in reversed(path)]


def edge_components(edges, ends) -> list:
    """Edge groups connected through shared junctions.

    Parameters
    ----------
    edges : iterable of int
    ends : sequence of (int, int)
        End junctions of every edge id.

    Returns
    -------
    list of list of int
        Each group's edge ids, sorted; the groups sorted.
    """
    parent = {e: e for e in edges}

    def root(e):
        while parent[e] != e:
            e = parent[e]
        return e
    at: dict = {}
    for e in edges:
        for x in set(ends[e]):
            if x in at:
                parent[root(e)] = root(at[x])
            at[x] = e
    out: dict = {}
    for e in edges:
        out.setdefault(root(e), []).append(e)
    return sorted(out.values())


def _rotated(network, loop, x) -> list:
    """``loop`` started at the item leaving junction ``x``."""
    starts = [network.edges[e].u if f else network.edges[e].v for e, f in loop]
    k = starts.index(x)
    return loop[k:] + loop[:k]


def loop_points(network, loop) -> np.ndarray:
    """Points of a loop's curves in walking order, each shared end once.

    Parameters
    ----------
    network : CurveNetwork
    loop : list of (int, bool)
        ``(edge_id, forward)`` as :func:`cycle_to_loop` returns.

    Returns
    -------
    (m, 3) float64
        The loop's polyline, not repeating its first point at the end.
    """
    pts = [network.edges[e].curve if f else network.edges[e].curve[::-1] for e, f in loop]
    return np.concatenate([p[:-1] for p in pts])


def newell_normal(network, loop) -> np.ndarray:
    """Unit Newell normal ``(3,) float64`` of a loop (right-hand rule along the walk).

    Zero when the loop spans no area (its points are collinear).
    """
    p = loop_points(network, loop)
    q = np.concatenate([p[1:], p[:1]])
    # np.cross(p, q), written out (its arithmetic, without its overhead on short loops)
    n = np.stack([p[:, 1] * q[:, 2] - p[:, 2] * q[:, 1], p[:, 2] * q[:, 0] - p[:, 0] * q[:, 2],
                  p[:, 0] * q[:, 1] - p[:, 1] * q[:, 0]], axis=1).sum(axis=0)
    return n / max(np.linalg.norm(n), DIVISION_GUARD)


def signed_volume(network, loops) -> float:
    """Signed volume of the fan-triangulated loops (divergence theorem).

    Positive when closed loops are oriented with outward normals.
    """
    total = 0.0
    for loop in loops:
        p = loop_points(network, loop)
        c = p.mean(axis=0)
        a, b = p, np.roll(p, -1, axis=0)
        total += float(np.einsum("ij,ij->", np.cross(a, b), np.broadcast_to(c, a.shape)))
    return total / 6.0


def orient_patches(network: CurveNetwork, patches) -> list:
    """Oriented outer loops of the patches, consistent across shared edges.

    Parameters
    ----------
    network : CurveNetwork
    patches : sequence of Patch or of edge-id sequences

    Returns
    -------
    loops : list of list of (int, bool)
        One loop per patch (its outer boundary), same order; see
        :func:`orient_boundaries` for the loops of patches with holes.
    """
    return [b[0] for b in orient_boundaries(network, patches)]


def orient_boundaries(network: CurveNetwork, patches) -> list:
    """Oriented boundary loops of the patches (outer first, then holes), consistent.

    Parameters
    ----------
    network : CurveNetwork
    patches : sequence of Patch or of edge-id sequences
        A :class:`~curvenet.model.patchset.Patch` with ``holes`` is bounded by its
        outer cycle and one cycle per hole.

    Returns
    -------
    boundaries : list of list of list of (int, bool)
        Per patch, its loops: ``[outer, hole_1, ...]``.

    Notes
    -----
    Patches are visited breadth-first across edges shared by exactly two
    patches; a neighbour is reversed (all its loops) when it walks the shared
    edge in the same direction, so adjacent patches traverse it in opposite
    directions where the surface is orientable (non-manifold edges, used by
    three or more patches, impose nothing; on a non-orientable surface the
    first orientation found wins). Each group of patches connected this way
    that is closed (every edge used twice within it) is then flipped as a
    whole if its fan-triangulated signed volume is negative, so closed
    surfaces come out with outward normals (right-hand rule); open ones keep
    the orientation of their first patch as :func:`cycle_to_loop` walks it.
    A hole is first walked against its outer loop (opposite Newell normals),
    so the face lies on one side of all its loops.
    """
    comps = [[p.edges, *p.holes] if isinstance(p, Patch) else [tuple(p)] for p in patches]
    bounds = [[cycle_to_loop(network, es) for es in c] for c in comps]
    for b in bounds:
        n = newell_normal(network, b[0]) if len(b) > 1 else None
        b[1:] = [[(x, not f) for x, f in reversed(lp)]
                 if float(newell_normal(network, lp) @ n) > 0 else lp for lp in b[1:]]
    edge_sets = [tuple(e for es in c for e in es) for c in comps]
    by_edge: dict = {}
    for i, es in enumerate(edge_sets):
        for e in es:
            by_edge.setdefault(int(e), []).append(i)

    def flipped(b):
        return [[(x, not f) for x, f in reversed(lp)] for lp in b]

    dirs = [{e: f for lp in b for e, f in lp} for b in bounds]
    done = [False] * len(bounds)
    for root in range(len(bounds)):
        if done[root]:
            continue
        done[root] = True
        group = [root]
        q = deque([root])
        while q:
            i = q.popleft()
            for e in edge_sets[i]:
                users = by_edge[int(e)]
                if len(users) != 2:
                    continue
                j = users[0] if users[1] == i else users[1]
                if done[j]:
                    continue
                if dirs[j][e] == dirs[i][e]:
                    bounds[j] = flipped(bounds[j])
                    dirs[j] = {x: f for lp in bounds[j] for x, f in lp}
                done[j] = True
                group.append(j)
                q.append(j)
        uses: dict = {}
        for i in group:
            for e in edge_sets[i]:
                uses[e] = uses.get(e, 0) + 1
        closed = all(n == 2 for n in uses.values())
        if closed and signed_volume(network, [lp for i in group for lp in bounds[i]]) < 0:
            for i in group:
                bounds[i] = flipped(bounds[i])
    return bounds
