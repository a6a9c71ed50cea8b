"""auto's check of the classical surface: walls inside the shape, and what it takes then.

Oracle: sparse tori, whose cycle basis caps meridians with discs inside the tube (walls)
or leaves curves bounding three patches, while the faces of their rotation system are
their true faces. The first patch selection is forced to the basis (the finder's own
``auto`` would take the faces before the check sees them).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import curvenet
import curvenet.cycles.find as find
from curvenet.datasets import shapes
from curvenet.evaluate import evaluate_mesh
from curvenet.route.decision import coverage

_find = find.find_patches


@pytest.fixture
def basis_first(monkeypatch):
    """find_patches' default mode is the basis: the pipeline's first selection."""
    monkeypatch.setattr(find, "find_patches", lambda net, mode="auto", **kw: _find(
        net, mode="basis" if mode == "auto" else mode, **kw))


def _fscore(res, shape):
    return evaluate_mesh(res.mesh, shape.reference_mesh(4), n_samples=20_000)["fscore"]


def test_auto_replaces_walls_by_the_faces_that_cover_as_much(basis_first):
    shape = shapes.torus(1.0, 0.25, n_u=4, n_v=3)
    res = curvenet.surface(shape.sketch())
    check = res.decision.check
    assert res.method == "classical" and check["taken"] == "faces"
    assert check["walls"]["basis"] > 0 and check["walls"]["faces"] == 0
    assert check["nonmanifold"] == 0
    assert check["coverage"]["faces"] == pytest.approx(check["coverage"]["basis"]) == 1.0
    assert len(res.patchset.patches) == 12
    assert res.diagnostics["patches"] == 12             # the figures of the set taken
    assert res.diagnostics["coverage"] == check["coverage"]["faces"]
    assert res.diagnostics["unused_edges"] == coverage(res.patchset)[1]
    assert "coverage basis 100%, faces 100%; kept the faces patches" in \
        res.decision.explain_check()
    assert _fscore(res, shape) > 0.99


def test_curves_of_three_patches_alone_keep_the_first_selection(basis_first):
    # a torus's basis, surfaced by the least-squares fit: no wall, curves in three
    # patches; the check passes it (the swept fit, auto's choice, bends some of these
    # patches into walls, which the check then replaces by the faces)
    shape = shapes.torus(1.0, 0.4, n_u=4, n_v=2)
    res = curvenet.surface(shape.sketch(), classical_options={"fit": "lsq"})
    check = res.decision.check
    assert check["walls"] == {"basis": 0} and check["nonmanifold"] > 0
    assert check["taken"] == "basis" and res.method == "classical"


@pytest.mark.parametrize("neural_fits", [True, False])
def test_the_neural_route_replaces_walls_only_when_it_holds_the_strokes(monkeypatch,
                                                                       neural_fits):
    # no other selection passes (the faces are the basis again); the neural fit is
    # stubbed: the true torus (it holds every stroke) or a far-away triangle
    shape = shapes.torus(1.0, 0.25, n_u=4, n_v=3)
    basis = _find(shape.network, mode="basis")
    monkeypatch.setattr(find, "find_patches", lambda net, mode="auto", **kw: _find(
        net, mode="basis", **kw))
    from curvenet.neural import flow
    ref = shape.reference_mesh(3)
    far = (np.array([[9.0, 9, 9], [9.1, 9, 9], [9, 9.1, 9]]), np.array([[0, 1, 2]]))
    mesh = (np.asarray(ref.vertices), np.asarray(ref.faces)) if neural_fits else far
    monkeypatch.setattr(flow, "fit_flow_surface", lambda strokes, **kw: SimpleNamespace(
        vertices=mesh[0], faces=mesh[1], report={}))
    res = curvenet.surface(shape.sketch())
    check = res.decision.check
    assert res.method == ("neural" if neural_fits else "classical")
    assert check["taken"] == ("neural" if neural_fits else "basis")
    assert check["walls"]["basis"] > 0 and len(res.patchset.patches) == len(basis.patches)
    assert check["fidelity"]["classical"] > 0.99
    assert (check["fidelity"]["neural"] > 0.99) is neural_fits
    assert "stroke fidelity classical 100%" in res.decision.explain_check()


def test_patches_the_user_gave_are_not_judged():
    shape = shapes.torus(1.0, 0.25, n_u=4, n_v=3)
    basis = _find(shape.network, mode="basis")
    res = curvenet.surface(basis)
    assert res.decision.check is None and res.patchset.patches == basis.patches
