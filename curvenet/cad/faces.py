"""Edges and trimmed elementary faces of the B-rep of a surfaced curve network.

One ``TopoDS_Edge`` per network curve, between shared vertices: a line, a circular
arc (a full circle for a closed curve) or a B-spline approximating its samples
(:func:`curve_edges`). A patch whose boundary lies on a plane, cylinder, cone, sphere
or torus (:mod:`curvenet.surfacing.analytic`) becomes that surface trimmed by wires
of those edges, an outer wire and one per hole, a seam edge twice in one wire
(:func:`analytic_face`); ``ShapeFix_Face`` computes the curves on the surface of planes,
cylinders, cones and seam faces, framed so the face starts at angle 0, and those of
sphere and torus faces bounded by arcs are made from the curves' samples
(:mod:`curvenet.cad.pcurves`). A band between two parallels (or a parallel and an apex
or pole) with a seam is one turn of its surface. A planar loop that crosses itself is
bad input (:class:`CadInputError`, naming the patch). :mod:`curvenet.cad.brep` sews
these faces and the B-spline pieces into solids.

Everything here needs OpenCascade (``cadquery-ocp``, the ``[cad]`` extra) and imports
it inside the functions.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..core.errors import CurvenetError
from .occ import area

__all__ = ["CadInputError", "TrimCheckError", "curve_edges", "analytic_face",
           "check_plane_loops", "EDGE_TOL", "LINE_TOL"]

#: Largest distance of a curve's samples to its B-spline edge, fraction of the diagonal.
EDGE_TOL = 1e-6
#: A curve is a line or a circular arc when its samples lie this close to one (fraction of
#: the curve's extent).
LINE_TOL = 1e-7

#: Model units: how close an edge of a natural face must come to a point to be degenerate
#: (a cone's apex, a sphere's pole).
_DEGENERATE_TOL = 1e-7


class CadInputError(CurvenetError):
    """A face of the network has no valid B-rep (its loop crosses itself, it does not
    close): bad input, named by its patch."""


class TrimCheckError(CadInputError):
    """OpenCascade's wire check finds a loop of patch ``patch`` crossing itself on its
    analytic surface where the curves' samples do not cross in the plane's frame (or
    no such sample test exists: cylinders, cones): the trimmed face is refused, the
    patch may still be written as its B-spline pieces."""

    def __init__(self, message: str, patch: int):
        super().__init__(message)
        self.patch = int(patch)


def _pnt(p):
    from OCP.gp import gp_Pnt
    return gp_Pnt(*(float(x) for x in p))


def _dir(v):
    from OCP.gp import gp_Dir
    return gp_Dir(*(float(x) for x in v))


def _straight(c, tol):
    d = c[-1] - c[0]
    L = float(np.linalg.norm(d))
    if L <= 0:
        return False
    off = (c - c[0]) - np.outer((c - c[0]) @ (d / L), d / L)
    return float(np.linalg.norm(off, axis=1).max()) <= tol * L


def _arc_edge(c, closed, v0, v1, tol):
    """A circular arc (full circle when ``closed``) through the samples, or None."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.gp import gp_Ax2, gp_Circ

    from ..surfacing.analytic import fit_circle
    got = fit_circle(c, tol=tol)
    if got is None:
        return None
    centre, n, r = got
    x = c[0] - centre
    x = x - (x @ n) * n
    y = np.cross(n, x)
    ang = np.unwrap(np.arctan2((c - centre) @ y, (c - centre) @ x))
    if ang[-1] < ang[0]:
        n = -n
        ang = -ang
    if not np.all(np.diff(ang) > -1e-12):
        return None
    circ = gp_Circ(gp_Ax2(_pnt(centre), _dir(n), _dir(x)), float(r))
    mk = BRepBuilderAPI_MakeEdge(circ, v0, v1)
    if not mk.IsDone():
        return None
    if not closed and abs(ang[-1] - ang[0]) >= 2 * np.pi - 1e-9:
        return None
    return mk.Edge()


