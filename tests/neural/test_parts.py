"""Separately drawn parts: which strokes form them, their settings, and their fits."""

import numpy as np
import pytest
import trimesh

from curvenet.neural.parts import PART_MIN_SAMPLES, _part_settings, fit_parts, stroke_parts
from curvenet.neural.presets import get_config

from ._metrics import fscore

T = np.linspace(0.0, 2.0 * np.pi, 120)


def _ball(centre, r=1.0):
    """Three great circles of a sphere: closed strokes meeting at six points."""
    z = np.zeros_like(T)
    c, s = r * np.cos(T), r * np.sin(T)
    return [np.c_[c, s, z] + centre, np.c_[c, z, s] + centre, np.c_[z, c, s] + centre]


def _arcs(centre, r=1.0):
    """The same sphere drawn as six half circles ending short of each other."""
    out = []
    for stroke in _ball(centre, r):
        out += [stroke[3:57], stroke[63:117]]
    return out


def test_two_balls_drawn_apart_are_two_parts():
    strokes = _ball(np.zeros(3)) + _ball(np.array([2.2, 0, 0]))
    assert [p.tolist() for p in stroke_parts(strokes)] == [[0, 1, 2], [3, 4, 5]]
    # touching balls are one drawing
    touching = _ball(np.zeros(3)) + _ball(np.array([2.0, 0, 0]))
    assert [p.tolist() for p in stroke_parts(touching)] == [list(range(6))]


def test_a_rough_drawing_is_not_split():
    # strokes ending short of each other: a gap says nothing about parts
    strokes = _arcs(np.zeros(3)) + _arcs(np.array([2.5, 0, 0]))
    assert len(stroke_parts(strokes)) == 1


def test_flat_groups_and_single_strokes_join_the_nearest_part():
    a, b = _ball(np.zeros(3)), _ball(np.array([4.0, 0, 0]))
    ring = np.c_[0.3 * np.cos(T), 0.3 * np.sin(T), 0 * T] + [1.6, 0, 0]     # near a
    fin = [np.array([[4.0, 1.2, 0], [5.0, 1.2, 0]]), np.array([[5.0, 1.2, 0], [4.5, 2.0, 0]]),
           np.array([[4.5, 2.0, 0], [4.0, 1.2, 0]])]                         # flat, near b
    strokes = a + b + [ring] + fin
    parts = stroke_parts(strokes)
    assert sorted(p.tolist() for p in parts) == [[0, 1, 2, 6], [3, 4, 5, 7, 8, 9]]
    assert np.array_equal(np.sort(np.concatenate(parts)), np.arange(len(strokes)))


def test_a_part_keeps_the_cell_size_and_the_sample_density():
    cfg = get_config("default")
    strokes = _ball(np.zeros(3)) + _ball(np.array([3.0, 0, 0]), r=0.25)
    extent = np.ptp(np.vstack(strokes), axis=0).max()
    big = _part_settings(cfg, strokes[:3], extent, 0.8)
    small = _part_settings(cfg, strokes[3:], extent, 0.2)
    # the whole spans 4.25 along x; the big ball 2 of it (128 * 2 / 4.25 -> 64 cells),
    # the small one 0.5 (15 -> the least, 32); the big ball has 0.8 of the length
    assert big["res"] == 64 and small["res"] == 32
    assert big["n_stroke"] == round(cfg.n_stroke * 0.8)
    assert big["n_surface"] == round(cfg.n_surface / 4)
    assert big["n_volume"] == small["n_surface"] == small["n_volume"] == PART_MIN_SAMPLES


def test_two_close_balls_fit_as_two_bodies_without_a_web():
    # one field for both spans the gap between them (measured: one body, F 0.93 at draft)
    a, b = _ball(np.zeros(3)), _ball(np.array([2.2, 0, 0]))
    res = fit_parts(a + b, quality="draft", progress=False)
    m = trimesh.Trimesh(res.vertices, res.faces, process=False)
    assert len(trimesh.graph.connected_components(m.face_adjacency)) == 2
    truth = trimesh.util.concatenate([trimesh.creation.icosphere(4),
                                      trimesh.creation.icosphere(4).apply_translation([2.2, 0, 0])])
    f, _ = fscore(m.vertices, m.faces, truth.vertices, truth.faces)
    assert f >= 0.97, f
    split = res.report["split"]
    assert [s["strokes"] for s in split] == [[0, 1, 2], [3, 4, 5]]
    assert res.report["n_faces"] == len(res.faces)


def test_parts_fitted_side_by_side_are_the_parts_fitted_one_after_the_other(monkeypatch):
    import curvenet.neural.parts as parts
    strokes = _ball(np.zeros(3)) + _ball(np.array([2.2, 0, 0]), r=0.5)
    meshes = []
    for workers in (1, 2):
        monkeypatch.setattr(parts, "PART_WORKERS", workers)
        res = fit_parts(strokes, quality="draft", progress=False, init_steps=10, steps=10)
        meshes.append((res.vertices, res.faces))
    assert len(meshes[0][0]) > 1000
    assert np.array_equal(meshes[0][0], meshes[1][0]) and np.array_equal(meshes[0][1], meshes[1][1])


