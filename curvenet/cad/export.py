"""CAD output of the classical surface: B-spline faces in STEP (OpenCascade) and 3DM (rhino3dm).

The geometry comes from :func:`curvenet.surfacing.bspline.extract_bsplines` (one
clamped bicubic B-spline per quad-grid piece of the control mesh, exact where the
control mesh is regular, fitted and measured near irregular vertices). This module
only turns those pieces into files:

* STEP (AP214 or AP242): one ``B_SPLINE_SURFACE`` face per piece, faces sewn with
  ``BRepBuilderAPI_Sewing`` so pieces meeting along a curve share that edge, one
  shell per manifold piece (curves bordering three or more patches separate them);
  each closed shell becomes a solid.
* 3DM: one NURBS surface per piece (rhino3dm has no sewing; Rhino joins them with
  ``Join``).

Both need the optional extra ``curvenet[cad]`` (``cadquery-ocp``, ``rhino3dm``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.atomic import atomic_path
from ..core.errors import InvalidParameterError, MissingDependencyError

__all__ = ["CAD_FORMATS", "STEP_SCHEMAS", "write_cad", "write_step", "write_3dm", "read_step",
           "occ_faces", "sew", "manifold_groups", "shape_report", "require_cad"]

CAD_FORMATS = (".step", ".stp", ".3dm")
#: STEP application protocols and the names OpenCascade's writer knows them by.
STEP_SCHEMAS = {"AP214": "AP214IS", "AP242": "AP242DIS"}
#: Sewing tolerance as a fraction of the diagonal, never below the largest seam gap.
SEW_TOL = 1e-6


def require_cad(fmt: str):
    """Import the package a CAD format needs, or raise MissingDependencyError."""
    name = "rhino3dm" if fmt == ".3dm" else "OCP"
    try:
        return __import__(name)
    except ImportError:
        raise MissingDependencyError(
            f"writing {fmt} needs the optional extra: pip install 'curvenet[cad]'") from None


def _quiet_occ() -> None:
    """Keep OpenCascade's progress chatter off stdout (failures still print)."""
    from OCP.Message import Message, Message_Gravity
    printers = Message.DefaultMessenger_s().Printers()
    for i in range(1, printers.Size() + 1):
        printers.Value(i).SetTraceLevel(Message_Gravity.Message_Fail)


