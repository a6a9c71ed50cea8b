"""Flat patches meshed in their plane (constrained Delaunay), against exact areas and planes."""

import numpy as np
import pytest

from curvenet.surfacing.api import surface_loops
from curvenet.surfacing.flat import flat_planes, mesh_flat
from curvenet.surfacing.sectors import surface_boundaries

# an L-shaped outline (area 4) with a square window (area 0.25) in its long leg
L_OUTLINE = [(0, 0), (3, 0), (3, 1), (1, 1), (1, 2), (0, 2)]
WINDOW = [(1.75, 0.25), (1.75, 0.75), (2.25, 0.75), (2.25, 0.25)]     # clockwise
TRUE_AREA = 4.0 - 0.25


def _frame(tilt):
    """Rotation taking the xy plane to a tilted plane, and an offset."""
    c, s = np.cos(tilt), np.sin(tilt)
    R = np.array([[1, 0, 0], [0, c, -s], [0, s, c]]) @ np.array([[c, -s, 0], [s, c, 0],
                                                                  [0, 0, 1]])
    return R, np.array([0.3, -0.2, 0.7])


def _polygon_curves(points, R, off, samples=9):
    t = np.linspace(0, 1, samples)[:, None]
    p3 = [R @ np.array([x, y, 0.0]) + off for x, y in points]
    return [(1 - t) * a + t * b for a, b in zip(p3, p3[1:] + p3[:1])]


def _face(tilt=0.4, hole=True):
    R, off = _frame(tilt)
    curves = _polygon_curves(L_OUTLINE, R, off)
    boundary = [[(i, True) for i in range(len(curves))]]
    if hole:
        n = len(curves)
        curves += _polygon_curves(WINDOW, R, off)
        boundary.append([(n + i, True) for i in range(4)])
    return curves, boundary, R @ [0, 0, 1.0], off


@pytest.mark.parametrize("hole", [False, True])
def test_flat_face_is_its_plane_region(hole):
    curves, boundary, normal, off = _face(hole=hole)
    res = surface_boundaries(curves, [boundary])
    assert res.report["flat_patches"] == res.report["flat_meshed"] == 1
    diag = res.control_net.diagonal
    V, F = res.vertices, res.faces
    assert np.abs((V - off) @ normal).max() <= 1e-9 * diag
    cross = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    # no fold: every triangle faces the way the outer loop turns (counter-clockwise here)
    assert (cross @ normal > 0).all()
    want = TRUE_AREA if hole else 4.0
    assert 0.5 * np.linalg.norm(cross, axis=1).sum() == pytest.approx(want, rel=1e-9)
    # the boundary of the mesh is exactly the loops, at the curves' output vertices
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, count = np.unique(e, axis=0, return_counts=True)
    assert count.max() == 2
    n_boundary = (count == 1).sum()
    # the outline at the output vertices of its curves; the window, in no surfaced loop,
    # at its own points
    chains = surface_loops(curves, boundary[:1]).curve_vertices
    assert n_boundary == sum(len(chains[c]) - 1 for c, _ in boundary[0]) + sum(
        len(curves[c]) - 1 for lp in boundary[1:] for c, _ in lp)


def test_flat_face_follows_the_edge_length():
    curves, boundary, _, _ = _face(hole=False)
    coarse = surface_boundaries(curves, [boundary], edge_length=0.02)
    fine = surface_boundaries(curves, [boundary], edge_length=0.005)
    assert len(fine.faces) > 4 * len(coarse.faces)
    diag = fine.control_net.diagonal
    V, F = fine.vertices, fine.faces
    lengths = np.linalg.norm(V[F] - V[np.roll(F, 1, axis=1)], axis=2)
    assert 0.3 * 0.005 * diag < np.median(lengths) < 1.5 * 0.005 * diag


def test_flat_faces_stay_under_the_face_budget():
    curves, boundary, _, _ = _face(hole=True)
    res = surface_loops(curves, [boundary[0]], subdiv=4)
    flat, normals, offsets = flat_planes(curves, [boundary])
    args = (res.vertices, res.faces, np.zeros(len(res.faces), np.int64), res.curve_vertices,
            curves, [boundary], flat, normals, offsets)
    free = mesh_flat(*args, edge_length=0.002)[1]
    capped = mesh_flat(*args, edge_length=0.002, max_faces=5000)[1]
    assert len(free) > 20_000
    assert 2500 < len(capped) < 6000


def test_a_curve_without_output_vertices_uses_its_own_points():
    # the window's curves are in no surfaced loop: the CDT takes their polyline points
    curves, boundary, normal, off = _face(hole=True)
    res = surface_loops(curves, [boundary[0]])
    assert all(res.curve_vertices[c] is None for c, _ in boundary[1])
    flat, normals, offsets = flat_planes(curves, [boundary])
    V, F, FP, meshed = mesh_flat(res.vertices, res.faces, np.zeros(len(res.faces), np.int64),
                                 res.curve_vertices, curves, [boundary], flat, normals, offsets)
    assert meshed.tolist() == [True]
    cross = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    assert 0.5 * np.linalg.norm(cross, axis=1).sum() == pytest.approx(TRUE_AREA, rel=1e-9)
    window = np.concatenate(curves[-4:])
    assert np.min(np.linalg.norm(V[:, None] - window[None], axis=2), axis=0).max() < 1e-12


@pytest.mark.parametrize("hole", [
    # a "hole" with a corner on the outline's corner (its own point there, a second vertex
    # at the same place): Triangle merges the two and loses a segment
    [(0, 0), (0.2, 0.5), (0.5, 0.2)],
    # a "hole" poking out through the outline: the loops cross and Triangle splits the
    # segments there
    [(2.5, 0.5), (3.5, 0.3), (3.5, 0.7)],
], ids=["loops touch", "loops cross"])
def test_a_patch_whose_loops_touch_or_cross_keeps_its_faces(hole):
    R, off = _frame(0.4)
    curves, boundary, _, _ = _face(hole=False)
    n = len(curves)
    curves += _polygon_curves(hole, R, off)
    boundary.append([(n + i, True) for i in range(3)])
    res = surface_loops(curves, boundary[:1])
    flat, normals, offsets = flat_planes(curves, [boundary])
    fp = np.zeros(len(res.faces), np.int64)
    V, F, FP, meshed = mesh_flat(res.vertices, res.faces, fp, res.curve_vertices, curves,
                                 [boundary], flat, normals, offsets)
    assert flat.tolist() == [True] and meshed.tolist() == [False]
    np.testing.assert_array_equal(np.sort(V[F].reshape(-1, 3), axis=0),
                                  np.sort(res.vertices[res.faces].reshape(-1, 3), axis=0))