def _three_balls():
    return sum((_ball(np.array([2.2 * k, 0, 0])) for k in range(3)), [])


@pytest.fixture
def python_sigint():
    """Python's own SIGINT handler for the test: a background job (``cmd &`` in a
    script) starts with SIGINT ignored, and then ``_thread.interrupt_main`` does
    nothing."""
    import signal
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


def test_ctrl_c_stops_the_running_parts_and_skips_the_rest(monkeypatch, python_sigint):
    import _thread
    import time

    import curvenet.neural.flow as flow
    import curvenet.neural.parts as parts
    from curvenet.core.result import MeshResult
    monkeypatch.setattr(parts, "PART_WORKERS", 2)
    started = []

    def fake(strokes, labels=None, *, stop, **kw):
        started.append(kw["desc"])
        if len(started) == 2:           # both workers busy: the user presses Ctrl-C
            time.sleep(0.5)             # (once every part is queued)
            _thread.interrupt_main()
        assert stop.wait(10.0)          # each running fit stops at its next step
        return MeshResult(np.vstack(strokes)[:3], [[0, 1, 2]], {"interrupted": True})

    monkeypatch.setattr(flow, "fit_flow_surface", fake)
    res = fit_parts(_three_balls(), quality="draft")
    assert sorted(started) == ["neural part 1/3", "neural part 2/3"]
    assert [s["strokes"] for s in res.report["split"]] == [[0, 1, 2], [3, 4, 5]]
    assert res.report["interrupted"] and len(res.faces) == 2


def test_ctrl_c_before_any_part_starts_still_gives_the_largest_part(monkeypatch):
    import concurrent.futures

    import curvenet.neural.flow as flow
    from curvenet.core.result import MeshResult
    submit, calls = concurrent.futures.ThreadPoolExecutor.submit, []

    def pressed_first(pool, fn, *args):
        calls.append(args)
        if len(calls) == 1:
            raise KeyboardInterrupt
        return submit(pool, fn, *args)

    def fake(strokes, labels=None, *, stop, **kw):
        assert stop.is_set()            # the fit stops at once and gives its best so far
        return MeshResult(np.vstack(strokes)[:3], [[0, 1, 2]], {"interrupted": True})

    monkeypatch.setattr(concurrent.futures.ThreadPoolExecutor, "submit", pressed_first)
    monkeypatch.setattr(flow, "fit_flow_surface", fake)
    res = fit_parts(_three_balls(), quality="draft")
    assert calls == [(0,), (0,)]
    assert [s["strokes"] for s in res.report["split"]] == [[0, 1, 2]]
    assert res.report["interrupted"]


def test_an_error_in_one_part_stops_the_others_and_is_raised(monkeypatch):
    import curvenet.neural.flow as flow
    import curvenet.neural.parts as parts
    monkeypatch.setattr(parts, "PART_WORKERS", 2)
    stopped = []

    def fake(strokes, labels=None, *, stop, desc, **kw):
        if desc == "neural part 2/3":
            raise ValueError("bad part")
        stopped.append(stop.wait(10.0))
        return None

    monkeypatch.setattr(flow, "fit_flow_surface", fake)
    with pytest.raises(ValueError, match="bad part"):
        fit_parts(_three_balls(), quality="draft")
    # part 1 was stopped; part 3 was not started, or stopped too if it took the freed worker
    # before the error reached the caller
    assert stopped and all(stopped)


def test_split_parts_off_or_a_refinement_fits_the_whole(monkeypatch):
    import curvenet.neural.flow as flow
    calls = []
    monkeypatch.setattr(flow, "fit_flow_surface", lambda strokes, **kw: calls.append(len(strokes)))
    strokes = _ball(np.zeros(3)) + _ball(np.array([2.2, 0, 0]))
    fit_parts(strokes, split_parts=0)
    fit_parts(strokes, init_mesh=(np.zeros((3, 3)), np.array([[0, 1, 2]])))
    assert calls == [6, 6]
    with pytest.raises(ValueError, match="split_parts"):
        get_config("draft", split_parts=2)


def test_construction_strokes_are_left_out_before_the_split(monkeypatch):
    import curvenet.neural.flow as flow
    from curvenet.core.result import MeshResult
    calls = []

    def fake(strokes, labels=None, **kw):
        calls.append((len(strokes), list(labels), kw["res"]))
        return MeshResult(np.vstack(strokes)[:3], [[0, 1, 2]], {"interrupted": False})

    monkeypatch.setattr(flow, "fit_flow_surface", fake)
    guide = np.array([[-5.0, 0, 0], [8.0, 0, 0]])        # through both balls
    strokes = [guide] + _ball(np.zeros(3)) + _ball(np.array([2.2, 0, 0]))
    res = fit_parts(strokes, ["construction"] + ["crease"] * 6, quality="draft")
    assert calls == [(3, ["crease"] * 3, 32), (3, ["crease"] * 3, 32)]
    assert [s["strokes"] for s in res.report["split"]] == [[0, 1, 2], [3, 4, 5]]
    assert res.faces.tolist() == [[0, 1, 2], [3, 4, 5]]
