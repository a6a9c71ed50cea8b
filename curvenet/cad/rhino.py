"""3DM output: each shell of a B-rep as one joined Rhino Brep (a closed polysurface).

rhino3dm reads and writes Breps but cannot join faces into one, so the Brep is
serialised here in openNURBS's own archive layout (``ON_Brep::Write``, chunk version
3.3, archive version 60) and handed to ``rhino3dm.Brep.Decode``; rhino3dm then checks
it (``IsValid``, ``IsSolid``) and writes the file. The shape is first converted to
NURBS by OpenCascade (``BRepBuilderAPI_NurbsConvert``: surfaces, edge curves and the
trims on the faces, consistently reparametrised); each edge is one ``ON_BrepEdge``
shared by the trims of its faces, a seam edge by two trims of one face.

The NURBS curves and surfaces themselves are built with rhino3dm and serialised by
it (``Encode``); only the Brep's tables (vertices, edges, trims, loops, faces) are
written here. Archive layout: a chunk is a 4-byte type code and an 8-byte length
(or value, for a short chunk), the length counting a trailing CRC-32 where the type
code has ``0x8000`` set; that CRC covers the chunk's own bytes, not those of the
chunks nested in it.
"""

from __future__ import annotations

import base64
import struct
import zlib
from pathlib import Path

import numpy as np

from ..core.atomic import atomic_path
from .occ import require_cad
from .trims import (close_loop, domain, into_window, iso, poles_only, sampled_uv, seams_on_sides,
                    shifted, singular_lines, traced_tiny_loops)

__all__ = ["write_3dm", "read_3dm_breps", "brep_bytes"]

#: openNURBS type codes: an anonymous chunk, and the three of a serialised object.
_ANONYMOUS = 0x40008000
_CLASS, _CLASS_UUID, _CLASS_DATA, _CLASS_END = 0x00027FFA, 0x0002FFFB, 0x0002FFFC, 0x80027FFF
#: ``ON_Brep``'s class id, as ``WriteUuid`` lays it out.
_BREP_UUID = bytes.fromhex("c5dbb56060e6d311bfe40010830122f0")
#: The archive version the Brep is written for, and the openNURBS version it names.
ARCHIVE_VERSION = 60
_OPENNURBS_VERSION = -1869833980
#: ``ON_BrepTrim`` types and ``ON_BrepLoop`` types.
_MATED, _SEAM, _BOUNDARY, _SINGULAR = 2, 3, 1, 4
_OUTER, _INNER = 1, 2


def _i(*v) -> bytes:
    return struct.pack(f"<{len(v)}i", *v)


def _d(*v) -> bytes:
    return struct.pack(f"<{len(v)}d", *v)


def _chunk(tcode: int, parts) -> bytes:
    """A long chunk: ``parts`` are bytes (the chunk's own) or nested chunks (``(bytes,)``)."""
    own = b"".join(p for p in parts if isinstance(p, bytes))
    body = b"".join(p if isinstance(p, bytes) else p[0] for p in parts)
    if tcode & 0x8000:
        body += struct.pack("<I", zlib.crc32(own))
    return struct.pack("<Iq", tcode, len(body)) + body


def _array(version: int, items, tail=()) -> tuple:
    """An anonymous chunk holding a version byte, a count, the items (each a list of
    parts, see :func:`_chunk`) and ``tail`` parts."""
    items = list(items)
    return (_chunk(_ANONYMOUS, [bytes([version]), _i(len(items)),
                                *[p for it in items for p in it], *tail]),)


def _object(geom) -> tuple:
    """``WriteObject`` of a rhino3dm curve or surface (its own class chunk)."""
    return (base64.b64decode(geom.Encode()["data"]),)


def _knots(flat) -> list:
    """openNURBS knots from OpenCascade's flat knot sequence (first and last dropped)."""
    return [flat.Value(i) for i in range(flat.Lower() + 1, flat.Upper())]


def _on_curve(bs, dim: int):
    """A Geom_BSplineCurve or Geom2d_BSplineCurve as ``rhino3dm.NurbsCurve``."""
    import rhino3dm
    rat = bool(bs.IsRational())
    n, order = bs.NbPoles(), bs.Degree() + 1
    c = rhino3dm.NurbsCurve(dim, rat, order, n)
    for i in range(n):
        p, w = bs.Pole(i + 1), bs.Weight(i + 1) if rat else 1.0
        z = p.Z() if dim == 3 else 0.0
        c.Points[i] = rhino3dm.Point4d(p.X() * w, p.Y() * w, z * w, w)
    for i, k in enumerate(_knots(bs.KnotSequence())):
        c.Knots[i] = k
    return c


