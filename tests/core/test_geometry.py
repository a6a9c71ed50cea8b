"""Oracles for the bottom-floor primitives (curvenet.core)."""

import math

import numpy as np
import pytest

from curvenet.core.geometry import segment_closest
from curvenet.core import (LABELS, arc_length, arc_length_params, as_polyline, boundary_edges,
                           check_labels, check_strokes, cumulative_length, densify_polyline,
                           face_normals_areas, interpolate_polyline, resample_polyline,
                           sample_at, sample_surface)
from curvenet.core.tolerances import SNAP_TOL_RANGE, check_snap_tol
from curvenet.core.errors import CurvenetError, InvalidParameterError



def _circle(n, r=2.0, closed=True):
    a = np.linspace(0.0, 2 * np.pi, n + 1 if closed else n, endpoint=closed)
    return np.stack([r * np.cos(a), r * np.sin(a), np.zeros_like(a)], axis=1)


# --------------------------------------------------------------------------- arc length
@pytest.mark.parametrize("n", [3, 8, 1000])
def test_arc_length_of_inscribed_polygon_is_exact(n):
    # n chords of a circle of radius r, each 2 r sin(pi / n)
    assert arc_length(_circle(n)) == pytest.approx(n * 2 * 2.0 * math.sin(math.pi / n), rel=1e-12)


def test_arc_length_of_circle_converges_to_2_pi_r():
    # chord error of an inscribed n-gon: 2 pi r (1 - sin(pi/n) / (pi/n)) ~ 2 pi r pi^2 / (6 n^2)
    n = 4000
    assert abs(arc_length(_circle(n)) - 4 * np.pi) < 4 * np.pi * np.pi ** 2 / (6 * n ** 2) * 1.01


def test_cumulative_length_hand_case():
    c = np.array([[0, 0, 0], [3, 4, 0], [3, 4, 0], [3, 4, 2.0]])
    assert cumulative_length(c).tolist() == [0.0, 5.0, 5.0, 7.0]


def test_arc_length_params_zero_length_curve_is_uniform():
    np.testing.assert_allclose(arc_length_params(np.zeros((4, 3))), [0, 1 / 3, 2 / 3, 1])


# --------------------------------------------------------------------------- interpolation
def test_sample_at_interpolates_vertices():
    c = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.]])
    np.testing.assert_allclose(sample_at(c, np.array([0.0, 0.5, 0.75, 1.0])),
                               [[0, 0, 0], [1, 0, 0], [1, 0.5, 0], [1, 1, 0]], atol=1e-12)


def test_interpolate_clamps_or_extrapolates():
    c = np.array([[0, 0, 0], [1, 0, 0], [1, 2, 0.]])
    np.testing.assert_allclose(interpolate_polyline(c, [-1.0, 2.0, 5.0]),
                               [[0, 0, 0], [1, 1, 0], [1, 2, 0]])
    np.testing.assert_allclose(interpolate_polyline(c, [-1.0, 5.0], extrapolate=True),
                               [[-1, 0, 0], [1, 4, 0]])


def test_interpolate_skips_repeated_points():
    c = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0], [1, 1, 0.]])
    p = interpolate_polyline(c, np.linspace(0, 2, 9))
    assert np.isfinite(p).all()
    np.testing.assert_allclose(p[4], [1, 0, 0])
    np.testing.assert_allclose(p[6], [1, 0.5, 0])


# --------------------------------------------------------------------------- resampling
@pytest.mark.parametrize("k", [1, 2, 5, 17])
def test_resample_keeps_ends_and_spaces_equally(k):
    # a straight line with irregular vertices: arc length is x, so samples are evenly spaced
    x = np.sort(np.random.default_rng(k).uniform(0, 3, 9))
    c = np.stack([x, 2 * x, -x], axis=1)
    r = resample_polyline(c, k)
    assert r.shape == (k + 1, 3)
    assert np.array_equal(r[0], c[0]) and np.array_equal(r[-1], c[-1])
    np.testing.assert_allclose(np.linalg.norm(np.diff(r, axis=0), axis=1),
                               arc_length(c) / k, rtol=1e-12)


def test_resample_circle_points_stay_on_it_equally_spaced():
    c = _circle(360)
    r = resample_polyline(c, 12)
    np.testing.assert_allclose(np.linalg.norm(r[:, :2], axis=1), 2.0, atol=1e-3)
    d = np.linalg.norm(np.diff(r, axis=0), axis=1)
    assert d.max() - d.min() < 1e-3 * d.mean()


