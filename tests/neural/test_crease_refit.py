"""The crease-refinement fit (Niu et al. 2025, SharpNet)."""

from __future__ import annotations

import numpy as np
import pytest

from curvenet.neural.crease_refit import crease_refine

from ._box import box_edges, box_mesh


def test_crease_refine_smoke_and_determinism():
    v, f = box_mesh()
    strokes = box_edges()
    kw = dict(steps=15, res=24, pool=3000, batch=500, hidden=16, layers=2, progress=False)
    r1 = crease_refine(v, f, strokes, ["crease"] * 12, **kw)
    r2 = crease_refine(v, f, strokes, ["crease"] * 12, **kw)
    assert r1.report["n_channels"] >= 3 and r1.report["n_strip_triangles"] > 0
    assert set(r1.report["timings"]) >= {"setup", "train", "extract"}
    assert np.isfinite(r1.report["final_loss"])
    assert np.array_equal(r1.faces, r2.faces) and np.allclose(r1.vertices, r2.vertices)
    r3 = crease_refine(v, f, strokes, ["crease"] * 12, use_features=False, **kw)
    assert r3.report["n_channels"] == 0


def test_crease_refine_invalid_input():
    v, f = box_mesh()
    s = [np.zeros((3, 3)) + [[0, 0, 0], [0, 0, 1], [0, 1, 1]]]
    with pytest.raises(ValueError, match="quality"):
        crease_refine(v, f, s, ["crease"], quality="best")
    with pytest.raises(ValueError, match="unknown"):
        crease_refine(v, f, s, ["crease"], stepz=3)
    with pytest.raises(ValueError, match="labels"):
        crease_refine(v, f, s, ["sharp"])
    with pytest.raises(ValueError, match="faces"):
        crease_refine(v, f + 10**6, s, ["crease"])
    with pytest.raises(ValueError, match="strokes"):
        crease_refine(v, f, [np.zeros((1, 3))], ["crease"])
    with pytest.raises(ValueError, match="device"):
        crease_refine(v, f, s, ["crease"], device="tpu")


def test_crease_refine_with_a_stroke_far_from_the_surface():
    # no strip element near any surface sample: those samples get f = 0 and grad f = 0
    # (regression: autograd used to fail on a chunk with no neighbour pairs)
    v, f = box_mesh()
    far = [np.stack([np.full(10, 3.0), np.linspace(0, 1, 10), np.zeros(10)], 1)]
    r = crease_refine(v, f, far, ["crease"], steps=3, res=16, pool=2000, batch=200, hidden=8,
                      layers=1, progress=False)
    assert r.report["n_strip_triangles"] > 0 and np.isfinite(r.report["final_loss"])
