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


#: ``ON_Surface::ISO`` flags: interior ``u`` / ``v`` = constant, the W, S, E, N sides.
_X_ISO, _Y_ISO, _W_ISO, _S_ISO, _E_ISO, _N_ISO = 1, 2, 3, 4, 5, 6
#: openNURBS's ``ON_SQRT_EPSILON`` and ``ON_EPSILON``, which its parameter tolerance uses,
#: and ``ON_ZERO_TOLERANCE``, which its iso test uses.
_ON_SQRT_EPSILON, _ON_EPSILON = 1.490116119385e-8, 2.220446049250313e-16
_ON_ZERO_TOLERANCE = 2.3283064365386962890625e-10
#: Largest offset from a side, as a fraction of the domain, that a seam or singular trim
#: is snapped across (conversions leave them up to about 6e-4 of it off at a pole).
_SIDE_SNAP = 1e-3


def _parameter_tolerance(surface, k: int, t: float) -> tuple:
    """``ON_NurbsSurface::GetParameterTolerance``: the interval around ``t`` counted as
    ``t`` in direction ``k``. Near either end of the domain it is scaled by the end
    span, not the domain (B-spline pieces have knots refined toward their sides, so a
    trim a little off a side is not on it)."""
    t0, t1 = _domain_of(surface, k)
    knots = surface.KnotsU if k == 0 else surface.KnotsV
    order = surface.OrderU if k == 0 else surface.OrderV
    cv_count = len(knots) - order + 2
    if t < knots[order - 1]:
        t1 = knots[order - 1]
    elif t > knots[cv_count - 2]:
        t0 = knots[cv_count - 2]
    t = min(max(t, t0), t1)                                  # ON_GetParameterTolerance
    dt = (t1 - t0) * 8.0 * _ON_SQRT_EPSILON + (abs(t0) + abs(t1)) * _ON_EPSILON
    dt = min(dt, 0.5 * (t1 - t0))
    return t - dt, t + dt


def _control_uv(curve) -> np.ndarray:
    """(k, 2) float64: a 2D NURBS curve's control points in Euclidean coordinates."""
    return np.array([[p.X / p.W, p.Y / p.W] for p in
                     (curve.Points[i] for i in range(len(curve.Points)))])


def _sampled_uv(curve, n: int = 33) -> np.ndarray:
    """(n, 2) float64: points of a 2D NURBS curve at ``n`` even parameters (a rational
    curve's control points may lie far off it)."""
    d = curve.Domain
    return _points3d(curve, np.linspace(d.T0, d.T1, n))[:, :2]


def _iso(curve, surface) -> int:
    """The ``m_iso`` flag openNURBS expects of a trim (``ON_Surface::IsIsoparametric``
    of the trim curve: its control points' box against the surface's domain, then
    straightness), or 0."""
    uv = _control_uv(curve)
    lo, hi = uv.min(axis=0), uv.max(axis=0)
    ext = hi - lo
    (s0, s1), (t0, t1) = (_domain_of(surface, k) for k in (0, 1))
    tol = np.array([(s1 - s0) / 32.0, (t1 - t0) / 32.0])
    if not (s0 < s1 and t0 < t1 and (ext <= tol).any()):
        return 0
    k = 0 if ext[0] * (t1 - t0) <= ext[1] * (s1 - s0) else 1
    a0, a1 = (s0, s1) if k == 0 else (t0, t1)
    low, high, inner = ((_W_ISO, _E_ISO, _X_ISO) if k == 0 else (_S_ISO, _N_ISO, _Y_ISO))
    iso = 0
    if hi[k] <= a0 + tol[k]:
        a, b = _parameter_tolerance(surface, k, a0)
        iso = low if a <= lo[k] and hi[k] <= b else 0
    elif lo[k] >= a1 - tol[k]:
        a, b = _parameter_tolerance(surface, k, a1)
        iso = high if a <= lo[k] and hi[k] <= b else 0
    if not iso and (a0 < hi[k] or lo[k] < a1):
        a, b = _parameter_tolerance(surface, k, 0.5 * (lo[k] + hi[k]))
        iso = inner if a <= lo[k] and hi[k] <= b else 0
    if iso and not (ext[k] < _ON_ZERO_TOLERANCE
                    and _ON_ZERO_TOLERANCE * 1024.0 <= ext[1 - k]):
        if not curve.IsLinear(float(ext[k])):
            iso = 0
    return iso


