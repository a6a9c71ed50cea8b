"""Polyline helpers: arc length, uniform resampling, end tangents, point-to-polyline distance.

Notes
-----
Every function takes ``(m, 3) float64`` polylines with ``m >= 2`` and is vectorised
over the points; none of them loops over samples in Python.
"""

from __future__ import annotations

import numpy as np

__all__ = ["arc_length_params", "resample", "end_tangents", "point_polyline_distance",
           "sample_at"]

#: Relative length under which a segment counts as degenerate (fraction of the total length).
_EPS_LEN = 1e-12


def arc_length_params(curve: np.ndarray) -> np.ndarray:
    """Normalised cumulative arc length of a polyline.

    Parameters
    ----------
    curve : (m, 3) float64

    Returns
    -------
    t : (m,) float64
        ``t[0] = 0``, ``t[-1] = 1``, non-decreasing. A zero-length curve gets
        uniform parameters (index / (m - 1)).
    """
    curve = np.asarray(curve, dtype=np.float64)
    seg = np.linalg.norm(np.diff(curve, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    total = cum[-1]
    if total <= _EPS_LEN:
        return np.linspace(0.0, 1.0, len(curve))
    return cum / total


def sample_at(curve: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Points of ``curve`` at normalised arc-length parameters ``t`` (linear interpolation).

    Parameters
    ----------
    curve : (m, 3) float64
    t : (k,) float64 in [0, 1]

    Returns
    -------
    (k, 3) float64
    """
    curve = np.asarray(curve, dtype=np.float64)
    s = arc_length_params(curve)
    t = np.clip(np.asarray(t, dtype=np.float64), 0.0, 1.0)
    return np.stack([np.interp(t, s, curve[:, d]) for d in range(3)], axis=1)


def resample(curve: np.ndarray, k: int) -> np.ndarray:
    """Resample a polyline into ``k`` segments of equal arc length.

    Parameters
    ----------
    curve : (m, 3) float64
    k : int, >= 1

    Returns
    -------
    (k + 1, 3) float64
        First and last points are exactly ``curve[0]`` and ``curve[-1]``.
    """
    curve = np.asarray(curve, dtype=np.float64)
    out = sample_at(curve, np.linspace(0.0, 1.0, k + 1))
    out[0], out[-1] = curve[0], curve[-1]
    return out


def end_tangents(curve: np.ndarray, fraction: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangents at both ends of a polyline, pointing *away from* each end.

    The direction is taken to the point at ``fraction`` of the arc length from the
    end, which is robust to a noisy last sample.

    Returns
    -------
    t0, t1 : (3,) float64
        ``t0`` points from ``curve[0]`` into the curve, ``t1`` from ``curve[-1]`` into
        the curve. Zero vectors for a zero-length curve.
    """
    curve = np.asarray(curve, dtype=np.float64)
    p = sample_at(curve, np.array([fraction, 1.0 - fraction]))
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
    den = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)       # guard zero-length segments
    ap = points[:, None, :] - a[None]                             # (k, s, 3)
    t = np.clip(np.einsum("ksj,sj->ks", ap, ab) / den, 0.0, 1.0)
    d = ap - t[..., None] * ab[None]
    return np.sqrt(np.min(np.einsum("ksj,ksj->ks", d, d), axis=1))
