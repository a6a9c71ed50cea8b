"""The surfacer registry: toy surfacers through the pipeline and the CLI, the error seam."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import asdict

import numpy as np
import pytest
import trimesh

import curvenet
from curvenet import MeshResult, Sketch
from curvenet.datasets import shapes
from curvenet.cli import main
from curvenet.io.sketch import write_sketch
from curvenet.route.registry import (SurfaceInput, get_surfacer, register_surfacer, surfacer_names,
                                unregister_surfacer)


def hull(inp: SurfaceInput, options: dict) -> MeshResult:
    """A toy stroke surfacer: the convex hull of the stroke points."""
    h = trimesh.convex.convex_hull(np.concatenate(inp.strokes))
    return MeshResult(h.vertices, h.faces, {"n_strokes": len(inp.strokes)})


def fan(inp: SurfaceInput, options: dict) -> MeshResult:
    """A toy patch surfacer: each loop's boundary fanned around its centroid."""
    verts, faces = [], []
    for loop in inp.loops:
        ring = np.concatenate([(inp.curves[c] if fwd else inp.curves[c][::-1])[:-1]
                               for c, fwd in loop])
        base = sum(len(v) for v in verts)
        verts += [ring, ring.mean(0, keepdims=True)]
        k = np.arange(len(ring))
        faces.append(np.c_[base + k, base + (k + 1) % len(ring), np.full_like(k, base + len(k))])
    return MeshResult(np.concatenate(verts), np.concatenate(faces), {"loops": len(inp.loops)})


@pytest.fixture
def toys():
    register_surfacer("hull", hull, needs="strokes", summary="convex hull of the strokes")
    register_surfacer("fan", fan, needs="patches", summary="one fan per patch")
    yield
    unregister_surfacer("hull")
    unregister_surfacer("fan")


@pytest.fixture
def box_obj(tmp_path):
    path = tmp_path / "box.obj"
    write_sketch(path, shapes.box().sketch())
    return path


