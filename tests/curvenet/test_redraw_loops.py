"""Tests of curvenet.datasets.redraw_loops: rings redrawn as one stroke past or short of
their start (issue 33)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from curvenet.core.errors import InvalidParameterError
from curvenet.core.geometry import arc_length, resample_polyline
from curvenet.datasets import shapes
from curvenet.datasets.redraw_loops import loop_sketch, smooth_chains

CURVED = ["sphere", "ellipsoid", "capped_cylinder", "torus"]


def _dense(net, n=400):
    return np.concatenate([resample_polyline(e.curve, n) for e in net.edges])


@pytest.mark.parametrize("name,rings,open_", [("sphere", 6, 0), ("capped_cylinder", 3, 4),
                                              ("torus", 10, 0), ("box", 0, 12)])
def test_smooth_chains_find_the_rings(name, rings, open_):
    """Sphere: 3 parallels and 3 meridian loops through both poles; capped cylinder: 3
    circles, 4 rulings from rim to rim; torus: 6 + 4 circles; box: 12 edges, no ring."""
    net = shapes.SHAPES[name]().network
    chains = smooth_chains(net)
    assert sum(c for _, c, _ in chains) == rings and sum(not c for _, c, _ in chains) == open_
    total = sum(arc_length(p) for p, _, _ in chains)
    assert total == pytest.approx(sum(e.length() for e in net.edges), rel=1e-9)
    for poly, closed, _ in chains:
        assert closed == bool(np.allclose(poly[0], poly[-1]))


def test_deterministic_per_seed():
    net = shapes.torus().network
    a, b = loop_sketch(net, seed=4), loop_sketch(net, seed=4)
    assert all(np.array_equal(x, y) for x, y in zip(a.strokes, b.strokes))
    c = loop_sketch(net, seed=5)
    assert len(c) != len(a) or any(not np.array_equal(x, y) for x, y in zip(a.strokes, c.strokes))


@pytest.mark.parametrize("name", CURVED)
def test_zero_noise_rings_are_closed_strokes_on_the_curves(name):
    """No gap, no overshoot, no wobble, no split: one closed stroke per ring, on the curve."""
    net = shapes.SHAPES[name]().network
    sk = loop_sketch(net, seed=0, gap=0, ends=0, overshoot=0, wobble=0, split=0)
    assert len(sk) == len(smooth_chains(net))
    d, _ = cKDTree(_dense(net)).query(sk.points)
    assert d.max() < 1e-3 * net.diagonal  # the 400-sample discretisation of the oracle
    rings = [s for s in sk.strokes if np.linalg.norm(s[0] - s[-1]) < 1e-9 * net.diagonal]
    assert len(rings) == sum(c for _, c, _ in smooth_chains(net))


@pytest.mark.parametrize("seed", range(4))
def test_rings_run_past_their_start_within_the_bounds(seed):
    """Every ring past its start (no wobble): its length is 1 to 1.1 laps (1% for the
    drift across a curved ring), its end lies within ``gap`` of its own first 15%, and
    no point strays farther than ``gap`` from the true curves."""
    net = shapes.latlong_sphere().network
    diag, gap = net.diagonal, 0.02
    laps = np.array(sorted(arc_length(p) for p, c, _ in smooth_chains(net) if c))
    sk = loop_sketch(net, seed=seed, gap=gap, past=1.0, split=0.0, wobble=0.0)
    d, _ = cKDTree(_dense(net)).query(sk.points)
    assert d.max() <= gap * diag * (1 + 1e-6) + 1e-3 * diag
    for s in sk.strokes:
        L = arc_length(s)
        lap = laps[laps <= 1.01 * L].max()
        assert 0.99 * lap <= L <= 1.1 * lap * 1.01
        cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(s, axis=0), axis=1))])
        head = resample_polyline(s[:np.searchsorted(cum, 0.15 * L) + 1], 200)
        assert cKDTree(head).query(s[-1])[0] <= gap * diag * (1 + 1e-6) + 1e-3 * diag


def test_rings_short_of_their_start_leave_a_gap_within_bounds():
    net = shapes.torus().network
    diag, gap = net.diagonal, 0.015
    sk = loop_sketch(net, seed=1, gap=gap, past=0.0, split=0.0, wobble=0.0)
    ends = np.array([np.linalg.norm(s[0] - s[-1]) for s in sk.strokes]) / diag
    assert ends.max() <= np.hypot(gap, 0.5 * gap) * (1 + 1e-6) and ends.max() > 0.1 * gap


@pytest.mark.parametrize("kw", [{"gap": -0.1}, {"ends": float("nan")}, {"past": 1.5},
                                {"split": -0.1}, {"overshoot": 0.5}])
def test_invalid_parameters(kw):
    with pytest.raises(InvalidParameterError):
        loop_sketch(shapes.torus().network, seed=0, **kw)
