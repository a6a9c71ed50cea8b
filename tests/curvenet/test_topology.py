"""Topology of meshes (curvenet.evaluate.topology) against shapes whose topology is known."""

import numpy as np
import pytest
import trimesh

from curvenet.evaluate.topology import format_topology, surface_topology


def _topology(mesh):
    return surface_topology(mesh.vertices, mesh.faces)


def test_closed_shapes_of_genus_0_and_1():
    for mesh, genus in ((trimesh.creation.icosphere(3), 0), (trimesh.creation.box(), 0),
                        (trimesh.creation.torus(1.0, 0.3), 1)):
        t = _topology(mesh)
        assert (t["pieces"], t["closed"], t["boundary_loops"], t["genus"]) == (1, 1, 0, genus)
        assert t["euler"] == mesh.euler_number == 2 - 2 * genus
        assert format_topology(t) == f"surface: 1 piece, closed, genus {genus}"


def test_open_tube_has_two_boundary_loops():
    tube = trimesh.creation.cylinder(0.5, 1.0, sections=24)
    keep = np.abs(tube.face_normals[:, 2]) < 0.5               # drop both caps
    t = surface_topology(tube.vertices, tube.faces[keep])
    assert (t["pieces"], t["closed"], t["boundary_loops"], t["genus"]) == (1, 0, 2, None)
    assert t["euler"] == 0
    assert format_topology(t) == "surface: 1 piece, 2 boundary loops, Euler characteristic 0"


def test_pieces_are_counted_apart_and_unused_vertices_ignored():
    sphere = trimesh.creation.icosphere(2)
    torus = trimesh.creation.torus(1.0, 0.3)
    both = trimesh.util.concatenate([sphere, torus.apply_translation([5.0, 0, 0])])
    V = np.vstack([both.vertices, np.zeros((7, 3))])         # vertices of no face
    t = surface_topology(V, both.faces)
    assert (t["pieces"], t["closed"], t["genus"], t["euler"]) == (2, 2, 1, 2)
    # one face of the sphere removed: one closed piece left, one loop of three edges
    F = np.vstack([sphere.faces[1:], torus.faces + len(sphere.vertices)])
    t = surface_topology(both.vertices, F)
    assert (t["pieces"], t["closed"], t["boundary_loops"], t["genus"]) == (2, 1, 1, 1)
    assert format_topology(t).startswith("surface: 2 pieces, 1 closed (genus 1), 1 boundary loop,")


def test_edges_in_three_faces_are_reported():
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1]], float)
    F = np.array([[0, 1, 2], [0, 1, 3], [0, 1, 4]])
    t = surface_topology(V, F)
    assert t["nonmanifold_edges"] == 1 and t["closed"] == 0 and t["pieces"] == 1
    assert format_topology(t).endswith(", 1 edge in three or more faces")


@pytest.mark.parametrize("faces", [np.zeros((0, 3), np.int64), []])
def test_no_faces(faces):
    t = surface_topology(np.zeros((4, 3)), faces)
    assert t["pieces"] == 0 and t["genus"] is None
    assert format_topology(t) == "surface: 0 pieces, 0 boundary loops, Euler characteristic 0"


def test_an_opening_at_the_neural_box_is_named():
    t = {"pieces": 1, "closed": 0, "boundary_loops": 2, "nonmanifold_edges": 0, "euler": 0,
         "genus": None, "open_at_box": 40}
    assert format_topology(t) == ("surface: 1 piece, 2 boundary loops, Euler characteristic 0"
                                  " (open where the neural field's zero set reaches its padded"
                                  " box; --closed-box keeps the surface inside)")
