"""Closing patches (Abbasinejad, Joshi, Amenta 2011, Sec. 5).

A cycle basis holds no solid: the faces of a closed surface sum to zero over
GF(2), so one face of each solid is missing. :func:`closing_suggestions` ranks
the candidates that close a solid with the current patches by
``Ws = 10 (a + b) + k``; :func:`auto_close` accepts the ones that fill holes
or unexplained creases (``find_patches(close="auto")``).

References
----------
F. Abbasinejad, P. Joshi, N. Amenta. Surface patches from unorganized space
curves. Computer Graphics Forum 30(5) (SGP 2011), Sec. 5.
"""

from __future__ import annotations

import numpy as np

from .gf2 import bitset_solve, edge_mask, gf2_solve, mask_edges, popcount
from .candidates import CandidatePool
from ..core.tolerances import DIVISION_GUARD
from .loops import cycle_to_loop, newell_normal

__all__ = ["closing_suggestions", "auto_close"]

#: Closing weight constant of Sec. 5: ``Ws = 10 (a + b) + k``.
_WS_FACTOR = 10.0
#: Two patches are "smoothly continued" across an edge when their normals near
#: the edge are within this angle (degrees); used by ``close="auto"`` walls.
_SMOOTH_DEG = 30.0
#: Largest null-space dimension searched exhaustively for the smallest solid.
_MAX_NULL_ENUM = 8


def _smallest_in_coset(x: int, null: list) -> int:
    """Smallest-popcount element of ``x + span(null)``: exhaustive for small spans, else greedy."""
    if not null:
        return x
    if len(null) <= _MAX_NULL_ENUM:
        best, bc = x, popcount(x)
        sums = [0]
        for v in null:
            sums += [s ^ v for s in sums]
        for s in sums:
            c = popcount(x ^ s)
            if c < bc:
                best, bc = x ^ s, c
        return best
    improved = True
    while improved:
        improved = False
        for v in null:
            if popcount(x ^ v) < popcount(x):
                x ^= v
                improved = True
    return x


def closing_suggestions(pool: CandidatePool, patch_edges, *, exclude=(), max_length=None,
                        backend: str = "bitset", candidates=None, faces=frozenset()):
    """Closing patches for a patch set (Sec. 5), best first.

    Parameters
    ----------
    pool : CandidatePool
        Its ``all_candidates`` are the cycles considered.
    patch_edges : list of tuple of int
        Current patches.
    exclude : iterable of tuple of int
        Edge sets not to suggest (rejected ones).
    max_length : int, optional
        Longest candidate considered (default: every enumerated candidate).
    backend : {"bitset", "galois"}
        GF(2) solver: Python-int elimination, or ``galois`` row reduction (same answers).
    candidates : list of Candidate, optional
        Cycles to consider instead of ``pool.all_candidates``.
    faces : set of tuple of int
        Edge sets known to be faces of the surface (:mod:`curvenet.cycles.rotation`):
        exempt from the overlap filter below.

    Returns
    -------
    list of dict
        Keys ``edges``, ``size`` (k = number of edges), ``score`` (``Ws``),
        ``a``, ``b``, ``solid`` (indices of current patches closing the solid
        with the suggestion), ``candidate``.

    Notes
    -----
    ``Ws = 10 (a + b) + k`` (Sec. 5), larger is better; ``a`` = area estimate of
    the solid (sum over its cycles, the suggestion included) / area estimate
    of the suggestion, ``b`` = edges of the suggestion used by exactly one
    current patch. The paper's text says short cycles are preferred while its
    formula adds ``k``; we implement the formula. The solid is found by rank
    (Sec. 5): the suggestion ``c`` is the GF(2) sum of a subset ``J`` of the
    patches; the solid is ``J + c``. When the patches are dependent (solids
    already closed) ``J`` is not unique: we take the smallest one in its coset
    (exhaustive when the null space has dimension <= 8, else greedy). Only
    candidates in the span of the patches close a solid; independent ones are
    not closing patches.

    Our addition: a candidate (not one of ``faces``) sharing two or more edges and at least half of
    the edges of some current patch ``p`` is not suggested. Then ``c + p`` is a
    cycle no longer than ``c``, and ``c`` is bent around ``p`` (two faces of a
    box merged across an edge, a skew hexagon through half of a face); with the
    paper's ``Ws`` such cycles outrank true faces because they inherit large
    solids and open edges. Faces of a curve network normally share one curve.
    """
    current = {tuple(sorted(p)) for p in patch_edges}
    excl = {tuple(sorted(p)) for p in exclude}
    cands = [c for c in (pool.all_candidates if candidates is None else candidates)
             if c.edges not in current and c.edges not in excl
             and (max_length is None or c.length <= max_length)]
    if not cands or not patch_edges:
        return []
    # Overlap filter (our addition): drop c when it shares two or more edges and at
    # least half of some patch p (then c + p is no longer than c): c folds onto p.
    users: dict = {}
    for i, p in enumerate(patch_edges):
        for e in p:
            users.setdefault(e, []).append(i)
    plen = [len(p) for p in patch_edges]
    kept = []
    for c in cands:
        shared: dict = {}
        for e in c.edges:
            for i in users.get(e, ()):
                shared[i] = shared.get(i, 0) + 1
        if c.edges in faces or all(n < 2 or 2 * n < plen[i] for i, n in shared.items()):
            kept.append(c)
    cands = kept
    if not cands:
        return []
    pmasks = [edge_mask(p) for p in patch_edges]
    if backend == "galois":
        sols, null = gf2_solve(pmasks, [c.mask for c in cands], pool.n_edges)
    else:
        sols, null = bitset_solve(pmasks, [c.mask for c in cands])
    parea = _patch_areas(pool, patch_edges)
    degree = np.zeros(pool.n_edges, dtype=np.int64)
    for p in patch_edges:
        degree[list(p)] += 1
    out = []
    for c, x in zip(cands, sols):
        if x is None:
            continue
        J = mask_edges(_smallest_in_coset(x, null))
        ca = max(c.area, DIVISION_GUARD)
        a = (float(parea[list(J)].sum()) + c.area) / ca
        b = int((degree[list(c.edges)] == 1).sum())
        ws = _WS_FACTOR * (a + b) + c.length
        out.append({"edges": c.edges, "size": c.length, "score": float(ws), "a": float(a),
                    "b": b, "solid": J, "candidate": c})
    out.sort(key=lambda s: (-s["score"], s["candidate"].length, s["candidate"].geo))
    return out


