"""Polyline helpers of the classical surfacer: end tangents, point-to-polyline distance.

Arc length, interpolation and resampling live in :mod:`curvenet.core.geometry`.

Notes
-----
Every function takes ``(m, 3) float64`` polylines with ``m >= 2`` and is vectorised
over the points; none of them loops over samples in Python.
"""

from __future__ import annotations

import numpy as np

from curvenet.core.geometry import cumulative_length, interpolate_polyline, sample_at
from curvenet.core.tolerances import DIVISION_GUARD

__all__ = ["end_tangents", "point_polyline_distance"]


def end_tangents(curve: np.ndarray, fraction: float = 0.1,
                 lengths=None) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangents at both ends of a polyline, pointing *away from* each end.

    The direction is taken to the point at ``fraction`` of the arc length from the
    end, which is robust to a noisy last sample; or, with ``lengths = (l0, l1)``, to
    the points at arc length ``l0`` from the start and ``l1`` from the end.

    Returns
    -------
    t0, t1 : (3,) float64
        ``t0`` points from ``curve[0]`` into the curve, ``t1`` from ``curve[-1]`` into
        the curve. Zero vectors for a zero-length curve.
    """
    curve = np.asarray(curve, dtype=np.float64)
    if lengths is None:
        p = sample_at(curve, np.array([fraction, 1.0 - fraction]))
    else:
        cum = cumulative_length(curve)
        p = interpolate_polyline(curve, np.array([lengths[0], cum[-1] - lengths[1]]), cum=cum)
    d0, d1 = p[0] - curve[0], p[1] - curve[-1]
    n0, n1 = np.linalg.norm(d0), np.linalg.norm(d1)
    return (d0 / n0 if n0 > 0 else d0), (d1 / n1 if n1 > 0 else d1)


def point_polyline_distance(points: np.ndarray, curve: np.ndarray) -> np.ndarray:
    """Distance from each point to the nearest point of a polyline.

    Parameters
    ----------
    points : (k, 3) float64
    curve : (m, 3) float64

    Returns
    -------
    (k,) float64

    Notes
    -----
    Brute force over all (point, segment) pairs: O(k m) memory, meant for one curve
    at a time (k, m in the hundreds).
    """
    points = np.asarray(points, dtype=np.float64)
    curve = np.asarray(curve, dtype=np.float64)
    a, b = curve[:-1], curve[1:]                                  # (s, 3)
    ab = b - a
    den = np.maximum(np.einsum("ij,ij->i", ab, ab), DIVISION_GUARD)  # zero-length segments
    ap = points[:, None, :] - a[None]                             # (k, s, 3)
    t = np.clip(np.einsum("ksj,sj->ks", ap, ab) / den, 0.0, 1.0)
    d = ap - t[..., None] * ab[None]
    return np.sqrt(np.min(np.einsum("ksj,ksj->ks", d, d), axis=1))
