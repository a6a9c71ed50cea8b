"""B-spline pieces of the Catmull-Clark limit: exact on regular meshes, measured near
extraordinary vertices (oracles: the limit points of further subdivision, scipy's bisplev)."""

import numpy as np
from scipy.spatial import cKDTree

from curvenet.surfacing import subdivide
from curvenet.surfacing.bspline import ControlNet, evaluate, extract_bsplines, project
from curvenet.surfacing.limit import limit_matrix


def _torus_net(nu=8, nv=6, pieces=2):
    """A closed all-valence-4 control mesh cut into ``pieces`` grids along u."""
    a = 2 * np.pi * np.arange(nu) / nu
    b = 2 * np.pi * np.arange(nv) / nv
    A, B = np.meshgrid(a, b, indexing="ij")
    V = np.stack([(2 + 0.7 * np.cos(B)) * np.cos(A), (2 + 0.7 * np.cos(B)) * np.sin(A),
                  0.7 * np.sin(B) + 0.1 * np.cos(3 * A)], -1).reshape(-1, 3)
    idx = np.arange(nu * nv).reshape(nu, nv)
    step = nu // pieces
    quads, fp = [], []
    for k in range(pieces):
        rows = np.arange(k * step, (k + 1) * step + 1) % nu
        G = idx[rows][:, np.r_[np.arange(nv), 0]]
        q = np.stack([G[:-1, :-1].ravel(), G[1:, :-1].ravel(), G[1:, 1:].ravel(),
                      G[:-1, 1:].ravel()], 1)
        quads.append(q)
        fp.append(np.full(len(q), k))
    Q = np.concatenate(quads)
    return ControlNet(V, Q, np.concatenate(fp), np.zeros((0, 2), np.int64),
                      np.zeros(len(V), bool), [], float(np.ptp(V, 0).max() * 1.7))


def _cube_net():
    """Smooth cube: every vertex has valence 3 (extraordinary), one piece per face."""
    V = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    Q = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2],
                  [1, 3, 7, 5]])
    return ControlNet(V, Q, np.arange(6), np.zeros((0, 2), np.int64), np.zeros(8, bool), [],
                      float(np.sqrt(3)))


def _limit_points(net, levels):
    V, Q, se, cr = subdivide(net.vertices, net.quads, levels, net.sharp_edges, net.corners)
    return limit_matrix(Q, len(V), se, cr) @ V


def _piece_points(bset, r):
    pts = []
    for pc in bset.pieces:
        m, n = pc.knots_u[-1], pc.knots_v[-1]
        u, v = np.meshgrid(np.arange(m * r + 1) / r, np.arange(n * r + 1) / r, indexing="ij")
        pts.append(evaluate(pc, u.ravel(), v.ravel()))
    return np.concatenate(pts)


def test_regular_torus_is_exact_everywhere():
    net = _torus_net()
    level = 1
    bset = extract_bsplines(net, level)
    assert bset.report["n_exact"] == bset.report["n_pieces"] == 2
    assert bset.report["max_deviation"] < 1e-13
    # independent oracle: three more levels of subdivision, limit points, dyadic params
    r = 8
    P = _piece_points(bset, r)
    L = _limit_points(net, level + 3)
    d, _ = cKDTree(L).query(P)
    assert d.max() < 1e-12 * net.diagonal
    d2, _ = cKDTree(P).query(L)                      # and every limit point is covered
    assert d2.max() < 1e-12 * net.diagonal
    for s in bset.seams:
        assert s["gap"] < 1e-13 and s["angle"] < 1e-5 and not s["crease"]


def test_clamped_borders_are_shared_poles():
    bset = extract_bsplines(_torus_net(), 1)
    a, b = bset.pieces
    # piece 0 ends where piece 1 starts (u = M of one is u = 0 of the other)
    assert np.abs(a.poles[-1] - b.poles[0]).max() < 1e-12


def test_extraordinary_cube_deviation_is_measured_and_shrinks():
    net = _cube_net()
    devs = []
    for level in (2, 3):
        bset = extract_bsplines(net, level)
        assert bset.report["n_exact"] == 0                  # every corner has valence 3
        dev = bset.report["max_deviation"]
        # limit points one level finer than the measure, projected onto the nearest piece
        # (started from the nearest of a dense sample of all pieces)
        L = _limit_points(net, level + bset.report["sample_levels"] + 1)
        r = 16
        dense, owner, uv = [], [], []
        for k, pc in enumerate(bset.pieces):
            m, n = pc.knots_u[-1], pc.knots_v[-1]
            u, v = np.meshgrid(np.arange(m * r + 1) / r, np.arange(n * r + 1) / r,
                               indexing="ij")
            dense.append(evaluate(pc, u.ravel(), v.ravel()))
            owner.append(np.full(u.size, k))
            uv.append(np.stack([u.ravel(), v.ravel()], 1))
        dense, owner, uv = np.concatenate(dense), np.concatenate(owner), np.concatenate(uv)
        _, near = cKDTree(dense).query(L)
        d = np.empty(len(L))
        for k, pc in enumerate(bset.pieces):
            m = owner[near] == k
            d[m] = project(pc, L[m], uv[near[m], 0], uv[near[m], 1])[2]
        assert d.max() / net.diagonal <= 1.25 * dev + 1e-12
        assert 0 < dev < 1e-3
        devs.append(dev)
    assert devs[1] < devs[0]


def test_crease_sheet_is_exact_with_phantom_rows():
    # two flat-ish grids meeting at a crease, open boundary all round
    G = np.arange(15).reshape(5, 3)
    x, y = np.meshgrid(np.arange(5.0), np.arange(3.0), indexing="ij")
    V = np.stack([x, y, np.where(x > 2, x - 2, 0.0) + 0.1 * y ** 2], -1).reshape(-1, 3)
    q0 = np.stack([G[:2, :-1].ravel(), G[1:3, :-1].ravel(), G[1:3, 1:].ravel(),
                   G[:2, 1:].ravel()], 1)
    q1 = np.stack([G[2:4, :-1].ravel(), G[3:, :-1].ravel(), G[3:, 1:].ravel(),
                   G[2:4, 1:].ravel()], 1)
    se = np.stack([G[2, :-1], G[2, 1:]], 1)
    net = ControlNet(V, np.concatenate([q0, q1]), np.r_[[0] * 4, [1] * 4], se,
                     np.zeros(15, bool), [], 5.0)
    net.corners[[G[0, 0], G[0, -1], G[-1, 0], G[-1, -1], G[2, 0], G[2, -1]]] = True
    bset = extract_bsplines(net, 1)
    assert bset.report["max_deviation"] < 1e-13
    d, _ = cKDTree(_limit_points(net, 4)).query(_piece_points(bset, 8))
    assert d.max() < 1e-12
    (seam,) = bset.seams
    assert seam["crease"] is True and seam["angle"] > 20 and seam["gap"] < 1e-13
