"""Curve network to patches: candidate cycles, the GF(2) greedy basis, loops, faces with
holes, closing patches, and the session that edits them."""

from .find import (DEFAULT_MAX_WORK, ENGINES, NUMBA_MIN_WORK, SEPARATING_EPS, TIE_BREAKS,
                   Candidate, CandidatePool, closing_suggestions, cycle_to_loop, find_patches,
                   greedy_basis, orient_patches)

__all__ = ["find_patches", "cycle_to_loop", "orient_patches", "closing_suggestions",
           "greedy_basis", "Candidate", "CandidatePool", "SEPARATING_EPS", "TIE_BREAKS",
           "ENGINES", "DEFAULT_MAX_WORK", "NUMBA_MIN_WORK"]
