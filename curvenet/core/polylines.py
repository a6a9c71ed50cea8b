"""Many polylines at once: arc lengths and points at arc-length parameters, batched.

The stages that walk every curve of a network (end tangents, resampling, transport along
curves) called :func:`~curvenet.core.geometry.interpolate_polyline` once per curve:
linear, but a few numpy calls per curve. :class:`Polylines` groups the polylines by
point count, stacks each group into one array and answers the same queries for all of
them with the same arithmetic, so the results are those of the one-by-one functions,
bit for bit.
"""

from __future__ import annotations

import numpy as np

from .tolerances import ZERO_LENGTH

__all__ = ["Polylines", "row_norms", "row_dots"]

#: Largest ``points x queries`` comparison array built at once (bounds the memory).
_CHUNK = 4_000_000


class Polylines:
    """Polylines grouped by point count, with their cumulative arc lengths.

    Parameters
    ----------
    polylines : list of (m_k, d) float64, m_k >= 2
    reverse : bool
        Hold every polyline walked backwards, its arc length measured from its last
        point as ``cum[-1] - cum[::-1]`` (as the callers that reverse a polyline do).

    Attributes
    ----------
    groups : list of (ids (g,) int64, points (g, m, d) float64, cum (g, m) float64)
        ``cum`` as :func:`~curvenet.core.geometry.cumulative_length` gives it row by row.
    length : (K,) float64
        Arc length of each polyline.

    Examples
    --------
    >>> lines = Polylines([np.array([[0.0, 0], [2, 0]]), np.array([[0.0, 0], [0, 1], [0, 3]])])
    >>> lines.length.tolist()
    [2.0, 3.0]
    >>> lines.at(np.array([[1.0], [2.0]]))[:, 0].tolist()
    [[1.0, 0.0], [0.0, 2.0]]
    """

    def __init__(self, polylines, *, reverse: bool = False):
        sizes = np.array([len(p) for p in polylines], np.int64)
        self.length = np.zeros(len(polylines))
        self.groups = []
        order = np.argsort(sizes, kind="stable")
        cuts = np.flatnonzero(np.diff(sizes[order])) + 1
        for ids in np.split(order, cuts):
            if len(ids) == 0:
                continue
            pts = np.stack([np.asarray(polylines[i], dtype=np.float64) for i in ids])
            seg = np.linalg.norm(np.diff(pts, axis=1), axis=2)               # (g, m - 1)
            cum = np.concatenate([np.zeros((len(ids), 1)), np.cumsum(seg, axis=1)], axis=1)
            if reverse:
                pts, cum = pts[:, ::-1], cum[:, -1:] - cum[:, ::-1]
            self.groups.append((ids, pts, cum))
            self.length[ids] = cum[:, -1]

    def at(self, s) -> np.ndarray:
        """Points at arc-length parameters, as :func:`interpolate_polyline` with ``cum``.

        Parameters
        ----------
        s : (K, k) float64
            Per polyline, parameters in its arc length (clamped to ``[0, length]``).

        Returns
        -------
        (K, k, d) float64
        """
        s = np.asarray(s, dtype=np.float64)
        out = None
        for ids, pts, cum in self.groups:
            got = _interpolate(pts, cum, s[ids])
            if out is None:
                out = np.empty((len(s), s.shape[1], pts.shape[2]))
            out[ids] = got
        return out if out is not None else np.zeros((0, s.shape[1], 0))

    def at_params(self, t) -> np.ndarray:
        """Points at normalised parameters, as :func:`~curvenet.core.geometry.sample_at`.

        Parameters
        ----------
        t : (K, k) float64
            Per polyline, parameters in ``[0, 1]`` of its arc length (index / (m - 1)
            where the polyline is no longer than ``ZERO_LENGTH``).

        Returns
        -------
        (K, k, d) float64
        """
        t = np.asarray(t, dtype=np.float64)
        out = None
        for ids, pts, cum in self.groups:
            total = cum[:, -1:]
            flat = total[:, 0] <= ZERO_LENGTH
            params = np.where(flat[:, None], np.linspace(0.0, 1.0, cum.shape[1])[None],
                              cum / np.where(flat, 1.0, total[:, 0])[:, None])
            got = _interpolate(pts, params, t[ids])
            if out is None:
                out = np.empty((len(t), t.shape[1], pts.shape[2]))
            out[ids] = got
        return out if out is not None else np.zeros((0, t.shape[1], 0))

    def interp(self, x) -> np.ndarray:
        """Points at arc-length parameters as :func:`numpy.interp` gives them per coordinate
        (``np.interp(x, cum, points[:, k])``), which rounds differently from :meth:`at`.

        Parameters
        ----------
        x : (K, k) float64

        Returns
        -------
        (K, k, d) float64
        """
        x = np.asarray(x, dtype=np.float64)
        out = None
        for ids, pts, cum in self.groups:
            got = _interp(pts, cum, x[ids])
            if out is None:
                out = np.empty((len(x), x.shape[1], pts.shape[2]))
            out[ids] = got
        return out if out is not None else np.zeros((0, x.shape[1], 0))