def _into_window(bs, uv: np.ndarray) -> np.ndarray:
    """Put a face's trims and its closed surface's domain in the same period; returns
    the shift ((2,) float64) its trims take, and may move ``bs``'s origin.

    OpenCascade's curves on a closed surface may lie in another period than the surface's
    domain (a sphere's loop at ``u`` in ``[1.7, 8.0]`` on a domain ``[-2.1, 4.2]``: NURBS
    conversion keeps the pcurves, and evaluation off the domain extrapolates). In each
    parameter in which the surface is closed, the trims move by whole periods so their
    lowest ``u`` lies in the domain; where they then still run past its end, the surface
    is made periodic, given a knot at their lowest ``u`` as its origin and opened there
    (``Geom_BSplineSurface::SetUOrigin``), so its domain is the trims' period. A face
    whose trims span more than one period is left as it is.

    Parameters
    ----------
    bs : OCP.Geom.Geom_BSplineSurface
        The face's surface, changed in place.
    uv : (n, 2) float64
        Points along all the face's trims.
    """
    shift = np.zeros(2)
    ends = bs.Bounds()
    for k in (0, 1):
        lo, hi = ends[2 * k], ends[2 * k + 1]
        period, tol = hi - lo, 1e-9 * max(1.0, hi - lo)
        closed = (bs.IsUClosed() or bs.IsUPeriodic()) if k == 0 else \
            (bs.IsVClosed() or bs.IsVPeriodic())
        a, b = uv[:, k].min(), uv[:, k].max()
        if not closed or (lo - tol <= a and b <= hi + tol) or b - a > period + tol:
            continue
        shift[k] = -np.floor((a - lo + tol) / period) * period
        a += shift[k]
        if b + shift[k] <= hi + tol:
            continue
        periodic, insert, origin, index = ((bs.SetUPeriodic, bs.InsertUKnot, bs.SetUOrigin,
                                            bs.UKnot) if k == 0 else
                                           (bs.SetVPeriodic, bs.InsertVKnot, bs.SetVOrigin,
                                            bs.VKnot))
        periodic()
        insert(a, 1, tol, True)
        n = bs.NbUKnots() if k == 0 else bs.NbVKnots()
        origin(min(range(1, n + 1), key=lambda i: abs(index(i) - a)))
    return shift


def _shifted(curve, shift):
    """A 2D NURBS curve moved by ``shift`` ((2,) float64) in place; returns it."""
    import rhino3dm
    if shift.any():
        for i in range(len(curve.Points)):
            p = curve.Points[i]
            curve.Points[i] = rhino3dm.Point4d(p.X + shift[0] * p.W, p.Y + shift[1] * p.W,
                                               p.Z, p.W)
    return curve


def _domain_of(surface, k: int) -> tuple:
    d = surface.Domain(k)
    return min(d.T0, d.T1), max(d.T0, d.T1)


def _close_loop(curves) -> None:
    """Make consecutive curves of a loop meet exactly: each junction's end control points
    (the ends of clamped curves) moved to their mean. Trims of a loop (sewn faces' curves
    on the surface meet within the sewing tolerance only) and, as a loop of one, a 3D
    edge curve that starts and ends at one vertex: openNURBS wants them to meet."""
    import rhino3dm
    for a, b in zip(curves, curves[1:] + curves[:1]):
        pa, pb = a.Points[len(a.Points) - 1], b.Points[0]
        x, y, z = (0.5 * (getattr(pa, k) / pa.W + getattr(pb, k) / pb.W) for k in "XYZ")
        a.Points[len(a.Points) - 1] = rhino3dm.Point4d(x * pa.W, y * pa.W, z * pa.W, pa.W)
        b.Points[0] = rhino3dm.Point4d(x * pb.W, y * pb.W, z * pb.W, pb.W)


