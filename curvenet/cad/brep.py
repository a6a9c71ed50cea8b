"""The B-rep of a surfaced curve network: trimmed faces and pieces sewn into solids.

The curves' shared edges and the analytic patches' trimmed elementary faces come from
:mod:`curvenet.cad.faces`; the other patches keep their B-spline faces (the
Catmull-Clark limit pieces, :func:`curvenet.cad.occ.occ_faces`). :func:`build_solids`
sews all faces per manifold piece (faces meeting along the curves they share), turns
each closed shell into a solid oriented outward (``ShapeFix_Solid``) and checks it
(``BRepCheck_Analyzer``); :func:`brep_shape` falls back to the pieces of spheres and
tori when the shape with them trimmed is not valid.

Everything here needs OpenCascade (``cadquery-ocp``, the ``[cad]`` extra) and imports
it inside the functions.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .faces import CadInputError, TrimCheckError, analytic_face, check_plane_loops, curve_edges
from .occ import free_edge_count, heal, is_valid, occ_faces, volume

__all__ = ["CadModel", "brep_shape", "build_solids", "solid_volumes", "face_kinds",
           "manifold_groups", "SEW_TOL", "SEW_MARGINS", "CAD_KINDS", "nurbs_convertible"]

#: Analytic kinds written as trimmed elementary faces (spheres and tori with their
#: curves on the surface made from the samples, :mod:`curvenet.cad.pcurves`).
CAD_KINDS = ("plane", "cylinder", "cone", "sphere", "torus")
#: Sewing tolerance as a fraction of the diagonal, never below a margin of
#: :data:`SEW_MARGINS` times the largest gap between the B-spline pieces' borders and the
#: curves (when the shape has pieces) and the largest residual of the trimmed faces'
#: surfaces.
SEW_TOL = 1e-6
#: Margins tried in turn for STEP while the sewn shape is not valid: a face narrower than
#: the tolerance (a sliver between two strokes drawn almost on top of each other) has
#: its sides sewn together; ``ShapeFix_Shape`` makes the shape valid with degenerate
#: edges inside faces, whose curves on the surface STEP readers rebuild from their
#: neighbours, wrongly there (the file read back is not valid). The first valid shape
#: is kept; when none is, the first one, healed. 3DM keeps the first margin, healed when
#: it must be: its writer makes such edges singular trims or leaves them out of their
#: loop (:mod:`curvenet.cad.trims`), and openNURBS refused a loop of the NURBS
#: conversion of a shape sewn at a smaller margin (flowrep espresso).
SEW_MARGINS = (2.0, 1.5, 1.0)
#: OpenCascade's surface types by the names the report uses.
_KIND_NAMES = {"GeomAbs_Plane": "plane", "GeomAbs_Cylinder": "cylinder",
               "GeomAbs_Cone": "cone", "GeomAbs_Sphere": "sphere", "GeomAbs_Torus": "torus",
               "GeomAbs_BSplineSurface": "bspline"}


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
        out.append(volume(exp.Current()))
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
        as their B-spline pieces; the sewing keeps the first of :data:`SEW_MARGINS`.

    Returns
    -------
    shape : TopoDS_Compound
    report : dict
        ``faces``: per face ``patch``, ``kind`` (``"plane"`` ... ``"bspline"``) and
        ``residual`` (analytic faces: largest distance of the boundary samples to the
        surface, fraction of the diagonal); ``edges``: counts per curve kind;
        ``sew_tolerance`` (model units: for STEP the first of :data:`SEW_MARGINS` that
        gave a valid shape), ``sewing_free_edges``, ``volumes``,
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
    margins = SEW_MARGINS[:1] if nurbs else SEW_MARGINS
    shape, rep = _brep(model, CAD_KINDS, pieces, margins)
    pieced = {int(k) for k in model.piece_patch}
    curved = [k for k, s in enumerate(model.surfaces)
              if s is not None and s.kind in _DOUBLY_CURVED and k in pieced]
    plain = tuple(k for k in CAD_KINDS if k not in _DOUBLY_CURVED)
    if curved and not is_valid(shape):
        shape2, rep2 = _brep(model, plain, pieces, margins)
        if is_valid(shape2):
            shape, rep = shape2, rep2
            rep["pieced_for_validity"] = curved
    if nurbs and curved and "pieced_for_validity" not in rep and not nurbs_convertible(shape):
        shape, rep = _brep(model, plain, pieces, margins)
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


def _brep(model: CadModel, kinds, pieces: list, margins):
    """:func:`brep_shape` with the patches of ``kinds`` as trimmed faces and the others
    as their pieces (``pieces``: the faces of ``model.pieces``; patches with none are
    left out), sewn at ``margins`` in turn (:data:`SEW_MARGINS`)."""
    diag = model.diagonal if model.diagonal > 0 else 1.0
    analytic = [k for k, s in enumerate(model.surfaces) if s is not None and s.kind in kinds]
    # the pieces' borders lie up to the gap from the curves; trimmed faces' edges are the
    # curves themselves, on their surfaces within the residual
    trimmed = set(analytic)
    with_pieces = any(int(k) not in trimmed for k in model.piece_patch)
    need = max([model.gap if with_pieces else 0.0]
               + [model.surfaces[k].residual for k in analytic])
    tols = list(dict.fromkeys(max(SEW_TOL * diag, m * need) for m in margins))
    used = {e for k in analytic for lp in model.boundaries[k] for e, _ in lp}
    edges = curve_edges(model.curves, model.ends, model.positions, used, diagonal=diag)
    faces, info, of_patch = [], [], {}
    for k in analytic:
        s = model.surfaces[k]
        if s.kind == "plane":
            check_plane_loops(s, model.boundaries[k], model.curves, model.name(k))
        try:
            face = analytic_face(s, model.boundaries[k], edges, tolerance=tols[0],
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
    tries = []
    for t in tols:
        tries.append((t, *build_solids(faces, groups, t)))
        if is_valid(tries[-1][1]):
            break
    tol, shape, rep = tries[-1]
    fixed = not is_valid(shape)
    if fixed:
        tol, shape, rep = tries[0]
        shape = heal(shape)
    kinds: dict = {}
    for _, kind in edges.values():
        kinds[kind] = kinds.get(kind, 0) + 1
    rep.update(faces=info, edges=kinds, sew_tolerance=float(tol), manifold_pieces=len(groups),
               shape_fixed=fixed)
    return shape, rep
