"""Tests of curvenet.cycles.closing: closing suggestions and auto-closing (Sec. 5).

Oracles: the analytic solids, whose cycle basis misses exactly one true face
(the faces of a closed surface sum to zero over GF(2)); the hand-computed
``Ws`` of a unit box's missing face.
"""

from __future__ import annotations

import pytest

from curvenet.datasets import shapes
from curvenet.cycles.candidates import CandidatePool
from curvenet.cycles.closing import auto_close, closing_suggestions
from curvenet.cycles.find import find_patches

from ._networks import found, true_faces


def _basis_and_pool(shape):
    basis = find_patches(shape.network, close="none")
    patches = [p.edges for p in basis.patches]
    pool = CandidatePool(shape.network)
    longest = max(len(p) for p in patches)
    for L in range(1, longest + 1):
        pool.cycles_of_length(L)
    return basis, patches, pool, longest


@pytest.mark.parametrize("name", ["box", "house", "l_prism", "capped_cylinder"])
@pytest.mark.parametrize("backend", ["bitset", "galois"])
def test_missing_face_closes_the_solid(name, backend):
    s = getattr(shapes, name)()
    basis, patches, pool, longest = _basis_and_pool(s)
    missing = true_faces(s) - found(basis)
    assert len(missing) == 1
    sugg = closing_suggestions(pool, patches, backend=backend)
    by_edges = {g["edges"]: g for g in sugg}
    face = by_edges[next(iter(missing))]
    # the missing face is the GF(2) sum of all basis patches; each of its curves is open
    assert set(face["solid"]) == set(range(len(patches)))
    assert face["b"] == face["size"] == len(face["edges"])
    for g in sugg:
        assert g["score"] == pytest.approx(10 * (g["a"] + g["b"]) + g["size"])
    assert [g["score"] for g in sugg] == sorted((g["score"] for g in sugg), reverse=True)
    # a rejected cycle is not suggested again
    rest = closing_suggestions(pool, patches, exclude=[face["edges"]], backend=backend)
    assert face["edges"] not in {g["edges"] for g in rest}
    # close="auto" fills exactly this hole
    assert auto_close(pool, patches, longest) == [face["edges"]]


def test_unit_box_score_by_hand():
    """Missing face of a unit box: a = (5 + 1) faces of equal area / 1 face = 6, b = 4, k = 4."""
    basis, patches, pool, _ = _basis_and_pool(shapes.box())
    top = closing_suggestions(pool, patches)[0]
    assert {top["edges"]} == true_faces(shapes.box()) - found(basis)
    assert (top["a"], top["b"], top["size"]) == (pytest.approx(6.0), 4, 4)
    assert top["score"] == pytest.approx(104.0)


def test_no_suggestions_without_patches_or_candidates():
    s = shapes.box()
    _, patches, pool, _ = _basis_and_pool(s)
    assert closing_suggestions(pool, []) == []
    assert closing_suggestions(pool, patches, candidates=[]) == []
