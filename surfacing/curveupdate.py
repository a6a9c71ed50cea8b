"""Curve-network update: curves conform to the faired surface (Orbay & Kara 2011, Sec. 4.3.3).

"These curves are recalculated to approximate the limit positions of the associated
vertices through cubic curve fitting." We fit a cubic smoothing B-spline
(``scipy.interpolate.make_splprep``) to the limit points along each chosen curve,
parametrised by chord length, and resample it at the curve's original sample count.
"""

from __future__ import annotations

import numpy as np

from curvenet.core.geometry import arc_length, cumulative_length
from curvenet.core.tolerances import DIVISION_GUARD, DUPLICATE_POINT_REL

__all__ = ["fit_cubic_curve"]


def fit_cubic_curve(points: np.ndarray, n_out: int, smoothing: float = 0.0) -> np.ndarray:
    """Cubic B-spline through (or near) ``points``, resampled uniformly in its parameter.

    Parameters
    ----------
    points : (k, 3) float64
        Limit points along a curve, in order (k >= 2).
    n_out : int
        Samples in the result (>= 2).
    smoothing : float
        ``s`` of the spline fit relative to ``k * diag^2``; 0 interpolates.

    Returns
    -------
    (n_out, 3) float64
        First and last points equal ``points[0]`` and ``points[-1]``.
    """
    from scipy.interpolate import make_splprep

    P = np.asarray(points, dtype=np.float64)
    if P.ndim != 2 or P.shape[1] != 3 or len(P) < 2:
        raise ValueError(f"points: expected a (k, 3) array with k >= 2, got {P.shape}")
    if n_out < 2:
        raise ValueError(f"n_out: expected >= 2, got {n_out}")
    d = np.linalg.norm(np.diff(P, axis=0), axis=1)
    keep = np.concatenate([[True], d > DUPLICATE_POINT_REL * max(arc_length(P), DIVISION_GUARD)])
    P = P[keep]
    if len(P) < 4:
        t = np.linspace(0, 1, n_out)[:, None]
        return (1 - t) * P[0] + t * P[-1] if len(P) == 2 else np.asarray(
            [P[min(int(round(x * (len(P) - 1))), len(P) - 1)] for x in t[:, 0]])
    u = cumulative_length(P)
    u /= u[-1]
    diag = float(np.linalg.norm(P.max(0) - P.min(0)))
    spl, _ = make_splprep(P.T, u=u, k=3, s=smoothing * len(P) * diag ** 2)
    out = np.asarray(spl(np.linspace(0.0, 1.0, n_out))).T
    out[0], out[-1] = P[0], P[-1]
    return out
