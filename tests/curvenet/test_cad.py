"""STEP / 3DM export of the classical surface (optional extra curvenet[cad])."""

import sys

import numpy as np
import pytest

from curvenet.datasets import shapes
from curvenet.cli import main
from curvenet.io.network import write_network
from curvenet.pipeline import surface


def test_cad_format_without_the_extra_names_it(monkeypatch, tmp_path, capsys):
    monkeypatch.setitem(sys.modules, "OCP", None)          # import OCP -> ImportError
    monkeypatch.setitem(sys.modules, "rhino3dm", None)
    src = tmp_path / "box.json"
    write_network(src, shapes.box().network)
    for out in ("m.step", "m.3dm"):
        assert main(["surface", str(src), "-o", str(tmp_path / out), "--no-progress"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "pip install 'curvenet[cad]'" in err[0]
        assert not (tmp_path / out).exists()


def test_neural_or_soapfilm_result_refuses_cad(tmp_path):
    pytest.importorskip("OCP")
    from curvenet.core.errors import InvalidParameterError
    res = surface(shapes.box().sketch(), method="classical", surfacer="soapfilm")
    with pytest.raises(InvalidParameterError, match="classical Catmull-Clark"):
        res.save(tmp_path / "x.step")


def test_hybrid_result_with_neural_faces_refuses_cad_in_one_line(tmp_path, capsys):
    pytest.importorskip("OCP")
    from curvenet.core.errors import InvalidParameterError
    res = surface(shapes.box().sketch(), method="classical")
    n = len(res.mesh.faces)
    res.routes, res.face_route = ("classical", "neural"), (np.arange(n) >= n - 5).astype(np.uint8)
    with pytest.raises(InvalidParameterError, match="5 faces came from the neural fill") as err:
        res.save(tmp_path / "x.step")
    assert "\n" not in str(err.value) and not (tmp_path / "x.step").exists()


def test_wires_are_written_beside_the_faces(tmp_path):
    rhino3dm = pytest.importorskip("rhino3dm")
    pytest.importorskip("OCP")
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

    from curvenet import cad
    res = surface(shapes.box().sketch(), method="classical")
    wire = np.array([[2.0, 0, 0], [2.5, 0.2, 0], [3.0, 0, 0.1], [3.2, 0.4, 0.3]])
    res.routes, res.face_route = ("classical",), np.zeros(len(res.mesh.faces), np.uint8)
    res.wires = [wire]
    res.save(tmp_path / "w.step")
    assert res.diagnostics["cad"]["file"]["wires"] == 1
    shape = cad.read_step(tmp_path / "w.step")
    exp, loose = TopExp_Explorer(shape, TopAbs_EDGE, TopAbs_FACE), 0
    while exp.More():
        loose += 1
        exp.Next()
    assert loose == len(wire) - 1 and cad.shape_report(shape)["faces"] == 6
    res.save(tmp_path / "w.3dm")
    objs = [o.Geometry for o in rhino3dm.File3dm.Read(str(tmp_path / "w.3dm")).Objects]
    curves = [g for g in objs if isinstance(g, rhino3dm.PolylineCurve)]
    assert len(objs) == 7 and len(curves) == 1
    pts = np.array([[p.X, p.Y, p.Z] for p in (curves[0].Point(i)
                                              for i in range(curves[0].PointCount))])
    assert np.allclose(pts, wire)


def _face_points(shape, n=5):
    """Points of every face of a read-back shape on an n x n parameter grid."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepTools import BRepTools
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    out = []
    exp = TopExp_Explorer(shape, TopAbs_FACE)
    while exp.More():
        f = TopoDS.Face(exp.Current())
        s = BRep_Tool.Surface_s(f)
        u0, u1, v0, v1 = BRepTools.UVBounds_s(f)
        for u in np.linspace(u0, u1, n):
            for v in np.linspace(v0, v1, n):
                p = s.Value(u, v)
                out.append((p.X(), p.Y(), p.Z()))
        exp.Next()
    return np.array(out)


def _open_curves(res):
    uses = np.zeros(len(res.network.edges), int)
    for p in res.patchset.patches:
        for e in p.edges:
            uses[e] += 1
    return int((uses == 1).sum())


@pytest.mark.parametrize("make, closed, schema", [(shapes.box, True, "AP242"),
                                                  (shapes.torus, True, "AP214"),
                                                  (shapes.grid_sheet, False, "AP214")])
def test_step_round_trip(tmp_path, make, closed, schema):
    pytest.importorskip("OCP")
    from scipy.spatial import cKDTree

    from curvenet import cad
    shp = make()
    res = surface(shp.sketch(), method="classical")
    path = tmp_path / "m.step"
    res.save(path, schema=schema)
    head = path.read_text()[:2000]
    assert ("AP242_MANAGED" if schema == "AP242" else "AUTOMOTIVE_DESIGN") in head
    rep = res.diagnostics["cad"]
    back = cad.shape_report(cad.read_step(path))
    n_patches = len(res.patchset.patches)
    assert back["valid"]
    assert back["faces"] == rep["pieces"]["n_pieces"] == n_patches    # regular: 1 per patch
    assert back["free_edges"] == (0 if closed else _open_curves(res))
    assert back["solids"] == (1 if closed else 0)
    # these networks have regular control meshes: the faces are the limit surface
    assert rep["pieces"]["max_deviation"] < 1e-12
    P = _face_points(cad.read_step(path))
    d, _ = cKDTree(res.mesh.vertices).query(P)
    spacing = np.linalg.norm(np.diff(res.mesh.vertices[res.mesh.faces[:, :2]], axis=1),
                             axis=2).max()
    assert d.max() < spacing                      # on the mesh, up to its edge length
    for s in rep["seams"]:
        assert s["gap"] < 1e-9
        if not s["crease"]:
            assert s["angle"] < 1e-4


@pytest.mark.parametrize("make", [shapes.latlong_sphere, shapes.l_prism, shapes.house])
def test_irregular_shapes_graded_pieces_valid_and_close(tmp_path, make):
    """Extraordinary vertices (split patches, valence-6 centres): graded B-spline faces,
    valid closed solid, deviation well below 1e-4 of the diagonal, G1 below 1 degree."""
    pytest.importorskip("OCP")
    from curvenet import cad
    res = surface(make().sketch(), method="classical")
    res.save(tmp_path / "s.step")
    rep = res.diagnostics["cad"]
    pieces = rep["pieces"]
    back = cad.shape_report(cad.read_step(tmp_path / "s.step"))
    assert back["valid"] and back["free_edges"] == 0 and back["solids"] == 1
    n_patches = len(res.patchset.patches)
    extra = sum(c - 1 for c in pieces["pieces_per_patch"].values())
    assert back["faces"] == pieces["n_pieces"] == n_patches + extra
    smooth = [s["angle"] for s in rep["seams"] if not s["crease"]]
    assert max(smooth, default=0.0) < 1.0
    assert 0 < pieces["max_deviation"] < 2e-5 and pieces["n_exact"] < pieces["n_pieces"]


def test_flat_faces_with_holes_refuse_cad_in_one_line(tmp_path):
    """A washer's annular faces are flat: meshed in their plane over a control mesh of
    the outer loop only, so a B-spline face would fill the hole: refused, no file."""
    pytest.importorskip("OCP")
    from curvenet.core.errors import InvalidParameterError
    res = surface(shapes.washer().sketch(), method="classical")
    with pytest.raises(InvalidParameterError, match="2 faces with holes") as err:
        res.save(tmp_path / "w.step")
    assert "\n" not in str(err.value) and not (tmp_path / "w.step").exists()


@pytest.mark.parametrize("make", [shapes.torus, shapes.l_prism])
def test_3dm_round_trip(tmp_path, make):
    """Read back with rhino3dm: one surface per piece, equal to the pieces (so with
    their measured deviation) on a grid that crosses the graded knots."""
    rhino3dm = pytest.importorskip("rhino3dm")
    pytest.importorskip("OCP")
    from curvenet.surfacing.bspline import evaluate, extract_bsplines
    res = surface(make().sketch(), method="classical")
    res.save(tmp_path / "t.3dm")
    model = rhino3dm.File3dm.Read(str(tmp_path / "t.3dm"))
    srfs = [o.Geometry for o in model.Objects]
    bset = extract_bsplines(res.control_net)
    assert len(srfs) == len(bset.pieces) == res.diagnostics["cad"]["pieces"]["n_pieces"]
    for srf, pc in zip(srfs, bset.pieces):
        u = np.r_[np.linspace(0, pc.knots_u[-1], 5), 2.0 ** -np.arange(1, 7)]
        v = np.r_[np.linspace(0, pc.knots_v[-1], 4), 2.0 ** -np.arange(2, 8)]
        ours = evaluate(pc, np.repeat(u, len(v)), np.tile(v, len(u)))
        theirs = np.array([[p.X, p.Y, p.Z] for p in (srf.PointAt(a, b) for a in u for b in v)])
        assert np.abs(ours - theirs).max() < 1e-9


def test_cli_step_explain(tmp_path, capsys):
    pytest.importorskip("OCP")
    src = tmp_path / "box.json"
    write_network(src, shapes.box().network)
    assert main(["surface", str(src), "-o", str(tmp_path / "b.step"), "--explain",
                 "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "cad: 6 B-spline faces (6 exact" in out and "valid True" in out
    src2 = tmp_path / "sheet.json"
    write_network(src2, shapes.grid_sheet().network)
    rep = tmp_path / "r.json"
    assert main(["surface", str(src), str(src2), "--out-dir", str(tmp_path / "d"), "--format",
                 "step", "--report", str(rep), "--no-progress"]) == 0
    from curvenet import cad
    faces = [cad.shape_report(cad.read_step(tmp_path / "d" / f"{n}.step"))["faces"]
             for n in ("box", "sheet")]
    assert faces == [6, 9]
    assert '"cad_faces": 6' in rep.read_text().replace("\n", " ")