def test_builtins_are_registered_without_importing_backends():
    assert surfacer_names() == ("catmull-clark", "soapfilm", "neural", "hybrid")
    assert surfacer_names("patches") == ("catmull-clark", "soapfilm")
    assert surfacer_names("regions") == ("hybrid",)
    assert get_surfacer("catmull-clark").label == "classical"
    code = ("import sys, curvenet.route, curvenet.cli; curvenet.cli.build_parser(); "
            "bad = [m for m in ('torch', 'curvenet.surfacing', 'curvenet.neural') "
            "if m in sys.modules]; sys.exit(str(bad) if bad else 0)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_a_toy_stroke_surfacer_runs_through_surface(toys):
    sk = shapes.box().sketch()
    res = curvenet.surface(sk, method="hull")
    # oracle: the hull of the unit box's edges is the unit cube
    assert res.method == "hull" and res.mesh.is_watertight
    assert res.mesh.volume == pytest.approx(1.0, abs=1e-9)
    assert res.diagnostics["hull"] == {"n_strokes": 12} and "hull" in res.timings
    assert res.decision.explain() == res.diagnostics["decision"] == "hull: requested"
    assert res.patchset is None                       # a stroke surfacer gets no patches


def test_a_toy_patch_surfacer_gets_oriented_loops(toys):
    res = curvenet.surface(shapes.box().sketch(), method="fan")
    # oracle: fans over the six planar unit squares have the box's area, 6
    assert res.method == "fan" and res.diagnostics["fan"] == {"loops": 6}
    assert res.mesh.area == pytest.approx(6.0, abs=1e-9)
    np.testing.assert_allclose(res.mesh.bounds, [[0, 0, 0], [1, 1, 1]], atol=1e-12)
    # consistently oriented loops: the fans close into a solid of volume 1 (up to sign)
    assert abs(res.mesh.volume) == pytest.approx(1.0, abs=1e-9)
    # the same toy also serves as the classical route's surfacer
    res2 = curvenet.surface(shapes.box().sketch(), surfacer="fan")
    assert res2.method == "fan" and res2.decision.route == "classical"
    assert res2.decision.reason == "covered"


def test_a_toy_surfacer_runs_through_the_cli(toys, box_obj, tmp_path, capsys):
    out = tmp_path / "hull.ply"
    assert main(["surface", str(box_obj), "-o", str(out), "--method", "hull", "--explain"]) == 0
    stdout = capsys.readouterr().out
    assert "route: hull: requested" in stdout
    assert trimesh.load(out).volume == pytest.approx(1.0, abs=1e-6)
    out = tmp_path / "fan.obj"
    assert main(["surface", str(box_obj), "-o", str(out), "--surfacer", "fan"]) == 0
    assert out.is_file()


def test_registry_rejects_bad_entries(toys):
    with pytest.raises(curvenet.InvalidParameterError, match="already registered"):
        register_surfacer("hull", hull, needs="strokes")
    with pytest.raises(curvenet.InvalidParameterError, match="reserved"):
        register_surfacer("auto", hull, needs="strokes")
    with pytest.raises(curvenet.InvalidParameterError, match="needs"):
        register_surfacer("blob", hull, needs="points")
    with pytest.raises(curvenet.InvalidParameterError, match="surfacer"):
        curvenet.surface(shapes.box().sketch(), surfacer="hull")    # hull needs strokes
    register_surfacer("bad", lambda inp, options: (inp.strokes, []), needs="strokes")
    try:
        with pytest.raises(TypeError, match="MeshResult"):
            curvenet.surface(shapes.box().sketch(), method="bad")
    finally:
        unregister_surfacer("bad")


def test_decorator_form_and_lazy_reference():
    @register_surfacer("hull2", needs="strokes")
    def hull2(inp, options):
        return hull(inp, options)
    register_surfacer("hull3", "tests.curvenet.test_surfacers:hull", needs="strokes")
    try:
        sk = shapes.box().sketch()
        for name in ("hull2", "hull3"):
            assert curvenet.surface(sk, method=name).mesh.volume == pytest.approx(1.0)
    finally:
        unregister_surfacer("hull2")
        unregister_surfacer("hull3")
    assert "hull2" not in surfacer_names()


@pytest.mark.parametrize("kwargs, match", [
    (dict(classical_options={"bogus": 1}), "bogus"),
    (dict(classical_options={"crease_curves": [0]}), "crease_curves"),
    (dict(classical_options={"fit": "magic"}), "fit"),
    (dict(resolution=1), "resolution"),
    (dict(method="classical", surfacer="soapfilm", classical_options={"fit": "lsq"}), "fit"),
    (dict(method="neural", neural_options={"bogus": 1}), "bogus"),
    (dict(method="neural", neural_options={"res": 2}), "res"),
    (dict(surfacer="magic"), "surfacer"),
])
def test_bad_options_fail_before_any_work(monkeypatch, kwargs, match):
    import curvenet.pipeline as pipeline

    def no_work(source):
        raise AssertionError("work started before the options were checked")
    monkeypatch.setattr(pipeline, "load_source", no_work)
    with pytest.raises(curvenet.InvalidParameterError, match=match):
        curvenet.surface(shapes.box().sketch(), **kwargs)


def test_an_internal_value_error_stays_internal(monkeypatch, box_obj, capsys):
    # the classical surfacer calls surface_loops through surfacing.sectors.surface_boundaries
    from curvenet.surfacing import sectors

    def broken(curves, loops, **kw):
        raise ValueError("operands could not be broadcast together")  # a numpy bug, say
    monkeypatch.setattr(sectors, "surface_loops", broken)
    with pytest.raises(ValueError, match="broadcast") as exc:
        curvenet.surface(shapes.box().sketch(), method="classical")
    assert not isinstance(exc.value, curvenet.CurvenetError)
    rc = main(["surface", str(box_obj), "-o", str(box_obj.with_suffix(".ply")),
               "--method", "classical"])
    err = capsys.readouterr().err
    assert rc == 1 and "internal error" in err and "broadcast" in err
    assert not box_obj.with_suffix(".ply").exists()


def test_route_decision_is_data():
    from curvenet.route.decision import auto_route
    res = curvenet.surface(shapes.box().sketch())
    d = res.decision
    assert (d.route, d.surfacer, d.reason, d.patches) == ("classical", "catmull-clark",
                                                           "covered", 6)
    assert json.loads(json.dumps(asdict(d)))["coverage"] == pytest.approx(1.0)
    # the sentences are those --explain has always printed
    kw = dict(patch_surfacer="catmull-clark", stroke_surfacer="neural")
    assert auto_route(0, 0.0, **kw).explain() == \
        "neural: the strokes form no cycles that can be patches"
    assert auto_route(3, 0.5, **kw).explain() == \
        "neural: patches cover only 50% of the curve length (< 80%)"
    assert auto_route(6, 1.0, **kw).explain() == \
        "classical: 6 patches cover 100% of the curve length (>= 80%)"
    assert auto_route(3, 0.5, **kw).surfacer == "neural"
    sk = Sketch([[[0, 0, 0], [1, 0, 0]]])
    with pytest.raises(curvenet.CurvenetError, match="no patches"):
        curvenet.surface(sk, method="soapfilm")
