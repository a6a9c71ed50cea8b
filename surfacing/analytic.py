"""Analytic faces: the plane, cylinder, cone, sphere or torus a patch's boundary lies on.

A CAD part's faces are mostly elementary surfaces, and a face's boundary curves fix
them: two coaxial circles and a straight seam lie on one cylinder, three quarter
circles meeting at right angles on one sphere. :func:`fit_analytic` fits each kind,
simplest first (plane, cylinder, cone, sphere, torus), to the boundary samples and
keeps the first whose residual at *every* sample is within the tolerance, among the
kinds the samples over-determine (:data:`FREEDOMS`) and whose surface holds the arcs
drawn through the curves' samples; a free-form boundary fits none and stays a
B-spline face. The classical route then puts the
patch's mesh on that surface (:func:`AnalyticSurface.project`) and the CAD export
writes the surface itself, trimmed by the boundary curves, so both agree.

Fitting: an algebraic first guess (the plane of least spread; Kasa's linear circle
fit in the plane normal to an axis for cylinders, its linear extension with a radius
linear in height for cones, and its meridian-section form for tori; the linear
sphere fit), then a Levenberg-Marquardt refinement of the geometric distance. Axis
guesses come from the boundary itself: the directions of its straight curves (a
cylinder's rulings), the normals of its circular arcs (circles of revolution), its
principal directions, and for tori the lines where two arcs' planes meet (two meridians'
planes meet in the axis, whatever the boundary's other curves are).

Arrays in, arrays out: this module knows no graph and no CAD kernel.

Notes
-----
The boundary alone cannot always tell the surface: two equal coaxial circles lie on
a cylinder and on a sphere zone. The simplest kind wins, and a periodic face's seam
(a line on a cylinder, an arc on a sphere) settles it. Radii are bounded by
:data:`MAX_RADIUS` diagonals, so a nearly flat free-form face is not taken for a
huge sphere.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from curvenet.core.geometry import bbox_diagonal, fit_plane
from curvenet.core.tolerances import DIVISION_GUARD

from .arcs import (circle_spread, fit_circle, in_axis_frame, kasa, normal_to, straight,
                   turns, unit)

__all__ = ["AnalyticSurface", "fit_analytic", "fit_kinds", "fit_circle", "KINDS", "ANALYTIC_TOL",
           "MAX_RADIUS", "FREEDOMS", "in_axis_frame"]

#: Surface kinds, simplest first: the order :func:`fit_analytic` tries them in.
KINDS = ("plane", "cylinder", "cone", "sphere", "torus")
#: Largest distance of a boundary sample to the fitted surface, fraction of the diagonal,
#: for the patch to be that surface.
ANALYTIC_TOL = 1e-5
#: Largest radius (cylinder, cone base, sphere, torus) of a fitted surface, in diagonals.
MAX_RADIUS = 10.0
#: Curves this close to a circle (fraction of their extent) give first guesses of a
#: torus's axis (:func:`_meridian_axes`); the refined surface is judged by the patch's
#: own tolerance.
GUESS_CURVE_TOL = 1e-3
#: Cosine above which two axis guesses count as the same direction.
SAME_AXIS = 1.0 - 1e-9
#: Parameters that fix a surface of each kind (a cylinder: its axis line 4 and its
#: radius; a cone: apex 3, axis 2, semi-angle; a torus: centre 3, axis 2, both radii). A
#: boundary is taken for a kind only when more distinct samples than these lie on it: six
#: points lie on some cone, and eight or fewer on some torus, whatever they are.
FREEDOMS = {"plane": 3, "cylinder": 5, "cone": 6, "sphere": 4, "torus": 7}


@dataclass(frozen=True)
class AnalyticSurface:
    """An elementary surface in a frame ``origin, xdir, ydir = axis x xdir, axis``.

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    origin : (3,) float64
        Plane: a point of it. Cylinder, cone: a point of the axis (for the cone, where
        the radius is ``radius``). Sphere, torus: the centre.
    axis : (3,) float64
        Unit; the plane's normal, the axis of revolution otherwise.
    xdir : (3,) float64
        Unit, normal to ``axis``: where the angle parameter starts.
    radius : float
        Cylinder, sphere; the cone's radius at ``origin``; the torus's major radius.
        0 for a plane.
    minor : float
        The torus's minor radius; the cone's semi-angle (radians, the radius grows by
        ``tan(minor)`` per unit along ``axis``); 0 otherwise.
    residual : float
        Largest distance of the fitted samples to the surface (model units).

    Examples
    --------
    >>> s = AnalyticSurface("sphere", np.zeros(3), np.array([0., 0, 1]), np.array([1., 0, 0]),
    ...                     2.0, 0.0, 0.0)
    >>> s.distance(np.array([[3.0, 0, 0]])).tolist(), s.project(np.array([[0, 0, 5.0]])).tolist()
    ([1.0], [[0.0, 0.0, 2.0]])
    """

    kind: str
    origin: np.ndarray
    axis: np.ndarray
    xdir: np.ndarray
    radius: float
    minor: float
    residual: float

    @property
    def ydir(self) -> np.ndarray:
        """``axis x xdir``: (3,) float64."""
        return np.cross(self.axis, self.xdir)

    def _local(self, points):
        """``(rho, z, radial unit (n, 3))``: distance to the axis, height along it."""
        d = np.asarray(points, np.float64) - self.origin
        z = d @ self.axis
        r = d - z[:, None] * self.axis
        rho = np.linalg.norm(r, axis=1)
        unit = np.where(rho[:, None] > DIVISION_GUARD, r / np.maximum(rho, DIVISION_GUARD)[:, None],
                        self.xdir)
        return rho, z, unit

    def distance(self, points) -> np.ndarray:
        """Signed distance of ``points`` ``(n, 3)`` to the surface: (n,) float64
        (positive away from the axis or the centre, along the normal for a plane)."""
        p = np.asarray(points, np.float64)
        if self.kind == "plane":
            return (p - self.origin) @ self.axis
        if self.kind == "sphere":
            return np.linalg.norm(p - self.origin, axis=1) - self.radius
        rho, z, _ = self._local(p)
        if self.kind == "cylinder":
            return rho - self.radius
        if self.kind == "cone":
            return (rho - self.radius - z * np.tan(self.minor)) * np.cos(self.minor)
        return np.hypot(rho - self.radius, z) - self.minor

    def project(self, points) -> np.ndarray:
        """Closest points of the surface to ``points`` ``(n, 3)``: (n, 3) float64.

        Points on the axis (cylinder, cone, torus) or at the centre (sphere) go along
        ``xdir``; the cone's projection is onto its full double cone.
        """
        p = np.asarray(points, np.float64)
        if self.kind == "plane":
            return p - self.distance(p)[:, None] * self.axis
        if self.kind == "sphere":
            d = p - self.origin
            n = np.linalg.norm(d, axis=1, keepdims=True)
            u = np.where(n > DIVISION_GUARD, d / np.maximum(n, DIVISION_GUARD), self.xdir)
            return self.origin + self.radius * u
        rho, z, unit = self._local(p)
        if self.kind == "cylinder":
            return self.origin + z[:, None] * self.axis + self.radius * unit
        if self.kind == "cone":
            t, c, s = np.tan(self.minor), np.cos(self.minor), np.sin(self.minor)
            # along the generator through the apex side: foot of (rho, z) on rho = R + z t
            along = (rho - self.radius) * s + z * c          # coordinate along the line
            zz = along * c
            rr = self.radius + zz * t
            return self.origin + zz[:, None] * self.axis + rr[:, None] * unit
        ring = self.origin + self.radius * unit                 # nearest point of the spine
        d = p - ring
        n = np.linalg.norm(d, axis=1, keepdims=True)
        u = np.where(n > DIVISION_GUARD, d / np.maximum(n, DIVISION_GUARD), self.axis)
        return ring + self.minor * u

    def to_dict(self) -> dict:
        """JSON-ready: lists and floats."""
        return {"kind": self.kind, "origin": self.origin.tolist(), "axis": self.axis.tolist(),
                "xdir": self.xdir.tolist(), "radius": float(self.radius),
                "minor": float(self.minor), "residual": float(self.residual)}

    @classmethod
    def from_dict(cls, d: dict) -> "AnalyticSurface":
        """Inverse of :meth:`to_dict`."""
        return cls(d["kind"], np.asarray(d["origin"], np.float64),
                   np.asarray(d["axis"], np.float64), np.asarray(d["xdir"], np.float64),
                   float(d["radius"]), float(d["minor"]), float(d["residual"]))


# --------------------------------------------------------------------------- angles
def _angles(axis) -> np.ndarray:
    """Polar angles ``(theta, phi)`` of a unit vector."""
    a = unit(axis)
    return np.array([np.arccos(np.clip(a[2], -1.0, 1.0)), np.arctan2(a[1], a[0])])


def _from_angles(theta, phi) -> np.ndarray:
    return np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])


# --------------------------------------------------------------------------- first guesses
def _guess_cylinder(p, axis):
    o = p.mean(axis=0)
    x, y, _, e1, e2 = in_axis_frame(p, axis, o)
    got = kasa(x, y)
    if got is None:
        return None
    cx, cy, r = got
    return np.r_[_angles(axis), o + cx * e1 + cy * e2, r]


def _guess_cone(p, axis):
    """``x^2 + y^2 = 2 cx x + 2 cy y - e + 2 m z + q z^2`` with ``rho = R + k z``."""
    o = p.mean(axis=0)
    x, y, z, e1, e2 = in_axis_frame(p, axis, o)
    A = np.c_[2 * x, 2 * y, -np.ones_like(x), 2 * z, z * z]
    sol, *_ = np.linalg.lstsq(A, x * x + y * y, rcond=None)
    cx, cy, e, m, q = sol
    r2 = cx * cx + cy * cy - e
    if not (r2 > 0 and q > 0):
        return None
    R = float(np.sqrt(r2))
    k = float(np.sqrt(q)) * (1.0 if m >= 0 else -1.0)
    return np.r_[_angles(axis), o + cx * e1 + cy * e2, R, np.arctan(k)]


def _guess_sphere(p):
    A = np.c_[2 * p, np.ones(len(p))]
    sol, *_ = np.linalg.lstsq(A, (p * p).sum(axis=1), rcond=None)
    r2 = sol[3] + sol[:3] @ sol[:3]
    return np.r_[sol[:3], np.sqrt(r2)] if r2 > 0 else None


def _guess_torus(p, axis, point):
    """The meridian section of points about the axis line ``point + t axis`` is a circle."""
    d = p - point
    z = d @ axis
    rho = np.linalg.norm(d - np.outer(z, axis), axis=1)
    got = kasa(rho, z)
    if got is None:
        return None
    R, z0, r = got
    return np.r_[_angles(axis), point + z0 * axis, R, r]


# --------------------------------------------------------------------------- residuals
def _surface(kind, x, residual=0.0) -> AnalyticSurface:
    """The surface of a parameter vector (see :func:`_residuals`)."""
    if kind == "sphere":
        return AnalyticSurface(kind, x[:3], np.array([0.0, 0, 1]), np.array([1.0, 0, 0]),
                               abs(float(x[3])), 0.0, residual)
    axis = _from_angles(x[0], x[1])
    o = np.asarray(x[2:5], np.float64)
    if kind == "cylinder":
        o = o - (o @ axis) * axis
        return AnalyticSurface(kind, o, axis, normal_to(axis), abs(float(x[5])), 0.0, residual)
    if kind == "cone":
        return AnalyticSurface(kind, o, axis, normal_to(axis), float(x[5]), float(x[6]),
                               residual)
    return AnalyticSurface(kind, o, axis, normal_to(axis), abs(float(x[5])), abs(float(x[6])),
                           residual)


def _rebased(s: AnalyticSurface, p) -> AnalyticSurface:
    """A cone's axis turned the way its radius grows (a positive semi-angle), and its
    origin moved along it to the samples' mean height, where the radius is positive
    (the frame OpenCascade's conical surface needs)."""
    if s.kind != "cone":
        return s
    sign = 1.0 if s.minor >= 0 else -1.0
    axis = sign * s.axis
    zm = float(((p - s.origin) @ axis).mean())
    return AnalyticSurface("cone", s.origin + zm * axis, axis, s.xdir,
                           float(s.radius + zm * np.tan(abs(s.minor))), abs(s.minor),
                           s.residual)


def _refine(kind, x0, p):
    """Levenberg-Marquardt on the geometric distance; ``(x, max |residual|)``."""
    from scipy.optimize import least_squares

    def f(x):
        return _surface(kind, x).distance(p)
    if len(p) <= len(x0):
        return x0, float(np.abs(f(x0)).max())
    try:
        sol = least_squares(f, x0, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                            max_nfev=40 * len(x0))
        x = sol.x
    except (ValueError, np.linalg.LinAlgError):     # singular start: keep the guess
        x = x0
    return x, float(np.abs(f(x)).max())


#: Guesses refined per kind (best first by their own residual)...
REFINED_GUESSES = 2
#: ...and only those whose RMS distance is under this fraction of the samples' extent.
GUESS_SCREEN = 0.05
#: Samples the refinement uses at most (evenly picked; the check uses all).
REFINE_SAMPLES = 256


def _refined(kind, p, guesses, tol):
    """``(x, max |residual| over all p)`` of the best guesses, refined; stops at the
    first within ``tol``."""
    if not guesses:
        return
    ext = bbox_diagonal(p)
    rms = [float(np.sqrt(np.mean(_surface(kind, g).distance(p) ** 2))) for g in guesses]
    order = [i for i in np.argsort(rms)[:REFINED_GUESSES] if rms[i] <= GUESS_SCREEN * ext]
    sub = p[np.linspace(0, len(p) - 1, min(len(p), REFINE_SAMPLES)).astype(int)]
    for i in order:
        x, _ = _refine(kind, guesses[i], sub)
        res = float(np.abs(_surface(kind, x).distance(p)).max())
        yield x, res
        if res <= tol:
            return


def _shapes(curves) -> list:
    """Per curve ``(direction, None)`` when it is straight, ``(None, (centre, normal,
    radius))`` when it lies on a circle (:func:`fit_circle`), else ``(None, None)``."""
    out = []
    for c in curves:
        u = straight(c)
        out.append((u, None if u is not None else fit_circle(c)))
    return out


def _axis_guesses(p, shapes) -> list:
    """Unit axis guesses: straight curves' directions, arcs' normals (``shapes``,
    :func:`_shapes`), principal axes."""
    out = [u for u, _ in shapes if u is not None]
    arcs = [a for _, a in shapes if a is not None]
    out += [n for _, n, _ in arcs]
    out += list(np.linalg.svd(p - p.mean(axis=0), full_matrices=False)[2])
    uniq = []
    for a in out:
        a = unit(a)
        if not any(abs(a @ b) > SAME_AXIS for b in uniq):
            uniq.append(a)
    return uniq, arcs


def _candidates(kind, p, axes, arcs, near=()):
    """First guesses of one kind's parameter vector (``near``: the curves' circles within
    :data:`GUESS_CURVE_TOL`, for the torus's axis)."""
    if kind == "sphere":
        g = _guess_sphere(p)
        return [] if g is None else [g]
    if kind == "cylinder":
        return [g for g in (_guess_cylinder(p, a) for a in axes) if g is not None]
    if kind == "cone":
        return [g for g in (_guess_cone(p, a) for a in axes) if g is not None]
    lines = [(c, n) for c, n, _ in arcs] + _meridian_axes(near) + [(p.mean(axis=0), a)
                                                                   for a in axes]
    return [g for g in (_guess_torus(p, unit(n), c) for c, n in lines) if g is not None]


def _meridian_axes(arcs) -> list:
    """Axis lines ``(point, direction)`` where the planes of two arcs meet.

    Two meridians of a torus lie in planes through its axis, so their planes meet in it,
    whatever the other curves of the boundary are (rings cut by tilted planes are no
    circles, and their arcs give no axis). A ring's arc gives its axis itself
    (:func:`_candidates`); arcs in parallel planes meet nowhere and give none.
    """
    out = []
    for i, (c1, n1, _) in enumerate(arcs):
        for c2, n2, _ in arcs[i + 1:]:
            d = np.cross(n1, n2)
            if np.linalg.norm(d) < 1.0 - SAME_AXIS:
                continue
            d = unit(d)
            M = np.stack([n1, n2, d])
            out.append((np.linalg.solve(M, [n1 @ c1, n2 @ c2, d @ (c1 + c2) / 2.0]), d))
    return out


def fit_analytic(curves, *, tol: float, diagonal: float, kinds=KINDS, loops=None):
    """The simplest elementary surface all of a boundary's samples lie on.

    Parameters
    ----------
    curves : list of (m_i, 3) float64
        The boundary curves (every loop of the patch, a seam once).
    tol : float
        Largest distance of any sample to the surface, model units.
    diagonal : float
        The model's diagonal: radii above :data:`MAX_RADIUS` times it are refused.
    kinds : sequence of str
        Kinds tried, in this order (default :data:`KINDS`).
    loops : list of (n_i, 3) float64, optional
        The boundary's closed loops in walking order, a seam walked twice: with them a
        cone face around its apex is refused too (:func:`_through_singularity`).

    Returns
    -------
    AnalyticSurface or None
        The first kind within ``tol`` (its ``residual`` the largest distance) that the
        samples over-determine (more distinct ones than its :data:`FREEDOMS`) and that
        holds the arcs the curves are written as between their samples
        (:func:`_arcs_on`), or None.

    Examples
    --------
    >>> t = np.linspace(0, 2 * np.pi, 33)
    >>> top = np.c_[np.cos(t), np.sin(t), np.ones_like(t)]
    >>> seam = np.c_[np.ones(5), np.zeros(5), np.linspace(1, 0, 5)]
    >>> s = fit_analytic([top, top - [0, 0, 1], seam], tol=1e-6, diagonal=3.0)
    >>> s.kind, round(s.radius, 9)
    ('cylinder', 1.0)
    """
    curves = [np.asarray(c, np.float64) for c in curves]
    p = np.concatenate(curves)
    if len(p) < 3:
        return None
    distinct = _distinct(p, tol)
    c, n, _ = fit_plane(p)
    axes, arcs, shapes = None, None, None
    for kind in kinds:
        if distinct <= FREEDOMS[kind]:
            continue
        if kind == "plane":
            res = float(np.abs((p - c) @ n).max())
            if res <= tol:
                return AnalyticSurface("plane", c, unit(n), normal_to(n), 0.0, 0.0, res)
            continue
        if axes is None:
            shapes = _shapes(curves)
            axes, arcs = _axis_guesses(p, shapes)
        best = _best(kind, p, curves, axes, arcs, tol, GUESS_CURVE_TOL)
        if best is not None and best[1] <= tol:
            s = _rebased(_surface(kind, best[0], best[1]), p)
            if (not _too_wide(s, diagonal) and not _through_singularity(s, p, tol, loops)
                    and (kind != "cone" or _drawn_cone(s, curves, shapes, tol))
                    and _arcs_on(s, curves, shapes, tol)):
                return s
    return None


def _best(kind, p, curves, axes, arcs, tol: float, guess_tol: float, guess_curves=None):
    """``(x, max |residual|)`` of the best refined guess of one kind, or None
    (``guess_tol``: curves this close to a circle give torus axes, the
    ``guess_curves`` closest of them when given)."""
    near = []
    if kind == "torus":
        got = [(a, cv) for a, cv in ((fit_circle(cv, tol=guess_tol), cv) for cv in curves)
               if a is not None]
        if guess_curves is not None and len(got) > guess_curves:
            got.sort(key=lambda ac: circle_spread(*ac))
            got = got[:guess_curves]
        near = [a for a, _ in got]
    best = None
    for x, res in _refined(kind, p, _candidates(kind, p, axes, arcs, near), tol):
        if best is None or res < best[1]:
            best = (x, res)
    return best


def fit_kinds(curves, kinds, *, diagonal: float, guess_tol: float, guess_curves: int):
    """Per kind, the surface closest to noisy samples, whatever its distance.

    Parameters
    ----------
    curves : list of (m_i, 3) float64
    kinds : sequence of str
        Of :data:`KINDS` but ``"plane"``; fitted lazily, in this order.
    diagonal : float
        Radii above :data:`MAX_RADIUS` times it are refused.
    guess_tol, guess_curves : float, int
        The ``guess_curves`` curves closest to a circle among those within ``guess_tol``
        of their extent of one give the torus's axis guesses (:func:`_meridian_axes`).

    Yields
    ------
    AnalyticSurface or None
        Per kind, its ``residual`` the largest distance of a sample; None when the samples
        do not over-determine it (:data:`FREEDOMS`) or no guess refines to one within the
        radius bound and without a singular point (:func:`_through_singularity`).
    """
    curves = [np.asarray(c, np.float64) for c in curves]
    p = np.concatenate(curves)
    distinct = _distinct(p, 0.0)
    axes, arcs = _axis_guesses(p, _shapes(curves))
    for kind in kinds:
        best = None if distinct <= FREEDOMS[kind] else _best(
            kind, p, curves, axes, arcs, 0.0, guess_tol, guess_curves)
        if best is None:
            yield None
            continue
        s = _rebased(_surface(kind, best[0], best[1]), p)
        yield None if _too_wide(s, diagonal) or _through_singularity(s, p, best[1]) else s


def _too_wide(s: AnalyticSurface, diagonal: float) -> bool:
    """Whether a radius of ``s`` passes :data:`MAX_RADIUS` diagonals."""
    return max(abs(s.radius), s.minor if s.kind == "torus" else 0.0) > MAX_RADIUS * diagonal


def _arcs_on(s: AnalyticSurface, curves, shapes, tol: float) -> bool:
    """Whether the circular arcs through the curves that lie on circles (``shapes``, as
    the CAD output writes them, :func:`fit_circle`) stay within ``tol`` of ``s`` midway
    between their samples. Any three points lie on a circle: a curve of three samples is written
    as the arc through them, which leaves the surface unless the curve is a circle of it
    (a section of a cylinder by a slanted plane is an ellipse, not the arc through three
    of its points)."""
    for c, (_, arc) in zip(curves, shapes):
        if arc is None:
            continue
        centre, normal, r = arc
        d = c - centre
        d = d - np.outer(d @ normal, normal)
        mid = d[:-1] + d[1:]
        half = np.linalg.norm(mid, axis=1) <= DIVISION_GUARD * r   # samples half a turn apart
        mid[half] = np.cross(normal, d[:-1][half])
        mid = centre + r * mid / np.linalg.norm(mid, axis=1, keepdims=True)
        if np.abs(s.distance(mid)).max() > tol:
            return False
    return True


def _distinct(p, tol: float) -> int:
    """Samples ``p`` (n, 3) counted once per cluster within ``tol`` (a junction's
    sample is the end of every curve through it)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree
    pairs = cKDTree(p).query_pairs(max(tol, 0.0), output_type="ndarray")
    if not len(pairs):
        return len(p)
    g = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(p), len(p)))
    return int(connected_components(g, directed=False)[0])


def _apex(s: AnalyticSurface):
    """A cone's apex (3,), or None for a semi-angle too small to place it."""
    if not np.tan(s.minor) > DIVISION_GUARD:
        return None
    return s.origin - (s.radius / np.tan(s.minor)) * s.axis


def _drawn_cone(s: AnalyticSurface, curves, shapes, tol: float) -> bool:
    """Whether a cone's boundary holds one of the curves a cone face is drawn with: a
    circle about its axis (a chamfer's or countersink's rim), a ruling (a line through
    its apex) or the apex itself (a pin's point). A loop of free-form curves that happens
    to lie within the tolerance of some cone is a free-form face: nearly flat ones fit
    wide cones (semi-angles near 90 degrees) whose apex the face's curves on the
    surface wander across."""
    apex = _apex(s)
    if apex is None:
        return False
    for c, (u, arc) in zip(curves, shapes):
        if np.linalg.norm(c[[0, -1]] - apex, axis=1).min() <= tol:
            return True
        if u is not None:
            off = (apex - c[0]) - ((apex - c[0]) @ u) * u
            if np.linalg.norm(off) <= tol:
                return True
            continue
        if arc is not None:
            centre, normal, _ = arc
            d = centre - apex
            on_axis = np.linalg.norm(d - (d @ s.axis) * s.axis) <= tol
            if abs(normal @ s.axis) > SAME_AXIS and on_axis:
                return True
    return False


#: A cone's apex within this fraction of its boundary's extent of a boundary sample is a
#: vertex of the face (a pin's point), not inside it: the fit places the apex less
#: precisely than the samples (a ruling's end is the only sample that fixes it).
APEX_AT_BOUNDARY = 1e-3


def _through_singularity(s: AnalyticSurface, p, tol: float, loops=None) -> bool:
    """Whether the face would hold a singular point of its surface inside it.

    That is a torus that crosses itself (minor radius at least the major: a spindle or
    horn torus, its points on the axis singular), a cone whose boundary lies on both
    sides of its apex (farther than ``tol`` along its rulings), or, given the loops, a
    cone face around its apex (the loops' total winding number about the axis is not 0
    and the apex is no vertex of the face, see :data:`APEX_AT_BOUNDARY`). No trimmed
    face can carry such a point (OpenCascade marks it with a degenerate edge inside the
    face, openNURBS refuses a singular trim off the domain's sides), and it is never
    what a boundary that fits nothing simpler means: nearly flat free-form loops fit
    wide cones around their apex, nearly spherical ones tori of almost no major radius.
    A cone ending at its apex (a pin's point) and a band between two circles (winding
    0) are kept."""
    if s.kind == "torus":
        return s.minor >= s.radius
    apex = _apex(s) if s.kind == "cone" else None
    if apex is None:
        return False
    z = (np.asarray(p) - apex) @ s.axis / np.cos(s.minor)   # along the rulings
    if z.min() < -tol and z.max() > tol:
        return True
    ext = bbox_diagonal(p)
    if loops is None or np.linalg.norm(p - apex, axis=1).min() <= APEX_AT_BOUNDARY * ext:
        return False
    e1 = s.xdir
    e2 = np.cross(s.axis, e1)
    total = 0.0
    for lp in loops:
        d = np.asarray(lp, np.float64) - apex
        total += turns(np.arctan2(d @ e2, d @ e1))
    return round(total) != 0
