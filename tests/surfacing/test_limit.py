import numpy as np
import pytest

from curvenet.datasets import shapes
from curvenet.surfacing.catmull_clark import edge_index, subdivide, subdivision_step
from curvenet.surfacing.controlmesh import build_control_mesh
from curvenet.surfacing.sharp import sharp_structure
from curvenet.surfacing.limit import limit_matrix, limit_normals, tangent_matrices

from ._meshes import cube, grid


def _local_limit(Q, n, V, v, ring, sharp=None, corners=None, steps=200):
    """Position of vertex v after ``steps`` subdivision steps, via its local matrix.

    The 1-ring of an old vertex after one step (the vertex point, the edge points of
    its edges, the face points of its faces) depends only on the old 1-ring, so the
    ring's evolution is a small matrix power: exact "many steps" without the 4^k mesh.
    """
    st = subdivision_step(Q, n, sharp, corners)
    ne = len(st.topo.edges)
    nb_e, faces = ring
    r0 = np.concatenate([[v], nb_e, Q[faces].ravel()])
    r0 = np.unique(r0)
    e1 = n + edge_index(st.topo, np.full(len(nb_e), v), nb_e)
    f1 = n + ne + faces
    r1 = np.concatenate([[v], e1, f1])
    A = st.S[r1][:, r0].toarray()
    assert np.allclose(A.sum(1), 1)
    assert np.allclose(st.S[r1].sum(1).A.ravel(), A.sum(1))      # closed under one step
    # rows of r1 map to the ring at the next level in the same role order as r0
    role = {int(x): k for k, x in enumerate(r0)}
    x = V[r0]
    for _ in range(steps):
        y = A @ x
        # next ring in r0 order: vertex, then edge neighbours, then face corners
        nx = np.empty_like(x)
        nx[role[v]] = y[0]
        for k, w in enumerate(nb_e):
            nx[role[int(w)]] = y[1 + k]
        # face points take the place of the diagonal vertices
        for k, f in enumerate(faces):
            quad = list(Q[f])
            i = quad.index(v)
            nx[role[int(quad[(i + 2) % 4])]] = y[1 + len(nb_e) + k]
        x = nx
    return x[role[v]]


def _ring(Q, v):
    faces = np.flatnonzero((Q == v).any(1))
    nb = set()
    for f in faces:
        q = list(Q[f])
        i = q.index(v)
        nb.update([q[(i + 1) % 4], q[(i + 3) % 4]])
    return np.array(sorted(nb)), faces


def test_limit_mask_matches_many_steps_on_cube():
    V, Q = cube()
    L = limit_matrix(Q, 8)
    V7, _, _, _ = subdivide(V, Q, 7)
    # seven steps shrink a valence-3 vertex's error by 0.41^7 (subdominant eigenvalue)
    assert np.abs(L @ V - V7[:8]).max() < 1e-6
    for v in range(8):
        np.testing.assert_allclose(_local_limit(Q, 8, V, v, _ring(Q, v)), (L @ V)[v],
                                   atol=1e-10)


@pytest.mark.parametrize("name", ["sphere", "torus"])
def test_limit_mask_matches_many_steps_on_control_meshes(name):
    s = shapes.SHAPES[name]()
    cm = build_control_mesh([e.curve for e in s.network.edges], s.faces, 4)
    V = cm.vertices + np.random.default_rng(0).normal(scale=0.01, size=cm.vertices.shape)
    Q = cm.quads
    L = limit_matrix(Q, len(V))
    val = np.bincount(Q.ravel())
    # one vertex of each valence present (3, 4, 5, 6 ...)
    picks = [int(np.flatnonzero(val == k)[0]) for k in np.unique(val)]
    for v in picks:
        lim = _local_limit(Q, len(V), V, v, _ring(Q, v))
        assert np.abs(lim - (L @ V)[v]).max() < 1e-6


def test_crease_and_corner_masks_match_subdivision():
    V, Q, idx = grid(4, 4, lambda x, y: np.sin(3 * x) + y * y)
    corners = np.zeros(len(V), bool)
    corners[idx[[0, 0, -1, -1], [0, -1, 0, -1]]] = True
    L = limit_matrix(Q, len(V), corners=corners)
    V4, _, _, _ = subdivide(V, Q, 4, corners=corners)
    V5, _, _, _ = subdivide(V, Q, 5, corners=corners)
    # boundary vertices follow the cubic B-spline rule, whose vertex positions approach
    # the limit with the single eigenvalue 1/4 (the 1/2 mode is the tangent, which a
    # vertex does not see): Richardson (4 V5 - V4) / 3 is the limit itself
    bnd = np.unique(np.concatenate([idx[0], idx[-1], idx[:, 0], idx[:, -1]]))
    assert np.abs((L @ V)[bnd] - V5[bnd]).max() < 1e-4
    assert np.abs((L @ V)[bnd] - (4 * V5[bnd] - V4[bnd]) / 3).max() < 1e-6
    # interior vertices: exact via the local matrix
    for v in idx[1:-1, 1:-1].ravel()[:3]:
        lim = _local_limit(Q, len(V), V, v, _ring(Q, v), corners=corners)
        assert np.abs(lim - (L @ V)[v]).max() < 1e-6


def test_tangent_masks_are_tangent_to_the_limit_surface():
    s = shapes.SHAPES["ellipsoid"]()
    cm = build_control_mesh([e.curve for e in s.network.edges], s.faces, 4)
    Q, n = cm.quads, len(cm.vertices)
    V = cm.vertices
    T1, T2, has = tangent_matrices(Q, n)
    assert has.all()
    N = limit_normals(V, Q, T1, T2, has)
    # compare with the normal of the subdivided limit mesh near each control vertex
    V4, Q4, _, _ = subdivide(V, Q, 4)
    L4 = limit_matrix(Q4, len(V4))
    from curvenet.surfacing.limit import quad_vertex_normals
    N4 = quad_vertex_normals(L4 @ V4, Q4)[:n]
    cos = np.einsum("ij,ij->i", N, N4)
    # 4 levels: the one-ring of the fine mesh spans 1/16 of a control edge, so the
    # discrete normal is off by O(1e-2) rad at most; outward orientation agrees
    assert cos.min() > 0.999
    # outward: positive dot with the position on a centred ellipsoid
    assert np.all(np.einsum("ij,ij->i", N, V) > 0)


def test_limit_normals_fall_back_at_creases():
    V, Q = cube()
    from curvenet.surfacing.catmull_clark import edge_topology
    se = edge_topology(Q, 8).edges
    T1, T2, has = tangent_matrices(Q, 8, sharp_edges=se)
    assert not has.any()
    L = limit_matrix(Q, 8, sharp_edges=se)
    N = limit_normals(V, Q, T1, T2, has, L)
    np.testing.assert_allclose(np.abs(N), 1 / np.sqrt(3), atol=1e-12)


def test_sharp_structure_on_box_makes_corners_fixed():
    s = shapes.box()
    curves = [e.curve for e in s.network.edges]
    cm = build_control_mesh(curves, s.faces, 4)
    crease, det, se, corners, _ = sharp_structure(cm, curves, crease_angle=30)
    assert crease.all() and corners.sum() == 8
    L = limit_matrix(cm.quads, len(cm.vertices), se, corners)
    np.testing.assert_allclose((L @ cm.vertices)[corners], cm.vertices[corners])