def occ_faces(pieces: list) -> list:
    """One ``TopoDS_Face`` per B-spline piece (clamped bicubic, see the module doc)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.Geom import Geom_BSplineSurface
    from OCP.gp import gp_Pnt
    from OCP.OCP.collections import Array1_double, Array1_int, Array2_gp_Pnt

    def knots(t):
        k, m = np.unique(t, return_counts=True)
        K, Mu = Array1_double(1, len(k)), Array1_int(1, len(k))
        for i, (a, b) in enumerate(zip(k.tolist(), m.tolist()), 1):
            K.SetValue(i, a)
            Mu.SetValue(i, b)
        return K, Mu

    faces = []
    for pc in pieces:
        a, b = pc.poles.shape[:2]
        P = Array2_gp_Pnt(1, a, 1, b)
        for (i, j), (x, y, z) in zip(np.ndindex(a, b), pc.poles.reshape(-1, 3).tolist()):
            P.SetValue(i + 1, j + 1, gp_Pnt(x, y, z))
        ku, mu = knots(pc.knots_u)
        kv, mv = knots(pc.knots_v)
        srf = Geom_BSplineSurface(P, ku, kv, mu, mv, 3, 3)
        faces.append(BRepBuilderAPI_MakeFace(srf, 1e-9).Face())
    return faces


def manifold_groups(n_pieces: int, seams: list) -> list:
    """Pieces joined across manifold seams: one group per manifold piece of the surface.

    A seam is manifold when no third piece borders it (its ``manifold`` flag of
    :func:`curvenet.surfacing.bspline.extract_bsplines`); a curve shared by three or
    more patches (a wall between two cells) separates groups.

    Returns
    -------
    list of (k,) int64
    """
    parent = np.arange(n_pieces)

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    for s in seams:
        if s["manifold"]:
            a, b = (root(i) for i in s["pieces"])
            parent[a] = b
    roots = np.array([root(i) for i in range(n_pieces)])
    return [np.flatnonzero(roots == r) for r in np.unique(roots)]


def sew(faces: list, tolerance: float, groups=None):
    """Sew faces into shells, one sewing per group; closed shells become solids.

    Parameters
    ----------
    faces : list of TopoDS_Face
    tolerance : float
        Model units.
    groups : list of index arrays, optional
        Faces sewn together (:func:`manifold_groups`); default all.

    Returns
    -------
    shape : TopoDS_Compound
        The solids and the open shells.
    free_edges : int
        Edges used by one face only, summed over the groups.
    """
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS, TopoDS_Compound

    comp = TopoDS_Compound()
    bld = BRep_Builder()
    bld.MakeCompound(comp)
    free = 0
    for group in groups if groups is not None else [range(len(faces))]:
        sw = BRepBuilderAPI_Sewing(tolerance)
        for i in group:
            sw.Add(faces[i])
        sw.Perform()
        sewn = sw.SewedShape()
        free += int(sw.NbFreeEdges())
        exp = TopExp_Explorer(sewn, TopAbs_SHELL)
        if not exp.More():               # a single face: sewing returns the face itself
            bld.Add(comp, sewn)
        while exp.More():
            shell = TopoDS.Shell(exp.Current())
            if _free_edges(shell) == 0:
                bld.Add(comp, BRepBuilderAPI_MakeSolid(shell).Solid())
            else:
                bld.Add(comp, shell)
            exp.Next()
    return comp, free


def _count(shape, kind) -> int:
    from OCP.TopExp import TopExp_Explorer
    exp, k = TopExp_Explorer(shape, kind), 0
    while exp.More():
        k += 1
        exp.Next()
    return k


def _free_edges(shape) -> int:
    """Edges of ``shape`` bounding one face only (open and closed free wires)."""
    from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
    from OCP.TopAbs import TopAbs_EDGE
    fb = ShapeAnalysis_FreeBounds(shape, 1e-7)
    return _count(fb.GetOpenWires(), TopAbs_EDGE) + _count(fb.GetClosedWires(), TopAbs_EDGE)


def _valid(shape) -> bool:
    from OCP.BRepCheck import BRepCheck_Analyzer
    return bool(BRepCheck_Analyzer(shape).IsValid())


def _fix(shape):
    """``ShapeFix_Shape``: edge and vertex tolerances raised to the real distances
    between the sewn faces' borders (fitted pieces meet within their deviation, not
    exactly), same-parameter flags recomputed."""
    from OCP.ShapeFix import ShapeFix_Shape
    fx = ShapeFix_Shape(shape)
    fx.Perform()
    return fx.Shape()


def shape_report(shape) -> dict:
    """Faces, shells, solids, free edges and validity of a B-rep shape."""
    from OCP.TopAbs import TopAbs_FACE, TopAbs_SHELL, TopAbs_SOLID
    return {"faces": _count(shape, TopAbs_FACE), "shells": _count(shape, TopAbs_SHELL),
            "solids": _count(shape, TopAbs_SOLID), "free_edges": _free_edges(shape),
            "valid": _valid(shape)}


def write_step(path, bset, *, schema: str = "AP214", wires=()) -> dict:
    """Write the pieces of ``bset`` (:class:`surfacing.bspline.BSplineSet`) as STEP.

    Parameters
    ----------
    path : str or os.PathLike
    bset : BSplineSet
    schema : {"AP214", "AP242"}
    wires : list of (m, 3) float64
        Polylines written as edges beside the faces.

    Returns
    -------
    dict
        :func:`shape_report` of the written shape plus ``sew_tolerance``.
    """
    require_cad(".step")
    _quiet_occ()
    if schema not in STEP_SCHEMAS:
        raise InvalidParameterError(f"schema: {schema!r} is not one of {tuple(STEP_SCHEMAS)}")
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Controller, STEPControl_Writer

    diag = bset.report.get("diagonal", 1.0)
    gap = max((s["gap"] for s in bset.seams), default=0.0)
    tol = max(SEW_TOL, 2.0 * gap) * diag
    groups = manifold_groups(len(bset.pieces), bset.seams)
    shape, free = sew(occ_faces(bset.pieces), tol, groups)
    fixed = not _valid(shape)
    if fixed:
        shape = _fix(shape)
    shape = _with_wires(shape, wires)
    STEPControl_Controller.Init_s()              # registers the parameter the schema sets
    Interface_Static.SetCVal_s("write.step.schema", STEP_SCHEMAS[schema])
    Interface_Static.SetIVal_s("write.precision.mode", 1)   # uncertainty: largest tolerance
    writer = STEPControl_Writer()
    writer.Transfer(shape, STEPControl_AsIs)
    path = Path(path)
    with atomic_path(path) as tmp:
        if writer.Write(str(tmp)) != IFSelect_RetDone:
            raise OSError(f"{path}: the STEP writer failed")
    rep = shape_report(shape)
    rep.update(sew_tolerance=float(tol), sewing_free_edges=free, schema=schema,
               manifold_pieces=len(groups), shape_fixed=fixed, wires=len(wires))
    return rep


def _with_wires(shape, wires):
    """``shape`` and one polyline wire per ``(m, 3)`` array, in a compound."""
    if not len(wires):
        return shape
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakePolygon
    from OCP.gp import gp_Pnt
    from OCP.TopoDS import TopoDS_Compound
    comp, bld = TopoDS_Compound(), BRep_Builder()
    bld.MakeCompound(comp)
    bld.Add(comp, shape)
    for w in wires:
        poly = BRepBuilderAPI_MakePolygon()
        for x, y, z in np.asarray(w, np.float64).tolist():
            poly.Add(gp_Pnt(x, y, z))
        bld.Add(comp, poly.Wire())
    return comp


def read_step(path):
    """Read a STEP file back into one ``TopoDS_Shape``."""
    require_cad(".step")
    _quiet_occ()
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader
    rd = STEPControl_Reader()
    if rd.ReadFile(str(path)) != IFSelect_RetDone:
        raise OSError(f"{path}: not readable as STEP")
    rd.TransferRoots()
    return rd.OneShape()


def write_3dm(path, bset, *, wires=()) -> dict:
    """Write the pieces of ``bset`` as NURBS surfaces in a Rhino 3DM file, and
    ``wires`` (list of ``(m, 3)`` polylines) as polyline curves.

    Returns
    -------
    dict
        ``faces``: surfaces written, ``wires``: polylines written.
    """
    rhino3dm = require_cad(".3dm")
    model = rhino3dm.File3dm()
    for pc in bset.pieces:
        a, b = pc.poles.shape[:2]
        srf = rhino3dm.NurbsSurface.Create(3, False, 4, 4, a, b)
        for (i, j), (x, y, z) in zip(np.ndindex(a, b), pc.poles.reshape(-1, 3).tolist()):
            srf.Points[i, j] = rhino3dm.Point4d(x, y, z, 1.0)
        for kv, t in ((srf.KnotsU, pc.knots_u[1:-1]), (srf.KnotsV, pc.knots_v[1:-1])):
            for i, x in enumerate(t.tolist()):
                kv[i] = x
        model.Objects.AddSurface(srf)
    for w in wires:
        model.Objects.AddPolyline([rhino3dm.Point3d(*p) for p in np.asarray(w, float).tolist()])
    path = Path(path)
    with atomic_path(path) as tmp:
        if not model.Write(str(tmp), 7):
            raise OSError(f"{path}: the 3DM writer failed")
    return {"faces": len(bset.pieces), "wires": len(wires)}


def write_cad(path, bset, *, schema: str = "AP214", wires=()) -> dict:
    """Write STEP or 3DM by the extension of ``path``; returns the writer's report.

    ``wires`` (list of ``(m, 3)`` polylines: curves that bound no surface) are written
    beside the faces as polyline edges (STEP) or polyline curves (3DM).
    """
    suffix = Path(path).suffix.lower()
    if suffix not in CAD_FORMATS:
        raise InvalidParameterError(f"output {path}: {suffix!r} is not one of {CAD_FORMATS}")
    require_cad(suffix)
    if suffix == ".3dm":
        return write_3dm(path, bset, wires=wires)
    return write_step(path, bset, schema=schema, wires=wires)
