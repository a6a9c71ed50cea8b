"""Tests of curvenet.cycles (the patch finder) against oracles.

Oracles: the cycle-rank formula E - V + C and GF(2) rank (galois), the true
faces of the analytic shapes, invariance under relabelling, the public networks.
"""

from __future__ import annotations


import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from curvenet.datasets import shapes
from curvenet.cycles.gf2 import edge_mask, gf2_rank
from curvenet.cycles.find import cycle_to_loop, find_patches
from curvenet.core.errors import InvalidParameterError
from curvenet.model.network import CurveNetwork

from ._networks import found, permuted, random_network, true_faces


# --------------------------------------------------------------------------- invariants
@pytest.mark.parametrize("seed", range(12))
def test_basis_size_and_rank_on_random_graphs(seed):
    net = random_network(seed)
    ps = find_patches(net, close="none")
    r = net.cycle_rank()
    assert ps.report["rank"] == r
    assert len(ps.patches) == r and ps.report["full_rank"]
    assert gf2_rank([edge_mask(p.edges) for p in ps.patches], net.number_of_edges) == r
    for p in ps.patches:  # every patch is one simple closed loop
        assert len(cycle_to_loop(net, p.edges)) == len(p.edges)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 10_000), st.integers(3, 10), st.integers(2, 22))
def test_basis_invariants_hypothesis(seed, n, m):
    net = random_network(seed, n=n, m=m)
    ps = find_patches(net, close="auto", seams=False)     # the basis; seam faces come after
    r = net.cycle_rank()
    auto = [p.edges for p in ps.patches if p.source == "auto"] + ps.report["handle_cycles"]
    assert len(auto) == r
    assert gf2_rank([edge_mask(p) for p in auto], max(net.number_of_edges, 1)) == r


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("close", ["none", "auto"])
def test_unchanged_by_relabelling_and_reordering(seed, close):
    net = random_network(seed, n=10, m=20)
    net2, eorder = permuted(net, seed + 100)
    a = found(find_patches(net, close=close))
    b = {tuple(sorted(int(eorder[e]) for e in p.edges))
         for p in find_patches(net2, close=close).patches}
    assert a == b


def test_shape_unchanged_by_reordering():
    s = shapes.two_boxes()
    net2, eorder = permuted(s.network, 7)
    b = {tuple(sorted(int(eorder[e]) for e in p.edges)) for p in find_patches(net2).patches}
    assert b == true_faces(s)


# --------------------------------------------------------------------------- analytic shapes
@pytest.mark.parametrize("name", ["box", "l_prism", "house", "grid_box", "capped_cylinder",
                                  "latlong_sphere", "ellipsoid", "two_boxes"])
@pytest.mark.parametrize("tie_break", ["pca", "aabb"])
def test_closed_shapes_exact_faces(name, tie_break):
    ctor = {"grid_box": lambda: shapes.grid_box(3)}.get(name, getattr(shapes, name))
    s = ctor()
    ps = find_patches(s.network, tie_break=tie_break)
    assert found(ps) == true_faces(s)
    assert ps.report["full_rank"] and not ps.report["work_bound_hit"]
    # the solid-free basis is the true faces minus the closing ones
    basis = find_patches(s.network, close="none", tie_break=tie_break)
    assert found(basis) < true_faces(s)
    assert len(basis.patches) == s.network.cycle_rank()
    n_closing = len(s.faces) - s.network.cycle_rank()
    assert [p.source for p in ps.patches].count("closing") == n_closing


@pytest.mark.parametrize("shape", [shapes.grid_sheet(3), shapes.grid_sheet(5),
                                   shapes.saddle_grid(4)])
def test_open_sheets_exact_cells(shape):
    ps = find_patches(shape.network)
    assert found(ps) == true_faces(shape)
    assert ps.report["closing_added"] == []


def test_pca_tie_break_is_rotation_invariant():
    s = shapes.latlong_sphere()
    rng = np.random.default_rng(3)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    net = s.network
    rot = CurveNetwork(net.positions @ q.T)
    for e in net.edges:
        rot.add_edge(e.u, e.v, e.curve @ q.T, label=e.label)
    assert found(find_patches(rot, tie_break="pca")) == true_faces(s)
    assert found(find_patches(rot, tie_break="pca")) == found(find_patches(net, tie_break="pca"))


