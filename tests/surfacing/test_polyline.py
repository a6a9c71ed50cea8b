import numpy as np
import pytest

from curvenet.surfacing.polyline import (arc_length_params, end_tangents, point_polyline_distance,
                                resample, sample_at)


def test_resample_equal_arc_length_on_a_straight_line():
    c = np.array([[0, 0, 0], [0.1, 0, 0], [1.0, 0, 0], [3.0, 0, 0]])
    r = resample(c, 6)
    # on a straight polyline arc length is x, so samples are exactly evenly spaced
    np.testing.assert_allclose(r[:, 0], np.linspace(0, 3, 7), atol=1e-12)
    assert np.array_equal(r[0], c[0]) and np.array_equal(r[-1], c[-1])


def test_arc_length_params_zero_length_curve_is_uniform():
    c = np.zeros((4, 3))
    np.testing.assert_allclose(arc_length_params(c), [0, 1 / 3, 2 / 3, 1])


def test_sample_at_interpolates_vertices():
    c = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.]])
    np.testing.assert_allclose(sample_at(c, np.array([0.0, 0.5, 0.75, 1.0])),
                               [[0, 0, 0], [1, 0, 0], [1, 0.5, 0], [1, 1, 0]], atol=1e-12)


def test_end_tangents_point_into_the_curve():
    c = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.]])
    t0, t1 = end_tangents(c, fraction=0.25)
    np.testing.assert_allclose(t0, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(t1, [0, -1, 0], atol=1e-12)


def test_point_polyline_distance_matches_brute_force():
    rng = np.random.default_rng(0)
    c = rng.normal(size=(7, 3))
    p = rng.normal(size=(20, 3))
    fine = np.concatenate([np.linspace(c[i], c[i + 1], 2001) for i in range(6)])
    brute = np.linalg.norm(p[:, None] - fine[None], axis=2).min(1)
    d = point_polyline_distance(p, c)
    assert np.all(d <= brute + 1e-12)
    # dense sampling is within half a sample spacing of the exact distance
    assert np.max(brute - d) < 0.5 * np.linalg.norm(np.diff(c, axis=0), axis=1).max() / 2000


@pytest.mark.parametrize("k", [1, 2, 5])
def test_resample_count(k):
    assert resample(np.array([[0, 0, 0], [1, 2, 3.]]), k).shape == (k + 1, 3)
