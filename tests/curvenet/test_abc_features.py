"""ABC ``*_features_*.yml`` reader: fixtures built here for every curve type."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from curvenet.io.abc import read_abc_features
from curvenet.cli import main
from curvenet.core.errors import SketchFormatError
from curvenet.io.sketch import detect_format, read_sketch, write_sketch

TAU = 2 * np.pi


def _line(a, b, ia, ib, n=5, sharp=True):
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = (b - a) / np.linalg.norm(b - a)
    t = np.linspace(0, np.linalg.norm(b - a), n)
    return {"type": "Line", "sharp": sharp, "location": a.tolist(), "direction": d.tolist(),
            "vert_indices": [ia, *range(10_000 + 10 * ia + 100 * ib, 10_000 + 10 * ia
                                        + 100 * ib + n - 2), ib],
            "vert_parameters": t.tolist()}


def _circle(centre, r, vids, t, sharp=True, z=(0, 0, 1)):
    return {"type": "Circle", "sharp": sharp, "location": list(centre), "radius": r,
            "x_axis": [1, 0, 0], "y_axis": [0, 1, 0], "z_axis": list(z),
            "vert_indices": list(vids), "vert_parameters": list(map(float, t))}


def _write(tmp_path, curves, surfaces=(), name="m_features_000.yml"):
    p = tmp_path / name
    p.write_text(yaml.safe_dump({"curves": curves, "surfaces": list(surfaces)}))
    return p


def test_lines_meeting_share_one_exact_junction(tmp_path):
    c = [_line([0, 0, 0], [1, 0, 0], 0, 1), _line([1, 0, 0], [1, 2, 0], 1, 2, sharp=False)]
    c[1]["location"] = [1.0, 1e-9, 0]  # a rounding gap between the two evaluations
    sk = read_sketch(_write(tmp_path, c))
    assert sk.labels == ["crease", "boundary"]
    np.testing.assert_allclose(sk.strokes[0], np.c_[np.linspace(0, 1, 5), np.zeros((5, 2))],
                               atol=1e-8)
    assert np.array_equal(sk.strokes[0][-1], sk.strokes[1][0])  # one junction, bit-exact
    np.testing.assert_allclose(sk.strokes[1][-1], [1, 2, 0], atol=1e-8)


def test_full_circle_is_closed_and_on_the_circle(tmp_path):
    t = np.arange(12) * TAU / 12
    sk = read_sketch(_write(tmp_path, [_circle([1, 2, 3], 0.5, range(12), t)]))
    s = sk.strokes[0]
    assert len(s) == 13 and np.array_equal(s[0], s[-1])
    np.testing.assert_allclose(np.linalg.norm(s - [1, 2, 3], axis=1), 0.5)
    np.testing.assert_allclose(s[:, 2], 3)


@pytest.mark.parametrize("kind", ["Circle", "Ellipse"])
@pytest.mark.parametrize("t0,t1", [(0.3, 2.0), (0.001, 0.004), (5.0, 7.5), (2.0, 0.3)])
def test_x1000_interior_parameters_are_undone(kind, t0, t1):
    t = np.linspace(t0, t1, 9)
    stored = t.copy()
    stored[1:-1] *= 1000
    curve = _circle([0, 0, 0], 2.0, range(9), stored)
    if kind == "Ellipse":
        curve = {**curve, "type": "Ellipse", "maj_radius": 2.0, "min_radius": 1.0,
                 "focus1": [-3 ** 0.5, 0, 0], "focus2": [3 ** 0.5, 0, 0]}
        del curve["radius"], curve["location"]
    plain = {**curve, "vert_parameters": t.tolist()}
    (fixed,), _, meta = read_abc_features(yaml.safe_dump({"curves": [curve]}))
    (ref,), _, meta_ref = read_abc_features(yaml.safe_dump({"curves": [plain]}))
    b = 1.0 if kind == "Ellipse" else 2.0
    np.testing.assert_allclose(ref, np.c_[2 * np.cos(t), b * np.sin(t), np.zeros(9)],
                               atol=1e-12)
    np.testing.assert_allclose(fixed, ref, atol=1e-12)
    assert meta["abc"]["rescaled_curves"] == [0] and meta_ref["abc"]["rescaled_curves"] == []


def test_ellipse_points_satisfy_the_focal_definition():
    t = np.linspace(0, 1.5, 7)
    e = {"type": "Ellipse", "sharp": False, "focus1": [1, 1, 1 - 4], "focus2": [1, 1, 1 + 4],
         "maj_radius": 5.0, "min_radius": 3.0, "x_axis": [0, 0, 1], "y_axis": [1, 0, 0],
         "z_axis": [0, 1, 0], "vert_indices": list(range(7)), "vert_parameters": t.tolist()}
    (s,), labels, _ = read_abc_features(yaml.safe_dump({"curves": [e]}))
    d = np.linalg.norm(s - [1, 1, -3], axis=1) + np.linalg.norm(s - [1, 1, 5], axis=1)
    np.testing.assert_allclose(d, 10.0)  # sum of focal distances = 2 * major radius
    assert labels == ["boundary"]


def test_rational_bspline_quarter_circle_and_degree_one_polyline():
    w = 2 ** -0.5
    arc = {"type": "BSpline", "sharp": True, "degree": 2, "rational": True,
           "closed": False, "periodic": False, "knots": [0, 0, 0, 1, 1, 1],
           "poles": [[1, 0, 0], [1, 1, 0], [0, 1, 0]], "weights": [1, w, 1],
           "vert_indices": list(range(20)), "vert_parameters": np.linspace(0, 1, 20).tolist()}
    poles = [[0, 1, 0], [1, 0, 0], [1, 1, 0], [0, 1, 1]]
    poly = {"type": "BSpline", "sharp": True, "degree": 1, "rational": False, "closed": False,
            "periodic": False, "knots": [0, 0, 1, 2, 3, 3], "poles": poles,
            "vert_indices": [19, 50, 51, 52], "vert_parameters": [0, 1, 2, 3]}
    (s, p), _, _ = read_abc_features(yaml.safe_dump({"curves": [arc, poly]}))
    np.testing.assert_allclose(np.linalg.norm(s, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(s[[0, -1]], [[1, 0, 0], [0, 1, 0]], atol=1e-12)
    np.testing.assert_allclose(p, poles, atol=1e-12)  # degree 1: the poles at the knots
    assert np.array_equal(p[0], s[-1])


def test_closed_bspline_gets_its_first_vertex_back():
    t = np.linspace(0, 4, 8, endpoint=False)
    sq = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 0]]
    c = {"type": "BSpline", "sharp": True, "degree": 1, "rational": False, "closed": True,
         "periodic": False, "knots": [0, 0, 1, 2, 3, 4, 4], "poles": sq,
         "vert_indices": list(range(8)), "vert_parameters": t.tolist()}
    (s,), _, _ = read_abc_features(yaml.safe_dump({"curves": [c]}))
    assert len(s) == 9 and np.array_equal(s[0], s[-1])
    np.testing.assert_allclose(s[2], [1, 0, 0])


def test_other_curves_are_skipped_with_a_warning_and_surfaces_counted(tmp_path):
    c = [_line([0, 0, 0], [1, 0, 0], 0, 1), {"type": "Other", "sharp": False,
                                            "vert_indices": [1, 2], "vert_parameters": [0, 1]}]
    with pytest.warns(UserWarning, match=r"curves\[1\].*Other"):
        sk = read_sketch(_write(tmp_path, c, [{"type": "Plane"}, {"type": "Plane"},
                                              {"type": "Cylinder"}]))
    assert len(sk) == 1
    abc = sk.metadata["abc"]
    assert abc["skipped_curves"] == [1] and abc["surface_types"] == {"Plane": 2, "Cylinder": 1}


def test_format_detected_by_content_and_is_read_only(tmp_path):
    p = _write(tmp_path, [_line([0, 0, 0], [1, 0, 0], 0, 1)], name="model.feat")
    assert detect_format(p) == "abc"
    sk = read_sketch(p)
    with pytest.raises(SketchFormatError, match="read-only"):
        write_sketch(tmp_path / "out.yml", sk)


@pytest.mark.parametrize("breaker,needle", [
    (lambda c: c.pop("radius"), "missing 'radius'"),
    (lambda c: c.update(vert_parameters=[0, 1]), "3 vert_indices but 2"),
    (lambda c: c.update(x_axis=[1, 0]), "'x_axis' must be 3"),
])
def test_bad_curve_names_file_curve_and_line(tmp_path, breaker, needle):
    bad = _circle([0, 0, 0], 1.0, [7, 8, 9], [0, 0.1, 0.2])
    breaker(bad)
    p = _write(tmp_path, [_line([0, 0, 0], [1, 0, 0], 0, 1), bad])
    with pytest.raises(SketchFormatError) as info:
        read_sketch(p)
    err = info.value
    assert err.path == str(p) and needle in err.message and "curves[1] (Circle)" in err.message
    lines = p.read_text().splitlines()
    assert lines[err.line - 1].lstrip().startswith("- ")  # the line opening curves[1]
    assert sum(ln.startswith("- ") for ln in lines[:err.line]) == 2


def test_invalid_yaml_gives_the_line(tmp_path, capsys):
    p = tmp_path / "x_features_000.yml"
    p.write_text("curves:\n  - type: Line\n    location: [0, 0\n  - type: [\n")
    assert main(["snap", str(p), "-o", str(tmp_path / "n.json")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(p) in err[0] and "invalid YAML" in err[0]


def _box_curves():
    corners = np.array([[x, y, z] for x in (0, 2) for y in (0, 1) for z in (0, 1.5)], float)
    edges = [(a, b) for a in range(8) for b in range(a + 1, 8)
             if np.count_nonzero(corners[a] != corners[b]) == 1]
    return [_line(corners[a], corners[b], a, b) for a, b in edges]


def _cylinder_curves(n=6):
    """A cylinder as ABC may split it: each circle in four arcs (one stored x1000), four
    straight seams; vertex ``v + n * k`` is the start of arc ``k``."""
    arcs, seams = [], []
    for z, v in ((0.0, 0), (2.0, 100)):
        for k in range(4):
            t = np.linspace(k, k + 1, n + 1) * np.pi / 2
            end = v + n * ((k + 1) % 4)
            arcs.append(_circle([0, 0, z], 1.0, [v + n * k, *range(v + n * k + 1,
                                                                   v + n * k + n), end], t))
    arcs[5]["vert_parameters"][1:-1] = (np.asarray(arcs[5]["vert_parameters"][1:-1])
                                        * 1000).tolist()
    for k in range(4):
        a = [np.cos(k * np.pi / 2), np.sin(k * np.pi / 2), 0]
        seams.append(_line(a, np.add(a, [0, 0, 2]), n * k, 100 + n * k))
    return arcs + seams


def _off_box(v):
    """Distance of points to the surface of the box [0, 2] x [0, 1] x [0, 1.5]."""
    return np.abs(np.c_[v, v - [2, 1, 1.5]]).min(axis=1)


def _off_cylinder(v):
    """Distance of points to the closed cylinder of radius 1 from z = 0 to z = 2."""
    r = np.linalg.norm(v[:, :2], axis=1)
    return np.minimum(np.abs(r - 1), np.where(r < 1 + 1e-9, np.abs(np.c_[v[:, 2],
                                                                  v[:, 2] - 2]).min(1), 9))


# OBJ output carries 8 significant digits; the classical fit of a quarter cylinder strays
# a few percent of the radius from it between the curves.
@pytest.mark.parametrize("curves,off,n_patches,tol", [(_box_curves(), _off_box, 6, 1e-6),
                                                       (_cylinder_curves(), _off_cylinder, 6,
                                                        0.05)])
def test_abc_fixture_surfaces_end_to_end(tmp_path, curves, off, n_patches, tol):
    import trimesh

    p = _write(tmp_path, curves)
    out, rep = tmp_path / "out", tmp_path / "r.json"
    assert main(["surface", str(p), "--out-dir", str(out), "--report", str(rep)]) == 0
    row = json.loads(rep.read_text())["rows"][0]
    assert row["route"] == "classical" and row["patches"] == n_patches
    assert row["fidelity"] == 1.0  # every curve on the surface
    mesh = trimesh.load(out / (p.stem + ".obj"), process=False)
    assert off(np.asarray(mesh.vertices)).max() < tol
