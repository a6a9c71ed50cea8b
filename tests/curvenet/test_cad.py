"""STEP / 3DM export of the classical surface (optional extra curvenet[cad])."""

import importlib.util
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
    assert len(objs) == 2 and len(curves) == 1          # one joined Brep and the wire
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
    assert back["faces"] == len(rep["faces"]) == n_patches    # one face per patch
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


@pytest.mark.parametrize("make", [shapes.ellipsoid, shapes.l_prism, shapes.house])
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
    flat = {f["patch"] for f in rep["faces"] if f["kind"] == "plane"}
    extra = sum(c - 1 for p, c in pieces["pieces_per_patch"].items() if int(p) not in flat)
    assert back["faces"] == len(rep["faces"]) == n_patches + extra
    smooth = [s["angle"] for s in rep["seams"] if not s["crease"]]
    assert max(smooth, default=0.0) < 1.0
    # only the B-spline faces' pieces are extracted; a graded piece deviates a little
    assert pieces["n_pieces"] == sum(f["kind"] == "bspline" for f in rep["faces"])
    assert pieces["max_deviation"] < 2e-5
    assert (pieces["max_deviation"] > 0) == (pieces["n_exact"] < pieces["n_pieces"])


def test_flat_faces_with_holes_are_trimmed_planes_of_a_valid_solid(tmp_path):
    """A washer: two annular planes (outer and inner wires) and eight quarter cylinders,
    one closed solid with the true volume, in STEP and as one joined 3DM Brep."""
    pytest.importorskip("OCP")
    rhino3dm = pytest.importorskip("rhino3dm")
    from curvenet import cad
    res = surface(shapes.washer().sketch(), method="classical")
    res.save(tmp_path / "w.step")
    rep = res.diagnostics["cad"]
    assert sorted(f["kind"] for f in rep["faces"]) == ["cylinder"] * 8 + ["plane"] * 2
    assert max(f["residual"] for f in rep["faces"]) < 1e-9
    shape = cad.read_step(tmp_path / "w.step")
    back = cad.shape_report(shape)
    assert back["valid"] and back["solids"] == 1 and back["free_edges"] == 0
    assert cad.face_kinds(shape).count("plane") == 2
    assert rep["volumes"] == [pytest.approx(np.pi * (1.0 - 0.25) * 0.2, rel=1e-9)]
    res.save(tmp_path / "w.3dm")
    (brep,) = cad.read_3dm_breps(tmp_path / "w.3dm")
    assert isinstance(brep, rhino3dm.Brep) and brep.IsSolid and brep.IsValid
    assert len(brep.Faces) == 10


def test_a_seam_bore_is_one_cylinder_face_of_the_solid(tmp_path):
    pytest.importorskip("OCP")
    from curvenet import cad
    from ._networks import bored_prism
    res = surface(bored_prism(6), method="classical", subdiv=1)
    res.save(tmp_path / "n.step")
    rep = res.diagnostics["cad"]
    back = cad.shape_report(cad.read_step(tmp_path / "n.step"))
    assert back["valid"] and back["solids"] == 1 and back["faces"] == 9
    assert [f["kind"] for f in rep["faces"]].count("cylinder") == 1
    hexagon = 6 * 0.5 * np.sin(np.pi / 3)
    assert rep["volumes"] == [pytest.approx((hexagon - np.pi * 0.25) * 0.8, rel=1e-9)]


@pytest.mark.parametrize("make", [shapes.torus, shapes.house])
def test_3dm_is_one_joined_closed_brep(tmp_path, make):
    """The faces of a closed network as one Brep (a closed polysurface), not loose
    surfaces; its faces lie on the STEP solid's."""
    pytest.importorskip("rhino3dm")
    pytest.importorskip("OCP")
    from curvenet import cad
    res = surface(make().sketch(), method="classical")
    res.save(tmp_path / "t.3dm")
    breps = cad.read_3dm_breps(tmp_path / "t.3dm")
    assert len(breps) == 1 and breps[0].IsSolid and breps[0].IsValid
    assert len(breps[0].Faces) == len(res.diagnostics["cad"]["faces"])
    assert res.diagnostics["cad"]["file"] == {"breps": 1, "faces": len(breps[0].Faces),
                                              "solids": 1, "valid": True, "wires": 0}


