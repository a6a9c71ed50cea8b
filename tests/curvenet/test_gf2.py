"""Tests of curvenet.cycles.gf2 against galois (GF(2) rank and solves)."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from curvenet.cycles.gf2 import (GF2Eliminator, bitset_solve, edge_mask, gf2_rank, gf2_solve,
                           mask_edges)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(min_value=0, max_value=(1 << 24) - 1), max_size=30))
def test_eliminator_rank_matches_galois(masks):
    el = GF2Eliminator()
    flags = [el.add(m) for m in masks]
    kept = [m for m, f in zip(masks, flags) if f]
    assert el.rank == len(kept) == gf2_rank(masks, 24) == gf2_rank(kept, 24)
    # add() says False exactly for vectors in the span of the earlier kept ones
    sols, _ = gf2_solve(kept, [m for m, f in zip(masks, flags) if not f], 24)
    assert all(x is not None for x in sols)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(min_value=0, max_value=(1 << 16) - 1), min_size=1, max_size=20),
       st.lists(st.integers(min_value=0, max_value=(1 << 16) - 1), min_size=1, max_size=10))
def test_bitset_solve_matches_galois(basis, targets):
    for solver in (lambda: bitset_solve(basis, targets), lambda: gf2_solve(basis, targets, 16)):
        sols, null = solver()
        for t, x in zip(targets, sols):
            if x is not None:
                acc = 0
                for i in mask_edges(x):
                    acc ^= basis[i]
                assert acc == t
        for v in null:
            acc = 0
            for i in mask_edges(v):
                acc ^= basis[i]
            assert acc == 0 and v != 0
        assert len(null) == len(basis) - gf2_rank(basis, 16)
    a, _ = bitset_solve(basis, targets)
    b, _ = gf2_solve(basis, targets, 16)
    assert [x is None for x in a] == [x is None for x in b]


def test_edge_mask_roundtrip():
    assert mask_edges(edge_mask([5, 0, 64, 3])) == (0, 3, 5, 64)
