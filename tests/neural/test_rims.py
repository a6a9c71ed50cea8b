"""The zero set closed flat where it leaves the strokes' bounding box through a drawn rim."""

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

import curvenet
from curvenet.datasets.sections import great_circles
from curvenet.datasets.shapes import capped_cylinder
from curvenet.evaluate.topology import format_topology
from curvenet.model import Sketch
from curvenet.neural.extract import marching_cubes_world
from curvenet.neural.parts import fit_parts
from curvenet.neural.rims import clamp_to, close_rims, strokes_box

from ._metrics import fscore

N, H = 48, 0.06
ORIGIN = np.full(3, -1.41)
AXIS = ORIGIN[0] + H * np.arange(N)
X, Y, Z = np.meshgrid(AXIS, AXIS, AXIS, indexing="ij")
T = np.linspace(0.0, 2.0 * np.pi, 200)


def test_an_endless_tube_closes_flat_at_its_two_rims_and_nowhere_else():
    tube = (np.hypot(X, Y) - 0.6).astype(np.float32)
    rims = [np.c_[0.6 * np.cos(T), 0.6 * np.sin(T), np.full_like(T, z)] for z in (-0.7, 0.5)]
    f, lo, hi = close_rims(tube, ORIGIN, H, strokes_box(rims), rims, 0.5)
    assert lo.tolist() == [-np.inf, -np.inf, -0.7] and hi.tolist() == [np.inf, np.inf, 0.5]
    V, F = marching_cubes_world(f, ORIGIN, H)
    mesh = trimesh.Trimesh(V, F)
    assert mesh.is_watertight and mesh.euler_number == 2
    assert V[:, 2].min() == pytest.approx(-0.7, abs=H)
    assert V[:, 2].max() == pytest.approx(0.5, abs=H)
    side = np.abs(V[:, 2] - (-0.1)) < 0.4                       # the tube between, untouched
    assert np.abs(np.hypot(V[side, 0], V[side, 1]) - 0.6).max() < 0.1 * H
    assert f[0, 0, 0] == tube[0, 0, 0]                  # f's scale kept away from the surface


def test_a_sphere_whose_strokes_miss_its_poles_is_not_clipped():
    # three great circles turned so that none reaches the sphere's extremes: the strokes'
    # box is smaller than the sphere, whose zero set crosses each side along a circle
    # that no stroke follows
    R = Rotation.from_euler("xyz", [45, 20, 45], degrees=True).as_matrix()
    strokes = [e.curve @ R.T for e in great_circles(3).network.edges]
    lo_s, hi_s = strokes_box(strokes)
    assert (hi_s < 0.95).all() and (lo_s > -0.95).all()
    sphere = (np.sqrt(X ** 2 + Y ** 2 + Z ** 2) - 1.0).astype(np.float32)
    f, lo, hi = close_rims(sphere, ORIGIN, H, (lo_s, hi_s), strokes, 0.5)
    assert np.isinf(lo).all() and np.isinf(hi).all() and f is sphere


def test_a_flat_sketch_keeps_its_surface():
    # one circle: the box has no depth along z, and closing both of its z sides (which
    # the sphere crosses along the circle itself) would leave no surface
    equator = [np.c_[np.cos(T), np.sin(T), np.zeros_like(T)]]
    sphere = (np.sqrt(X ** 2 + Y ** 2 + Z ** 2) - 1.0).astype(np.float32)
    f, lo, hi = close_rims(sphere, ORIGIN, H, strokes_box(equator), equator, 0.5)
    assert f is sphere and np.isinf(lo).all() and np.isinf(hi).all()


def test_share_zero_closes_nothing():
    tube = (np.hypot(X, Y) - 0.6).astype(np.float32)
    rims = [np.c_[0.6 * np.cos(T), 0.6 * np.sin(T), np.full_like(T, z)] for z in (-0.7, 0.5)]
    f, lo, hi = close_rims(tube, ORIGIN, H, strokes_box(rims), rims, 0.0)
    assert f is tube and np.isinf(lo).all() and np.isinf(hi).all()


def test_clamp_puts_vertices_back_on_the_closed_planes_only():
    V = np.array([[2.0, -3.0, 0.9], [0.0, 0.0, -2.0]])
    lo, hi = np.array([-np.inf, -np.inf, -1.0]), np.array([np.inf, np.inf, 0.5])
    assert clamp_to(V, lo, hi).tolist() == [[2.0, -3.0, 0.5], [0.0, 0.0, -1.0]]
    assert clamp_to(V, np.full(3, -np.inf), np.full(3, np.inf)) is V


def test_parts_close_rims_on_the_whole_sketch_box(monkeypatch):
    import curvenet.neural.flow as flow
    from curvenet.core.result import MeshResult
    boxes = []

    def fake(strokes, labels=None, **kw):
        boxes.append(np.asarray(kw["box"]).tolist())
        return MeshResult(np.vstack(strokes)[:3], [[0, 1, 2]], {"interrupted": False})

    monkeypatch.setattr(flow, "fit_flow_surface", fake)
    balls = [e.curve for e in great_circles(3).network.edges]
    strokes = balls + [c * 0.5 + [3.0, 0, 0] for c in balls]
    fit_parts(strokes, quality="draft")
    whole = [np.vstack(strokes).min(axis=0).tolist(), np.vstack(strokes).max(axis=0).tolist()]
    assert boxes == [whole, whole]


def test_a_cylinder_drawn_by_its_rims_and_rulings_is_capped_not_a_tube():
    # the true shape is the capped cylinder; without the rims (rims=0) the draft fit runs
    # on past both rim circles into the box's walls, an open tube
    shape = capped_cylinder(0.5, 1.5, n_around=4, n_height=1)
    curves = [e.curve for e in shape.network.edges]
    ref = shape.reference_mesh(5)
    scores = {}
    for over in ({}, {"rims": 0.0}):
        res = curvenet.surface(Sketch(strokes=curves), method="neural", quality="draft",
                               neural_options=over)
        V, F = res.mesh.vertices, res.mesh.faces
        scores[bool(over)] = fscore(V, F, ref.vertices, ref.faces)
        closed = trimesh.Trimesh(V, F).is_watertight
        topology = res.diagnostics["topology"]
        if over:
            assert not closed and V[:, 2].max() > 1.6 and "rims_closed" not in topology
        else:
            assert closed and topology["rims_closed"] >= 2
            assert "rims on the strokes' bounding box" in format_topology(topology)
            assert -0.01 < V[:, 2].min() and V[:, 2].max() < 1.51
    assert scores[False][0] > scores[True][0] + 0.1          # F-score at 1%
    assert scores[False][1] < 0.5 * scores[True][1]          # Chamfer distance