def _spline_edge(c, v0, v1, tol):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.GeomAbs import GeomAbs_C2
    from OCP.GeomAPI import GeomAPI_PointsToBSpline
    from OCP.OCP.collections import Array1_gp_Pnt
    arr = Array1_gp_Pnt(1, len(c))
    for i, p in enumerate(c, 1):
        arr.SetValue(i, _pnt(p))
    bs = GeomAPI_PointsToBSpline(arr, 3, 8, GeomAbs_C2, float(tol)).Curve()
    bs.SetPole(1, _pnt(c[0]))             # clamped: the end poles are the ends, made exact
    bs.SetPole(bs.NbPoles(), _pnt(c[-1]))
    mk = BRepBuilderAPI_MakeEdge(bs, v0, v1, bs.FirstParameter(), bs.LastParameter())
    if not mk.IsDone():
        raise CadInputError(f"no edge along its {len(c)} samples ({mk.Error().name})")
    return mk.Edge()


def curve_edges(curves, ends, positions, used, *, diagonal: float) -> dict:
    """One shared ``TopoDS_Edge`` per used curve.

    Parameters
    ----------
    curves : list of (m_i, 3) float64
        Network curves, each from ``positions[u]`` to ``positions[v]``.
    ends : list of (int, int)
        ``(u, v)`` junctions of each curve (``u == v``: a closed curve).
    positions : (V, 3) float64
    used : iterable of int
        The curves some B-rep face is bounded by.
    diagonal : float
        Model units of the tolerances.

    Returns
    -------
    dict
        ``{curve id: (TopoDS_Edge, kind)}``, kind ``"line"``, ``"circle"`` or
        ``"bspline"``; the edges run from ``u`` to ``v``.
    """
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeVertex
    used = sorted(set(int(i) for i in used))
    verts = {}
    for i in used:
        for x in ends[i]:
            if x not in verts:
                verts[x] = BRepBuilderAPI_MakeVertex(_pnt(positions[x])).Vertex()
    out = {}
    for i in used:
        c = np.asarray(curves[i], np.float64)
        u, v = ends[i]
        closed = u == v
        if not closed and _straight(c, LINE_TOL):
            out[i] = (BRepBuilderAPI_MakeEdge(verts[u], verts[v]).Edge(), "line")
            continue
        arc = _arc_edge(c, closed, verts[u], verts[v], LINE_TOL)
        if arc is not None:
            out[i] = (arc, "circle")
            continue
        try:
            out[i] = (_spline_edge(c, verts[u], verts[v], EDGE_TOL * diagonal), "bspline")
        except CadInputError as err:
            raise CadInputError(f"curve {i}: {err}") from None
    return out


def _geom_surface(s):
    """The ``Geom_Surface`` of an :class:`~curvenet.surfacing.analytic.AnalyticSurface`."""
    from OCP.Geom import (Geom_ConicalSurface, Geom_CylindricalSurface, Geom_Plane,
                          Geom_SphericalSurface, Geom_ToroidalSurface)
    from OCP.gp import gp_Ax3
    ax = gp_Ax3(_pnt(s.origin), _dir(s.axis), _dir(s.xdir))
    if s.kind == "plane":
        return Geom_Plane(ax)
    if s.kind == "cylinder":
        return Geom_CylindricalSurface(ax, float(s.radius))
    if s.kind == "cone":
        return Geom_ConicalSurface(ax, float(s.minor), float(s.radius))
    if s.kind == "sphere":
        return Geom_SphericalSurface(ax, float(s.radius))
    return Geom_ToroidalSurface(ax, float(s.radius), float(s.minor))


def _wire(loop, edges):
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS, TopoDS_Wire
    w, b = TopoDS_Wire(), BRep_Builder()
    b.MakeWire(w)
    for e, fwd in loop:
        edge = edges[e][0]
        b.Add(w, edge if fwd else TopoDS.Edge(edge.Reversed()))
    w.Closed(True)
    return w


