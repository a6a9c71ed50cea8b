"""Circles and lines that a curve's samples lie on, and frames about an axis.

The analytic faces (:mod:`.analytic`) read a boundary's curves first: a straight curve
gives a cylinder's ruling, a circular arc an axis of revolution, and bands of revolution
(:mod:`.bands`) are meshed in the frame of their axis.
"""

from __future__ import annotations

import numpy as np

from curvenet.core.geometry import bbox_diagonal, fit_plane
from curvenet.core.tolerances import DIVISION_GUARD

__all__ = ["CURVE_TOL", "circle_spread", "fit_circle", "kasa", "straight", "in_axis_frame",
           "normal_to", "turns", "unit"]

#: A curve is straight (a ruling) when its points lie this close to its chord, and a
#: circular arc when they lie this close to a circle (fractions of the curve's extent).
CURVE_TOL = 1e-6


def unit(v) -> np.ndarray:
    """``v`` scaled to length 1 (unchanged where it is zero)."""
    v = np.asarray(v, np.float64)
    return v / max(float(np.linalg.norm(v)), DIVISION_GUARD)


def normal_to(axis) -> np.ndarray:
    """A unit vector normal to ``axis``."""
    a = unit(axis)
    e = np.eye(3)[int(np.argmin(np.abs(a)))]
    return unit(e - (e @ a) * a)


def in_axis_frame(points, axis, origin):
    """Coordinates ``x, y, z`` ((n,) float64 each) of points (n, 3) in a frame with ``z``
    along the unit ``axis`` from ``origin``, and the frame's ``e1, e2`` ((3,) each)."""
    e1 = normal_to(axis)
    e2 = np.cross(axis, e1)
    d = np.asarray(points) - origin
    return d @ e1, d @ e2, d @ axis, e1, e2


def turns(angles) -> float:
    """Turns (float) of the closed sequence ``angles`` (n,) in radians, each step taken
    the short way round: the winding number of a loop about a point."""
    step = np.diff(np.r_[angles, angles[:1]])
    return float(np.sum((step + np.pi) % (2 * np.pi) - np.pi)) / (2 * np.pi)


def fit_circle(points, *, tol: float = CURVE_TOL):
    """The circle a curve's points lie on, if they do.

    Parameters
    ----------
    points : (n, 3) float64
    tol : float
        Largest distance to the circle (and to its plane), fraction of the points'
        extent.

    Returns
    -------
    (centre (3,), normal (3,), radius) or None
        None for straight, non-planar or non-circular points, or fewer than 3.
    """
    p = np.asarray(points, np.float64)
    if len(p) < 3:
        return None
    ext = bbox_diagonal(p)
    c, n, _ = fit_plane(p)
    if ext <= 0 or np.abs((p - c) @ n).max() > tol * ext:
        return None
    x, y, _, e1, e2 = in_axis_frame(p, n, c)
    got = kasa(x, y)
    if got is None:
        return None
    cx, cy, r = got
    if np.abs(np.hypot(x - cx, y - cy) - r).max() > tol * ext or r > 1e3 * ext:
        return None
    return c + cx * e1 + cy * e2, n, r


def kasa(x, y):
    """Kasa's linear circle fit to points ``x, y`` ((n,) float64 each) in a plane:
    ``(cx, cy, r)``, or None where the fit has no real radius."""
    A = np.c_[2 * x, 2 * y, np.ones_like(x)]
    sol, *_ = np.linalg.lstsq(A, x * x + y * y, rcond=None)
    r2 = sol[2] + sol[0] ** 2 + sol[1] ** 2
    return (sol[0], sol[1], float(np.sqrt(r2))) if r2 > 0 else None


def circle_spread(arc, points) -> float:
    """Largest distance of ``points`` (n, 3) to the circle ``arc`` ``(centre, normal,
    radius)`` (:func:`fit_circle`), as a fraction of its radius."""
    centre, normal, r = arc
    d = np.asarray(points, np.float64) - centre
    h = d @ normal
    rho = np.linalg.norm(d - np.outer(h, normal), axis=1)
    return float(np.hypot(rho - r, h).max() / r)


def straight(points, tol: float = CURVE_TOL):
    """Unit direction of a straight curve, or None."""
    p = np.asarray(points, np.float64)
    d = p[-1] - p[0]
    L = float(np.linalg.norm(d))
    if L <= 0:
        return None
    u = d / L
    off = (p - p[0]) - np.outer((p - p[0]) @ u, u)
    return u if np.linalg.norm(off, axis=1).max() <= tol * L else None
