"""Tests of curvenet.cycles.loops: walking cycles, orienting patches, loop geometry.

Oracles: the analytic shapes' true face loops and orientations.
"""

from __future__ import annotations

import numpy as np
import pytest

from curvenet.datasets import shapes
from curvenet.cycles.find import find_patches
from curvenet.core.errors import NetworkError
from curvenet.cycles.loops import (cycle_to_loop, loop_points, newell_normal, orient_patches,
                            signed_volume)


def test_cycle_to_loop_walks_the_cycle():
    net = shapes.box().network
    for f in shapes.box().faces:
        ids = [e for e, _ in f]
        loop = cycle_to_loop(net, ids[::-1])
        assert loop[0] == (min(ids), True)
        ends = [(net.edges[e].u, net.edges[e].v)[::1 if fw else -1] for e, fw in loop]
        for (_, b), (c, _) in zip(ends, ends[1:] + ends[:1]):
            assert b == c


def test_cycle_to_loop_errors():
    net = shapes.two_boxes().network
    with pytest.raises(NetworkError):
        cycle_to_loop(net, [])
    with pytest.raises(NetworkError):
        cycle_to_loop(net, [0, 1])                      # open path
    with pytest.raises(NetworkError):
        cycle_to_loop(net, [0, 0, 1, 2, 3])             # repeated id
    with pytest.raises(NetworkError):
        cycle_to_loop(net, [0, 1, 2, 99])               # out of range
    with pytest.raises(NetworkError):
        cycle_to_loop(net, [0, 1, 2, 3, 8, 9, 10, 11])  # two disjoint loops
    with pytest.raises(NetworkError):
        # top face + upper sides + ...: vertex of degree 4 (figure eight through a vertex)
        cycle_to_loop(net, [0, 1, 2, 3, 4, 13, 12])


@pytest.mark.parametrize("name", ["box", "house", "latlong_sphere", "capped_cylinder",
                                  "grid_sheet", "torus"])
def test_orient_patches_matches_true_orientation(name):
    s = getattr(shapes, name)()
    loops = orient_patches(s.network, [[e for e, _ in f] for f in s.faces])
    for ours, truth in zip(loops, s.faces):
        assert set(ours) == set(truth) or (not s.closed and
                                           set(ours) == {(e, not d) for e, d in truth})
    # shared manifold edges are walked in opposite directions
    use: dict = {}
    for lp in loops:
        for e, d in lp:
            use.setdefault(e, []).append(d)
    assert all(len(v) == 1 or (len(v) == 2 and v[0] != v[1]) for v in use.values())


def test_orient_patches_after_find_patches_outward():
    s = shapes.grid_box(2)
    ps = find_patches(s.network)
    loops = orient_patches(s.network, ps.patches)
    truth = {frozenset(f) for f in s.faces}
    assert {frozenset(lp) for lp in loops} == truth


def test_newell_normal_and_signed_volume_of_a_box():
    """Oracle: a 2 x 3 x 4 box has volume 24; its outward face normals are the axes."""
    s = shapes.box(size=(2.0, 3.0, 4.0))
    net = s.network
    assert signed_volume(net, s.faces) == pytest.approx(24.0)
    flipped = [[(e, not d) for e, d in reversed(f)] for f in s.faces]
    assert signed_volume(net, flipped) == pytest.approx(-24.0)
    center = np.array([1.0, 1.5, 2.0])
    for f in s.faces:
        p = loop_points(net, f)
        assert len(p) == sum(len(net.edges[e].curve) - 1 for e, _ in f)
        n = newell_normal(net, f)
        assert np.sort(np.abs(n)) == pytest.approx([0, 0, 1], abs=1e-12)
        assert n @ (p.mean(axis=0) - center) > 0      # outward
