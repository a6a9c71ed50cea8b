"""Tests of curvenet.cycles.candidates: cycle enumeration against networkx, the pool's record.

Oracles: networkx (simple cycles), the python search against the numba kernel.
"""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest

from curvenet.datasets import shapes
from curvenet.cycles.candidates import CandidatePool
from curvenet.cycles.find import find_patches
from curvenet.model.network import CurveNetwork

from ._networks import found, random_simple_network


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


def test_pool_enumerates_each_length_once_and_records_it():
    net = shapes.grid_box(2).network
    pool = CandidatePool(net, engine="python")
    a = pool.cycles_of_length(4)
    work = pool.work
    b = pool.cycles_of_length(4)
    assert pool.work == work and a is not b           # not searched again
    assert [c.edges for c in a] == [c.edges for c in b]
    assert len(a) > 0 and pool.all_candidates == sorted(a, key=lambda c: (c.length, c.geo))
    with pytest.raises(AttributeError):
        pool.all_candidates = []                      # nobody outside writes the record
    # the record's order does not depend on the enumeration kernel
    other = CandidatePool(net, engine="numba")
    other.cycles_of_length(4)
    assert [c.edges for c in other.all_candidates] == [c.edges for c in pool.all_candidates]


def test_horton_candidates_skip_enumerated_cycles():
    net = shapes.grid_box(2).network
    horton = {c.edges for c in CandidatePool(net, engine="python").horton_candidates()}
    pool = CandidatePool(net, engine="python")
    for L in range(1, 5):
        pool.cycles_of_length(L)
    known = {c.edges for c in pool.all_candidates}
    extra = pool.horton_candidates()
    assert {c.edges for c in extra} == horton - known and extra
    assert {c.edges for c in pool.all_candidates} == known | horton
    assert len(pool.all_candidates) == len(known) + len(extra)
