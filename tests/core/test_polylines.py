"""Batched polyline queries against the one-by-one functions (bit for bit)."""

import numpy as np
import pytest

from curvenet.core.geometry import cumulative_length, interpolate_polyline, sample_at
from curvenet.core.polylines import Polylines, row_norms


@pytest.fixture(scope="module")
def polylines():
    rng = np.random.default_rng(0)
    polys = [np.cumsum(rng.normal(size=(int(rng.integers(2, 40)), 3)), axis=0)
             for _ in range(500)]
    polys[5][:] = polys[5][0]            # zero length
    polys[7][3] = polys[7][2]            # a zero-length segment
    return polys


def test_points_at_arc_length_are_interpolate_polyline(polylines):
    s = np.random.default_rng(1).uniform(-1, 60, (len(polylines), 5))
    s[:, 0] = 0.0
    want = [interpolate_polyline(p, s[i], cum=cumulative_length(p))
            for i, p in enumerate(polylines)]
    assert np.array_equal(Polylines(polylines).at(s), np.stack(want))


def test_reversed_polylines_are_the_reversed_walk(polylines):
    s = np.random.default_rng(2).uniform(0, 30, (len(polylines), 3))
    want = []
    for i, p in enumerate(polylines):
        c = cumulative_length(p)
        want.append(interpolate_polyline(p[::-1], s[i], cum=c[-1] - c[::-1]))
    assert np.array_equal(Polylines(polylines, reverse=True).at(s), np.stack(want))


def test_normalised_parameters_are_sample_at(polylines):
    t = np.random.default_rng(3).uniform(0, 1, (len(polylines), 4))
    t[:, 0], t[:, 1] = 0.0, 1.0
    want = [sample_at(p, t[i]) for i, p in enumerate(polylines)]
    lines = Polylines(polylines)
    assert np.array_equal(lines.at_params(t), np.stack(want))
    assert lines.length.tolist() == [cumulative_length(p)[-1] for p in polylines]


def test_row_norms_are_the_norm_of_each_vector():
    rng = np.random.default_rng(4)
    v = rng.normal(size=(20_000, 3)) * 10.0 ** rng.uniform(-3, 3, (20_000, 1))
    assert row_norms(v).tolist() == [np.linalg.norm(x) for x in v]


def test_interp_is_numpy_interp_per_coordinate(polylines):
    cums = [cumulative_length(p) for p in polylines]
    x = np.random.default_rng(5).uniform(-1, 60, (len(polylines), 5))
    x[:, 0] = 0.0
    x[:, 1] = [c[-1] for c in cums]                  # the last point, and a knot
    x[:, 2] = [c[len(c) // 2] for c in cums]
    want = [np.stack([np.interp(x[i], c, p[:, k]) for k in range(3)], axis=1)
            for i, (p, c) in enumerate(zip(polylines, cums))]
    assert np.array_equal(Polylines(polylines).interp(x), np.stack(want))
