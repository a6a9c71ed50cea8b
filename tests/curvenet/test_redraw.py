"""Tests of curvenet.datasets.redraw: the rough re-drawing generator and the network matcher."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from curvenet.datasets import shapes
from curvenet.core.errors import InvalidParameterError
from curvenet.model.network import CurveNetwork
from curvenet.datasets.redraw import match_networks, rough_sketch


def _dense(net, n=400):
    pts = []
    for e in net.edges:
        c = e.curve
        cum = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(c, axis=0), axis=1))])
        s = np.linspace(0, cum[-1], n)
        pts.append(np.stack([np.interp(s, cum, c[:, k]) for k in range(3)], axis=1))
    return np.concatenate(pts)


def test_deterministic_per_seed():
    net = shapes.box().network
    a, b = rough_sketch(net, seed=7), rough_sketch(net, seed=7)
    assert len(a) == len(b) and a.labels == b.labels
    for x, y in zip(a.strokes, b.strokes):
        np.testing.assert_array_equal(x, y)
    c = rough_sketch(net, seed=8)
    assert len(c) != len(a) or any(not np.array_equal(x, y) for x, y in zip(a.strokes, c.strokes))


def test_zero_noise_redraw_lies_on_the_curves():
    net = shapes.latlong_sphere().network
    sk = rough_sketch(net, seed=0, wobble=0, overshoot=0, gap=0, overdraw=0, split=0)
    assert len(sk) == net.number_of_edges
    d, _ = cKDTree(_dense(net)).query(sk.points)
    assert d.max() < 1e-3 * net.diagonal  # only the 400-sample discretisation of the oracle


def test_amplitudes_are_bounded():
    net = shapes.box().network
    diag = net.diagonal
    for seed in range(5):
        sk = rough_sketch(net, seed=seed, overshoot=0, gap=0, overdraw=0, split=0)
        d, _ = cKDTree(_dense(net)).query(sk.points)
        assert d.max() <= 0.003 * diag * (1 + 1e-6) + 1e-3 * diag  # wobble peak + sampling
        assert d.max() >= 0.0005 * diag  # and it does wobble
    # overshoot: ends move along the curve by at most 1.5% of the diagonal
    sk = rough_sketch(net, seed=1, wobble=0, gap=0, overdraw=0, split=0)
    corners = net.positions
    for s in sk.strokes:
        for end in (s[0], s[-1]):
            assert np.linalg.norm(corners - end, axis=1).min() <= 0.015 * diag + 1e-12


def test_jitter_moves_every_sample_by_its_deviation_and_leaves_default_sketches_alone():
    net = shapes.box().network
    diag = net.diagonal
    plain = dict(wobble=0, overshoot=0, gap=0, overdraw=0, split=0)
    base = rough_sketch(net, seed=3, **plain)
    noisy = rough_sketch(net, seed=3, jitter=0.002, **plain)
    off = np.concatenate([b - n for b, n in zip(base.strokes, noisy.strokes)])
    # same strokes, each sample moved by an independent Gaussian of 0.2% of the diagonal
    assert off.shape[0] == len(base.points)
    assert abs(off.std() / diag - 0.002) < 0.0003
    assert abs(np.corrcoef(off[1:, 0], off[:-1, 0])[0, 1]) < 0.2
    assert noisy.metadata["redraw"]["jitter"] == 0.002
    # jitter 0 draws nothing: the default sketches of a seed stay as they were
    for x, y in zip(rough_sketch(net, seed=5).strokes, rough_sketch(net, seed=5, jitter=0).strokes):
        np.testing.assert_array_equal(x, y)
    with pytest.raises(InvalidParameterError, match="jitter"):
        rough_sketch(net, seed=0, jitter=-1)


def test_split_gap_and_overdraw_counts():
    net = shapes.saddle_grid().network
    sk = rough_sketch(net, seed=2, split=1.0, overdraw=0.0)
    assert len(sk) == 2 * net.number_of_edges
    sk = rough_sketch(net, seed=2, split=0.0, overdraw=1.0)
    assert len(sk) == 2 * net.number_of_edges
    lab = shapes.box().network
    sk = rough_sketch(lab, seed=0)
    assert set(sk.labels) == {e.label for e in lab.edges}


@pytest.mark.parametrize("kw", [{"wobble": -1}, {"gap": float("nan")}, {"overdraw": 2},
                                {"split": 1.5}])
def test_invalid_parameters(kw):
    with pytest.raises(InvalidParameterError):
        rough_sketch(shapes.box().network, seed=0, **kw)


def test_match_networks_oracle():
    ref = shapes.box().network
    assert match_networks(ref, ref)["ok"]
    assert match_networks(ref, ref)["max_distance"] == 0.0
    # moving one curve by 5% of the diagonal breaks the match but not the counts
    moved = CurveNetwork(ref.positions.copy())
    for i, e in enumerate(ref.edges):
        c = e.curve.copy()
        if i == 0:
            c[1:-1] += 0.05 * ref.diagonal * np.array([0, 0, 1.0])
        moved.add_edge(e.u, e.v, c, label=e.label)
    m = match_networks(ref, moved)
    assert m["same_counts"] and not m["ok"]
    assert m["max_distance"] == pytest.approx(0.05, rel=0.05)
    # dropping an edge breaks the counts
    fewer = CurveNetwork(ref.positions.copy())
    for e in ref.edges[1:]:
        fewer.add_edge(e.u, e.v, e.curve, label=e.label)
    assert not match_networks(ref, fewer)["same_counts"]