def _on_surface(bs):
    import rhino3dm
    if bs.IsUPeriodic():
        bs.SetUNotPeriodic()
    if bs.IsVPeriodic():
        bs.SetVNotPeriodic()
    rat = bool(bs.IsURational() or bs.IsVRational())
    nu, nv = bs.NbUPoles(), bs.NbVPoles()
    s = rhino3dm.NurbsSurface.Create(3, rat, bs.UDegree() + 1, bs.VDegree() + 1, nu, nv)
    for i in range(nu):
        for j in range(nv):
            p, w = bs.Pole(i + 1, j + 1), bs.Weight(i + 1, j + 1) if rat else 1.0
            s.Points[i, j] = rhino3dm.Point4d(p.X() * w, p.Y() * w, p.Z() * w, w)
    for kv, flat in ((s.KnotsU, bs.UKnotSequence()), (s.KnotsV, bs.VKnotSequence())):
        ks = _knots(flat)
        if len(ks) != len(kv):
            raise ValueError(f"knots: {len(ks)} for {len(kv)} ({nu} x {nv} poles)")
        for i, k in enumerate(ks):
            kv[i] = k
    return s


def _bspline3d(edge):
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.Geom import Geom_TrimmedCurve
    from OCP.GeomConvert import GeomConvert
    a = BRepAdaptor_Curve(edge)
    t0, t1 = a.FirstParameter(), a.LastParameter()
    c = BRep_Tool.Curve_s(edge, t0, t1)
    bs = GeomConvert.CurveToBSplineCurve_s(Geom_TrimmedCurve(c, t0, t1))
    if bs.IsPeriodic():
        bs.SetNotPeriodic()
    return bs


def _bspline2d(edge, face):
    """The trim of ``edge`` (as oriented in the wire) on ``face``, running with the loop."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d
    from OCP.Geom2d import Geom2d_TrimmedCurve
    from OCP.Geom2dConvert import Geom2dConvert
    from OCP.TopAbs import TopAbs_REVERSED
    a = BRepAdaptor_Curve2d(edge, face)
    t0, t1 = a.FirstParameter(), a.LastParameter()
    c = BRep_Tool.CurveOnSurface_s(edge, face, t0, t1)
    bs = Geom2dConvert.CurveToBSplineCurve_s(Geom2d_TrimmedCurve(c, t0, t1))
    if bs.IsPeriodic():
        bs.SetNotPeriodic()
    if edge.Orientation() == TopAbs_REVERSED:
        bs.Reverse()
    return bs


def _wire_edges(wire, face) -> list:
    """The oriented edges of a wire in walking order: ``BRepTools_WireExplorer``'s, or the
    wire's own order where the explorer stops early (it gives up at a degenerate edge
    that healing put inside a face, and the loop's other edges would be lost)."""
    from OCP.BRepTools import BRepTools_WireExplorer
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    walked, we = [], BRepTools_WireExplorer(wire, face)
    while we.More():
        walked.append(we.Current())
        we.Next()
    own, ex = [], TopExp_Explorer(wire, TopAbs_EDGE)
    while ex.More():
        own.append(TopoDS.Edge(ex.Current()))
        ex.Next()
    return walked if len(walked) == len(own) else own