@pytest.mark.parametrize("stem, breps", [
    # B-spline pieces have knots refined toward their sides, and openNURBS scales its
    # parameter tolerance with the end span: a trim a hair off a side is no side iso
    # there, and a Brep whose m_iso flags disagree is invalid (the cup's three were)
    ("mingzou/cup", 3),
    # healing closes a gap in one of the submarine's loops with a degenerate edge that
    # is no pole; BRepTools_WireExplorer stopped there and the loop lost five of its
    # eight edges ("trim vertex mismatch"): the wire's own order is walked instead, the
    # degenerate edge left out and the pole trims left put on their sides
    ("mingzou/SGA_Submarine", 3),
    # a sphere face whose loop crosses the seam of the NURBS conversion's domain: its
    # trims were evaluated off the surface (see into_window)
    ("flowrep/spherecylinder", 1),
    # a speck of a closed edge in a face's loop: openNURBS judges its direction by end
    # tangents that are noise there (see traced_tiny_loops); a minute each
    pytest.param("flowrep/bottle", 1, marks=pytest.mark.slow),
    pytest.param("flowrep/espresso", 11, marks=pytest.mark.slow),
])
def test_3dm_of_public_networks_is_valid(tmp_path, data_dir, stem, breps):
    pytest.importorskip("rhino3dm")
    pytest.importorskip("OCP")
    from curvenet import cad
    res = surface(data_dir / "networks" / f"{stem}.obj", method="classical",
                  classical_options={"subdiv": 1})
    res.save(tmp_path / "c.3dm")
    got = cad.read_3dm_breps(tmp_path / "c.3dm")
    assert len(got) == breps and all(b.IsValid for b in got)


def test_tori_go_to_3dm_as_their_pieces_when_the_nurbs_conversion_refuses(tmp_path,
                                                                        monkeypatch):
    """OpenCascade's torus-to-NURBS conversion raises on some sewn trimmed tori (a
    periodic range a rounding past 2 pi: the wine glass's foot, the boat); 3DM then gets
    the tori's B-spline pieces, STEP keeps the trimmed tori."""
    pytest.importorskip("OCP")
    pytest.importorskip("rhino3dm")
    from curvenet import cad
    from curvenet.cad import brep
    res = surface(shapes.torus().sketch(), method="classical", subdiv=1)
    asked = []
    monkeypatch.setattr(brep, "nurbs_convertible", lambda shape: asked.append(shape) and False)
    res.save(tmp_path / "t.step")
    assert [f["kind"] for f in res.diagnostics["cad"]["faces"]] == ["torus"] * 24 and not asked
    res.save(tmp_path / "t.3dm")
    rep = res.diagnostics["cad"]
    assert len(asked) == 1 and len(rep["pieced_for_nurbs"]) == 24
    assert {f["kind"] for f in rep["faces"]} == {"bspline"}
    (b,) = cad.read_3dm_breps(tmp_path / "t.3dm")
    assert b.IsSolid and b.IsValid


def test_a_trimmed_face_opencascade_refuses_becomes_its_pieces(tmp_path, monkeypatch):
    """OpenCascade's wire check refusing a planar face whose samples do not cross (its
    approximated edges do: mingzou/Boat, haopan/sga_torso) no longer stops the export:
    that patch is written as its B-spline pieces and the solid stays valid."""
    pytest.importorskip("OCP")
    from curvenet import cad
    from curvenet.cad import brep
    res = surface(shapes.box().sketch(), method="classical", subdiv=1)
    real, calls = brep.analytic_face, []

    def refuse_first(surface_, boundary, *a, name, **kw):
        calls.append(name)
        if name.startswith("patch 2 "):
            raise cad.CadInputError(f"{name}: its outer loop crosses itself on its plane")
        return real(surface_, boundary, *a, name=name, **kw)
    monkeypatch.setattr(brep, "analytic_face", refuse_first)
    res.save(tmp_path / "b.step")
    rep = res.diagnostics["cad"]
    assert rep["pieced_for_trims"] == [2]
    assert sorted(f["kind"] for f in rep["faces"]) == ["bspline"] + ["plane"] * 5
    back = cad.shape_report(cad.read_step(tmp_path / "b.step"))
    assert back["valid"] and back["solids"] == 1 and back["free_edges"] == 0
    assert rep["volumes"] == [pytest.approx(1.0, rel=1e-6)]


