"""OpenCascade helpers shared by the B-rep builder and the writers.

The optional extra check (:func:`require_cad`), quiet messages, B-spline pieces as
faces, counts, free edges, validity and healing. OpenCascade is imported inside the
functions, so importing this module needs no extra.
"""

from __future__ import annotations

import numpy as np

from ..core.errors import MissingDependencyError

__all__ = ["require_cad", "quiet_occ", "occ_faces", "count", "free_edge_count", "is_valid",
           "heal", "shape_report", "area", "volume"]


def require_cad(fmt: str):
    """Import the package a CAD format needs, or raise MissingDependencyError."""
    name = "rhino3dm" if fmt == ".3dm" else "OCP"
    try:
        module = __import__(name)
        if fmt == ".3dm":           # 3DM Breps are built with OpenCascade too
            __import__("OCP")
        return module
    except ImportError:
        raise MissingDependencyError(
            f"writing {fmt} needs the optional extra: pip install 'curvenet[cad]'") from None


def quiet_occ() -> None:
    """Keep OpenCascade's progress chatter off stdout (failures still print)."""
    from OCP.Message import Message, Message_Gravity
    printers = Message.DefaultMessenger_s().Printers()
    for i in range(1, printers.Size() + 1):
        printers.Value(i).SetTraceLevel(Message_Gravity.Message_Fail)


def occ_faces(pieces: list) -> list:
    """One ``TopoDS_Face`` per B-spline piece (clamped bicubic,
    :class:`curvenet.surfacing.bspline.BSplinePiece`), bounded by its natural borders."""
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


def count(shape, kind) -> int:
    """Sub-shapes of one ``TopAbs`` kind (with repeats, as ``TopExp_Explorer`` meets them)."""
    from OCP.TopExp import TopExp_Explorer
    exp, k = TopExp_Explorer(shape, kind), 0
    while exp.More():
        k += 1
        exp.Next()
    return k


def free_edge_count(shape) -> int:
    """Edges of ``shape`` bounding one face only (open and closed free wires)."""
    from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
    from OCP.TopAbs import TopAbs_EDGE
    fb = ShapeAnalysis_FreeBounds(shape, 1e-7)
    return count(fb.GetOpenWires(), TopAbs_EDGE) + count(fb.GetClosedWires(), TopAbs_EDGE)


def is_valid(shape) -> bool:
    """``BRepCheck_Analyzer``'s verdict."""
    from OCP.BRepCheck import BRepCheck_Analyzer
    return bool(BRepCheck_Analyzer(shape).IsValid())


def area(shape) -> float:
    """Signed area of a shape's faces (``BRepGProp``; a face whose wires bound the
    outside of their region counts negative)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    g = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, g)
    return float(g.Mass())


def volume(shape) -> float:
    """Signed volume a shape's faces enclose (``BRepGProp``; positive: faces outward)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    g = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, g)
    return float(g.Mass())


def heal(shape):
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
    return {"faces": count(shape, TopAbs_FACE), "shells": count(shape, TopAbs_SHELL),
            "solids": count(shape, TopAbs_SOLID), "free_edges": free_edge_count(shape),
            "valid": is_valid(shape)}