def _singular_lines(c2, trims, tis) -> None:
    """A singular trim's curve made the straight line along the collapsed side, from the
    previous trim's end to the next one's start (NURBS conversion can leave it a point,
    which openNURBS rejects)."""
    import rhino3dm
    for k, t in enumerate(tis):
        if trims[t]["ei"] >= 0:
            continue
        prev, nxt = c2[trims[tis[k - 1]]["c2i"]], c2[trims[tis[(k + 1) % len(tis)]]["c2i"]]
        a, b = prev.Points[len(prev.Points) - 1], nxt.Points[0]
        t0, t1 = trims[t]["dom"]
        line = rhino3dm.NurbsCurve(2, False, 2, 2)
        line.Points[0] = rhino3dm.Point4d(a.X / a.W, a.Y / a.W, 0.0, 1.0)
        line.Points[1] = rhino3dm.Point4d(b.X / b.W, b.Y / b.W, 0.0, 1.0)
        line.Knots[0], line.Knots[1] = t0, (t1 if t1 > t0 else t0 + 1.0)
        c2[trims[t]["c2i"]] = line
        trims[t]["dom"] = _domain(line)


def _side_gap(uv, surface) -> tuple:
    """``(gap, k, t)``: the side ``u`` (``k = 0``) or ``v`` (``k = 1``) ``= t`` of the
    surface's domain nearest to a trim's control points ``uv`` (k, 2), and their largest
    distance to it as a fraction of the domain's extent in that direction."""
    off = []
    for k in (0, 1):
        t0, t1 = _domain_of(surface, k)
        off += [(float(np.abs(uv[:, k] - t).max()) / (t1 - t0), k, t) for t in (t0, t1)]
    return min(off)


def _poles_only(items, surface) -> list:
    """A loop's ``(edge, edge index, trim curve)`` items less the degenerate edges
    (index -1) that are no pole or apex: those off the domain's sides (healing closes a
    gap with one inside a face) and those whose neighbours already meet (a point between
    two trims). openNURBS takes a singular trim only along a collapsed side; without
    them the neighbours' ends are made to meet (:func:`_close_loop`)."""
    uv = [_control_uv(c) for _, _, c in items]
    extent = np.array([b - a for a, b in (_domain_of(surface, d) for d in (0, 1))])
    keep = []
    for k, (e, ei, c) in enumerate(items):
        if ei < 0:
            span = np.abs(uv[(k + 1) % len(items)][0] - uv[k - 1][-1]) / extent
            if _side_gap(uv[k], surface)[0] > _SIDE_SNAP or span.max() <= _SIDE_SNAP:
                continue
        keep.append((e, ei, c))
    return keep


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


def _seams_on_sides(c2, trims, tis, surface) -> None:
    """Seam and singular trims' curves put exactly on the side of the domain they run
    along, and the neighbouring trims' ends onto their ends: openNURBS wants their
    ``m_iso`` to be a side, and near the ends of a B-spline piece's domain its tolerance
    is the end span's (NURBS conversion and the loop's closing leave them a hair off)."""
    import rhino3dm
    for k, t in enumerate(tis):
        if not (trims[t]["seam"] or trims[t]["ei"] < 0):
            continue
        c = c2[trims[t]["c2i"]]
        uv = _control_uv(c)
        gap, d, b = _side_gap(uv, surface)
        if gap > _SIDE_SNAP and trims[t]["ei"] >= 0:    # a seam off the sides: leave it
            continue        # (a singular trim was on its side before the loop was closed)
        uv[:, d] = b
        for i in range(len(uv)):
            w = c.Points[i].W
            c.Points[i] = rhino3dm.Point4d(uv[i, 0] * w, uv[i, 1] * w, 0.0, w)
        prev = c2[trims[tis[k - 1]]["c2i"]]
        nxt = c2[trims[tis[(k + 1) % len(tis)]]["c2i"]]
        for curve, i, (x, y) in ((prev, len(prev.Points) - 1, uv[0]), (nxt, 0, uv[-1])):
            w = curve.Points[i].W
            curve.Points[i] = rhino3dm.Point4d(x * w, y * w, 0.0, w)


