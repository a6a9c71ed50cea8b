"""Curves on the surface of a sphere or torus face, computed from the network's samples.

OpenCascade's ``ShapeFix_Face`` computes the curve on the surface (the *pcurve*) of
each edge by itself; on a doubly curved periodic surface it can put an arc in the
wrong period, and the face then covers the rest of the sphere (a lat-long sphere's
solid came out 11 times too large). Here the pcurves are made from the samples: each
loop's samples are mapped to the surface's ``(u, v)`` (OpenCascade's parametrisation
of ``gp_Sphere`` / ``gp_Torus`` in the frame of
:class:`~curvenet.surfacing.analytic.AnalyticSurface`), the angles unwrapped along the
whole walk so consecutive edges meet, each hole shifted by whole periods into the outer
loop's range, and every edge gets a 2D B-spline through its samples at its own 3D
parameters (same parameter). A sphere's pole, where ``u`` is undefined, takes the ``u``
of the neighbouring sample; the gap in ``u`` there is closed by a degenerate edge
(``ShapeFix_Wire``).

Needs OpenCascade, imported inside the functions.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

__all__ = ["surface_uv", "pcurve_face", "POLE_TOL"]

#: A sample is at a sphere's pole when its distance to the axis is below this fraction
#: of the radius.
POLE_TOL = 1e-9


def surface_uv(surface, points) -> np.ndarray:
    """``(u, v)`` of points on a sphere or torus, wrapped angles: (n, 2) float64.

    Sphere: ``P = O + R cos v (cos u X + sin u Y) + R sin v Z``; torus:
    ``P = O + (R + r cos v)(cos u X + sin u Y) + r sin v Z`` (OpenCascade's
    ``ElSLib``); ``u`` is NaN at a sphere's pole.
    """
    d = np.asarray(points, np.float64) - surface.origin
    x, y, z = d @ surface.xdir, d @ surface.ydir, d @ surface.axis
    rho = np.hypot(x, y)
    u = np.arctan2(y, x)
    if surface.kind == "sphere":
        v = np.arctan2(z, rho)
        u = np.where(rho <= POLE_TOL * surface.radius, np.nan, u)
    else:
        v = np.arctan2(z, rho - surface.radius)
    return np.c_[u, v]


def _fill_poles(uv) -> np.ndarray:
    """NaN ``u`` (pole samples) replaced by the nearest defined one along the curve."""
    uv = uv.copy()
    bad = np.isnan(uv[:, 0])
    if bad.all():
        uv[:, 0] = 0.0
    elif bad.any():
        idx = np.flatnonzero(~bad)
        near = idx[np.abs(np.arange(len(uv))[:, None] - idx[None]).argmin(axis=1)]
        uv[bad, 0] = uv[near[bad], 0]
    return uv


def _unwrap_loop(parts, periodic_v: bool) -> list:
    """Unwrap each part's angles, and each part's start against the previous end."""
    out, prev = [], None
    for uv in parts:
        uv = uv.copy()
        uv[:, 0] = np.unwrap(uv[:, 0])
        if periodic_v:
            uv[:, 1] = np.unwrap(uv[:, 1])
        if prev is not None:
            for k in (0, 1) if periodic_v else (0,):
                uv[:, k] += 2 * np.pi * np.round((prev[-1, k] - uv[0, k]) / (2 * np.pi))
        out.append(uv)
        prev = uv
    return out


def _params(edge, points) -> np.ndarray:
    """The edge's 3D curve parameters at its samples (projection): (n,) float64."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GeomAPI import GeomAPI_ProjectPointOnCurve
    from OCP.gp import gp_Pnt
    a = BRepAdaptor_Curve(edge)
    t0, t1 = a.FirstParameter(), a.LastParameter()
    curve = BRep_Tool.Curve_s(edge, t0, t1)
    out = np.empty(len(points))
    for i, p in enumerate(points):
        pr = GeomAPI_ProjectPointOnCurve(gp_Pnt(*map(float, p)), curve, t0, t1)
        out[i] = pr.LowerDistanceParameter() if pr.NbPoints() else np.nan
    out[0], out[-1] = t0, t1
    return out


