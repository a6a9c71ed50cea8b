"""Clamped bicubic B-spline pieces (oracle: scipy's bisplev)."""

import numpy as np
from scipy.interpolate import bisplev

from curvenet.surfacing.splines import BSplinePiece, clamp_uniform, evaluate, project, uniform_knots


def _piece(seed=0):
    rng = np.random.default_rng(seed)
    ku = np.r_[[0.0] * 4, 0.5, 1.0, 2.0, [3.0] * 4]              # 7 poles along u
    kv = np.r_[[0.0] * 4, 1.0, [2.0] * 4]                         # 5 poles along v
    return BSplinePiece(rng.normal(size=(7, 5, 3)), ku, kv, 0, True, 0.0)


def test_evaluate_matches_scipy_bisplev():
    pc = _piece()
    u = np.linspace(0, pc.knots_u[-1], 7)
    v = np.linspace(0, pc.knots_v[-1], 5)
    U, Vv = np.meshgrid(u, v, indexing="ij")
    ours, du, dv = evaluate(pc, U.ravel(), Vv.ravel(), derivatives=True)
    for k in range(3):
        tck = [pc.knots_u, pc.knots_v, pc.poles[:, :, k].ravel(), 3, 3]
        assert np.abs(bisplev(u, v, tck) - ours[:, k].reshape(7, 5)).max() < 1e-12
        assert np.abs(bisplev(u, v, tck, dx=1) - du[:, k].reshape(7, 5)).max() < 1e-11
        assert np.abs(bisplev(u, v, tck, dy=1) - dv[:, k].reshape(7, 5)).max() < 1e-11


def test_clamp_uniform_keeps_the_spline():
    # a uniform spline on [0, 4] and its clamped form (with an extra break) agree everywhere
    rng = np.random.default_rng(1)
    E = rng.normal(size=(7, 6, 3))                              # 4 x 3 spans, uniform knots
    P, ku = clamp_uniform(E, 4, 0, breaks=[0, 0.5, 1, 2, 3, 4])
    P, kv = clamp_uniform(P, 3, 1)
    uniform = BSplinePiece(E, uniform_knots(4), uniform_knots(3), 0, True, 0.0)
    clamped = BSplinePiece(P, ku, kv, 0, True, 0.0)
    u, v = rng.uniform(0, 4, 50), rng.uniform(0, 3, 50)
    assert np.abs(evaluate(uniform, u, v) - evaluate(clamped, u, v)).max() < 1e-12
    assert np.abs(P[0, 0] - evaluate(clamped, [0.0], [0.0])[0]).max() < 1e-12


def test_project_finds_points_on_the_piece():
    pc = _piece(2)
    u, v = np.array([0.4, 1.7, 2.9]), np.array([0.3, 1.1, 1.9])
    S = evaluate(pc, u, v)
    pu, pv, d = project(pc, S, u + 0.05, v - 0.05)
    assert d.max() < 1e-9