def test_grid_box_9_exact():
    s = shapes.grid_box(9)
    ps = find_patches(s.network)
    assert len(ps.patches) == 486 and found(ps) == true_faces(s)


# --------------------------------------------------------------------------- bounds and errors
def test_work_bound_reported_and_basis_still_full():
    net = shapes.grid_box(2).network
    ps = find_patches(net, max_work=5, close="none")
    assert ps.report["work_bound_hit"]
    assert ps.report["horton_candidates"] > 0
    assert len(ps.patches) == net.cycle_rank()
    assert gf2_rank([edge_mask(p.edges) for p in ps.patches], net.number_of_edges) \
        == net.cycle_rank()


def test_max_cycle_length_can_leave_basis_incomplete():
    ps = find_patches(shapes.house().network, max_cycle_length=4, close="none")
    assert not ps.report["full_rank"]
    # the house's five quads; the two pentagons need length 5
    assert len(ps.patches) == 5 and all(len(p.edges) == 4 for p in ps.patches)
    assert found(ps) < true_faces(shapes.house())


@pytest.mark.parametrize("kwargs", [{"close": "yes"}, {"tie_break": "obb"},
                                    {"max_cycle_length": 0}, {"max_work": 0},
                                    {"max_cycle_length": 2.5}])
def test_invalid_parameters(kwargs):
    with pytest.raises(InvalidParameterError):
        find_patches(shapes.box().network, **kwargs)
    with pytest.raises(InvalidParameterError):
        find_patches("not a network")


# --------------------------------------------------------------------------- public data
def test_runs_on_public_networks(data_dir):
    from curvenet.io.sketch import read_network_obj

    files = sorted((data_dir / "networks").glob("*/*.obj"))
    if not files:
        pytest.skip("no networks in the data folder")
    for f in files:
        net = read_network_obj(f)
        for p in find_patches(net).patches:       # whichever selection auto keeps
            cycle_to_loop(net, p.edges)
        ps = find_patches(net, mode="basis")      # the basis invariants
        assert ps.report["full_rank"], f
        auto = [p for p in ps.patches if p.source == "auto"]
        # a basis cycle that became a hole of the face around it, its disc dropped
        absorbed = [h for h in ps.report["holes"] if not h["disc_kept"] and h["source"] == "auto"]
        assert len(auto) + len(ps.report["handle_cycles"]) + len(absorbed) == net.cycle_rank()
        for p in ps.patches:
            cycle_to_loop(net, p.edges)


def test_tree_and_empty_networks_have_no_patches():
    empty = CurveNetwork(np.zeros((0, 3)))
    ps = find_patches(empty)
    assert ps.patches == [] and ps.report["rank"] == 0 and ps.report["full_rank"]
    tree = CurveNetwork(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]))
    tree.add_edge(0, 1, [[0, 0, 0], [1, 0, 0]])
    tree.add_edge(0, 2, [[0, 0, 0], [0, 1, 0]])
    ps = find_patches(tree)
    assert ps.patches == [] and ps.report["rank"] == 0


@pytest.mark.parametrize("shape", [shapes.torus(), shapes.torus(n_u=8, n_v=6),
                                   shapes.torus(n_u=5, n_v=4, minor=0.6)])
def test_torus_gives_exactly_its_faces(shape):
    """Genus 1: the two handle rings complete the basis but are not patches.

    (A ring shorter than the faces, e.g. 3 curves around a tube of 4-sided
    faces, still wins on k alone; that case is out of reach of a tie-break.)"""
    assert found(find_patches(shape.network)) == set(shape.face_edge_sets())
    ps = find_patches(shape.network, mode="basis")
    assert found(ps) == set(shape.face_edge_sets())
    assert len(ps.report["handle_cycles"]) == 2 and ps.report["order"] == "genus_aware"
    assert ps.report["manifold_defect"]["genus_aware"] == 0
    # the paper's weights alone pick planar handle rings over curved faces
    paper = find_patches(shape.network, mode="basis", genus_aware=False)
    assert found(paper) != set(shape.face_edge_sets())
    # the basis itself stays a full basis
    basis = find_patches(shape.network, mode="basis", close="none")
    assert len(basis.patches) == shape.network.cycle_rank()