def _strip_model(gap):
    """Three flat B-spline pieces side by side, sewn across two curves, ``gap`` apart."""
    from curvenet.cad.brep import CadModel
    from curvenet.surfacing.splines import BSplinePiece
    knots = np.r_[0, 0, 0, 0, 1, 1, 1, 1.0]
    pieces = []
    for k, (x0, x1) in enumerate([(0.0, 1.0), (1.0, 1.1), (1.1, 2.1)]):
        u, v = np.meshgrid(np.linspace(x0, x1, 4), np.linspace(0, 1, 4), indexing="ij")
        pieces.append(BSplinePiece(np.stack([u, v, 0 * u], -1), knots, knots, k, True, 0.0))
    bounds = [[[(0, True), (2, True)]], [[(0, False), (1, True), (3, True)]],
              [[(1, False), (4, True)]]]
    return CadModel(curves=[np.zeros((2, 3))] * 5, ends=[(0, 1)] * 5,
                    positions=np.zeros((2, 3)), boundaries=bounds, surfaces=[None] * 3,
                    pieces=pieces, piece_patch=[0, 1, 2], diagonal=2.3, gap=gap)


@pytest.mark.parametrize("valid_from, kept, fixed", [(1, 1, False), (9, 0, True)])
def test_sewing_tries_smaller_margins_while_the_shape_is_not_valid(monkeypatch, valid_from,
                                                                   kept, fixed):
    """A face narrower than the sewing tolerance has its sides sewn together (a sliver
    between two strokes of flowrep/espresso): the margins are tried in turn, the first
    valid shape kept, else the first one healed."""
    pytest.importorskip("OCP")
    from curvenet.cad import brep
    tried, real_build, real_valid = [], brep.build_solids, brep.is_valid
    monkeypatch.setattr(brep, "build_solids",
                        lambda faces, groups, t: tried.append(t) or real_build(faces, groups, t))
    monkeypatch.setattr(brep, "is_valid",
                        lambda shape: len(tried) > valid_from and real_valid(shape))
    shape, rep = brep.brep_shape(_strip_model(0.01))          # as for STEP
    want = [m * 0.01 for m in brep.SEW_MARGINS]
    assert tried == pytest.approx(want[:valid_from + 1] if valid_from < 3 else want)
    assert rep["sew_tolerance"] == pytest.approx(want[kept])
    assert rep["shape_fixed"] == fixed and real_valid(shape)
    # 3DM keeps the first margin, healed (its writer makes degenerate edges singular trims)
    tried.clear()
    shape, rep = brep.brep_shape(_strip_model(0.01), nurbs=True)
    assert tried == pytest.approx(want[:1]) and rep["shape_fixed"] and real_valid(shape)


@pytest.mark.slow
@pytest.mark.parametrize("stem", [
    # a cone and a torus fitted to three curves of three samples each (six points lie on
    # some cone, eight on some torus): their arcs left the surfaces, the faces came out
    # inside out and the healed shape read back invalid from STEP
    "mingzou/Boat",
    # the same on cylinders and tori, and a sliver patch between two strokes, narrower
    # than the sewing tolerance at the first margin
    "flowrep/espresso",
])
def test_step_of_public_networks_reads_back_valid(tmp_path, data_dir, stem):
    pytest.importorskip("OCP")
    from curvenet import cad
    res = surface(data_dir / "networks" / f"{stem}.obj", method="classical",
                  classical_options={"subdiv": 1})
    res.save(tmp_path / "c.step")
    assert res.diagnostics["cad"]["file"]["valid"]
    assert cad.shape_report(cad.read_step(tmp_path / "c.step"))["valid"]


