"""Periodic faces: a bore wall bounded by two circles and one seam walked twice."""

import numpy as np
import pytest

from curvenet.core.errors import NetworkError
from curvenet.cycles import find_patches
from curvenet.cycles.loops import cycle_to_loop, newell_normal, orient_boundaries, signed_volume
from curvenet.cycles.seams import seam_chains
from curvenet.model.network import CurveNetwork
from curvenet.model.patchset import PatchSet

from ._networks import bored_prism, seam_cylinder

SIDES = 6


def test_a_nut_bore_wall_is_one_face_walking_its_seam_twice():
    net = bored_prism(SIDES)
    ps = find_patches(net)
    seam, bottom, top = net.number_of_edges - 1, 3 * SIDES, 3 * SIDES + 1
    # 6 walls, top and bottom faces each with the bore as a hole, and the bore wall;
    # the circles' discs are gone (the wall continues through them)
    assert len(ps.patches) == SIDES + 3
    wall = ps.patches[-1]
    assert wall.edges == (bottom, top, seam, seam) and not wall.holes
    assert sorted(p.holes for p in ps.patches if p.holes) == [((bottom,),), ((top,),)]
    assert ps.report["seams"] == [{"face": SIDES + 2, "seam": [seam],
                                   "loops": [[bottom], [top]], "discs_dropped": 2}]
    assert [h["disc_kept"] for h in ps.report["holes"]] == [False, False]
    # every curve, the seam included, bounds two faces: a closed surface
    uses = np.zeros(net.number_of_edges, int)
    for p in ps.patches:
        np.add.at(uses, list(p.all_edges), 1)
    assert (uses == 2).all()


def test_without_seams_the_seam_stays_unused():
    ps = find_patches(bored_prism(SIDES), seams=False)
    assert ps.report["seams"] == [] and len(ps.patches) == SIDES + 4


def test_the_walk_is_loop_seam_loop_against_it_seam_back():
    net = bored_prism(SIDES)
    seam, bottom, top = net.number_of_edges - 1, 3 * SIDES, 3 * SIDES + 1
    walk = cycle_to_loop(net, [top, seam, bottom, seam])
    assert [e for e, _ in walk] == [bottom, seam, top, seam]
    assert walk[1][1] != walk[3][1]                          # the seam, there and back
    # the two circles walked in opposite senses: the two borders of a band
    assert newell_normal(net, walk[:1]) @ newell_normal(net, walk[2:3]) < 0
    with pytest.raises(NetworkError, match="more than twice"):
        cycle_to_loop(net, [top, seam, seam, seam, bottom])
    with pytest.raises(NetworkError, match="no seam face"):
        cycle_to_loop(net, [0, 1, 2, 3, 4, 5, seam, seam, top, bottom])


def test_a_closed_cylinder_keeps_its_caps():
    net = seam_cylinder()
    ps = find_patches(net)
    assert sorted(p.edges for p in ps.patches) == [(0,), (0, 1, 2, 2), (1,)]
    bounds = orient_boundaries(net, ps.patches)
    # closed, so oriented outward (the fan volume's sign; its size is a fan's)
    assert signed_volume(net, [lp for b in bounds for lp in b]) > 0


def test_a_blind_hole_gets_its_wall_and_keeps_its_floor():
    ps = find_patches(bored_prism(SIDES, through=False))
    floor = (3 * SIDES,)
    assert floor in {p.edges for p in ps.patches}            # the floor is no hole
    assert len(ps.report["seams"]) == 1


def test_a_chain_between_faces_that_meet_is_no_seam():
    # a curve from a top corner (on three face loops) to the top circle's junction
    net = bored_prism(SIDES, seam=False)
    s = np.linspace(0, 1, 9)[:, None]
    corner, circle = SIDES, 2 * SIDES + 1
    net.add_edge(corner, circle, (1 - s) * net.positions[corner] + s * net.positions[circle])
    ps = find_patches(net, seams=False)
    assert seam_chains(net, ps.patches) == []
    assert len(find_patches(net).patches) == len(ps.patches)


def test_a_seam_face_survives_patches_json(tmp_path):
    from curvenet.io.network import read_patches, write_patches
    net = bored_prism(SIDES)
    ps = find_patches(net)
    write_patches(tmp_path / "p.json", ps)
    back = read_patches(tmp_path / "p.json")
    assert [p.edges for p in back.patches] == [p.edges for p in ps.patches]
    assert isinstance(back, PatchSet)


