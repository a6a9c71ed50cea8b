"""Graded knots around irregular vertices (oracles: limit points of further global
subdivision at dyadic parameters, projected onto the pieces)."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from curvenet.surfacing import bspline
from curvenet.surfacing.bspline import ControlNet, evaluate, extract_bsplines, project
from curvenet.surfacing.graded import corner_chains, graded_breaks
from curvenet.surfacing.levels import extended_poles, subdivide_net
from curvenet.surfacing.splines import tensor_grid, uniform_design


def _cube_net():
    """Cube control mesh (every vertex valence 3), one corner moved, the face
    ``0 2 3 1`` bordered by creases (crease vertices with one face on one side).
    (No darts: their limit mask is not exact.)"""
    V = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    V[7] += 0.3                                 # not symmetric
    Q = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2],
                  [1, 3, 7, 5]])
    crease = np.array([[0, 2], [2, 3], [3, 1], [1, 0]])
    return ControlNet(V, Q, np.arange(6), crease, np.zeros(8, bool), [], float(np.sqrt(3)))


def test_graded_breaks():
    b = graded_breaks(4, [0, 2], 3)
    assert np.allclose(b, [0, .125, .25, .5, 1, 1.5, 1.75, 1.875, 2, 2.125, 2.25, 2.5, 3, 4])


def test_exact_limit_around_irregular_corners_matches_deep_subdivision():
    """The exact evaluator (rings of uniform poles + corner lattice) against the limit
    points of a globally subdivided mesh, at every dyadic parameter of every site."""
    net = _cube_net()
    level, grade, sl, d = 1, 2, 2, 4
    _, lv, grids, limit = subdivide_net(net, level)
    _, _, fine, fine_limit = subdivide_net(net, level + d)
    offs = []
    for G in grids:
        M, N = G.shape[0] - 1, G.shape[1] - 1
        E = extended_poles(lv, G)[0]
        at = tensor_grid(uniform_design(np.arange(M + 1), M), E,
                         uniform_design(np.arange(N + 1), N))
        offs.append(np.linalg.norm(at - limit[G], axis=2) > 1e-10)
    sites, spans, own = bspline._sites(lv, grids, offs, limit, 1e-10)
    assert (sites[:, 3] >= 0).all()              # every irregular span at a cube vertex
    corner_ids = [grids[p][i, j] for p, i, j in sites[:, [0, 3, 4]]]
    assert set(corner_ids) == set(range(8))     # (vertex ids survive subdivision)
    chains = corner_chains(lv, np.stack(spans), grade, sl)
    worst = 0.0
    for pid, G in enumerate(grids):
        M, N = G.shape[0] - 1, G.shape[1] - 1
        exact = bspline._exact_in(sites, chains, own, pid, M, N)
        a, b = np.meshgrid(np.arange(M * 2 ** d + 1), np.arange(N * 2 ** d + 1), indexing="ij")
        u, v = a.ravel() / 2 ** d, b.ravel() / 2 ** d
        bad = np.zeros((M, N), bool)
        mine = sites[sites[:, 0] == pid]
        bad[mine[:, 1], mine[:, 2]] = True
        inside = bad[np.minimum(np.floor(u), M - 1).astype(int),
                     np.minimum(np.floor(v), N - 1).astype(int)]
        ref = fine_limit[fine[pid][a.ravel()[inside], b.ravel()[inside]]]
        worst = max(worst, np.abs(exact(u[inside], v[inside]) - ref).max())
    assert worst < 1e-12


@pytest.mark.parametrize("level", [1, 2])
def test_grading_shrinks_the_deviation_and_measures_it(level):
    net = _cube_net()
    _, _, fine, fine_limit = subdivide_net(net, level + 4)
    true = {}
    for grade in (0, 4):
        bset = extract_bsplines(net, level, grade=grade)
        # oracle: limit points four levels finer, projected onto their piece
        worst = 0.0
        for pc, G in zip(bset.pieces, fine):
            a, b = np.meshgrid(np.arange(G.shape[0]), np.arange(G.shape[1]), indexing="ij")
            u, v = a.ravel() / 16, b.ravel() / 16
            worst = max(worst, project(pc, fine_limit[G.ravel()], u, v)[2].max())
        true[grade] = worst / net.diagonal
    assert true[4] <= 1.25 * bset.report["max_deviation"] + 1e-12
    assert true[4] < true[0] / 4
    # each irregular vertex adds 2 grade poles per direction, never a face
    assert bset.report["n_pieces"] == 6 and bset.report["grade"] == 4
    base = 2 ** level + 3                       # one control quad a side
    assert all(pc.poles.shape[0] in (base, base + 4, base + 8) for pc in bset.pieces)
    assert max(pc.poles.shape[0] for pc in bset.pieces) == base + 8    # 4 knots each end


def test_graded_pieces_stay_watertight_at_seams():
    net = _cube_net()
    bset = extract_bsplines(net, 2)
    dev = bset.report["max_deviation"]
    assert 0 < dev < 1e-3
    for s in bset.seams:
        assert s["gap"] <= 2 * dev + 1e-12
    # dense points of all pieces cover the whole limit surface
    _, _, fine, fine_limit = subdivide_net(net, 5)
    P = []
    for pc in bset.pieces:
        u, v = np.meshgrid(np.linspace(0, pc.knots_u[-1], 33),
                           np.linspace(0, pc.knots_v[-1], 33), indexing="ij")
        P.append(evaluate(pc, u.ravel(), v.ravel()))
    d, _ = cKDTree(np.concatenate(P)).query(fine_limit)
    assert d.max() < 0.05 * net.diagonal
