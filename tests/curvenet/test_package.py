"""Exploring the API: dir(curvenet) and short reprs that never dump arrays."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import curvenet
from curvenet import CurveNetwork, MeshResult, PatchSet, Sketch
from curvenet.datasets import shapes


def test_dir_lists_the_lazy_names_before_first_use():
    # a fresh interpreter: nothing has been imported lazily yet
    code = ("import curvenet; names = set(dir(curvenet)); "
            "need = {'surface', 'patches', 'read_sketch', 'find_patches', 'SurfaceResult', "
            "'register_surfacer', 'MeshResult', 'Sketch'}; "
            "print(sorted(need - names))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"
    assert set(curvenet.__all__) <= set(dir(curvenet))


def test_dir_shows_public_names_only_and_each_resolves():
    code = ("import curvenet; names = dir(curvenet); "
            "print([n for n in names if n.startswith('_') and n != '__version__'], "
            "[n for n in names if not hasattr(curvenet, n)], 'annotations' in names)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[] [] False"


def _dense_sketch(n=20_001):
    t = np.linspace(0, 2 * np.pi, n)
    circle = np.c_[np.cos(t), np.sin(t), 0 * t]
    return Sketch([circle, circle[::-1] * 2.5 + [0, 0, 3]], ["boundary", "crease"])


def test_reprs_are_short_and_say_what_is_inside():
    sk = _dense_sketch()
    r = repr(sk)
    assert r.startswith("<Sketch(strokes=2, points=40002,") and len(r) < 200
    assert "{'boundary': 1, 'crease': 1}" in r
    assert "[[-2.5, -2.5, 0.0], [2.5, 2.5, 3.0]]" in r          # the bounding box
    box = shapes.box()
    net = box.network
    rn = repr(net)
    assert rn.startswith("<CurveNetwork(vertices=8, edges=12,") and "array" not in rn
    assert "[[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]" in rn
    assert repr(net.edges[0]).startswith("<Edge(u=")
    ps = curvenet.patches(box.sketch())
    rp = repr(ps)
    assert rp.startswith("<PatchSet(patches=6,") and len(rp) < 300
    assert repr(PatchSet(CurveNetwork(np.zeros((0, 3))))) == (
        "<PatchSet(patches=0, sources={}, network=<CurveNetwork(vertices=0, edges=0, "
        "labels={}, bounds=None)>)>")
    res = curvenet.surface(box.sketch(), method="classical", subdiv=1)
    assert repr(res) == f"<SurfaceResult(method='classical', vertices={len(res.mesh.vertices)}, " \
                        f"faces={len(res.mesh.faces)})>"


def test_reprs_stay_short_however_big_the_data():
    small, big = _dense_sketch(1_001), _dense_sketch(200_001)
    assert len(repr(big)) - len(repr(small)) <= 6             # only the point count grows
    assert len(str(big)) < 200


def test_mesh_result_has_the_documented_dtypes():
    res = MeshResult([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], {"k": 1})
    assert res.vertices.dtype == np.float64 and res.vertices.shape == (3, 3)
    assert res.faces.dtype == np.int64 and res.faces.shape == (1, 3)
    assert repr(res) == "<MeshResult(vertices.shape=(3, 3), faces.shape=(1, 3))>"
    mesh = res.to_trimesh()
    assert mesh.area == pytest.approx(0.5)
    v = np.zeros((4, 3))
    assert MeshResult(v, np.zeros((0, 3), np.int64)).vertices is v      # no copy


def test_backend_results_are_mesh_results():
    from curvenet.neural.flow import FlowResult
    from curvenet.surfacing import PatchMeshResult, surface_loops
    t = np.linspace(0, 1, 9)[:, None]
    sq = [t * [1, 0, 0], [1, 0, 0] + t * [0, 1, 0], [1, 1, 0] - t * [1, 0, 0],
          [0, 1, 0] - t * [0, 1, 0]]
    res = surface_loops(sq, [[(0, True), (1, True), (2, True), (3, True)]], subdiv=1)
    assert isinstance(res, PatchMeshResult) and isinstance(res, MeshResult)
    assert len(res.face_patch) == len(res.faces) and repr(res).startswith("<PatchMeshResult(")
    assert issubclass(FlowResult, MeshResult)


def test_mesh_result_rejects_wrong_shapes():
    # a backend that returns quads or a flat list has a bug: an internal error, not bad input
    with pytest.raises(ValueError, match="faces") as exc:
        MeshResult(np.zeros((4, 3)), [[0, 1, 2, 3]])
    assert not isinstance(exc.value, curvenet.CurvenetError)
    assert MeshResult([], []).faces.shape == (0, 3)


def test_curvenet_is_the_only_top_level_name(tmp_path):
    # run outside the checkout, so only what the installation provides is importable
    code = ("import importlib.util, curvenet.neural, curvenet.surfacing; "
            "print(importlib.util.find_spec('neural'), importlib.util.find_spec('surfacing'), "
            "curvenet.neural.__name__, curvenet.surfacing.__name__)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["None", "None", "curvenet.neural", "curvenet.surfacing"]