def test_densify_keeps_vertices_and_bounds_the_step():
    c = np.array([[0, 0, 0], [1, 0, 0], [1, 0.05, 0], [1, 2.5, 0.]])
    d = densify_polyline(c, 0.3)
    assert np.linalg.norm(np.diff(d, axis=0), axis=1).max() <= 0.3 + 1e-12
    for p in c:  # every input point is kept
        assert np.min(np.linalg.norm(d - p, axis=1)) == 0.0
    assert arc_length(d) == pytest.approx(arc_length(c), rel=1e-12)
    assert len(d) == 4 + 1 + 9 + 1  # ceil(1/.3), 1 (short segment), ceil(2.45/.3), the end


# --------------------------------------------------------------------------- triangles
def test_boundary_edges_of_a_closed_mesh_are_none_and_of_a_cut_one_its_rim():
    import trimesh
    m = trimesh.creation.icosphere(2)
    assert boundary_edges(m.faces).shape == (0, 2)
    cut = m.faces[m.triangles_center[:, 2] > 0.0]          # the upper half: one rim loop
    rim = boundary_edges(cut)
    assert bool((rim[:, 0] < rim[:, 1]).all())
    deg = np.bincount(rim.ravel())
    assert set(deg[deg > 0].tolist()) == {2}                  # every rim vertex on two edges
    assert len(rim) == len(np.unique(rim))                    # a single loop: E = V


def test_face_normals_areas_hand_case():
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 3, 0], [1, 1, 1.0]])
    n, a = face_normals_areas(v, np.array([[0, 1, 2], [0, 2, 1], [0, 0, 3]]))
    np.testing.assert_allclose(n, [[0, 0, 1], [0, 0, -1], [0, 0, 0]])
    np.testing.assert_allclose(a, [3, 3, 0])


def test_sampling_is_area_uniform_on_two_triangles_of_different_areas():
    # face 0 has area 1/2, face 1 area 3/2: a quarter of the samples on face 0
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 0, 1], [8, 0, 1], [5, 1, 1.0]])
    f = np.array([[0, 1, 2], [3, 4, 5]])
    n = 40_000
    p, fi = sample_surface(v, f, n, seed=0)
    sd = math.sqrt(0.25 * 0.75 / n)  # binomial standard deviation of the fraction
    assert abs(np.mean(fi == 0) - 0.25) < 5 * sd
    # every point lies on its own triangle: barycentric coordinates in [0, 1]
    b0 = p[fi == 0][:, :2]
    b1 = (p[fi == 1] - [5, 0, 1])[:, :2] / [3, 1]
    for b in (b0, b1):
        assert (b >= -1e-12).all() and (b.sum(axis=1) <= 1 + 1e-12).all()
    assert np.allclose(p[fi == 0][:, 2], 0) and np.allclose(p[fi == 1][:, 2], 1)
    # uniform inside a triangle: the mean is the centroid, the corner sub-triangle of
    # half the edge length holds a quarter of the points
    sd = math.sqrt(1 / 18 / len(b1))  # barycentric coordinate variance on a triangle: 1/18
    np.testing.assert_allclose(b1.mean(axis=0), [1 / 3, 1 / 3], atol=5 * sd)
    frac = np.mean(b1.sum(axis=1) < 0.5)
    assert abs(frac - 0.25) < 5 * math.sqrt(0.25 * 0.75 / len(b1))


def test_sampling_is_seeded_and_threads_a_generator():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    f = np.array([[0, 1, 2]])
    a, _ = sample_surface(v, f, 50, seed=3)
    b, _ = sample_surface(v, f, 50, seed=3)
    assert np.array_equal(a, b)
    rng = np.random.default_rng(3)
    c, _ = sample_surface(v, f, 50, rng)
    d, _ = sample_surface(v, f, 50, rng)  # the generator advanced
    assert np.array_equal(a, c) and not np.array_equal(c, d)


def test_sampling_rejects_zero_area():
    v = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]])
    with pytest.raises(InvalidParameterError, match="positive area"):
        sample_surface(v, np.array([[0, 1, 2]]), 10, seed=0)


# --------------------------------------------------------------------------- validation
@pytest.mark.parametrize("bad, words", [
    ([[0, 0, 0], [1, np.nan, 0]], "NaN"),
    ([[0, 0, 0], [np.inf, 0, 0]], "NaN or infinite"),
    ([[0, 0, 0]], "at least 2 points, got 1"),
    ([], "at least 2 points, got 0"),
    ([[0, 0], [1, 1]], r"\(n, 3\)"),
    ([[[0, 0, 0]]], r"\(n, 3\)"),
    ([["a", "b", "c"], [0, 0, 0]], "not numbers"),
    ([[10 ** 400, 0, 0], [0, 0, 0]], "too large for a float"),
])
def test_as_polyline_rejects_with_named_errors(bad, words):
    with pytest.raises(InvalidParameterError, match=r"^strokes\[3\]: .*" + words):
        as_polyline(bad, name="strokes[3]")
    assert issubclass(InvalidParameterError, CurvenetError)
    assert issubclass(InvalidParameterError, ValueError)


