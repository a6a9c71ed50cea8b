"""Trims of the 3DM writer as openNURBS checks them: flags, periods, loops, sides.

``ON_Brep::IsValid`` checks each trim against its surface and its edge: its ``m_iso``
flag as ``ON_Surface::IsIsoparametric`` computes it (:func:`iso`), its curve inside the
surface's domain (:func:`into_window`), consecutive trims meeting (:func:`close_loop`),
seam and singular trims on a side of the domain (:func:`seams_on_sides`,
:func:`singular_lines`, :func:`poles_only`), and a closed edge running with its trims'
images on the surface (:func:`traced_tiny_loops`). The curves are ``rhino3dm`` NURBS
curves from OpenCascade's NURBS conversion (:mod:`curvenet.cad.rhino`); the functions
change them in place or return the changes.
"""

from __future__ import annotations

import numpy as np

__all__ = ["iso", "into_window", "sampled_uv", "shifted", "close_loop", "singular_lines",
           "poles_only", "seams_on_sides", "traced_tiny_loops", "domain", "polyline"]

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


def sampled_uv(curve, n: int = 33) -> np.ndarray:
    """(n, 2) float64: points of a 2D NURBS curve at ``n`` even parameters (a rational
    curve's control points may lie far off it)."""
    d = curve.Domain
    return _points3d(curve, np.linspace(d.T0, d.T1, n))[:, :2]


def iso(curve, surface) -> int:
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


def into_window(bs, uv: np.ndarray) -> np.ndarray:
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


def shifted(curve, shift):
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


def close_loop(curves) -> None:
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


def singular_lines(c2, trims, tis) -> None:
    """A singular trim's curve made the straight line along the collapsed side, from the
    previous trim's end to the next one's start (NURBS conversion can leave it a point,
    which openNURBS rejects)."""
    for k, t in enumerate(tis):
        if trims[t]["ei"] >= 0:
            continue
        prev, nxt = c2[trims[tis[k - 1]]["c2i"]], c2[trims[tis[(k + 1) % len(tis)]]["c2i"]]
        a, b = prev.Points[len(prev.Points) - 1], nxt.Points[0]
        t0, t1 = trims[t]["dom"]
        line = polyline([[a.X / a.W, a.Y / a.W, 0.0], [b.X / b.W, b.Y / b.W, 0.0]], 2,
                        (t0, t1 if t1 > t0 else t0 + 1.0))
        c2[trims[t]["c2i"]] = line
        trims[t]["dom"] = domain(line)


def _side_gap(uv, surface) -> tuple:
    """``(gap, k, t)``: the side ``u`` (``k = 0``) or ``v`` (``k = 1``) ``= t`` of the
    surface's domain nearest to a trim's control points ``uv`` (k, 2), and their largest
    distance to it as a fraction of the domain's extent in that direction."""
    off = []
    for k in (0, 1):
        t0, t1 = _domain_of(surface, k)
        off += [(float(np.abs(uv[:, k] - t).max()) / (t1 - t0), k, t) for t in (t0, t1)]
    return min(off)


def poles_only(items, surface) -> list:
    """A loop's ``(edge, edge index, trim curve)`` items less the degenerate edges
    (index -1) that are no pole or apex: those off the domain's sides (healing closes a
    gap with one inside a face) and those whose neighbours already meet (a point between
    two trims). openNURBS takes a singular trim only along a collapsed side; without
    them the neighbours' ends are made to meet (:func:`close_loop`)."""
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


def seams_on_sides(c2, trims, tis, surface) -> None:
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


def traced_tiny_loops(pts, c2, c3, edges, trims, loop_surfaces, tol: float) -> None:
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
        c3[ei] = polyline(image, 3, e["dom"])


def polyline(points, dim: int, dom):
    """A degree-1 rhino3dm ``NurbsCurve`` of dimension ``dim`` through ``points`` ((k, 3)
    float64; z ignored when ``dim`` is 2), its knots spread evenly over ``dom`` = (t0, t1)."""
    import rhino3dm
    c = rhino3dm.NurbsCurve(dim, False, 2, len(points))
    for i, p in enumerate(np.asarray(points, np.float64).tolist()):
        c.Points[i] = rhino3dm.Point4d(*p, 1.0)
    for i, k in enumerate(np.linspace(*dom, len(points))):
        c.Knots[i] = float(k)
    return c


def _points3d(curve, ts) -> np.ndarray:
    """(len(ts), 3) float64: a rhino3dm curve's points at the parameters ``ts``."""
    return np.array([[p.X, p.Y, p.Z] for p in (curve.PointAt(t) for t in ts)])


def domain(c) -> tuple:
    d = c.Domain
    return float(d.T0), float(d.T1)
