"""Tests of curvenet.cycles and curvenet._gf2 against oracles.

Oracles: galois (GF(2) rank and solves), networkx (simple cycles, components),
the cycle-rank formula E - V + C, the true faces of the analytic shapes, and a
brute-force greedy over every simple cycle of small graphs (Theorem 1).
"""

from __future__ import annotations


import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from curvenet import shapes
from curvenet._gf2 import (GF2Eliminator, bitset_solve, edge_mask, gf2_rank, gf2_solve,
                           mask_edges)
from curvenet.cycles import (SEPARATING_EPS, CandidatePool, cycle_to_loop, find_patches,
                             orient_patches)
from curvenet.errors import InvalidParameterError, NetworkError
from curvenet.network import CurveNetwork


# --------------------------------------------------------------------------- helpers
def random_network(seed, n=9, m=16, *, loops=True, parallel=True) -> CurveNetwork:
    """Random multigraph with straight (or bent, for parallel/loop) curves at random points."""
    rng = np.random.default_rng(seed)
    pos = rng.normal(size=(n, 3))
    net = CurveNetwork(pos)
    for _ in range(m):
        u, v = (int(x) for x in rng.integers(0, n, size=2))
        if u == v and not loops:
            continue
        bend = rng.normal(scale=0.3, size=3)
        if u == v:
            c = [pos[u], pos[u] + bend, pos[u] + np.roll(bend, 1), pos[u]]
        else:
            c = [pos[u], (pos[u] + pos[v]) / 2 + bend, pos[v]]
        net.add_edge(u, v, c)
        if parallel and rng.random() < 0.1 and u != v:
            net.add_edge(v, u, [pos[v], (pos[u] + pos[v]) / 2 - bend, pos[u]])
    return net


def random_simple_network(seed, n=9, m=16) -> CurveNetwork:
    """Random simple graph (no loops, no parallel curves) with straight curves."""
    rng = np.random.default_rng(seed)
    pos = rng.normal(size=(n, 3))
    net = CurveNetwork(pos)
    pairs = [(u, v) for u in range(n) for v in range(u + 1, n)]
    for j in rng.permutation(len(pairs))[:m]:
        u, v = pairs[j]
        net.add_edge(u, v, [pos[u], pos[v]])
    return net


def permuted(net: CurveNetwork, seed):
    """Same network with vertices relabelled and edges reordered (and some reversed)."""
    rng = np.random.default_rng(seed)
    nv, ne = net.number_of_vertices, net.number_of_edges
    vperm = rng.permutation(nv)            # old vertex i -> new vperm[i]
    eorder = rng.permutation(ne)           # new edge j is old edge eorder[j]
    pos = np.empty_like(net.positions)
    pos[vperm] = net.positions
    out = CurveNetwork(pos)
    for old in eorder:
        e = net.edges[old]
        if rng.random() < 0.5:
            out.add_edge(int(vperm[e.v]), int(vperm[e.u]), e.curve[::-1], label=e.label)
        else:
            out.add_edge(int(vperm[e.u]), int(vperm[e.v]), e.curve, label=e.label)
    return out, eorder


def true_faces(shape):
    return {tuple(sorted(e for e, _ in f)) for f in shape.faces}


def found(ps):
    return {p.edges for p in ps.patches}


# --------------------------------------------------------------------------- GF(2)
@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(min_value=0, max_value=(1 << 24) - 1), max_size=30))
def test_eliminator_rank_matches_galois(masks):
    el = GF2Eliminator()
    flags = [el.add(m) for m in masks]
    kept = [m for m, f in zip(masks, flags) if f]
    assert el.rank == len(kept) == gf2_rank(masks, 24) == gf2_rank(kept, 24)
    # add() says False exactly for vectors in the span of the earlier kept ones
    sols, _ = gf2_solve(kept, [m for m, f in zip(masks, flags) if not f], 24)
    assert all(x is not None for x in sols)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(min_value=0, max_value=(1 << 16) - 1), min_size=1, max_size=20),
       st.lists(st.integers(min_value=0, max_value=(1 << 16) - 1), min_size=1, max_size=10))
def test_bitset_solve_matches_galois(basis, targets):
    for solver in (lambda: bitset_solve(basis, targets), lambda: gf2_solve(basis, targets, 16)):
        sols, null = solver()
        for t, x in zip(targets, sols):
            if x is not None:
                acc = 0
                for i in mask_edges(x):
                    acc ^= basis[i]
                assert acc == t
        for v in null:
            acc = 0
            for i in mask_edges(v):
                acc ^= basis[i]
            assert acc == 0 and v != 0
        assert len(null) == len(basis) - gf2_rank(basis, 16)
    a, _ = bitset_solve(basis, targets)
    b, _ = gf2_solve(basis, targets, 16)
    assert [x is None for x in a] == [x is None for x in b]


def test_edge_mask_roundtrip():
    assert mask_edges(edge_mask([5, 0, 64, 3])) == (0, 3, 5, 64)


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
    ps = find_patches(net, close="auto")
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


