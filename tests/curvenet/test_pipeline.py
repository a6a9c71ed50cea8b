"""curvenet.surface: the auto route decision, the classical and neural routes, errors."""

from __future__ import annotations

import numpy as np
import pytest

import curvenet
from curvenet import Sketch
from curvenet.datasets import shapes
from curvenet.evaluate import evaluate_mesh
from curvenet.pipeline import AUTO_MIN_COVERAGE

#: a neural budget small enough for CI; the decision, not the quality, is under test here
TINY = dict(res=32, width=32, hidden_layers=2, n_stroke=500, n_surface=400, n_volume=400,
            init_steps=10, steps=15)


def test_auto_takes_classical_on_a_clean_network():
    s = shapes.latlong_sphere()
    res = curvenet.surface(s.sketch())
    assert res.method == "classical"
    assert res.diagnostics["decision"].startswith("classical")
    assert res.diagnostics["coverage"] >= AUTO_MIN_COVERAGE
    assert res.diagnostics["unused_edges"] == []
    m = evaluate_mesh(res.mesh, s.reference_mesh(), n_samples=20_000)
    assert m["fscore"] > 0.99
    assert set(res.timings) >= {"snap", "patches", "classical"}


def test_refine_keeps_the_classical_sphere():
    # classical then the draft flow fit (about 10 s): the refinement may lose a little but
    # must keep the surface (F 0.992 measured; 0.465 when the prefit collapsed g)
    from curvenet.datasets.redraw import rough_sketch
    s = shapes.SHAPES["sphere"]()
    res = curvenet.surface(rough_sketch(s.network, seed=0), refine=True)
    assert res.method == "classical+refine"
    m = evaluate_mesh(res.mesh, s.reference_mesh(4), n_samples=20_000)
    assert m["fscore"] > 0.95, m["fscore"]


def test_rough_torus_keeps_one_control_spacing_per_strip():
    # the classical surface of a re-drawn torus: before the turning was measured at the
    # control polygon's scale, stroke wobble gave single quad strips twice the control
    # points of their neighbours and the fit bulged between the curves (F 0.76-0.95 on
    # seeds 0-3; the clean torus with one strip doubled: 0.95)
    from curvenet.datasets.redraw import rough_sketch
    s = shapes.SHAPES["torus"]()
    for seed in (0, 1):
        res = curvenet.surface(rough_sketch(s.network, seed=seed), method="classical")
        m = evaluate_mesh(res.mesh, s.reference_mesh(4), n_samples=20_000)
        assert m["fscore"] > 0.99, (seed, m["fscore"])


def test_auto_takes_neural_on_disjoint_strokes():
    # parallel circles that never touch: no cycles, so no patches
    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    strokes = [np.c_[np.cos(t[:-3]) * r, np.sin(t[:-3]) * r, np.full(37, z)]
               for z, r in [(-0.6, 0.8), (0.0, 1.0), (0.6, 0.8)]]
    res = curvenet.surface(Sketch(strokes), neural_options=TINY)
    assert res.diagnostics["decision"].startswith("neural")
    assert res.method == "neural"
    assert len(res.mesh.faces) > 0 and np.isfinite(res.mesh.vertices).all()


def test_patches_api_and_dangling_strokes_are_reported():
    s = shapes.box()
    sk = s.sketch()
    # a dangling detail stroke hanging off a corner
    sk = Sketch(sk.strokes + [np.array([[1, 1, 1], [1.2, 1.3, 1.4], [1.3, 1.6, 1.5]])],
                sk.labels + ["boundary"])
    res = curvenet.surface(sk, method="classical")
    assert len(res.patchset.patches) == 6
    assert len(res.diagnostics["unused_edges"]) == 1
    assert res.mesh.is_watertight


def test_bad_parameters_raise_curvenet_errors():
    sk = shapes.box().sketch()
    with pytest.raises(curvenet.InvalidParameterError, match="method"):
        curvenet.surface(sk, method="magic")
    with pytest.raises(curvenet.InvalidParameterError, match="quality"):
        curvenet.surface(sk, quality="ultra")
    with pytest.raises(curvenet.InvalidParameterError, match="crease_angle"):
        curvenet.surface(sk, crease_angle=-3)
    with pytest.raises(curvenet.CurvenetError, match="no patches"):
        curvenet.surface(Sketch([[[0, 0, 0], [1, 0, 0]]]), method="classical")
    with pytest.raises(curvenet.SketchFormatError, match="no such file"):
        curvenet.surface("/nonexistent/sketch.obj")
    # crease-refit settings are checked before any fit
    with pytest.raises(curvenet.InvalidParameterError, match="bogus"):
        curvenet.surface(sk, method="neural", crease_options={"bogus": 1})
    with pytest.raises(curvenet.InvalidParameterError, match="steps"):
        curvenet.surface(sk, method="neural", crease_options={"steps": 0})


def test_crease_options_reach_the_crease_refit(monkeypatch):
    import types

    from curvenet.neural import crease_refit as neural_creases
    from curvenet.neural import flow as neural_flow
    box = shapes.box()
    ref = box.reference_mesh()
    seen = {}

    def flow(strokes, **kw):
        return types.SimpleNamespace(vertices=np.asarray(ref.vertices),
                                     faces=np.asarray(ref.faces), report={})

    def refit(v, f, strokes, labels, **kw):
        seen.update(kw)
        return types.SimpleNamespace(vertices=v, faces=f, report={})
    monkeypatch.setattr(neural_flow, "fit_flow_surface", flow)
    monkeypatch.setattr(neural_creases, "crease_refine", refit)
    res = curvenet.surface(box.sketch(), method="neural", crease_options={"use_features": False})
    assert seen["use_features"] is False and res.diagnostics["neural"]["creases"] == {}
