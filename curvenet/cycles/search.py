"""Search for simple cycles of a multigraph given as adjacency lists: the Python engine.

``adj[x]`` lists ``(y, edge id)`` for every edge at vertex ``x``. :func:`simple_cycles`
enumerates every simple cycle with ``L`` edges exactly once, from its smallest vertex,
in a depth-bounded search (Abbasinejad et al. 2011, Algorithm 1, line 6);
:mod:`curvenet.cycles.kernel` is the same search compiled with numba, which the tests
compare with this one. :func:`horton_cycles` gives Horton's shortest-path cycles,
which span the cycle space.

References
----------
J. D. Horton. A polynomial-time algorithm to find the shortest cycle basis of a
graph. SIAM J. Comput. 16(2), 1987.
"""

from __future__ import annotations

from collections import deque

import numpy as np

__all__ = ["simple_cycles", "horton_cycles"]


def simple_cycles(adj, L: int, dist_from, work: int, budget: int):
    """Every simple cycle with ``L >= 2`` edges, once each.

    Parameters
    ----------
    adj : list of list of (int, int)
        Per vertex, ``(neighbour, edge id)``.
    L : int
    dist_from : callable
        ``dist_from(s) -> dict``: hop distances from ``s`` to the vertices above ``s``
        (they bound the search depth).
    work, budget : int
        Steps already spent, and the bound on them.

    Returns
    -------
    edges, vertices : (n, L) int64 or None
        The cycles' edge ids and vertices; None when the budget ran out.
    work : int
        Steps spent in all.
    """
    out = []
    for s in range(len(adj)):
        if not adj[s]:
            continue
        dist = dist_from(s)
        # stack of (vertex, depth, edge path, vertex path)
        for y, e in adj[s]:
            if y < s:
                continue
            if L == 2:
                if y == s:
                    continue
                for y2, e2 in adj[y]:
                    if y2 == s and e2 > e:
                        out.append(((e, e2), (s, y)))
                continue
            if y == s or dist.get(y, L + 1) + 1 > L:
                continue
            stack = [(y, 1, (e,), (s, y))]
            while stack:
                x, depth, ep, vp = stack.pop()
                work += 1
                if depth == L - 1:
                    for z, ez in adj[x]:
                        if z == s and ez > ep[0]:
                            out.append((ep + (ez,), vp))
                    continue
                for z, ez in adj[x]:
                    if z <= s or z in vp:
                        continue
                    dz = dist.get(z)
                    if dz is None or depth + 1 + dz > L:
                        continue
                    stack.append((z, depth + 1, ep + (ez,), vp + (z,)))
            if work > budget:
                return None, None, work
    return (np.array([o[0] for o in out], dtype=np.int64).reshape(-1, L),
            np.array([o[1] for o in out], dtype=np.int64).reshape(-1, L), work)


def horton_cycles(adj, seen: set, min_length: int = 1) -> dict:
    """Horton's cycles ``P(s, x) + (x, y) + P(y, s)`` from breadth-first trees.

    They span the cycle space (they contain a minimum-length basis).

    Parameters
    ----------
    adj : list of list of (int, int)
        Per vertex, ``(neighbour, edge id)``.
    seen : set of frozenset
        Edge sets already known: none of them is returned, and the cycles found are
        added to it.
    min_length : int

    Returns
    -------
    dict
        Length -> list of ``(edge ids, vertices)`` tuples.
    """
    by_len: dict = {}
    for s in range(len(adj)):
        if not adj[s]:
            continue
        par = {s: (-1, -1)}  # vertex -> (parent, edge)
        branch = {s: -1}
        q = deque([s])
        while q:
            x = q.popleft()
            for y, e in adj[x]:
                if y not in par:
                    par[y] = (x, e)
                    branch[y] = y if x == s else branch[x]
                    q.append(y)
        tree_edges = {pe for _, pe in par.values()}
        for x in par:
            for y, e in adj[x]:
                if e in tree_edges or y < x:
                    continue
                if x != s and y != s and branch[x] == branch[y]:
                    continue
                edges, verts = [e], [x, y]
                for w in (x, y):
                    while w != s:
                        p, pe = par[w]
                        edges.append(pe)
                        if p != s:
                            verts.append(p)
                        w = p
                verts.append(s)
                fe = frozenset(edges)
                if len(fe) != len(edges) or len(fe) < min_length or fe in seen:
                    continue
                if len(set(verts)) != len(edges):
                    continue
                seen.add(fe)
                by_len.setdefault(len(edges), []).append((tuple(edges), tuple(set(verts))))
    return by_len
