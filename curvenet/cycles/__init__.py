"""Curve network to patches: candidate cycles, the GF(2) greedy basis, loops, holes, closing patches, the review session."""

from .find import (find_patches, cycle_to_loop, orient_patches, closing_suggestions, greedy_basis, Candidate,
    CandidatePool, SEPARATING_EPS, TIE_BREAKS, ENGINES, DEFAULT_MAX_WORK, NUMBA_MIN_WORK)

__all__ = ['find_patches', 'cycle_to_loop', 'orient_patches', 'closing_suggestions', 'greedy_basis',
    'Candidate', 'CandidatePool', 'SEPARATING_EPS', 'TIE_BREAKS', 'ENGINES', 'DEFAULT_MAX_WORK',
    'NUMBA_MIN_WORK']
