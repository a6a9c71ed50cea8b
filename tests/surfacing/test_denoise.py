"""Curves drawn with per-sample jitter: smoothed for the fit, the jitter put back."""

import numpy as np
import pytest

import curvenet
from curvenet.datasets import shapes
from curvenet.datasets.redraw import rough_sketch
from curvenet.evaluate import evaluate_mesh
from curvenet.core.geometry import boundary_edges
from curvenet.surfacing.denoise import MIN_SAMPLES, restore, smooth_curves
from curvenet.surfacing.polyline import point_polyline_distance
from curvenet.surfacing.sectors import surface_boundaries


@pytest.fixture(scope="module")
def jittered_torus():
    """A torus drawn with 4 meridians and 3 rings, re-drawn rough with a 0.3% jitter on
    every sample: ``{denoise: result}`` and the true surface. (At 0.2% the thinner torus
    this was first measured on comes out round without the smoothing too, since the
    snapping stopped cutting its strokes at false corners.)"""
    shape = shapes.torus(1.0, 0.4, n_u=4, n_v=3)
    sketch = rough_sketch(shape.network, seed=0, jitter=0.003)
    out = {flag: curvenet.surface(sketch, method="classical",
                                  classical_options={"denoise": flag})
           for flag in (True, False)}
    return out, shape.reference_mesh(4)


def test_a_jittered_torus_comes_out_round_and_on_its_strokes(jittered_torus):
    out, ref = jittered_torus
    on, off = (evaluate_mesh(out[flag].mesh, ref, n_samples=20_000) for flag in (True, False))
    assert on["fscore"] >= 0.95, on
    assert off["fscore"] < on["fscore"] - 0.1, (off, on)      # what the smoothing is for
    rep = out[True].diagnostics["classical"]["denoised"]
    assert rep and all(1e-4 < r["rms"] < 0.01 for r in rep), rep
    assert out[True].diagnostics["fidelity"]["surface"] >= 0.99


def _ring(n=120):
    t = np.linspace(0.0, np.pi, n)
    return np.c_[np.cos(t), np.sin(t), 0.0 * t]


def test_smooth_and_detailed_curves_are_left_as_drawn():
    rng = np.random.default_rng(3)
    ring = _ring()
    bump = ring.copy()          # a drawn detail: a smooth bump of 5% over a tenth of it
    bump[:, 2] = 0.05 * np.exp(-((np.arange(len(ring)) - 60) / 6.0) ** 2)
    short = ring[::10] + rng.normal(0, 0.01, ring[::10].shape)
    assert len(short) < MIN_SAMPLES
    out, rep = smooth_curves([ring, bump, short], 1e-4)
    assert rep == []
    assert all(o is c for o, c in zip(out, [ring, bump, short]))


def test_jitter_is_smoothed_ends_held_and_put_back_on_the_mesh():
    """A unit square whose sides are jittered out of its plane."""
    rng = np.random.default_rng(0)
    t = np.linspace(0, 1, 60)
    sides = [np.c_[t, 0 * t, 0 * t], np.c_[1 + 0 * t, t, 0 * t],
             np.c_[1 - t, 1 + 0 * t, 0 * t], np.c_[0 * t, 1 - t, 0 * t]]
    drawn = []
    for c in sides:
        d = c.copy()
        d[1:-1, 2] += rng.normal(0, 0.003, len(c) - 2)      # jitter out of the plane
        drawn.append(d)
    smoothed, rep = smooth_curves(drawn, 1e-4)
    assert [r["curve"] for r in rep] == [0, 1, 2, 3]
    for s, d in zip(smoothed, drawn):
        assert np.array_equal(s[[0, -1]], d[[0, -1]])        # junctions kept
        assert np.abs(s[:, 2]).max() < 0.5 * np.abs(d[:, 2]).max()
    loop = [[(k, True) for k in range(4)]]
    res = surface_boundaries(drawn, [loop], subdiv=3)
    plain = surface_boundaries(drawn, [loop], subdiv=3, denoise=False)
    assert len(res.report["denoised"]) == 4 and plain.report["denoised"] == []
    inner = (np.abs(res.vertices[:, :2] - 0.5) < 0.4).all(axis=1)     # away from the sides
    assert np.abs(res.vertices[inner, 2]).max() < 0.5 * np.abs(plain.vertices[inner, 2]).max()
    rim = np.unique(boundary_edges(res.faces))             # the mesh's border meets the
    gap = np.min([point_polyline_distance(res.vertices[rim], d) for d in drawn], axis=0)
    assert np.median(gap) < 2e-4 and gap.max() < 2e-3      # drawn sides, jitter and all


def test_restore_without_smoothed_curves_changes_nothing():
    V = np.random.default_rng(1).random((4, 3))
    F = np.array([[0, 1, 2], [0, 2, 3]])
    c = [V[[0, 1]]]
    assert np.array_equal(restore(V, F, np.zeros(2, np.int64), c, c), V)
