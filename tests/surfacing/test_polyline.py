import numpy as np

from curvenet.surfacing.polyline import end_tangents, point_polyline_distance


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
