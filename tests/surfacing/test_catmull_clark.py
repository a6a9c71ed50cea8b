import numpy as np
import pytest
import trimesh

from curvenet.surfacing.catmull_clark import (edge_index, edge_topology, euler_characteristic,
                                              subdivide, subdivision_step)

from ._meshes import cube, grid


def _tri(V, Q):
    return trimesh.Trimesh(V, np.concatenate([Q[:, [0, 1, 2]], Q[:, [0, 2, 3]]]), process=False)


def test_one_step_matches_hand_computed_cube():
    V, Q = cube()
    st = subdivision_step(Q, 8)
    W = st.S @ V
    # vertex point of a valence-3 cube corner: (Q + 2R + 0 V) / 3 with Q the mean of the
    # three face centres (1/3 each coordinate at the origin) and R the mean of the three
    # edge midpoints (1/6): (1/3 + 2/6) / 3 = 2/9
    np.testing.assert_allclose(W[0], [2 / 9] * 3, atol=1e-15)
    np.testing.assert_allclose(W[7], [7 / 9] * 3, atol=1e-15)
    # edge point of edge (0,0,0)-(1,0,0): (v0 + v1 + F0 + F1) / 4 with face centres
    # (0.5, 0.5, 0) and (0.5, 0, 0.5) -> (0.5, 0.125, 0.125)
    e = edge_index(st.topo, np.array([0]), np.array([4]))[0]
    np.testing.assert_allclose(W[8 + e], [0.5, 0.125, 0.125], atol=1e-15)
    # face points: face centres
    np.testing.assert_allclose(W[8 + 12:], V[Q].mean(1), atol=1e-15)
    assert st.S.shape == (26, 8)
    np.testing.assert_allclose(np.asarray(st.S.sum(1)).ravel(), 1.0)


@pytest.mark.parametrize("levels", [1, 2, 3])
def test_euler_characteristic_and_orientation_preserved(levels):
    V, Q = cube()
    V2, Q2, _, _ = subdivide(V, Q, levels)
    assert euler_characteristic(Q2) == euler_characteristic(Q) == 2
    m = _tri(V2, Q2)
    assert m.is_watertight and m.is_winding_consistent and m.volume > 0
    assert len(Q2) == 6 * 4 ** levels


def test_sharp_creases_keep_a_cube():
    V, Q = cube()
    topo = edge_topology(Q, 8)
    V3, Q3, _, _ = subdivide(V, Q, 3, sharp_edges=topo.edges)
    # every vertex stays on the cube's surface: one coordinate is 0 or 1
    on_face = np.any(np.isclose(V3, 0, atol=1e-12) | np.isclose(V3, 1, atol=1e-12), axis=1)
    assert on_face.all()
    np.testing.assert_allclose(V3[:8], V, atol=1e-15)      # corners fixed


def test_boundary_rule_on_open_grid():
    V, Q, idx = grid(3, 3, lambda x, y: x * x)
    corners = np.zeros(len(V), bool)
    corners[idx[[0, 0, -1, -1], [0, -1, 0, -1]]] = True
    st = subdivision_step(Q, len(V), corners=corners)
    W = st.S @ V
    # boundary vertex (1/3, 0): crease rule (a + 6v + b) / 8 along the boundary
    v, a, b = idx[1, 0], idx[0, 0], idx[2, 0]
    np.testing.assert_allclose(W[v], (V[a] + 6 * V[v] + V[b]) / 8, atol=1e-15)
    np.testing.assert_allclose(W[idx[0, 0]], V[idx[0, 0]])
    assert euler_characteristic(st.quads) == 1


def test_relabelling_vertices_gives_the_same_surface():
    V, Q = cube()
    perm = np.random.default_rng(3).permutation(8)
    inv = np.argsort(perm)
    V2, Q2, _, _ = subdivide(V, Q, 2)
    Vp, Qp, _, _ = subdivide(V[perm], inv[Q], 2)
    a = np.unique(np.round(V2, 12), axis=0)
    b = np.unique(np.round(Vp, 12), axis=0)
    np.testing.assert_allclose(a, b, atol=1e-12)


def test_non_manifold_edge_is_sharp():
    # three quads on one edge (0, 1): the edge points on it are midpoints
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [1, 0, 1], [0, 0, 1],
                  [1, -1, 0], [0, -1, 0]], float)
    Q = np.array([[0, 1, 2, 3], [1, 0, 5, 4], [0, 1, 6, 7]])
    st = subdivision_step(Q, 8)
    e = edge_index(st.topo, np.array([0]), np.array([1]))[0]
    assert st.topo.face_count[e] == 3
    np.testing.assert_allclose((st.S @ V)[8 + e], [0.5, 0, 0])
