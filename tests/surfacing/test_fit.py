import numpy as np
import pytest

from curvenet.datasets import shapes
from curvenet.surfacing.catmull_clark import edge_topology
from curvenet.surfacing.controlmesh import build_control_mesh
from curvenet.surfacing.sharp import sharp_structure
from curvenet.surfacing.fit import (fairness_matrix, fit_iterative, fit_lsq, variation_matrix,
                           vspring_displacement)
from curvenet.surfacing.limit import limit_matrix, tangent_matrices


def _setup(name, N=4):
    s = shapes.SHAPES[name]()
    curves = [e.curve for e in s.network.edges]
    cm = build_control_mesh(curves, s.faces, N)
    _, _, se, cr, _ = sharp_structure(cm, curves)
    n = len(cm.vertices)
    L = limit_matrix(cm.quads, n, se, cr)
    cons = np.flatnonzero(cm.on_curve)
    return cm, se, cr, L, cons, cm.target[cons]


@pytest.mark.parametrize("name", ["sphere", "saddle", "torus"])
def test_lsq_interpolates_curve_samples(name):
    cm, se, cr, L, cons, q = _setup(name)
    F = variation_matrix(fairness_matrix(cm.quads, len(cm.vertices), se, cr))
    P = fit_lsq(L, F, cm.vertices, cons, q)
    # exact constraints through a KKT solve: round-off only
    assert np.abs(L[cons] @ P - q).max() < 1e-10 * cm.diagonal


@pytest.mark.parametrize("name", ["sphere", "torus", "grid_box"])
def test_quasi_definite_kkt_solve_is_the_pivoted_one(name, monkeypatch):
    """Above PIVOTED_MAX unknowns the KKT system is factorised without pivoting and
    refined: the same control points to round-off; and when refinement cannot reach
    round-off (no steps allowed, a coarse regularisation), the pivoted solve is used."""
    import curvenet.surfacing.fit as fit
    cm, se, cr, L, cons, q = _setup(name)
    F = variation_matrix(fairness_matrix(cm.quads, len(cm.vertices), se, cr))
    pivoted = fit_lsq(L, F, cm.vertices, cons, q)
    monkeypatch.setattr(fit, "PIVOTED_MAX", 10)
    quasi = fit_lsq(L, F, cm.vertices, cons, q)
    assert 0 < np.abs(quasi - pivoted).max() < 1e-11 * cm.diagonal
    monkeypatch.setattr(fit, "_REFINE_STEPS", 0)
    monkeypatch.setattr(fit, "QUASI_EPS", 1e-3)
    assert np.array_equal(fit_lsq(L, F, cm.vertices, cons, q), pivoted)


def test_lsq_penalty_trades_interpolation_for_fairness():
    cm, se, cr, L, cons, q = _setup("sphere")
    F = fairness_matrix(cm.quads, len(cm.vertices), se, cr)
    dev = []
    for w in (1e4, 1.0, 1e-2):
        P = fit_lsq(L, F, cm.vertices, cons, q, curve_weight=w)
        dev.append(np.abs(L[cons] @ P - q).max())
    assert dev[0] < dev[1] < dev[2]


def test_iterative_fit_converges_to_tolerance():
    cm, se, cr, L, cons, q = _setup("sphere")
    T1, T2, has = tangent_matrices(cm.quads, len(cm.vertices), se, cr)
    tol = 1e-4 * cm.diagonal
    P, it, dev = fit_iterative(L, T1, T2, has, cm.quads, cm.vertices, cons, q, tol=tol,
                               sharp_edges=se, corners=cr)
    assert dev < tol and it < 500
    # the published update halves the residual per step without fairing
    P0 = cm.vertices.copy()
    r0 = np.abs(L[cons] @ P0 - q).max()
    P1, _, d1 = fit_iterative(L, T1, T2, has, cm.quads, P0, cons, q, max_iter=1,
                              fair_free=False, tol=tol)
    assert d1 < r0


def test_vspring_is_zero_on_a_sphere():
    # points on a sphere with their exact normals: every V-spring offset
    # (v_j - v_i).(n_i + n_j) vanishes, and a symmetric ring has no tangential Laplacian
    k = 12
    a = 2 * np.pi * np.arange(k) / k
    ring = np.stack([np.sin(0.3) * np.cos(a), np.sin(0.3) * np.sin(a), np.full(k, np.cos(0.3))], 1)
    Q = np.concatenate([[[0, 0, 1.0]], ring])
    N = Q / np.linalg.norm(Q, axis=1, keepdims=True)
    edges = np.stack([np.zeros(k, int), np.arange(1, k + 1)], 1)
    d = vspring_displacement(Q, N, edges)
    assert np.linalg.norm(d[0]) < 1e-12


def test_vspring_pulls_a_raised_vertex_back():
    k = 6
    a = 2 * np.pi * np.arange(k) / k
    ring = np.stack([np.cos(a), np.sin(a), np.zeros(k)], 1)
    Q = np.concatenate([[[0, 0, 0.3]], ring])
    N = np.tile([0, 0, 1.0], (k + 1, 1))
    edges = np.stack([np.zeros(k, int), np.arange(1, k + 1)], 1)
    d = vspring_displacement(Q, N, edges)
    np.testing.assert_allclose(d[0], [0, 0, -0.3], atol=1e-12)


def test_fairness_rows_respect_creases():
    cm, se, cr, L, cons, q = _setup("box")
    F = fairness_matrix(cm.quads, len(cm.vertices), se, cr)
    topo = edge_topology(cm.quads, len(cm.vertices))
    assert len(se) > 0
    # corner rows are empty; crease rows have two neighbours
    assert F[np.flatnonzero(cr)].nnz == 0
    crease_v = np.setdiff1d(np.unique(se), np.flatnonzero(cr))
    assert np.all(np.diff(F[crease_v].indptr) == 3)
    assert topo.edges.shape[1] == 2
