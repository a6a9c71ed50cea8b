"""What a B-rep part is, and how close a rebuilt one comes: faces by kind, volume, F-score.

:func:`shape_truth` reads a solid's faces (OpenCascade's surface type and area each),
its volume and a fine triangulation with the face of every triangle.
:func:`score_against` compares a rebuilt B-rep (and the mesh of the same run) with
it: whether the rebuilt shape is one valid closed solid of nearly the true volume, the
F-score of both against the truth's triangulation, and the share of the truth's
analytic area (planes, cylinders, cones, spheres, tori) that the rebuilt B-rep covers
with a face of the same kind.

Needs OpenCascade (the ``[cad]`` extra), imported inside the functions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.distance import point_surface_distance
from ..core.geometry import sample_surface
from ..evaluate.metrics import evaluate_mesh

__all__ = ["ShapeTruth", "shape_truth", "triangulate", "score_against", "solid_check",
           "ANALYTIC_KINDS", "MESH_DEFLECTION", "KIND_SAMPLES", "NEAR_TOL", "VOLUME_TOL"]

#: Surface kinds that count as analytic, by OpenCascade's ``GeomAbs`` names.
ANALYTIC_KINDS = {"GeomAbs_Plane": "plane", "GeomAbs_Cylinder": "cylinder",
                  "GeomAbs_Cone": "cone", "GeomAbs_Sphere": "sphere", "GeomAbs_Torus": "torus"}
#: Linear deflection of the triangulations, fraction of the diagonal (angular: 0.1 rad).
MESH_DEFLECTION = 5e-4
#: Points sampled on the truth to measure the kinds recovered.
KIND_SAMPLES = 20_000
#: A truth sample counts as covered by a rebuilt face within this fraction of the diagonal.
NEAR_TOL = 2e-3
#: The rebuilt solid's volume is "close" within this relative error.
VOLUME_TOL = 0.01


@dataclass
class ShapeTruth:
    """A part's truth.

    Attributes
    ----------
    kinds : list of str
        Per face, ``"plane"`` ... ``"torus"`` or ``"bspline"`` / ``"other"``.
    areas : (F,) float64
        Per face.
    volume : float
    vertices : (V, 3) float64
    triangles : (T, 3) int64
        The triangulation.
    triangle_face : (T,) int64
        The face of each triangle.
    diagonal : float
    """

    kinds: list
    areas: np.ndarray
    volume: float
    vertices: np.ndarray
    triangles: np.ndarray
    triangle_face: np.ndarray
    diagonal: float

    @property
    def analytic_area(self) -> float:
        return float(sum(a for k, a in zip(self.kinds, self.areas) if k in _NAMES))


_NAMES = set(ANALYTIC_KINDS.values())


def _faces(shape) -> list:
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    out, exp = [], TopExp_Explorer(shape, TopAbs_FACE)
    while exp.More():
        out.append(TopoDS.Face(exp.Current()))
        exp.Next()
    return out


def _kind(face) -> str:
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    name = BRepAdaptor_Surface(face).GetType().name
    return ANALYTIC_KINDS.get(name, "bspline" if "BSpline" in name else "other")


def _diagonal(shape) -> float:
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    b = Bnd_Box()
    BRepBndLib.Add_s(shape, b)
    lo, hi = b.CornerMin(), b.CornerMax()
    return float(lo.Distance(hi))


def triangulate(shape, *, deflection: float = MESH_DEFLECTION):
    """Triangles of every face of ``shape``.

    Returns
    -------
    vertices : (V, 3) float64
    triangles : (T, 3) int64
        Oriented with their faces.
    triangle_face : (T,) int64
        Index of the face (in ``TopExp_Explorer`` order) of each triangle.
    """
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.TopAbs import TopAbs_REVERSED
    from OCP.TopLoc import TopLoc_Location
    BRepMesh_IncrementalMesh(shape, deflection * _diagonal(shape), False, 0.1, True)
    V, T, TF, base = [], [], [], 0
    for fi, f in enumerate(_faces(shape)):
        tri = BRep_Tool.Triangulation_s(f, TopLoc_Location())
        if tri is None:
            continue
        v = np.array([[p.X(), p.Y(), p.Z()] for p in
                      (tri.Node(i) for i in range(1, tri.NbNodes() + 1))])
        t = np.array([tri.Triangle(i).Get() for i in range(1, tri.NbTriangles() + 1)],
                     np.int64) - 1
        if f.Orientation() == TopAbs_REVERSED:
            t = t[:, ::-1]
        V.append(v)
        T.append(t + base)
        TF.append(np.full(len(t), fi, np.int64))
        base += len(v)
    if not T:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64), np.zeros(0, np.int64)
    return np.concatenate(V), np.concatenate(T), np.concatenate(TF)


def shape_truth(shape) -> ShapeTruth:
    """Faces (kind, area), volume and triangulation of a solid."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    faces = _faces(shape)
    areas = []
    for f in faces:
        g = GProp_GProps()
        BRepGProp.SurfaceProperties_s(f, g)
        areas.append(g.Mass())
    g = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, g)
    V, T, TF = triangulate(shape)
    return ShapeTruth([_kind(f) for f in faces], np.asarray(areas, np.float64), float(g.Mass()),
                      V, T, TF, _diagonal(shape))