def _pcurve(uv, params):
    from OCP.Geom2dAPI import Geom2dAPI_PointsToBSpline
    from OCP.GeomAbs import GeomAbs_C2
    from OCP.gp import gp_Pnt2d
    from OCP.OCP.collections import Array1_double, Array1_gp_Pnt2d
    keep = np.r_[True, np.diff(params) > 1e-12]
    uv, params = uv[keep], params[keep]
    P, T = Array1_gp_Pnt2d(1, len(uv)), Array1_double(1, len(uv))
    for i, ((a, b), t) in enumerate(zip(uv.tolist(), params.tolist()), 1):
        P.SetValue(i, gp_Pnt2d(a, b))
        T.SetValue(i, t)
    return Geom2dAPI_PointsToBSpline(P, T, 1 if len(uv) < 4 else 3, 8, GeomAbs_C2, 1e-9).Curve()


def pcurve_face(make_geom, surface, boundary, edges, curves, tolerance: float):
    """A sphere or torus face bounded by the loops, pcurves from the samples.

    Parameters
    ----------
    make_geom : callable
        ``AnalyticSurface -> Geom_Surface``.
    surface : AnalyticSurface
    boundary : list of list of (int, bool)
        ``[outer, hole_1, ...]`` loops of ``(curve id, forward)``, a seam twice.
    edges : dict
        ``{curve id: (TopoDS_Edge, kind)}``, each running along its curve's samples.
    curves : list of (m_i, 3) float64
    tolerance : float

    Returns
    -------
    TopoDS_Face
    """
    from OCP.BRep import BRep_Builder
    from OCP.ShapeFix import ShapeFix_Face
    from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Wire
    periodic_v = surface.kind == "torus"
    for turn in (True, False):
        loops = []
        for lp in boundary:
            parts = [_fill_poles(surface_uv(surface, np.asarray(curves[e])[:: 1 if f else -1]))
                     for e, f in lp]
            loops.append(_unwrap_loop(parts, periodic_v))
        lo = np.concatenate(loops[0]).min(axis=0)
        if turn:        # the frame turned so the face starts at u = 0 (3DM's domain)
            x = np.cos(lo[0]) * surface.xdir + np.sin(lo[0]) * surface.ydir
            surface = replace(surface, xdir=x / np.linalg.norm(x))
    b = BRep_Builder()
    face = TopoDS_Face()
    b.MakeFace(face, make_geom(surface), float(tolerance))
    shift = np.where([True, periodic_v], -2 * np.pi * np.floor(lo / (2 * np.pi)), 0.0)
    loops[0] = [uv + shift for uv in loops[0]]
    c0 = np.concatenate(loops[0]).mean(axis=0)
    for k in range(1, len(loops)):       # a hole into the outer loop's periods
        c = np.concatenate(loops[k]).mean(axis=0)
        s = np.where([True, periodic_v], 2 * np.pi * np.round((c0 - c) / (2 * np.pi)), 0.0)
        loops[k] = [uv + s for uv in loops[k]]
    seen: dict = {}
    for lp, parts in zip(boundary, loops):
        for (e, f), uv in zip(lp, parts):
            seen.setdefault(e, []).append((f, uv if f else uv[::-1]))
    for e, uses in seen.items():
        edge = edges[e][0]
        pts = np.asarray(curves[e], np.float64)
        t = _params(edge, pts)
        if len(uses) == 1:
            b.UpdateEdge(edge, _pcurve(uses[0][1], t), face, float(tolerance))
        else:                   # a seam: one pcurve per orientation
            fwd = next(uv for f, uv in uses if f)
            rev = next(uv for f, uv in uses if not f)
            b.UpdateEdge(edge, _pcurve(fwd, t), _pcurve(rev, t), face, float(tolerance))
    for lp in boundary:
        w = TopoDS_Wire()
        b.MakeWire(w)
        for e, f in lp:
            edge = edges[e][0]
            b.Add(w, edge if f else TopoDS.Edge(edge.Reversed()))
        b.Add(face, w)
    fx = ShapeFix_Face(face)
    fx.SetPrecision(float(tolerance))
    fx.FixOrientationMode = 0
    fx.Perform()
    face = fx.Face()
    outer = np.concatenate(loops[0])
    x, y = outer[:, 0], outer[:, 1]
    if np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)) < 0:
        face = TopoDS.Face(face.Reversed())     # a clockwise outer loop: the other side
    return face
