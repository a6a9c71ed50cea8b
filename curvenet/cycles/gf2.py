"""Linear algebra over GF(2) for cycle spaces: bitset elimination and galois helpers.

A cycle is a set of edge ids; as a GF(2) vector it is stored either as a Python
``int`` whose bit ``e`` is set when edge ``e`` belongs to the cycle (the hot
greedy path), or as a column of a ``galois.GF2`` matrix with one row per edge
(the session's algebra: rank, solving which patches sum to a cycle).

References
----------
Abbasinejad, Joshi, Amenta 2011, Sec. 3 (cycles as 0-1 columns, sums are
symmetric differences, independence by rank over GF(2)).
"""

from __future__ import annotations

import numpy as np

__all__ = ["edge_mask", "mask_edges", "popcount", "GF2Eliminator", "bitset_solve",
           "masks_to_gf2", "gf2_rank", "gf2_solve"]


def edge_mask(edges) -> int:
    """Bitset of a set of edge ids (bit ``e`` set for every edge ``e``).

    Examples
    --------
    >>> edge_mask([0, 2, 3])
    13
    """
    m = 0
    for e in edges:
        m ^= 1 << int(e)
    return m


def popcount(mask: int) -> int:
    """Number of set bits."""
    return mask.bit_count()


def mask_edges(mask: int) -> tuple:
    """Inverse of :func:`edge_mask`: sorted tuple of set bits."""
    out = []
    while mask:
        low = mask & -mask
        out.append(low.bit_length() - 1)
        mask ^= low
    return tuple(out)


class GF2Eliminator:
    """Incremental row echelon form over GF(2) on Python-int bitsets.

    Rows are kept keyed by their leading (highest) bit; reducing a vector XORs
    away its leading bit while a row owns it, so a vector is independent of the
    stored rows exactly when it does not reduce to zero.

    Optionally tracks, for each stored row, which inserted vectors it is the sum
    of (``track=True``), so :meth:`represent` answers which accepted vectors sum
    to a given one.

    Examples
    --------
    >>> el = GF2Eliminator()
    >>> el.add(0b011), el.add(0b110), el.add(0b101), el.rank
    (True, True, False, 2)
    """

    def __init__(self, *, track: bool = False):
        self._rows: dict = {}
        self._combo: dict = {}
        self._track = track
        self._count = 0
        #: with ``track=True``: one bitset of inserted-vector indices per
        #: dependent insertion, summing to zero (a basis of the dependencies).
        self.dependencies: list = []

    @property
    def rank(self) -> int:
        return len(self._rows)

    def reduce(self, x: int) -> int:
        """Residual of ``x`` after elimination (0 iff ``x`` is in the span)."""
        rows = self._rows
        while x:
            r = rows.get(x.bit_length() - 1)
            if r is None:
                return x
            x ^= r
        return 0

    def is_independent(self, x: int) -> bool:
        return self.reduce(x) != 0

    def add(self, x: int) -> bool:
        """Insert ``x``; returns whether it raised the rank.

        Every call counts as one inserted vector (index ``0, 1, ...``) for
        :meth:`represent`, whether or not it was independent.
        """
        idx = self._count
        self._count += 1
        rows, combo = self._rows, self._combo
        c = 1 << idx
        while x:
            h = x.bit_length() - 1
            r = rows.get(h)
            if r is None:
                rows[h] = x
                if self._track:
                    combo[h] = c
                return True
            x ^= r
            if self._track:
                c ^= combo[h]
        if self._track:
            self.dependencies.append(c)
        return False

    def represent(self, x: int):
        """Bitset of inserted-vector indices summing to ``x``, or ``None`` if not in the span."""
        if not self._track:
            raise RuntimeError("GF2Eliminator(track=True) is needed for represent()")
        rows, combo = self._rows, self._combo
        c = 0
        while x:
            h = x.bit_length() - 1
            r = rows.get(h)
            if r is None:
                return None
            x ^= r
            c ^= combo[h]
        return c


def masks_to_gf2(masks, n_edges: int):
    """``(n_edges, len(masks))`` ``galois.GF2`` matrix with the bitsets as columns."""
    import galois

    nbytes = max(1, (n_edges + 7) // 8)
    cols = np.zeros((len(masks), n_edges), dtype=np.uint8)
    for j, m in enumerate(masks):
        bits = np.unpackbits(np.frombuffer(int(m).to_bytes(nbytes, "little"), dtype=np.uint8),
                             bitorder="little")
        cols[j] = bits[:n_edges]
    return galois.GF2(np.ascontiguousarray(cols.T))


def gf2_rank(masks, n_edges: int) -> int:
    """Rank over GF(2) of the bitsets, computed with ``galois`` (the oracle)."""
    if len(masks) == 0:
        return 0
    return int(np.linalg.matrix_rank(masks_to_gf2(masks, n_edges)))


def bitset_solve(basis_masks, target_masks):
    """For each target, a subset of the basis vectors summing to it (bitset elimination).

    Parameters
    ----------
    basis_masks : sequence of int, length n
    target_masks : sequence of int, length m

    Returns
    -------
    solutions : list of (int or None), length m
        Bitset over basis indices ``0..n-1`` whose vectors sum to the target, or
        ``None`` when the target is not in their span.
    nullspace : list of int
        Bitsets over basis indices, a basis of the dependencies (subsets summing
        to zero); every solution is one of ``solutions[j]`` plus a sum of these.
    """
    el = GF2Eliminator(track=True)
    for m in basis_masks:
        el.add(int(m))
    return [el.represent(int(t)) for t in target_masks], list(el.dependencies)


def gf2_solve(basis_masks, target_masks, n_edges: int):
    """Same contract as :func:`bitset_solve`, computed by ``galois`` row reduction.

    The matrix ``[B | T]`` (one row per edge, one column per basis / target
    cycle) is brought to reduced row echelon form over GF(2) on its first ``n``
    columns; pivot rows give a particular solution (free variables 0) and the
    free columns the null space.
    """
    n, m = len(basis_masks), len(target_masks)
    if n == 0:
        return [0 if int(t) == 0 else None for t in target_masks], []
    A = masks_to_gf2(list(basis_masks) + list(target_masks), n_edges)
    Rn = np.asarray(A.row_reduce(ncols=n), dtype=np.uint8)
    piv_rows, piv_cols = [], []
    for i in range(Rn.shape[0]):
        nz = np.flatnonzero(Rn[i, :n])
        if nz.size:
            piv_rows.append(i)
            piv_cols.append(int(nz[0]))
    r = len(piv_rows)
    rhs = Rn[:, n:]
    in_span = ~rhs[r:].any(axis=0) if r < Rn.shape[0] else np.ones(m, bool)
    sols = []
    for j in range(m):
        if not in_span[j]:
            sols.append(None)
            continue
        x = 0
        for i, c in zip(piv_rows, piv_cols):
            if rhs[i, j]:
                x |= 1 << c
        sols.append(x)
    pivset = set(piv_cols)
    null = []
    for f in range(n):
        if f in pivset:
            continue
        x = 1 << f
        for i, c in zip(piv_rows, piv_cols):
            if Rn[i, f]:
                x |= 1 << c
        null.append(x)
    return sols, null
