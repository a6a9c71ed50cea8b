"""Marching cubes in world coordinates, component cleanup and the boundary cut."""

import numpy as np
import pytest
import trimesh

from curvenet.neural.extract import (LONE_NODE_AREA, cut_along_boundary, drop_redundant_bubbles,
                                     edges_at_walls,
                                     face_components, keep_supported_components,
                                     marching_cubes_world)


def _sphere_grid(n=40, r=0.3):
    c = (np.arange(n) + 0.5) / n
    X, Y, Z = np.meshgrid(c, c, c, indexing="ij")
    return np.sqrt((X - 0.5) ** 2 + (Y - 0.5) ** 2 + (Z - 0.5) ** 2) - r


def test_marching_cubes_world_coordinates_and_orientation():
    n, r = 40, 0.3
    origin = np.array([10.0, -2.0, 3.0])
    spacing = 2.0 / n
    V, F = marching_cubes_world(_sphere_grid(n, r), origin, spacing)
    centre = origin + spacing * (n - 1) / 2          # node (i + 0.5)/n = 0.5 <=> i = (n-1)/2
    rad = np.linalg.norm(V - centre, axis=1)
    # world radius = r * n * spacing; marching cubes on a 40^3 SDF is within ~1% of a cell
    assert np.abs(rad - r * n * spacing).max() < 0.05 * spacing * n * r
    m = trimesh.Trimesh(V, F, process=False)
    assert m.volume > 0                                # normals along grad f: outwards
    assert m.is_watertight and m.euler_number == 2


def test_no_crossing_gives_empty_mesh():
    V, F = marching_cubes_world(np.ones((8, 8, 8)), np.zeros(3), 1.0)
    assert V.shape == (0, 3) and F.shape == (0, 3)


def _unit_sphere_and_ball(radius, x, subdivisions=2):
    """The unit icosphere and a ball of ``radius`` centred at ``(x, 0, 0)``: the sphere's
    face count and the two pieces' ``(V, F)``."""
    a = trimesh.creation.icosphere(2, radius=1.0)
    b = trimesh.creation.icosphere(subdivisions, radius=radius)
    b.apply_translation([x, 0, 0])
    V = np.vstack([a.vertices, b.vertices])
    return len(a.faces), V, np.vstack([a.faces, b.faces + len(a.vertices)])


def test_keep_supported_components_drops_far_piece():
    n_sphere, V, F = _unit_sphere_and_ball(0.5, 5.0)
    assert len(np.unique(face_components(F, len(V)))) == 2
    t = np.linspace(0, 2 * np.pi, 50)
    stroke = np.c_[np.cos(t), np.sin(t), 0 * t]
    V2, F2 = keep_supported_components(V, F, [stroke], 0.05)
    assert len(F2) == n_sphere and np.abs(np.linalg.norm(V2, axis=1) - 1).max() < 1e-9


def test_specks_under_one_cell_face_are_dropped_even_on_a_stroke():
    # a ball of radius 0.02 on the stroke (area 0.005) goes when the cell is 0.1 (face
    # 0.01) and stays when it is 0.05; a lone piece is never dropped for its size
    n_sphere, V, F = _unit_sphere_and_ball(0.02, 1.5, subdivisions=1)
    stroke = np.array([[1.0, 0, 0], [1.5, 0, 0]])
    assert len(keep_supported_components(V, F, [stroke], 0.05, 0.05 ** 2)[1]) == len(F)
    V2, F2 = keep_supported_components(V, F, [stroke], 0.05, 0.1 ** 2)
    assert len(F2) == n_sphere and np.abs(np.linalg.norm(V2, axis=1) - 1).max() < 1e-9
    speck = F[n_sphere:] - F[n_sphere:].min()
    V3, F3 = keep_supported_components(V[F[n_sphere:].min():], speck, [stroke], 0.05, 1.0)
    assert len(F3) == len(speck)


@pytest.mark.parametrize("depth", [1.0, 1e6])
def test_lone_node_zero_set_is_within_its_area_bound(depth):
    # one node far below zero among positive ones: the octahedron of LONE_NODE_AREA;
    # just below zero, a smaller one
    from curvenet.core.geometry import face_normals_areas
    f = np.ones((7, 7, 7))
    f[3, 3, 3] = -depth
    V, F = marching_cubes_world(f, np.zeros(3), 0.5)
    area = face_normals_areas(V, F)[1].sum() / 0.5 ** 2
    assert len(np.unique(face_components(F, len(V)))) == 1
    assert area <= LONE_NODE_AREA * (1 + 1e-9)
    assert area > 0.99 * LONE_NODE_AREA if depth > 1 else area < 0.5 * LONE_NODE_AREA


