"""Tests of curvenet.cycles.basis: the greedy basis against a brute-force greedy (Theorem 1).

Oracle: a greedy over every simple cycle of small graphs (networkx), ranked by
galois; the cycle-rank formula E - V + C.
"""

from __future__ import annotations

import networkx as nx
import pytest

from curvenet.cycles.gf2 import edge_mask, gf2_rank
from curvenet.cycles.basis import greedy_basis
from curvenet.cycles.candidates import SEPARATING_EPS, CandidatePool
from curvenet.cycles.find import find_patches
from curvenet.model.network import CurveNetwork

from ._networks import random_network, random_simple_network


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


@pytest.mark.parametrize("seed", range(6))
def test_greedy_basis_accepts_in_k_order(seed):
    """The paper's order: k never decreases along the basis; the basis is full (GF(2) rank)."""
    net = random_network(seed)
    pool = CandidatePool(net, genus_aware=False)
    basis, allc, info = greedy_basis(pool)
    ks = [c.k for c in basis]
    assert ks == sorted(ks)
    assert len(basis) == net.cycle_rank() == pool.cycle_rank
    assert gf2_rank([c.mask for c in basis], max(net.number_of_edges, 1)) == len(basis)
    # every candidate the pass enumerated, by length then geometry, once each
    assert [c.edges for c in allc] == [c.edges for c in pool.all_candidates]
    assert allc == sorted(allc, key=lambda c: (c.length, c.geo))
    assert sum(v["total"] for v in info["candidates"].values()) == len(allc)
    assert {c.edges for c in basis} <= {c.edges for c in allc}


def test_greedy_basis_completes_with_horton_cycles():
    """Work bound hit: Horton cycles not enumerated before complete the basis."""
    net = random_network(3, n=10, m=22)
    pool = CandidatePool(net, max_work=5, engine="python")
    basis, allc, info = greedy_basis(pool)
    assert pool.work_bound_hit and info["horton_candidates"] > 0
    assert len(basis) == net.cycle_rank()
    assert gf2_rank([c.mask for c in basis], net.number_of_edges) == len(basis)
    assert len({c.edges for c in allc}) == len(allc)      # no cycle twice