def test_the_bore_is_surfaced_watertight_with_the_true_volume():
    from curvenet.pipeline import surface
    res = surface(bored_prism(SIDES), method="classical", subdiv=2)
    hexagon = 6 * 0.5 * np.sin(np.pi / 3)
    assert res.mesh.is_watertight
    # the walls are exact; the bore is polygonal between its curve vertices
    assert res.mesh.volume == pytest.approx((hexagon - np.pi * 0.25) * 0.8, rel=2e-3)
    assert res.diagnostics["classical"]["analytic"][-1]["kind"] == "cylinder"


@pytest.mark.parametrize("seed", range(12))
def test_seam_faces_never_add_a_third_patch_to_a_curve(seed):
    from ._networks import random_network
    net = random_network(seed, n=8, m=12)
    before, after = find_patches(net, seams=False), find_patches(net)

    def uses(ps):
        u = np.zeros(net.number_of_edges, int)
        for p in ps.patches:
            np.add.at(u, list(p.all_edges), 1)
        return u
    grew = uses(after) > np.maximum(uses(before), 2)
    assert not grew.any()
    for p in after.patches[len(after.patches) - len(after.report["seams"]):]:
        assert len(cycle_to_loop(net, p.edges)) == len(p.edges)


def test_two_loops_side_by_side_on_a_stem_are_not_the_ends_of_a_tube():
    # two leaves in one plane, hung on a stem: each a disc, the stem between them
    # unused, yet no tube runs from one to the other
    from curvenet.snap import snap
    from curvenet.model.sketch import Sketch
    t = np.linspace(0.0, 1.0, 31)[:, None]
    u = np.linspace(0.0, 2 * np.pi, 61)[:, None]
    stem = np.c_[0 * t, 0 * t, 3.0 * t]
    leaves = [np.c_[s * 0.6 * (1 - np.cos(u)), 0 * u, z + 0.15 * np.sin(u)]
              for s, z in ((1.0, 1.0), (-1.0, 1.6))]
    net = snap(Sketch([stem, *leaves], ["boundary"] * 3))
    ps = find_patches(net)
    assert ps.report["seams"] == []
    assert sorted(len(p.edges) for p in ps.patches) == [2, 2]


def _circle(r, z, n=33):
    t = np.linspace(0, 2 * np.pi, n)
    return np.c_[r * np.cos(t), r * np.sin(t), np.full(n, z)]


def test_a_cone_to_its_apex_is_one_face_walking_its_seam_twice():
    """A pointed cone: base circle, one seam line to the apex (a junction of that curve
    only). The cone face is the circle and the seam twice; the base a disc."""
    net = CurveNetwork(np.array([[1.0, 0, 0], [0.0, 0, 2]]))
    net.add_edge(0, 0, _circle(1.0, 0.0))
    net.add_edge(0, 1, np.linspace([1.0, 0, 0], [0.0, 0, 2], 9))
    edges = sorted(tuple(sorted(p.edges)) for p in find_patches(net).patches)
    assert edges == [(0,), (0, 1, 1)]


def test_walls_stacked_on_one_axis_replace_the_discs_between_them():
    """Cone, cylinder, cone along one axis (a chamfered bore, a shaft): three seam faces,
    the two circles between walls lose their discs (a curve of three patches otherwise)."""
    rz = [(1.0, 0.0), (1.2, 0.2), (1.2, 1.0), (1.0, 1.2)]
    net = CurveNetwork(np.array([[r, 0, z] for r, z in rz]))
    for k, (r, z) in enumerate(rz):
        net.add_edge(k, k, _circle(r, z))
    for k in range(3):
        net.add_edge(k, k + 1, np.linspace(net.positions[k], net.positions[k + 1], 5))
    ps = find_patches(net).patches
    uses = np.zeros(net.number_of_edges, int)
    for p in ps:
        np.add.at(uses, list(set(p.all_edges)), 1)
    walls = [p for p in ps if len(set(p.edges)) < len(p.edges)]
    assert len(walls) == 3 and len(ps) == 5 and uses.max() <= 2