def solid_check(shape) -> dict:
    """``solids`` (count), ``valid`` (``BRepCheck_Analyzer``), ``closed`` (no free edge),
    ``volume`` (total, ``BRepGProp``)."""
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    def count(s, kind):
        exp, k = TopExp_Explorer(s, kind), 0
        while exp.More():
            k += 1
            exp.Next()
        return k
    fb = ShapeAnalysis_FreeBounds(shape, 1e-7)
    free = count(fb.GetOpenWires(), TopAbs_EDGE) + count(fb.GetClosedWires(), TopAbs_EDGE)
    g = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, g)
    return {"solids": count(shape, TopAbs_SOLID),
            "valid": bool(BRepCheck_Analyzer(shape).IsValid()), "closed": free == 0,
            "volume": float(g.Mass())}


def score_against(truth: ShapeTruth, shape, mesh=None, *, seed: int = 0) -> dict:
    """Score a rebuilt B-rep (and the mesh of the same run) against a part's truth.

    Parameters
    ----------
    truth : ShapeTruth
    shape : TopoDS_Shape
        The rebuilt B-rep (as written or read back).
    mesh : trimesh.Trimesh or (vertices, faces), optional
        The run's mesh output.
    seed : int
        Seed of the samplings.

    Returns
    -------
    dict
        ``solid_ok`` (one valid closed solid, volume > 0 within :data:`VOLUME_TOL` of
        the truth's), ``solids``, ``valid``, ``closed``, ``volume``, ``volume_error``
        (relative), ``f_cad`` and ``f_mesh`` (F-score x 100 at 0.01 of the longest
        side, :func:`curvenet.evaluate.evaluate_mesh`), ``analytic_recovered`` (share of
        the truth's analytic area nearest to a rebuilt face of its own kind, within
        :data:`NEAR_TOL` of the diagonal), ``kinds`` (the rebuilt faces' kinds by count).
    """
    chk = solid_check(shape)
    vol_err = abs(chk["volume"] - truth.volume) / max(truth.volume, 1e-300)
    ok = chk["solids"] == 1 and chk["valid"] and chk["closed"] and chk["volume"] > 0 \
        and vol_err <= VOLUME_TOL
    V, T, TF = triangulate(shape)
    kinds_out = [_kind(f) for f in _faces(shape)]
    out = dict(chk, solid_ok=bool(ok), volume_error=float(vol_err),
               kinds={k: kinds_out.count(k) for k in sorted(set(kinds_out))})
    ref = (truth.vertices, truth.triangles)
    out["f_cad"] = 100.0 * evaluate_mesh((V, T), ref, n_samples=20_000, seed=seed)["fscore"] \
        if len(T) else 0.0
    out["f_mesh"] = None if mesh is None else \
        100.0 * evaluate_mesh(mesh, ref, n_samples=20_000, seed=seed)["fscore"]
    out["analytic_recovered"] = _kinds_recovered(truth, V, T, TF, kinds_out, seed)
    return out


def _kinds_recovered(truth: ShapeTruth, V, T, TF, kinds_out, seed) -> float:
    """Share of the truth's analytic area whose nearest rebuilt face has its kind."""
    total = truth.analytic_area
    if not len(T) or total <= 0:
        return 0.0
    pts, tri = sample_surface(truth.vertices, truth.triangles, KIND_SAMPLES, seed)
    true_kind = np.array([truth.kinds[f] for f in truth.triangle_face[tri]])
    d, near = point_surface_distance(pts, V, T)
    got = np.array(kinds_out, dtype=object)[TF[near]]
    analytic = np.isin(true_kind, list(_NAMES))
    hit = analytic & (got == true_kind) & (d <= NEAR_TOL * truth.diagonal)
    # samples are area-uniform over the whole surface: the share of the analytic ones
    return float(hit.sum() / max(int(analytic.sum()), 1))