def test_bubbles_whose_strokes_the_surface_carries_are_dropped_a_drawn_part_stays():
    """A unit sphere with great-circle strokes, a bubble inside it touching a stroke, one
    beside it, and a small ball drawn with a stroke of its own: the two bubbles go, the
    ball stays, and every stroke keeps a surface within the tolerance."""
    from curvenet.core.fidelity import sketch_fidelity
    t = np.linspace(0, 2 * np.pi, 200)
    strokes = [np.c_[np.cos(t), np.sin(t), 0 * t], np.c_[np.cos(t), 0 * t, np.sin(t)],
               np.c_[0.1 * np.cos(t) + 3, 0.1 * np.sin(t), 0 * t]]
    pieces = [trimesh.creation.icosphere(3, radius=1.0)]
    for radius, centre in ((0.03, (0.96, 0, 0)), (0.02, (0, 1.03, 0)), (0.1, (3, 0, 0))):
        s = trimesh.creation.icosphere(2, radius=radius)
        s.apply_translation(centre)
        pieces.append(s)
    V = np.vstack([p.vertices for p in pieces])
    F = np.vstack([p.faces + sum(len(q.vertices) for q in pieces[:i])
                   for i, p in enumerate(pieces)])
    V2, F2, dropped = drop_redundant_bubbles(V, F, strokes, 0.05)
    assert dropped == 2 and len(np.unique(face_components(F2, len(V2)))) == 2
    assert np.isclose(V2[:, 0].max(), 3.1) and np.abs(V2).max() <= 3.1 + 1e-9
    before, after = (sketch_fidelity(m, strokes)["surface"] for m in ((V, F), (V2, F2)))
    assert after == before == 1.0
    # an open piece is never dropped, nor the largest
    assert drop_redundant_bubbles(V, F[:-1], strokes, 0.05)[2] == 2
    one = pieces[0]
    assert drop_redundant_bubbles(one.vertices, one.faces, strokes, 0.05)[2] == 0


def test_cut_removes_unsupported_cap_beyond_boundary_loop():
    m = trimesh.creation.icosphere(4, radius=1.0)
    t = np.linspace(0, 2 * np.pi, 200)
    equator = np.c_[np.cos(t), np.sin(t), 0 * t]
    s = np.linspace(0.2, np.pi / 2 - 0.2, 50)
    arc = np.c_[np.cos(s), 0 * s, np.sin(s)]            # a flow line on the upper half
    V, F = cut_along_boundary(m.vertices, m.faces, [equator], [arc], band=0.05)
    assert V[:, 2].min() > -0.06                        # lower cap gone (up to the band)
    assert V[:, 2].max() > 0.99                          # upper half kept
    # nothing is cut when every stroke is a boundary stroke, or when no piece is unsupported
    V1, F1 = cut_along_boundary(m.vertices, m.faces, [equator], [], band=0.05)
    assert len(F1) == len(m.faces)
    V2, F2 = cut_along_boundary(m.vertices, m.faces, [arc], [equator], band=0.05)
    assert len(F2) == len(m.faces)


def test_edges_at_walls_counts_the_openings_marching_cubes_leaves_at_the_grid_edge():
    """A sphere's zero set cut off by the grid's walls is open there; a sphere inside the
    grid is closed, and a tube cut open at its ends far from the walls has no edge there."""
    n, h = 33, 1.0 / 32
    x = np.linspace(0.0, 1.0, n)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    for centre, radius, expect_open in (((0.5, 0.5, 0.5), 0.3, False),
                                        ((0.5, 0.5, 0.9), 0.3, True)):
        f = np.sqrt((X - centre[0]) ** 2 + (Y - centre[1]) ** 2 + (Z - centre[2]) ** 2) - radius
        V, F = marching_cubes_world(f, np.zeros(3), h)
        count = edges_at_walls(V, F, np.zeros(3), h, n)
        assert (count > 0) == expect_open, count
    tube = trimesh.creation.cylinder(0.2, 0.4, sections=32)
    tube.apply_translation([0.5, 0.5, 0.5])
    keep = np.abs(tube.face_normals[:, 2]) < 0.5
    assert edges_at_walls(tube.vertices, tube.faces[keep], np.zeros(3), h, n) == 0
