"""The greedy GF(2) cycle basis of Algorithm 1 (Abbasinejad, Joshi, Amenta 2011).

The greedy matroid algorithm (Theorem 1) keeps every candidate independent of
the ones already kept, in the order ``N_1, N_2, N_3, S_1, N_4, S_2, ...``
(Algorithm 1 interleaves the non-separating cycles ``N_i`` and the separating
ones ``S_{i-2}``), which realises the order of ``k = #edges + (2 + eps) s``.

References
----------
F. Abbasinejad, P. Joshi, N. Amenta. Surface patches from unorganized space
curves. Computer Graphics Forum 30(5) (SGP 2011), Sec. 4.1, Algorithm 1.
"""

from __future__ import annotations

from .gf2 import GF2Eliminator
from .candidates import CandidatePool

__all__ = ["greedy_basis"]


def greedy_basis(pool: CandidatePool, *, max_cycle_length=None):
    """Algorithm 1 with the greedy matroid test on bitsets.

    Returns
    -------
    basis : list of Candidate
        In acceptance order.
    pool_candidates : list of Candidate
        Every candidate the pool enumerated (for closing suggestions), by length
        then ``geo`` (:attr:`CandidatePool.all_candidates`).
    info : dict
        ``candidates`` per length, ``max_length`` reached, ``horton`` count.
    """
    el = GF2Eliminator()
    basis = []
    counts = {}
    r_full = pool.cycle_rank
    pending_sep: dict = {}
    limit = pool.n_vertices if max_cycle_length is None else min(max_cycle_length,
                                                                 max(pool.n_vertices, 1))
    limit = max(limit, 1)

    def consume(cands):
        """Greedy matroid step over cycles already in ``k`` order."""
        for c in cands:
            if el.rank >= r_full:
                return
            if el.add(c.mask):
                basis.append(c)

    L = 0
    n_horton = 0
    while el.rank < r_full and L < limit:
        L += 1
        cands = pool.cycles_of_length(L)
        if cands is None:
            break
        cands.sort(key=lambda c: c.geo)
        # N_L pass (k = L). A cycle dependent on the basis now stays dependent, so
        # it is dropped unclassified; independent separating ones wait for S_L.
        sep, cut = [], []
        for c in cands:
            if el.rank >= r_full:
                break
            if not el.is_independent(c.mask):
                continue
            pool.classify([c])
            if c.separating:
                sep.append(c)
            elif c.cutting:
                cut.append(c)        # same k, examined after the faces of length L
            else:
                el.add(c.mask)
                basis.append(c)
        consume(cut)
        pending_sep[L] = sep
        counts[L] = {"total": len(cands), "separating_examined": len(sep)}
        consume(pending_sep.pop(L - 2, []))       # S_{L-2} (k = L + eps)
    if el.rank < r_full:
        # flush separating cycles not yet examined, in k order
        consume([c for Ls in sorted(pending_sep) for c in pending_sep[Ls]])
    if el.rank < r_full and pool.work_bound_hit and max_cycle_length is None:
        extra = pool.horton_candidates(min_length=L)
        pool.classify(extra)
        n_horton = len(extra)
        consume(sorted(extra, key=lambda c: c.key))
    info = {"candidates": counts, "max_length": L, "horton_candidates": n_horton}
    return basis, pool.all_candidates, info
