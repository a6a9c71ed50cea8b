"""The B-rep of a surfaced curve network: shared edges, trimmed faces, sewn solids.

One ``TopoDS_Edge`` per network curve, between shared vertices: a line, a circular
arc (a full circle for a closed curve) or a B-spline approximating its samples
(:func:`curve_edges`). A patch whose boundary lies on a plane, cylinder, cone, sphere
or torus (:mod:`curvenet.surfacing.analytic`) becomes that surface trimmed by wires
of those edges, an outer wire and one per hole, a seam edge twice in one wire
(:func:`analytic_face`); ``ShapeFix_Face`` computes the curves on the surface of planes,
cylinders, cones and seam faces, framed so the face starts at angle 0, and those of
sphere and torus faces bounded by arcs are made from the curves' samples
(:mod:`curvenet.cad.pcurves`). A planar loop that
crosses itself is bad input (:class:`CadInputError`, naming the patch). The
other patches keep their B-spline faces (the Catmull-Clark limit pieces,
:func:`curvenet.cad.export.occ_faces`). :func:`build_solids` sews all faces per
manifold piece (faces meeting along the curves they share), turns each closed shell
into a solid oriented outward (``ShapeFix_Solid``) and checks it
(``BRepCheck_Analyzer``).

Everything here needs OpenCascade (``cadquery-ocp``, the ``[cad]`` extra) and imports
it inside the functions.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..core.errors import CurvenetError
from .occ import free_edge_count, heal, is_valid, occ_faces

__all__ = ["CadInputError", "TrimCheckError", "CadModel", "brep_shape", "curve_edges",
           "analytic_face", "build_solids", "solid_volumes", "face_kinds", "manifold_groups",
           "EDGE_TOL", "LINE_TOL", "SEW_TOL", "CAD_KINDS", "nurbs_convertible"]

#: Largest distance of a curve's samples to its B-spline edge, fraction of the diagonal.
EDGE_TOL = 1e-6
#: A curve is a line or a circular arc when its samples lie this close to one (fraction of
#: the curve's extent).
LINE_TOL = 1e-7

#: Analytic kinds written as trimmed elementary faces (spheres and tori with their
#: curves on the surface made from the samples, :mod:`curvenet.cad.pcurves`).
CAD_KINDS = ("plane", "cylinder", "cone", "sphere", "torus")
#: Sewing tolerance as a fraction of the diagonal, never below twice the largest gap
#: between the B-spline pieces' borders and the curves (when the shape has pieces) or
#: twice the largest residual of the trimmed faces' surfaces.
SEW_TOL = 1e-6
#: Model units: how close an edge of a natural face must come to a point to be degenerate
#: (a cone's apex, a sphere's pole).
_DEGENERATE_TOL = 1e-7

#: OpenCascade's surface types by the names the report uses.
_KIND_NAMES = {"GeomAbs_Plane": "plane", "GeomAbs_Cylinder": "cylinder",
               "GeomAbs_Cone": "cone", "GeomAbs_Sphere": "sphere", "GeomAbs_Torus": "torus",
               "GeomAbs_BSplineSurface": "bspline"}


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

    Raises
    ------
    CadInputError
        A loop crosses itself on the surface.
    """
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


def _check_plane_loops(surface, boundary, curves, name: str) -> None:
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


