"""Bicubic B-spline pieces: knots, evaluation, closest points and the uniform-to-clamped map.

A piece is one tensor-product cubic B-spline surface with clamped knot vectors, its
parameters in spans of a subdivided control grid (``u`` in ``[0, M]``, ``v`` in
``[0, N]``). The Catmull-Clark limit over a regular grid is the *uniform* (unclamped)
spline of the grid and its outer ring (:mod:`.levels`); :func:`clamp_uniform`
rewrites it with clamped knots, the form CAD kernels take.

Arrays in, arrays out: this module knows no mesh.

References
----------
Piegl & Tiller, *The NURBS Book*, 2nd ed. 1997: A2.2 (basis functions), eq. 2.9
(derivatives).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import BSpline

__all__ = ["BSplinePiece", "EXACT_TOL", "uniform_knots", "uniform_design", "tensor_grid",
           "clamp_uniform", "basis", "evaluate", "project", "span_points"]

#: Spans whose limit samples deviate more than this fraction of the diagonal from the
#: uniform B-spline are irregular (exact spans agree to rounding, about 1e-15).
EXACT_TOL = 1e-10


@dataclass
class BSplinePiece:
    """One clamped bicubic B-spline surface.

    Attributes
    ----------
    poles : (a, b, 3) float64
    knots_u : (a + 4,) float64, knots_v : (b + 4,) float64
        Clamped knot vectors (end knots repeated four times), parameters in spans of
        the subdivided grid: ``u`` in ``[0, M]``, ``v`` in ``[0, N]``.
    patch : int
        Loop index.
    exact : bool
        True when no span needed fitting.
    deviation : float
        Largest distance to the exact limit samples, fraction of the diagonal.
    """

    poles: np.ndarray
    knots_u: np.ndarray
    knots_v: np.ndarray
    patch: int
    exact: bool
    deviation: float


def uniform_knots(m: int) -> np.ndarray:
    """Unclamped uniform cubic knots ``-3 .. m + 3`` for ``m`` spans on ``[0, m]``.

    Returns
    -------
    (m + 7,) float64
    """
    return np.arange(-3, m + 4, dtype=np.float64)


def uniform_design(x, m: int) -> np.ndarray:
    """Dense design matrix ``(len(x), m + 3)`` of the uniform cubic basis on ``[0, m]`` at ``x``."""
    return BSpline.design_matrix(np.asarray(x, np.float64), uniform_knots(m), 3).toarray()


def tensor_grid(Bu: np.ndarray, E: np.ndarray, Bv: np.ndarray) -> np.ndarray:
    """Grid evaluation ``sum_ab Bu[r, a] E[a, b] Bv[c, b]``.

    Parameters
    ----------
    Bu : (r, a) float64, E : (a, b, 3) float64, Bv : (c, b) float64

    Returns
    -------
    (r, c, 3) float64
    """
    T = np.tensordot(Bu, E, axes=(1, 0))                      # (r, b, 3)
    return np.tensordot(T, Bv, axes=(1, 1)).transpose(0, 2, 1)


def clamp_uniform(poles: np.ndarray, m: int, axis: int, breaks=None) -> tuple:
    """Re-express uniform unclamped cubic poles along ``axis`` with clamped knots.

    Same spline on ``[0, m]``; the clamped end poles are the end points of the
    surface, so pieces sharing a boundary curve share its poles.

    Parameters
    ----------
    poles : (..., m + 3, ...) float64
    m : int
    axis : int
    breaks : (b,) float64, optional
        Breakpoints from 0 to m that include ``0, 1, ..., m`` (default exactly
        those); extra ones refine the knot vector (knot insertion: the same spline).

    Returns
    -------
    poles : ``len(breaks) + 2`` along ``axis``
    knots : (len(breaks) + 6,) float64 -- ``0, 0, 0, breaks, m, m, m``
    """
    b = np.arange(m + 1, dtype=np.float64) if breaks is None else np.asarray(breaks, np.float64)
    t = np.r_[[0.0] * 3, b, [float(m)] * 3]
    g = (t[1:-3] + t[2:-2] + t[3:-1]) / 3.0                  # Greville abscissae
    A_new = BSpline.design_matrix(g, t, 3).toarray()
    R = np.linalg.solve(A_new, uniform_design(g, m))          # (len(b) + 2, m + 3)
    return np.moveaxis(np.tensordot(R, np.moveaxis(poles, axis, 0), axes=1), 0, axis), t


def basis(x: np.ndarray, t: np.ndarray, derivative: int):
    """Non-zero cubic B-spline basis functions at ``x`` (Cox-de Boor).

    Parameters
    ----------
    x : (k,) float64
    t : (n + 4,) float64
        Knot vector.
    derivative : {0, 1}

    Returns
    -------
    cols : (k, 4) int64
        Indices of the four basis functions that do not vanish at each ``x``.
    values : (k, 4) float64
        Their values, or their first derivatives on the same columns.

    References
    ----------
    Piegl & Tiller, The NURBS Book, A2.2 and eq. 2.9.
    """
    x = np.asarray(x, np.float64)
    n = len(t) - 4
    s = np.clip(np.searchsorted(t, x, side="right") - 1, 3, n - 1)       # t[s] <= x < t[s+1]
    left = x[:, None] - t[s[:, None] + 1 - np.arange(1, 4)]             # x - t[s + 1 - j]
    right = t[s[:, None] + np.arange(1, 4)] - x[:, None]                # t[s + j] - x
    N = np.ones((len(x), 1))
    for j in range(1, 4):
        nxt = np.zeros((len(x), j + 1))
        for r in range(j):
            tmp = N[:, r] / (right[:, r] + left[:, j - r - 1])
            nxt[:, r] += right[:, r] * tmp
            nxt[:, r + 1] = left[:, j - r - 1] * tmp
        N = nxt
        if j == 2:
            quad = N                        # the quadratics, for the derivative
    cols = s[:, None] - 3 + np.arange(4)
    if derivative == 0:
        return cols, N
    # N'_(i,3) = 3 N_(i,2) / (t[i+3] - t[i]) - 3 N_(i+1,2) / (t[i+4] - t[i+1]);
    # quad[:, b] is N_(s-2+b, 2)
    den = t[cols + 3] - t[cols]
    w = np.where(den > 0, 3.0 / np.where(den > 0, den, 1.0), 0.0)     # 3 / (t[i+3] - t[i])
    q = np.zeros((len(x), 5))
    q[:, 1:4] = quad
    return cols, w * q[:, :4] - np.c_[w[:, 1:], np.zeros(len(x))] * q[:, 1:]


def evaluate(piece: BSplinePiece, u, v, derivatives: bool = False):
    """Points (and ``du``, ``dv``) of a piece at parameters ``u, v (k,)``.

    Returns
    -------
    (k, 3) float64, or a tuple of three when ``derivatives``.
    """
    u, v = np.asarray(u, np.float64), np.asarray(v, np.float64)
    if not len(u):
        z = np.zeros((0, 3))
        return (z, z, z) if derivatives else z
    iu, bu = basis(u, piece.knots_u, 0)
    iv, bv = basis(v, piece.knots_v, 0)
    P = piece.poles[iu[:, :, None], iv[:, None, :]]            # (k, 4, 4, 3)

    def pair(A, B):
        return np.einsum("ka,kb,kabc->kc", A, B, P)
    if not derivatives:
        return pair(bu, bv)
    du, dv = basis(u, piece.knots_u, 1)[1], basis(v, piece.knots_v, 1)[1]
    return pair(bu, bv), pair(du, bv), pair(bu, dv)


def project(piece: BSplinePiece, points, u0, v0, iterations: int = 8):
    """Closest points of a piece to ``points (k, 3)`` by Gauss-Newton from ``(u0, v0)``.

    Parameters stay in the piece's domain (a point beyond a border projects onto it).

    Returns
    -------
    u, v : (k,) float64
    distance : (k,) float64
    """
    p = np.asarray(points, np.float64)
    u, v = np.array(u0, np.float64), np.array(v0, np.float64)
    hi_u, hi_v = piece.knots_u[-1], piece.knots_v[-1]
    for _ in range(iterations):
        S, Su, Sv = evaluate(piece, u, v, derivatives=True)
        r = S - p
        a, b, c = (Su * Su).sum(1), (Su * Sv).sum(1), (Sv * Sv).sum(1)
        gu, gv = (Su * r).sum(1), (Sv * r).sum(1)
        det = np.maximum(a * c - b * b, 1e-300)
        u = np.clip(u - (c * gu - b * gv) / det, 0.0, hi_u)
        v = np.clip(v - (a * gv - b * gu) / det, 0.0, hi_v)
    return u, v, np.linalg.norm(evaluate(piece, u, v) - p, axis=1)


def span_points(P: np.ndarray, s: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Uniform bicubic B-spline spans ``P (n, 4, 4, 3)`` at ``s, t (n,)`` in ``[0, 1]``.

    Returns
    -------
    (n, 3) float64
    """
    return np.einsum("na,nb,nabc->nc", _uniform_weights(s), _uniform_weights(t), P)


def _uniform_weights(t: np.ndarray) -> np.ndarray:
    """Uniform cubic B-spline weights ``(n, 4)`` at ``t (n,)`` in ``[0, 1]``."""
    t2, t3 = t * t, t * t * t
    return np.stack([(1 - t) ** 3, 3 * t3 - 6 * t2 + 4, -3 * t3 + 3 * t2 + 3 * t + 1, t3],
                    axis=1) / 6.0
