"""numba kernel of the cycle enumeration of :class:`curvenet.cycles.candidates.CandidatePool`.

Imported only when the search is deep enough to pay for importing numba; the
compiled function is cached on disk (``cache=True``). Same search as
:func:`curvenet.cycles.search.simple_cycles`, which the tests compare it with.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["enumerate_cycles"]


@numba.njit(cache=True)
def enumerate_cycles(L, indptr, nbrs, eids, nv, max_work, work):  # pragma: no cover
    """Simple cycles with ``L >= 2`` edges, each once, from their smallest vertex.

    Parameters
    ----------
    L : int
    indptr, nbrs, eids : int64 arrays
        CSR adjacency without loop edges: neighbours ``nbrs[indptr[x]:indptr[x+1]]``
        of ``x`` through edges ``eids[...]``.
    nv : int
    max_work, work : int
        Step budget and steps already spent.

    Returns
    -------
    edges, vertices : (n, L) int64 arrays
    work : int
    hit : bool
        Whether the budget ran out (the arrays are then partial).
    """
    cap = 256
    out_e = np.empty((cap, L), np.int64)
    out_v = np.empty((cap, L), np.int64)
    n = 0
    dist = np.full(nv, -1, np.int64)
    queue = np.empty(nv, np.int64)
    onpath = np.zeros(nv, np.bool_)
    pv = np.empty(L, np.int64)
    pe = np.empty(L, np.int64)
    ptr = np.empty(L, np.int64)
    half = L // 2
    for s in range(nv):
        # breadth-first distances to s inside vertices >= s, up to L // 2
        dist[s] = 0
        queue[0] = s
        head, tail = 0, 1
        while head < tail:
            x = queue[head]
            head += 1
            if dist[x] >= half:
                continue
            for k in range(indptr[x], indptr[x + 1]):
                y = nbrs[k]
                if y > s and dist[y] < 0:
                    dist[y] = dist[x] + 1
                    queue[tail] = y
                    tail += 1
        # depth-first search of paths s -> ... -> back to s with L edges
        pv[0] = s
        ptr[0] = indptr[s]
        onpath[s] = True
        depth = 0
        while depth >= 0:
            x = pv[depth]
            if ptr[depth] == indptr[x + 1]:
                onpath[x] = False
                depth -= 1
                continue
            k = ptr[depth]
            ptr[depth] += 1
            z = nbrs[k]
            ez = eids[k]
            if depth == L - 1:
                if z == s and ez > pe[0]:
                    if n == out_e.shape[0]:
                        grow_e = np.empty((2 * n, L), np.int64)
                        grow_v = np.empty((2 * n, L), np.int64)
                        grow_e[:n] = out_e
                        grow_v[:n] = out_v
                        out_e, out_v = grow_e, grow_v
                    for i in range(L - 1):
                        out_e[n, i] = pe[i]
                    out_e[n, L - 1] = ez
                    for i in range(L):
                        out_v[n, i] = pv[i]
                    n += 1
                continue
            if z <= s or onpath[z]:
                continue
            dz = dist[z]
            if dz < 0 or depth + 1 + dz > L:
                continue
            work += 1
            pe[depth] = ez
            depth += 1
            pv[depth] = z
            ptr[depth] = indptr[z]
            onpath[z] = True
        for i in range(tail):
            dist[queue[i]] = -1
        if work > max_work:
            return out_e[:n], out_v[:n], work, True
    return out_e[:n], out_v[:n], work, False