def row_norms(v) -> np.ndarray:
    """Euclidean norm of each row, ``(n,) float64``, as :func:`numpy.linalg.norm` takes it
    of one vector (``sqrt(v @ v)``; its ``axis=1`` form sums the squares in another
    order, which can differ in the last bit).

    Parameters
    ----------
    v : (n, d) float64
    """
    return np.sqrt(row_dots(v, v))


def row_dots(u, v) -> np.ndarray:
    """``u[i] @ v[i]`` for each row, ``(n,) float64``, as ``@`` takes it of two vectors.

    Parameters
    ----------
    u, v : (n, d) float64
    """
    u, v = np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64)
    return np.matmul(u[:, None, :], v[:, :, None])[:, 0, 0]


def _interp(pts, cum, x):
    """Rows of :func:`numpy.interp` (its cases and arithmetic): ``pts (g, m, d)``,
    ``cum (g, m)`` non-decreasing, ``x (g, k)``."""
    g, m = cum.shape
    j = _last_at_or_below(cum, x)                                # -1 .. m - 1
    jc = np.clip(j, 0, m - 2)
    row = np.arange(g)[:, None]
    x0, x1 = cum[row, jc][..., None], cum[row, jc + 1][..., None]
    y0, y1 = pts[row, jc], pts[row, jc + 1]
    xv = x[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = (y1 - y0) / (x1 - x0)
        res = slope * (xv - x0) + y0
        other = slope * (xv - x1) + y1                           # numpy's retry after a NaN
    res = np.where(np.isnan(res), np.where(np.isnan(other) & (y0 == y1), y0, other), res)
    res = np.where((x0 == xv) & (j >= 0)[..., None], y0, res)   # at a knot: its value
    res = np.where((j < 0)[..., None], pts[:, :1], res)
    return np.where((j >= m - 1)[..., None], pts[:, -1:], res)


def _last_at_or_below(cum, x):
    """``searchsorted(cum, x, side="right") - 1`` row by row: ``(g, k) int64``."""
    g, m = cum.shape
    j = np.empty(x.shape, np.int64)
    step = max(1, _CHUNK // max(m * x.shape[1], 1))
    for lo in range(0, g, step):
        j[lo:lo + step] = (cum[lo:lo + step, :, None] <= x[lo:lo + step, None, :]).sum(axis=1) - 1
    return j


def _interpolate(pts, cum, s):
    """Rows of :func:`interpolate_polyline`: ``pts (g, m, d)``, ``cum (g, m)``, ``s (g, k)``."""
    g, m = cum.shape
    s = np.clip(s, cum[:, :1], cum[:, -1:])
    j = np.clip(_last_at_or_below(cum, s), 0, m - 2)
    row = np.arange(g)[:, None]
    c0, c1 = cum[row, j], cum[row, j + 1]
    seg = c1 - c0
    t = np.where(seg > 0, (s - c0) / np.where(seg > 0, seg, 1.0), 0.0)
    p0, p1 = pts[row, j], pts[row, j + 1]
    return p0 + t[..., None] * (p1 - p0)
