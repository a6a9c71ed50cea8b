"""Output density: the subdivision level follows a target edge length, capped in faces."""

from __future__ import annotations

import numpy as np
import pytest

from curvenet.core.errors import InvalidParameterError
from curvenet.surfacing.api import DEFAULT_MAX_FACES, density_subdiv, surface_loops


def _rectangle(w, h, n=9):
    t = np.linspace(0, 1, n)[:, None]
    return [t * [w, 0, 0], [w, 0, 0] + t * [0, h, 0], [w, h, 0] - t * [w, 0, 0],
            [0, h, 0] - t * [0, h, 0]]


LOOP = [[(0, True), (1, True), (2, True), (3, True)]]


def _mean_edge(res):
    f = res.faces
    v = res.vertices
    return np.linalg.norm(v[f] - v[np.roll(f, -1, axis=1)], axis=2).mean()


@pytest.mark.parametrize("edge_length", [0.05, 0.02, 0.01])
def test_level_gives_edges_near_the_target(edge_length):
    res = surface_loops(_rectangle(1, 1), LOOP, edge_length=edge_length)
    diag = np.sqrt(2)
    # triangles: two quad sides and a diagonal, so the mean edge is within (1, 1.5) quad edges
    assert _mean_edge(res) <= 1.5 * edge_length * diag
    coarser = surface_loops(_rectangle(1, 1), LOOP, subdiv=res.report["subdiv"] - 1)
    assert _mean_edge(coarser) > edge_length * diag
    assert np.abs(res.vertices[:, 2]).max() < 1e-12


def test_long_thin_patches_stay_under_the_face_budget():
    curves = _rectangle(200, 1, n=400)
    res = surface_loops(curves, LOOP, edge_length=1e-5)
    assert res.report["n_faces"] <= DEFAULT_MAX_FACES
    assert res.report["n_faces"] * 4 > DEFAULT_MAX_FACES  # the largest level that fits
    assert density_subdiv(np.zeros((4, 3)), np.array([[0, 1, 2, 3]]), 1.0,
                          max_faces=1) == 0


def test_explicit_subdiv_overrides_and_bad_edge_length_is_refused():
    res = surface_loops(_rectangle(1, 1), LOOP, subdiv=1, edge_length=1e-6)
    assert res.report["subdiv"] == 1
    with pytest.raises(InvalidParameterError, match="edge_length"):
        surface_loops(_rectangle(1, 1), LOOP, edge_length=0)