def test_as_polyline_copies():
    src = np.zeros((3, 3))
    out = as_polyline(src, min_points=3)
    out[0, 0] = 1
    assert src[0, 0] == 0 and out.flags.c_contiguous


def test_check_strokes_and_labels():
    s = [[[0, 0, 0], [1, 0, 0]], np.ones((3, 3))]
    st, lab = check_strokes(s, default_label="crease")
    assert lab == ["crease", "crease"] and [x.shape for x in st] == [(2, 3), (3, 3)]
    assert check_labels(["construction", "boundary"], 2) == ["construction", "boundary"]
    with pytest.raises(InvalidParameterError, match=r"labels\[1\]"):
        check_strokes(s, ["crease", "sharp"])
    with pytest.raises(InvalidParameterError, match="1 labels for 2 strokes"):
        check_strokes(s, ["crease"])
    with pytest.raises(InvalidParameterError, match=r"strokes\[1\]"):
        check_strokes([s[0], [[0, 0, 0]]])
    with pytest.raises(InvalidParameterError, match="at least one stroke"):
        check_strokes([], allow_empty=False)
    assert check_strokes([]) == ([], [])
    assert LABELS == ("boundary", "crease", "construction")


def test_snap_tol_range():
    lo, hi = SNAP_TOL_RANGE
    assert check_snap_tol(hi) == hi and check_snap_tol(np.float32(0.25)) == 0.25
    for bad in (lo, -0.1, hi + 1e-9, float("nan"), float("inf"), "0.01", None, True):
        with pytest.raises(InvalidParameterError, match="snap_tol"):
            check_snap_tol(bad)


def test_segment_closest_points_match_brute_force():
    rng = np.random.default_rng(0)
    p0, p1, q0, q1 = (rng.normal(size=(300, 3)) for _ in range(4))
    p1[:20] = p0[:20] + (q1[:20] - q0[:20])  # parallel pairs
    s, t = segment_closest(p0, p1, q0, q1)
    d = np.linalg.norm(p0 + s[:, None] * (p1 - p0) - q0 - t[:, None] * (q1 - q0), axis=1)
    g = np.linspace(0, 1, 301)
    for k in range(300):
        A = p0[k] + g[:, None] * (p1[k] - p0[k])
        B = q0[k] + g[:, None] * (q1[k] - q0[k])
        brute = np.linalg.norm(A[:, None] - B[None], axis=2).min()
        assert d[k] <= brute + 1e-12  # never worse than the 301 x 301 grid
        spacing = (np.linalg.norm(p1[k] - p0[k]) + np.linalg.norm(q1[k] - q0[k])) / 300
        assert d[k] >= brute - spacing  # and better only by the grid spacing


# --------------------------------------------------------------------------- invariants


# --------------------------------------------------------------------------- subdivision
def test_curved_subdivision_puts_new_vertices_near_the_sphere_and_keeps_the_topology():
    import trimesh

    from curvenet.core.geometry import subdivide_curved
    m = trimesh.creation.icosphere(2)                 # vertices on the unit sphere
    V, F = subdivide_curved(m.vertices, m.faces)
    assert V.shape == (len(m.vertices) + len(m.edges_unique), 3)
    assert F.shape == (4 * len(m.faces), 3)
    np.testing.assert_array_equal(V[:len(m.vertices)], m.vertices)
    curved = np.abs(np.linalg.norm(V[len(m.vertices):], axis=1) - 1.0).max()
    e = m.vertices[m.edges_unique]
    flat = np.abs(np.linalg.norm(e.mean(axis=1), axis=1) - 1.0).max()
    assert curved < flat / 8                          # the chord error an order smaller
    out = trimesh.Trimesh(V, F, process=False)
    assert out.is_watertight and out.is_winding_consistent
    assert out.euler_number == m.euler_number == 2
    assert out.volume > m.volume > 0                  # outward kept, nearer the ball's 4 pi / 3
    assert out.volume < 4 * np.pi / 3


def test_curved_subdivision_keeps_a_flat_open_mesh_flat():
    from curvenet.core.geometry import subdivide_curved
    g = np.stack(np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij"), -1).reshape(-1, 2)
    V0 = np.c_[g, np.zeros(len(g))]
    idx = np.arange(12).reshape(4, 3)
    a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
    c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    F0 = np.r_[np.c_[a, b, c], np.c_[a, c, d]]
    V, F = subdivide_curved(V0, F0)
    assert np.abs(V[:, 2]).max() == 0.0
    # the new vertices are the edges' midpoints (normals all equal: no correction)
    edges = np.unique(np.sort(F0[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1), axis=0)
    mids = V0[edges].mean(axis=1)
    np.testing.assert_allclose(np.unique(V[12:], axis=0), np.unique(mids, axis=0), atol=1e-12)
    assert len(F) == 4 * len(F0)