def brep_bytes(shape, tolerance: float) -> bytes:
    """``ON_Brep`` archive bytes of one shell (or face) of a B-rep.

    Parameters
    ----------
    shape : TopoDS_Shape
        A shell, a solid or a face; its geometry is converted to NURBS.
    tolerance : float
        Model units: the edges' and vertices' tolerance.

    Returns
    -------
    bytes
        What ``rhino3dm.Brep.Decode`` reads (base64 of it, with the versions).
    """
    from OCP.BRep import BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepTools import BRepTools
    from OCP.GeomConvert import GeomConvert
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_FORWARD, TopAbs_REVERSED, TopAbs_VERTEX
    from OCP.TopAbs import TopAbs_WIRE
    from OCP.TopExp import TopExp, TopExp_Explorer
    from OCP.TopoDS import TopoDS
    from OCP.OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as ShapeMap
    nurbs = BRepBuilderAPI_NurbsConvert(shape, True).Shape()
    maps = {}
    for kind in (TopAbs_VERTEX, TopAbs_EDGE, TopAbs_FACE):
        m = ShapeMap()
        TopExp.MapShapes_s(nurbs, kind, m)
        maps[kind] = m
    V, E, F = (maps[k] for k in (TopAbs_VERTEX, TopAbs_EDGE, TopAbs_FACE))
    pts = np.array([[p.X(), p.Y(), p.Z()] for p in
                    (BRep_Tool.Pnt_s(TopoDS.Vertex(V.FindKey(i))) for i in range(1, V.Size() + 1))])
    c3, edges, edge_of = [], [], {}
    for i in range(1, E.Size() + 1):
        e = TopoDS.Edge(E.FindKey(i))
        e = TopoDS.Edge(e.Oriented(TopAbs_FORWARD))
        if BRep_Tool.Degenerated_s(e):      # a pole or an apex: a singular trim, no edge
            continue
        curve = _on_curve(_bspline3d(e), 3)
        vi = [V.FindIndex(TopExp.FirstVertex_s(e)) - 1, V.FindIndex(TopExp.LastVertex_s(e)) - 1]
        if vi[0] == vi[1]:
            close_loop([curve])
        edge_of[i - 1] = len(edges)
        c3.append(curve)
        edges.append({"vi": vi, "ti": [], "dom": domain(curve)})
    c2, trims, loops, faces, surfaces = [], [], [], [], []
    for fi in range(1, F.Size() + 1):
        face0 = TopoDS.Face(F.FindKey(fi))
        face = TopoDS.Face(face0.Oriented(TopAbs_FORWARD))
        outer = BRepTools.OuterWire_s(face)
        wires, exp = [], TopExp_Explorer(face, TopAbs_WIRE)
        while exp.More():
            w = TopoDS.Wire(exp.Current())
            (wires.insert(0, w) if w.IsSame(outer) else wires.append(w))
            exp.Next()
        wire_items = [[(e, edge_of.get(E.FindIndex(e) - 1, -1),
                        _on_curve(_bspline2d(e, face), 2)) for e in _wire_edges(w, face)]
                      for w in wires]
        bss = GeomConvert.SurfaceToBSplineSurface_s(BRep_Tool.Surface_s(face))
        shift = into_window(bss, np.vstack([sampled_uv(c) for items in wire_items
                                             for _, _, c in items]))
        surfaces.append(_on_surface(bss))
        lis = []
        for items in wire_items:
            li, tis = len(loops), []
            for e, ei, curve in poles_only([(e, ei, shifted(c, shift)) for e, ei, c in items],
                                            surfaces[-1]):
                rev = e.Orientation() == TopAbs_REVERSED
                seam = BRep_Tool.IsClosed_s(e, face)
                ti = len(trims)
                if ei < 0:
                    vi = [V.FindIndex(TopExp.FirstVertex_s(e)) - 1] * 2
                else:
                    vi = edges[ei]["vi"][::-1] if rev else edges[ei]["vi"]
                    edges[ei]["ti"].append(ti)
                trims.append({"c2i": len(c2), "ei": ei, "vi": vi, "rev": int(rev),
                              "seam": seam, "li": li, "dom": domain(curve)})
                c2.append(curve)
                tis.append(ti)
            singular_lines(c2, trims, tis)
            close_loop([c2[trims[t]["c2i"]] for t in tis])
            seams_on_sides(c2, trims, tis, surfaces[-1])
            for t in tis:           # openNURBS checks the flag against the final curve
                trims[t]["iso"] = iso(c2[trims[t]["c2i"]], surfaces[-1])
            loops.append({"ti": tis, "type": _OUTER if not lis else _INNER, "fi": fi - 1})
            lis.append(li)
        faces.append({"li": lis, "si": fi - 1, "rev": int(face0.Orientation() == TopAbs_REVERSED)})
    traced_tiny_loops(pts, c2, c3, edges, trims, [surfaces[lp["fi"]] for lp in loops],
                       tolerance)
    for t in trims:
        if t["ei"] < 0:
            t["type"] = _SINGULAR
        elif not t["seam"]:
            t["type"] = _MATED if len(edges[t["ei"]]["ti"]) >= 2 else _BOUNDARY
        else:
            t["type"] = _SEAM
    return _brep_archive(pts, c2, c3, surfaces, edges, trims, loops, faces, tolerance)