def _patch_areas(pool, patch_edges) -> np.ndarray:
    out = np.zeros(len(patch_edges))
    by_len: dict = {}
    for i, p in enumerate(patch_edges):
        by_len.setdefault(len(p), []).append(i)
    for _, idx in by_len.items():
        _, area, _, _ = pool.measures([sorted(patch_edges[i]) for i in idx])
        out[idx] = area
    return out


def auto_close(pool, patch_edges, max_length, *, candidates=None, faces=frozenset()):
    """``close="auto"``: accept closing patches that fill holes or unexplained creases.

    Repeatedly takes the best closing suggestion (up to ``max_length`` edges,
    the longest cycle the automatic phase needed) that either (i) uses only
    edges currently used by exactly one patch (a hole bounded by open edges,
    like the missing face of a box), or (ii) uses only edges labelled
    ``"crease"`` that are each used by exactly two patches continuing smoothly
    across it (normals within 30 degrees): a crease that no current patch
    explains, like the wall shared by two stacked boxes. Rule (ii) is our
    addition to the paper (Sec. 5 leaves closing to the user).

    Parameters
    ----------
    pool : CandidatePool
        Its :attr:`~CandidatePool.all_candidates` are the cycles considered.
    patch_edges : list of tuple of int
        Current patches (not modified).
    max_length : int
        Longest closing cycle accepted.
    candidates : list of Candidate, optional
        Cycles considered instead of the pool's :attr:`~CandidatePool.all_candidates`.
    faces : set of tuple of int
        Edge sets of faces of the surface (see :func:`closing_suggestions`).

    Returns
    -------
    list of tuple of int
        Edge ids of the accepted closing patches, in acceptance order.
    """
    added = []
    patch_edges = list(patch_edges)
    normals: dict = {}
    cos_smooth = np.cos(np.deg2rad(_SMOOTH_DEG))
    net = pool.network
    crease = np.array([e.label == "crease" for e in net.edges], dtype=bool)
    pool_short = [c for c in (pool.all_candidates if candidates is None else candidates)
                  if c.length <= max_length]
    if not pool_short:
        return added
    ne = pool.n_edges
    width = max(c.length for c in pool_short)
    idx = np.full((len(pool_short), width), ne, dtype=np.int64)  # padded with sentinel ne
    for j, c in enumerate(pool_short):
        idx[j, :c.length] = c.edges
    pad = idx == ne
    crease_ok = (np.append(crease, True)[idx]).all(axis=1)

    def normal(i):
        if i not in normals:
            normals[i] = newell_normal(net, cycle_to_loop(net, patch_edges[i]))
        return normals[i]

    while True:
        users: dict = {}
        deg = np.zeros(ne + 1, dtype=np.int64)
        for i, p in enumerate(patch_edges):
            deg[list(p)] += 1
            for e in p:
                users.setdefault(e, []).append(i)
        dc = deg[idx]
        hole = ((dc == 1) | pad).all(axis=1)
        wall = ((dc == 2) | pad).all(axis=1) & crease_ok
        current = set(map(tuple, patch_edges))
        eligible = []
        for j in np.flatnonzero(hole | wall):
            c = pool_short[j]
            if c.edges in current:
                continue
            if hole[j] or all(abs(float(normal(users[e][0]) @ normal(users[e][1])))
                              >= cos_smooth for e in c.edges):
                eligible.append(c)
        sugg = closing_suggestions(pool, patch_edges, candidates=eligible, faces=faces)
        if not sugg:
            break
        patch_edges.append(sugg[0]["edges"])
        added.append(sugg[0]["edges"])
    return added
