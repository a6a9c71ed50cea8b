"""Polyline helpers of the classical surfacer: end tangents, point-to-polyline distance,
closest points of segments.

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

__all__ = ["end_tangents", "point_polyline_distance", "closest_on_segments"]


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
    return closest_on_segments(points[:, None], curve[None, :-1], curve[None, 1:])[1].min(axis=1)


def closest_on_segments(points, a, b) -> tuple[np.ndarray, np.ndarray]:
    """Closest points of the segments ``a -> b`` to ``points``.

    Parameters
    ----------
    points, a, b : (..., 3) float64
        Broadcast against each other.

    Returns
    -------
    t : (...) float64
        Parameter of the closest point along each segment, in [0, 1] (0 on a segment of
        zero length).
    distance : (...) float64

    Examples
    --------
    >>> t, d = closest_on_segments(np.array([[1.0, 1, 0]]), np.zeros((1, 3)),
    ...                            np.array([[2.0, 0, 0]]))
    >>> t.tolist(), d.tolist()
    ([0.5], [1.0])
    """
    ab = b - a
    ap = points - a
    t = np.clip((ap * ab).sum(axis=-1) / np.maximum((ab * ab).sum(axis=-1), DIVISION_GUARD),
                0.0, 1.0)
    return t, np.linalg.norm(ap - t[..., None] * ab, axis=-1)