# --------------------------------------------------------------------------- Algorithm 1 oracle
def _brute_force_basis_weights(net: CurveNetwork):
    """Sorted k values of a minimum-weight basis: greedy over all simple cycles (galois rank)."""
    g = nx.Graph()
    g.add_nodes_from(range(net.number_of_vertices))
    eid = {}
    for i, e in enumerate(net.edges):
        g.add_edge(e.u, e.v)
        eid[frozenset((e.u, e.v))] = i
    cycles = []
    for cyc in nx.simple_cycles(g):
        es = [eid[frozenset((a, b))] for a, b in zip(cyc, cyc[1:] + cyc[:1])]
        h = g.copy()
        h.remove_nodes_from(cyc)
        sep = nx.number_connected_components(h) > nx.number_connected_components(g)
        cycles.append((len(es) + (2 + SEPARATING_EPS) * sep, edge_mask(es)))
    cycles.sort(key=lambda t: t[0])
    chosen, masks = [], []
    for k, m in cycles:
        if gf2_rank(masks + [m], net.number_of_edges) > len(masks):
            masks.append(m)
            chosen.append(k)
    return sorted(chosen), len(cycles)


@pytest.mark.parametrize("seed", range(6))
def test_greedy_weight_is_minimum(seed):
    """Theorem 1: the greedy basis has the minimum multiset of k (simple graphs)."""
    keep = random_simple_network(seed, n=8, m=14)
    ps = find_patches(keep, close="none", genus_aware=False)
    pool = CandidatePool(keep)
    ks = sorted(len(p.edges) + (2 + SEPARATING_EPS) * pool.is_separating(
        {v for e in p.edges for v in (keep.edges[e].u, keep.edges[e].v)}) for p in ps.patches)
    oracle, n_cycles = _brute_force_basis_weights(keep)
    assert ks == oracle


@pytest.mark.parametrize("seed", range(4))
def test_enumeration_counts_match_networkx(seed):
    net = random_simple_network(seed, n=9, m=18)
    g = nx.Graph()
    for e in net.edges:
        g.add_edge(e.u, e.v)
    lengths = [len(c) for c in nx.simple_cycles(g)]
    for engine in ("python", "numba"):
        pool = CandidatePool(net, engine=engine)
        for L in range(1, 10):
            edges, verts = pool.raw_cycles_of_length(L)
            assert len(edges) == lengths.count(L)
            assert len({frozenset(r) for r in edges.tolist()}) == len(edges)  # deduplicated
            for es, vs in zip(edges.tolist(), verts.tolist()):
                ends = {v for e in es for v in (net.edges[e].u, net.edges[e].v)}
                assert ends == set(vs) and len(vs) == L


@pytest.mark.parametrize("shape", [shapes.grid_box(3), shapes.two_boxes(), shapes.torus()])
def test_numba_and_python_engines_agree(shape):
    net = shape.network
    for L in range(2, 9):
        a = CandidatePool(net, engine="python").raw_cycles_of_length(L)[0]
        b = CandidatePool(net, engine="numba").raw_cycles_of_length(L)[0]
        assert sorted(map(sorted, a.tolist())) == sorted(map(sorted, b.tolist()))
    pa = find_patches(net, engine="python")
    pb = find_patches(net, engine="numba")
    assert found(pa) == found(pb)


def test_multi_edges_and_loops_are_cycles():
    pos = np.array([[0.0, 0, 0], [1, 0, 0]])
    net = CurveNetwork(pos)
    net.add_edge(0, 1, [[0, 0, 0], [0.5, 0.2, 0], [1, 0, 0]])
    net.add_edge(0, 1, [[0, 0, 0], [0.5, -0.2, 0], [1, 0, 0]])
    net.add_edge(1, 1, [[1, 0, 0], [1.2, 0.1, 0], [1.2, -0.1, 0], [1, 0, 0]])
    ps = find_patches(net, close="none")
    assert found(ps) == {(0, 1), (2,)}
    assert ps.report["candidates"]["1"]["total"] == 1
    assert ps.report["candidates"]["2"]["total"] == 1


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


# --------------------------------------------------------------------------- loops and orientation
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


# --------------------------------------------------------------------------- public data
def test_runs_on_public_networks(data_dir):
    from curvenet.io import read_network_obj

    files = sorted((data_dir / "networks").glob("*/*.obj"))
    if not files:
        pytest.skip("no networks in the data folder")
    for f in files:
        net = read_network_obj(f)
        ps = find_patches(net)
        assert ps.report["full_rank"], f
        auto = [p for p in ps.patches if p.source == "auto"]
        assert len(auto) + len(ps.report["handle_cycles"]) == net.cycle_rank()
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
    ps = find_patches(shape.network)
    assert found(ps) == set(shape.face_edge_sets())
    assert len(ps.report["handle_cycles"]) == 2 and ps.report["order"] == "genus_aware"
    assert ps.report["manifold_defect"]["genus_aware"] == 0
    # the paper's weights alone pick planar handle rings over curved faces
    assert found(find_patches(shape.network, genus_aware=False)) != set(shape.face_edge_sets())
    # the basis itself stays a full basis
    basis = find_patches(shape.network, close="none")
    assert len(basis.patches) == shape.network.cycle_rank()