def _traced_tiny_loops(pts, c2, c3, edges, trims, loop_surfaces, tol: float) -> None:
    """A closed edge that stays within ``tol`` of its vertex gets, as its curve, the 3D
    image of its first trim, run from the vertex back to it.

    openNURBS checks a closed edge's direction by the sign of the dot product of its end
    tangents with those of each trim's image on its surface; on an edge no longer than a
    few tolerances (a speck of a loop where strokes cross twice) both are noise within
    the tolerance, and the signs disagree at one end. The new curve is a polyline
    through the trim's image whose first and last segments leave and reach the vertex
    along the image's end tangents, so it agrees with that trim by construction and lies
    within the tolerance of the old one.

    Parameters
    ----------
    pts : (V, 3) float64
        The vertices.
    c2, c3 : list of rhino3dm.NurbsCurve
        Trim and edge curves; ``c3`` is changed in place.
    edges, trims : list of dict
        The tables of :func:`brep_bytes`.
    loop_surfaces : list of rhino3dm.NurbsSurface
        The surface of each loop (trims name their loop by ``li``).
    tol : float
        The edges' tolerance.
    """
    import rhino3dm
    for ei, e in enumerate(edges):
        if e["vi"][0] != e["vi"][1] or not e["ti"]:
            continue
        vertex = pts[e["vi"][0]]
        if np.linalg.norm(_points3d(c3[ei], np.linspace(*e["dom"], 33)) - vertex,
                          axis=1).max() > tol:
            continue
        first = trims[e["ti"][0]]
        surface, trim = loop_surfaces[first["li"]], c2[first["c2i"]]
        t0, t1 = first["dom"]
        step = 1e-6 * (t1 - t0)
        uv = _points3d(trim, np.r_[t0, t0 + step, np.linspace(t0, t1, 33)[1:-1], t1 - step, t1])
        image = np.array([[p.X, p.Y, p.Z] for p in (surface.PointAt(u, v) for u, v, _ in uv)])
        image = np.vstack([vertex, vertex + image[1] - image[0], image[2:-2],
                           vertex + image[-2] - image[-1], vertex])
        if first["rev"]:
            image = image[::-1]
        traced = rhino3dm.NurbsCurve(3, False, 2, len(image))
        for i, p in enumerate(image):
            traced.Points[i] = rhino3dm.Point4d(*p, 1.0)
        for i, k in enumerate(np.linspace(*e["dom"], len(image))):
            traced.Knots[i] = k
        c3[ei] = traced


def _points3d(curve, ts) -> np.ndarray:
    """(len(ts), 3) float64: a rhino3dm curve's points at the parameters ``ts``."""
    return np.array([[p.X, p.Y, p.Z] for p in (curve.PointAt(t) for t in ts)])


def _domain(c) -> tuple:
    d = c.Domain
    return float(d.T0), float(d.T1)


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
            _close_loop([curve])
        edge_of[i - 1] = len(edges)
        c3.append(curve)
        edges.append({"vi": vi, "ti": [], "dom": _domain(curve)})
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
        shift = _into_window(bss, np.vstack([_sampled_uv(c) for items in wire_items
                                             for _, _, c in items]))
        surfaces.append(_on_surface(bss))
        lis = []
        for items in wire_items:
            li, tis = len(loops), []
            for e, ei, curve in _poles_only([(e, ei, _shifted(c, shift)) for e, ei, c in items],
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
                              "seam": seam, "li": li, "dom": _domain(curve)})
                c2.append(curve)
                tis.append(ti)
            _singular_lines(c2, trims, tis)
            _close_loop([c2[trims[t]["c2i"]] for t in tis])
            _seams_on_sides(c2, trims, tis, surfaces[-1])
            for t in tis:           # openNURBS checks the flag against the final curve
                trims[t]["iso"] = _iso(c2[trims[t]["c2i"]], surfaces[-1])
            loops.append({"ti": tis, "type": _OUTER if not lis else _INNER, "fi": fi - 1})
            lis.append(li)
        faces.append({"li": lis, "si": fi - 1, "rev": int(face0.Orientation() == TopAbs_REVERSED)})
    _traced_tiny_loops(pts, c2, c3, edges, trims, [surfaces[lp["fi"]] for lp in loops],
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