def face_kinds(shape) -> list:
    """The surface kind of every face of ``shape`` (``"plane"`` ... ``"bspline"``)."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    out = []
    exp = TopExp_Explorer(shape, TopAbs_FACE)
    while exp.More():
        t = BRepAdaptor_Surface(TopoDS.Face(exp.Current())).GetType()
        out.append(_KIND_NAMES.get(t.name, "other"))
        exp.Next()
    return out


def _volume(shape) -> float:
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    g = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, g)
    return float(g.Mass())


def build_solids(faces, groups, tolerance: float):
    """Sew faces per manifold group; closed shells become outward solids.

    Parameters
    ----------
    faces : list of TopoDS_Face
    groups : list of index arrays
        Faces sewn together (one manifold piece of the surface each).
    tolerance : float
        Sewing tolerance, model units.

    Returns
    -------
    shape : TopoDS_Compound
        The solids and the open shells (a lone face as it is).
    report : dict
        ``sewing_free_edges`` (edges bounding one face after sewing); the solids'
        volumes come from :func:`solid_volumes`.
    """
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
    from OCP.ShapeFix import ShapeFix_Solid
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS, TopoDS_Compound
    comp, bld = TopoDS_Compound(), BRep_Builder()
    bld.MakeCompound(comp)
    free = 0
    for group in groups:
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
            if free_edge_count(shell) == 0:
                fix = ShapeFix_Solid(BRepBuilderAPI_MakeSolid(shell).Solid())
                fix.Perform()
                bld.Add(comp, fix.Shape())
            else:
                bld.Add(comp, shell)
            exp.Next()
    return comp, {"sewing_free_edges": free}


def solid_volumes(shape) -> list:
    """The volume of each solid of ``shape``, in its order (positive: outward)."""
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    out, exp = [], TopExp_Explorer(shape, TopAbs_SOLID)
    while exp.More():
        out.append(_volume(exp.Current()))
        exp.Next()
    return out


@dataclass
class CadModel:
    """What the B-rep of a surfaced network is made of.

    Attributes
    ----------
    curves : list of (m_i, 3) float64
        The network's curves.
    ends : list of (int, int)
        Their junctions ``(u, v)``.
    positions : (V, 3) float64
        Junction positions.
    boundaries : list of list of list of (int, bool)
        Per patch ``[outer, hole_1, ...]``, oriented as the surface was.
    surfaces : list of AnalyticSurface or None
        Per patch: the elementary surface it is (a trimmed face when its kind is one
        of :data:`CAD_KINDS`), or None; the other patches' B-spline pieces are their
        faces.
    pieces : list of BSplinePiece
        Limit-surface pieces of the other patches.
    piece_patch : list of int
        The patch of each piece.
    diagonal : float
        Model units of the relative tolerances.
    gap : float
        Largest distance between neighbouring faces' borders expected (model units):
        seam gaps between pieces, the limit surface's deviation from the curves.
    names : list of str
        Per patch, how errors name it (default ``"patch i (curves [...])"``).
    """

    curves: list
    ends: list
    positions: np.ndarray
    boundaries: list
    surfaces: list
    pieces: list = field(default_factory=list)
    piece_patch: list = field(default_factory=list)
    diagonal: float = 1.0
    gap: float = 0.0
    names: list = field(default_factory=list)

    def name(self, k: int) -> str:
        if self.names:
            return self.names[k]
        ids = sorted({e for lp in self.boundaries[k] for e, _ in lp})
        return f"patch {k} (curves {ids})"


def manifold_groups(boundaries) -> list:
    """Patches joined across curves that exactly two patches share: one group per
    manifold piece of the surface (a curve bordering three or more patches, a wall
    between two cells, separates groups).

    Returns
    -------
    list of (k,) int64
        Patch indices per group, in order of their smallest.
    """
    n = len(boundaries)
    parent = np.arange(n)

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i
    users: dict = {}
    for k, b in enumerate(boundaries):
        for e in {e for lp in b for e, _ in lp}:
            users.setdefault(e, []).append(k)
    for us in users.values():
        if len(us) == 2:
            a, b = root(us[0]), root(us[1])
            parent[a] = b
    roots = np.array([root(i) for i in range(n)])
    return [np.flatnonzero(roots == r) for r in dict.fromkeys(roots.tolist())]


def brep_shape(model: CadModel, *, nurbs: bool = False):
    """The B-rep of ``model``: trimmed analytic faces, B-spline pieces, sewn solids.

    Parameters
    ----------
    model : CadModel
    nurbs : bool
        The shape will be converted to NURBS (3DM): when OpenCascade's conversion
        refuses the sewn shape (a trimmed torus whose periodic range came out a rounding
        past its period raises ``Standard_DomainError``), spheres and tori are written
        as their B-spline pieces.

    Returns
    -------
    shape : TopoDS_Compound
    report : dict
        ``faces``: per face ``patch``, ``kind`` (``"plane"`` ... ``"bspline"``) and
        ``residual`` (analytic faces: largest distance of the boundary samples to the
        surface, fraction of the diagonal); ``edges``: counts per curve kind;
        ``sew_tolerance`` (model units), ``sewing_free_edges``, ``volumes``,
        ``manifold_pieces``, ``shape_fixed`` (healed because the sewn shape was not
        valid), ``pieced_for_validity`` (sphere and torus patches written as their
        B-spline pieces because the shape with them trimmed was not valid; absent when
        none), ``pieced_for_nurbs`` (the same, because the NURBS conversion refused the
        shape with them; absent when none).

    Raises
    ------
    CadInputError
        A face whose boundary crosses itself (named by its patch).
    """
    pieces = occ_faces(model.pieces)
    shape, rep = _brep(model, CAD_KINDS, pieces)
    pieced = {int(k) for k in model.piece_patch}
    curved = [k for k, s in enumerate(model.surfaces)
              if s is not None and s.kind in _DOUBLY_CURVED and k in pieced]
    plain = tuple(k for k in CAD_KINDS if k not in _DOUBLY_CURVED)
    if curved and not is_valid(shape):
        shape2, rep2 = _brep(model, plain, pieces)
        if is_valid(shape2):
            shape, rep = shape2, rep2
            rep["pieced_for_validity"] = curved
    if nurbs and curved and "pieced_for_validity" not in rep and not nurbs_convertible(shape):
        shape, rep = _brep(model, plain, pieces)
        rep["pieced_for_nurbs"] = curved
    rep["volumes"] = solid_volumes(shape)
    return shape, rep


#: Kinds whose trimmed faces fall back to their B-spline pieces when the shape with them
#: is not valid (their curves on the surface are made from samples).
_DOUBLY_CURVED = ("sphere", "torus")


def nurbs_convertible(shape) -> bool:
    """Whether OpenCascade converts ``shape`` (a ``TopoDS_Shape``) to NURBS."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    try:
        BRepBuilderAPI_NurbsConvert(shape, True)
    except Exception:   # OCP gives each OpenCascade exception its own class, no common base
        return False
    return True