def _trimmed(surface, wires, tolerance: float):
    """The surface bounded by ``wires`` (outer first), curves on it by ``ShapeFix_Face``."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.ShapeFix import ShapeFix_Face
    mk = BRepBuilderAPI_MakeFace(_geom_surface(surface), wires[0], True)
    for w in wires[1:]:
        mk.Add(w)
    fx = ShapeFix_Face(mk.Face())
    fx.SetPrecision(tolerance)
    fx.Perform()
    return fx.Face()


def analytic_face(surface, boundary, edges, *, tolerance: float, name: str, curves=None):
    """The elementary surface trimmed by the boundary's wires.

    Parameters
    ----------
    surface : AnalyticSurface
    boundary : list of list of (int, bool)
        ``[outer, hole_1, ...]`` loops of ``(curve id, forward)``.
    edges : dict
        :func:`curve_edges`.
    tolerance : float
        Model units: the precision of the wire checks.
    name : str
        Names the face in errors (``"patch 4"``).
    curves : list of (m_i, 3) float64, optional
        The curves' samples: the curves on the surface of a sphere or torus face with
        no seam (one bounded by arcs) are made from them (:mod:`curvenet.cad.pcurves`),
        not by ``ShapeFix_Face``, which can take an arc in the wrong period there; a
        band between two parallels and its seam is left to ``ShapeFix_Face``.

    Returns
    -------
    TopoDS_Face
        Bounding a positive area of the surface; reversed (its normal against the
        surface's) when the loops run clockwise about the surface's normal, as half of
        the patches do whose surface's orientation the fit chose.

    Raises
    ------
    CadInputError
        A loop crosses itself on the surface.
    """
    face = _analytic_face(surface, boundary, edges, tolerance, name, curves)
    if area(face) >= 0.0:
        return face
    from OCP.TopoDS import TopoDS
    back = [[(e, not fwd) for e, fwd in reversed(lp)] for lp in boundary]
    return TopoDS.Face(_analytic_face(surface, back, edges, tolerance, name, curves).Reversed())


def _analytic_face(surface, boundary, edges, tolerance, name, curves):
    """:func:`analytic_face` with the loops as given."""
    from OCP.BRepTools import BRepTools
    from OCP.ShapeAnalysis import ShapeAnalysis_Wire
    wires = [_wire(lp, edges) for lp in boundary]
    seam = any(len({e for e, _ in lp}) < len(lp) for lp in boundary)
    if surface.kind in ("sphere", "torus") and curves is not None and not seam:
        from .pcurves import pcurve_face
        face = pcurve_face(_geom_surface, surface, boundary, edges, curves, tolerance)
    else:
        face = _trimmed(surface, wires, tolerance)
    if surface.kind in ("cylinder", "cone") or seam:
        # turn the frame so the face starts at angle 0: its parameter range is then
        # within the surface's first period, as NURBS conversion (3DM) needs
        u0 = BRepTools.UVBounds_s(face)[0]
        if abs(u0) > 1e-12:
            x = np.cos(u0) * surface.xdir + np.sin(u0) * surface.ydir
            face = _trimmed(replace(surface, xdir=x / np.linalg.norm(x)), wires, tolerance)
        band = _full_band(surface, face, boundary, seam)
        if band is not None:
            return band
    for k, w in enumerate(wires):
        sa = ShapeAnalysis_Wire(w, face, tolerance)
        if sa.CheckSelfIntersection():
            where = "outer loop" if k == 0 else f"hole {k}"
            raise CadInputError(f"{name}: its {where} crosses itself on its {surface.kind}")
    return face


def _full_band(surface, face, boundary, seam: bool):
    """A cylinder, cone or sphere face bounded by one loop with a seam whose other edges
    are parallels (a band between two circles, or a circle and an apex or pole), as its
    natural face over one turn; else None.

    Where such a loop meets an apex or a pole, ``u`` is undefined there, and
    ``ShapeFix_Face`` closes the loop with a degenerate edge that runs the wrong way (the
    seam's curve on the surface may come out slanted too): the face passes
    ``BRepCheck`` but meshes badly, and sewing or NURBS conversion turn its curves into
    a loop over two or three periods, which openNURBS rejects. The band is the surface
    between its two heights over the full turn (the frame starts at the seam); sewing
    joins its circles to the neighbours' edges, and the seam's own edge is a line of
    the face.
    """
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    if not seam or len(boundary) != 1 or surface.kind not in ("cylinder", "cone", "sphere"):
        return None
    uv, parallel = [], []      # points of every edge's curve on the face; the parallels' v
    exp = TopExp_Explorer(face, TopAbs_EDGE)
    while exp.More():
        e = TopoDS.Edge(exp.Current())
        exp.Next()
        c = BRepAdaptor_Curve2d(e, face)
        p = np.array([[q.X(), q.Y()] for q in (c.Value(t) for t in np.linspace(
            c.FirstParameter(), c.LastParameter(), 9))])
        uv.append(p)
        if not (BRep_Tool.Degenerated_s(e) or BRep_Tool.IsClosed_s(e, face)):
            parallel.append(p[:, 1])
    v0, v1 = np.vstack(uv)[:, 1].min(), np.vstack(uv)[:, 1].max()
    residual = surface.residual / (surface.radius if surface.kind == "sphere" else 1.0)
    v_tol = max(10.0 * residual, 1e-6 * (v1 - v0))
    if not all(np.abs(v - v0).max() <= v_tol or np.abs(v - v1).max() <= v_tol
               for v in parallel):
        return None                      # an edge is no parallel: the band is not the face
    return BRepBuilderAPI_MakeFace(_geom_surface(surface), 0.0, 2.0 * np.pi, v0, v1,
                                   _DEGENERATE_TOL).Face()


def _loop_points(loop, curves) -> np.ndarray:
    """The samples of a loop of ``(curve id, forward)`` in walking order: (n, 3) float64."""
    parts = [np.asarray(curves[e], np.float64)[:: 1 if fwd else -1][:-1] for e, fwd in loop]
    return np.concatenate(parts)


def _crossings(xy) -> np.ndarray:
    """Pairs ``(i, j)`` of non-neighbouring segments of the closed polygon ``xy (n, 2)``
    that cross or touch: (k, 2) int64."""
    n = len(xy)
    a, b = xy, np.roll(xy, -1, axis=0)

    def orient(p, q, r):        # (n, n) signs of the turn p -> q -> r
        return np.sign((q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1])
                       - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0]))
    def on(p, q, r, o):         # r on segment p-q, given the turn o of p -> q -> r
        lo, hi = np.minimum(p, q), np.maximum(p, q)
        return (o == 0) & ((lo <= r) & (r <= hi)).all(axis=-1)
    C, D = a[None], b[None]
    out = []
    for s in range(0, n, _CROSS_BLOCK):         # (block, n) tests at a time
        A, B = a[s:s + _CROSS_BLOCK, None], b[s:s + _CROSS_BLOCK, None]
        o1, o2, o3, o4 = orient(A, B, C), orient(A, B, D), orient(C, D, A), orient(C, D, B)
        hit = ((o1 * o2 < 0) & (o3 * o4 < 0)) | on(A, B, C, o1) | on(A, B, D, o2) \
            | on(C, D, A, o3) | on(C, D, B, o4)
        i, j = np.nonzero(hit)
        i = i + s
        keep = (j >= i + 2) & ~((i == 0) & (j == n - 1))   # neighbours share an end
        out.append(np.c_[i[keep], j[keep]])
    return np.concatenate(out) if out else np.zeros((0, 2), np.int64)


#: Rows of segment pairs tested at once by :func:`_crossings`.
_CROSS_BLOCK = 256


def check_plane_loops(surface, boundary, curves, name: str) -> None:
    """Raise :class:`CadInputError` when a planar face's loop crosses itself or another
    of its loops (in the plane's frame)."""
    loops = [_loop_points(lp, curves) for lp in boundary]
    frame = np.stack([surface.xdir, surface.ydir], axis=1)
    for k, p in enumerate(loops):
        if len(p) >= 4 and len(_crossings((p - surface.origin) @ frame)):
            where = "outer loop" if k == 0 else f"hole {k}"
            raise CadInputError(f"{name}: its {where} crosses itself")
    if len(loops) > 1:
        from matplotlib.path import Path
        outer = Path((loops[0] - surface.origin) @ frame)
        for k, p in enumerate(loops[1:], 1):
            if not outer.contains_points((p - surface.origin) @ frame).all():
                raise CadInputError(f"{name}: its hole {k} crosses its outer loop")