def test_cli_step_explain(tmp_path, capsys):
    pytest.importorskip("OCP")
    src = tmp_path / "box.json"
    write_network(src, shapes.box().network)
    assert main(["surface", str(src), "-o", str(tmp_path / "b.step"), "--explain",
                 "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "cad: 6 faces (6 plane)" in out and "valid True" in out
    if importlib.util.find_spec("rhino3dm"):     # a 3DM report has no shells
        assert main(["surface", str(src), "-o", str(tmp_path / "b.3dm"), "--explain",
                     "--no-progress"]) == 0
        assert "cad: 1 joined Breps, 1 closed, valid True" in capsys.readouterr().out
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


@pytest.mark.parametrize("u0, u1", [(-1.0, 2.0),      # a whole period off the domain
                                     (7.0, 12.5),     # runs past the domain's end
                                     (-2.0, 4.2)])    # already in it
def test_trims_and_a_closed_surface_are_put_in_one_period(u0, u1):
    """OpenCascade's curves on a closed surface may lie in another period than the
    surface's NURBS domain (flowrep/spherecylinder: a loop at u in [1.7, 8.0] on a domain
    [-2.1, 4.2] made its 3DM invalid); after ``into_window`` the shifted trims lie in the
    domain and map to the same points of the surface."""
    pytest.importorskip("rhino3dm")
    pytest.importorskip("OCP")
    from OCP.Geom import Geom_CylindricalSurface, Geom_RectangularTrimmedSurface
    from OCP.GeomConvert import GeomConvert
    from OCP.gp import gp_Ax3
    from curvenet.cad.trims import into_window
    def converted():        # a closed, non-periodic NURBS cylinder on u in [4.28, 10.57]
        return GeomConvert.SurfaceToBSplineSurface_s(Geom_RectangularTrimmedSurface(
            Geom_CylindricalSurface(gp_Ax3(), 1.0), -2.0, -2.0 + 2 * np.pi, 0.0, 1.0))
    bs, periodic = converted(), converted()
    periodic.SetUPeriodic()         # evaluates any u as the same point of its period
    uv = np.column_stack([np.linspace(u0, u1, 50), np.linspace(0.2, 0.8, 50)])
    shift = into_window(bs, uv)
    lo, hi, _, _ = bs.Bounds()
    moved = uv + shift
    assert lo - 1e-9 <= moved[:, 0].min() and moved[:, 0].max() <= hi + 1e-9
    for (u, v), (s, t) in zip(uv, moved):
        p, q = periodic.Value(u, v), bs.Value(s, t)
        assert p.Distance(q) < 1e-9


@pytest.mark.parametrize("rev", [0, 1])
def test_a_speck_of_a_closed_edge_runs_with_its_trim(rev):
    """A closed edge within the tolerance of its vertex whose curve runs against its
    trim's image (flowrep/bottle and espresso: openNURBS found such specks "reversed"
    with either flag) gets the image as its curve: its end tangents then agree with the
    trim's image's as the ``rev`` flag says, and it stays within the tolerance. A closed
    edge longer than the tolerance is left as it is."""
    rhino3dm = pytest.importorskip("rhino3dm")
    from curvenet.cad.trims import polyline, traced_tiny_loops
    plane = rhino3dm.NurbsSurface.Create(3, False, 2, 2, 2, 2)
    for i, j in np.ndindex(2, 2):
        plane.Points[i, j] = rhino3dm.Point4d(float(i), float(j), 0.0, 1.0)
    for kv in (plane.KnotsU, plane.KnotsV):
        kv[0], kv[1] = 0.0, 1.0
    t = np.linspace(0, 2 * np.pi, 40)
    tol = 0.01
    loops = []
    for r in (0.3 * tol, 10 * tol):       # a speck, and a loop the check must leave alone
        uv = np.c_[0.5 + r * np.cos(t) - r, 0.5 + r * np.sin(t), 0 * t]
        loops.append((uv, np.c_[uv[:, :2], 0.4 * tol * np.sin(3 * t)]))   # edge off-plane
    pts = np.array([[0.5, 0.5, 0.0], [0.5, 0.5, 0.0]])
    c2 = [polyline(uv, 2, (0, 1)) for uv, _ in loops]
    # the edge runs against the trim when rev = 0 and with it when rev = 1
    c3 = [polyline(e if rev else e[::-1], 3, (0, 1)) for _, e in loops]
    edges = [{"vi": [k, k], "ti": [k], "dom": (0.0, 1.0)} for k in (0, 1)]
    trims = [{"c2i": k, "ei": k, "vi": [k, k], "rev": rev, "li": 0, "dom": (0.0, 1.0)}
             for k in (0, 1)]
    big = c3[1]
    traced_tiny_loops(pts, c2, c3, edges, trims, [plane], tol)
    assert c3[1] is big
    edge, trim = c3[0], c2[0]
    sign = -1.0 if rev else 1.0
    for a, b in ((0.0, 1.0), (1.0, 0.0)):          # trim start / end against the edge end
        tt = trim.TangentAt(a)
        te = edge.TangentAt(b if rev else a)
        assert sign * (tt.X * te.X + tt.Y * te.Y + tt.Z * te.Z) > 0.9
    on = np.array([[p.X, p.Y, p.Z] for p in (edge.PointAt(s) for s in np.linspace(0, 1, 200))])
    assert np.linalg.norm(on - pts[0], axis=1).max() <= tol
    assert np.allclose([edge.PointAtStart.X, edge.PointAtEnd.X], 0.5)