def _brep_archive(pts, c2, c3, surfaces, edges, trims, loops, faces, tol) -> bytes:
    """``WriteObject`` of an ``ON_Brep`` from its tables (see ``ON_Brep::Write``)."""
    v_of = [[] for _ in range(len(pts))]
    for ei, e in enumerate(edges):
        for v in dict.fromkeys(e["vi"]):
            v_of[v].append(ei)
    def objects(geoms):
        return _array(0x10, [[_i(1), _object(g)] for g in geoms])
    verts = [_i(k) + _d(*p) + _i(len(v_of[k]), *v_of[k]) + _d(tol) for k, p in enumerate(pts)]
    eds = [_i(k, k, 0) + _d(*e["dom"]) + _i(*e["vi"]) + _i(len(e["ti"]), *e["ti"]) + _d(tol)
           + _d(*e["dom"]) for k, e in enumerate(edges)]
    trs = [_i(k, t["c2i"]) + _d(*t["dom"]) + _i(t["ei"], *t["vi"], t["rev"], t["type"],
                                                t["iso"], t["li"]) + _d(0.0, 0.0) + _d(*t["dom"])
           + bytes(32) + _d(0.0, 0.0) for k, t in enumerate(trims)]
    lps = [_i(k, len(lp["ti"]), *lp["ti"], lp["type"], lp["fi"]) for k, lp in enumerate(loops)]
    fcs = [_i(k, len(f["li"]), *f["li"], f["si"], f["rev"], 0) for k, f in enumerate(faces)]
    uuids = [bytes(16)] * len(faces)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    data = [bytes([0x33]), objects(c2), objects(c3), objects(surfaces),
            _array(0x10, [[v] for v in verts]), _array(0x10, [[e] for e in eds]),
            _array(0x10, [[t] for t in trs]), _array(0x10, [[lp] for lp in lps]),
            _array(0x11, [[f] for f in fcs], uuids), _d(*lo, *hi),
            (_chunk(_ANONYMOUS, [bytes(len(faces))]),), (_chunk(_ANONYMOUS, [bytes(len(faces))]),),
            _i(0), (_chunk(_ANONYMOUS, [_i(1, 1), b"\x00"]),)]
    cls = _chunk(_CLASS, [(_chunk(_CLASS_UUID, [_BREP_UUID]),), (_chunk(_CLASS_DATA, data),),
                          (struct.pack("<Iq", _CLASS_END, 0),)])
    return cls


def _shells(shape) -> list:
    """The shells of ``shape`` (solids' and open ones), or its faces when it has none."""
    from OCP.TopAbs import TopAbs_FACE, TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer
    out = []
    for kind in (TopAbs_SHELL, TopAbs_FACE):
        exp = TopExp_Explorer(shape, kind, TopAbs_SHELL if kind == TopAbs_FACE else kind)
        while exp.More():
            out.append(exp.Current())
            exp.Next()
    return out


def write_3dm(path, shape, *, wires=()) -> dict:
    """Write a B-rep as joined Breps (one per shell) in a Rhino 3DM file, and ``wires``
    (list of ``(m, 3)`` polylines) as polyline curves.

    Returns
    -------
    dict
        ``breps`` written, ``faces`` (their faces), ``solids`` (closed Breps, Rhino's
        ``IsSolid``), ``valid`` (every Brep's ``IsValid``), ``wires``.
    """
    rhino3dm = require_cad(".3dm")
    from .occ import quiet_occ
    quiet_occ()
    model = rhino3dm.File3dm()
    tol = _max_tolerance(shape)
    n_faces = solids = 0
    valid = True
    shells = _shells(shape)
    for sh in shells:
        data = brep_bytes(sh, tol)
        brep = rhino3dm.Brep.Decode({"version": 10000, "archive3dm": ARCHIVE_VERSION,
                                     "opennurbs": _OPENNURBS_VERSION,
                                     "data": base64.b64encode(data).decode()})
        if brep is None:
            raise OSError(f"{path}: rhino3dm could not read back a Brep of {sh}")
        valid &= bool(brep.IsValid)
        solids += bool(brep.IsSolid)
        n_faces += len(brep.Faces)
        model.Objects.AddBrep(brep)
    for w in wires:
        model.Objects.AddPolyline([rhino3dm.Point3d(*p) for p in np.asarray(w, float).tolist()])
    path = Path(path)
    with atomic_path(path) as tmp:
        if not model.Write(str(tmp), 7):
            raise OSError(f"{path}: the 3DM writer failed")
    return {"breps": len(shells), "faces": n_faces, "solids": solids, "valid": valid,
            "wires": len(wires)}


def _max_tolerance(shape) -> float:
    from OCP.ShapeAnalysis import ShapeAnalysis_ShapeTolerance
    return float(ShapeAnalysis_ShapeTolerance().Tolerance(shape, 1))


def read_3dm_breps(path) -> list:
    """The Breps of a 3DM file (``rhino3dm.Brep``), in file order."""
    rhino3dm = require_cad(".3dm")
    model = rhino3dm.File3dm.Read(str(path))
    if model is None:
        raise OSError(f"{path}: not readable as 3DM")
    return [o.Geometry for o in model.Objects if isinstance(o.Geometry, rhino3dm.Brep)]
