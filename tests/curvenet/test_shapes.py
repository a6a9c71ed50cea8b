"""The analytic oracles must themselves be right: counts, Euler characteristic, orientation,
curves on the true surface."""

import numpy as np
import pytest
import trimesh

from curvenet.datasets import shapes
from curvenet.cycles.loops import signed_volume


@pytest.mark.parametrize("name", sorted(shapes.SHAPES))
def test_shape_is_consistent(name):
    s = shapes.SHAPES[name]()
    net = s.network
    # every loop is closed: the head of each edge is the tail of the next
    for loop in s.faces:
        ends = [(net.edges[e].u, net.edges[e].v)[:: 1 if f else -1] for e, f in loop]
        assert all(b == c for (_, b), (c, _) in zip(ends, ends[1:] + ends[:1]))
    # manifold edges are walked in opposite directions by their two faces
    use = {}
    for loop in s.faces:
        for e, f in loop:
            use.setdefault(e, []).append(f)
    assert all(v[0] != v[1] for v in use.values() if len(v) == 2)
    # Euler characteristic of the patch complex: 2 - 2g closed, 1 for a disk
    chi = net.number_of_vertices - net.number_of_edges + len(s.faces)
    if name == "two_boxes":
        assert chi == 3  # two spheres glued along a disk
    elif s.closed:
        assert chi == 2 - 2 * s.genus
    else:
        assert chi == 1
    if s.closed and name != "two_boxes":
        assert signed_volume(net, s.faces) > 0
    # curve samples lie on the reference surface (chord error of the reference only)
    ref = s.reference_mesh(5)
    pts = np.concatenate([e.curve for e in net.edges])
    _, dist, _ = trimesh.proximity.closest_point(ref, pts[::5])
    assert dist.max() < 1e-3 * np.linalg.norm(ref.extents)


def test_grid_box_counts():
    s = shapes.grid_box(4)
    assert (s.network.number_of_edges, len(s.faces)) == (192, 96)
    assert sum(e.label == "crease" for e in s.network.edges) == 48
    assert shapes.grid_box(9).network.number_of_edges == 972


def test_sketch_has_one_stroke_per_edge():
    s = shapes.box()
    sk = s.sketch()
    assert len(sk) == 12 and set(sk.labels) == {"crease"}


def test_elliptic_torus_sections_lie_on_their_tube_and_reference():
    """``torus_sections(aspect=...)``: the rings and meridians lie on the elliptic tube
    (half-width ``minor``, half-height ``minor * aspect``), and so does the reference."""
    from curvenet.datasets import sections
    s = sections.torus_sections(1.0, 0.2, heights=(0.0, 0.5), angles=(0, 100, 220),
                                aspect=2.0)

    def off(p):
        return np.abs(np.hypot((np.hypot(p[:, 0], p[:, 1]) - 1.0) / 0.2, p[:, 2] / 0.4) - 1.0)
    assert off(np.concatenate([e.curve for e in s.network.edges])).max() < 1e-3
    # each height plane gives two rings, each meridian one closed curve: 6 + 3 x 4 curves
    assert s.network.number_of_edges == 2 * 2 * 3 + 3 * 4
    assert np.median(off(s.reference_mesh(1).vertices)) < 0.02
    with pytest.raises(ValueError, match="aspect"):
        sections.torus_sections(aspect=0.0)


def test_tilted_torus_sections_lie_on_the_torus_and_their_planes():
    """``torus_sections(tilts=...)``: a plane tilted by 6 degrees still cuts the tube all
    round into two rings, which lie on the torus and in the tilted plane."""
    from curvenet.datasets import sections
    s = sections.torus_sections(1.0, 0.4, heights=(0.1,), angles=(0, 100, 200, 290),
                                tilts=[(6.0, 30.0)])
    p = np.concatenate([e.curve for e in s.network.edges])
    # on the torus to round-off: resampled points are put back on it, not left on chords
    assert np.abs(np.hypot(np.hypot(p[:, 0], p[:, 1]) - 1.0, p[:, 2]) - 0.4).max() < 1e-9
    t, d = np.radians(6.0), np.radians(30.0)
    n = np.array([np.sin(t) * np.cos(d), np.sin(t) * np.sin(d), np.cos(t)])
    ring = np.abs(p @ n - 0.1 * 0.4 * np.cos(t)) < 1e-6     # through (0, 0, 0.1 x 0.4)
    assert ring.sum() > 0.3 * len(p)              # the ring samples, in the plane
    assert s.network.number_of_edges == 2 * 4 + 4 * 2   # 2 rings in 4, 4 meridians in 2
    assert s.name.endswith(" t6")
    with pytest.raises(ValueError, match="tilts"):
        sections.torus_sections(heights=(0.0, 0.5), tilts=[(6.0, 30.0)])


def test_great_circles_in_general_position():
    """``great_circles(normals=...)``: k circles in general position cross in k (k - 1)
    junctions of four curves, and bound k (k - 1) + 2 faces."""
    from curvenet.datasets import sections
    normals = np.random.default_rng(7).normal(size=(5, 3))
    s = sections.great_circles(normals=normals)
    net = s.network
    assert (net.number_of_vertices, net.number_of_edges) == (20, 40)
    p = np.concatenate([e.curve for e in net.edges])
    assert np.abs(np.linalg.norm(p, axis=1) - 1.0).max() < 1e-3
    assert s.name == "sphere_5_circles"