def _brep(model: CadModel, kinds, pieces: list):
    """:func:`brep_shape` with the patches of ``kinds`` as trimmed faces and the others
    as their pieces (``pieces``: the faces of ``model.pieces``; patches with none are
    left out)."""
    diag = model.diagonal if model.diagonal > 0 else 1.0
    analytic = [k for k, s in enumerate(model.surfaces) if s is not None and s.kind in kinds]
    # the pieces' borders lie up to the gap from the curves; trimmed faces' edges are the
    # curves themselves, on their surfaces within the residual
    trimmed = set(analytic)
    with_pieces = any(int(k) not in trimmed for k in model.piece_patch)
    tol = max([SEW_TOL * diag, 2.0 * model.gap if with_pieces else 0.0]
              + [2.0 * model.surfaces[k].residual for k in analytic])
    used = {e for k in analytic for lp in model.boundaries[k] for e, _ in lp}
    edges = curve_edges(model.curves, model.ends, model.positions, used, diagonal=diag)
    faces, info, of_patch = [], [], {}
    for k in analytic:
        s = model.surfaces[k]
        if s.kind == "plane":
            _check_plane_loops(s, model.boundaries[k], model.curves, model.name(k))
        try:
            face = analytic_face(s, model.boundaries[k], edges, tolerance=tol,
                                 name=model.name(k), curves=model.curves)
        except CadInputError as err:
            raise TrimCheckError(str(err), k) from None
        of_patch.setdefault(k, []).append(len(faces))
        faces.append(face)
        info.append({"patch": k, "kind": s.kind, "residual": float(s.residual / diag)})
    for pc, k in zip(pieces, model.piece_patch):
        if int(k) in trimmed:
            continue
        of_patch.setdefault(int(k), []).append(len(faces))
        faces.append(pc)
        info.append({"patch": int(k), "kind": "bspline", "residual": None})
    groups = [np.array([f for k in g for f in of_patch.get(int(k), [])], np.int64)
              for g in manifold_groups(model.boundaries)]
    groups = [g for g in groups if len(g)]
    shape, rep = build_solids(faces, groups, tol)
    fixed = not is_valid(shape)
    if fixed:
        shape = heal(shape)
    kinds: dict = {}
    for _, kind in edges.values():
        kinds[kind] = kinds.get(kind, 0) + 1
    rep.update(faces=info, edges=kinds, sew_tolerance=float(tol), manifold_pieces=len(groups),
               shape_fixed=fixed)
    return shape, rep
