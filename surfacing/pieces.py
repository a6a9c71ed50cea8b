"""How many control segments each curve gets (Orbay & Kara 2011, Sec. 4.2, adaptive).

The paper samples every curve with the same user-set ``N`` segments. Long or winding
curves of real networks need more: :func:`curve_pieces` gives each curve a number of
*pieces* of ``N`` segments, from its length and from how much it turns at the scale of
the pieces, and :func:`equalise_strips` raises the counts so that opposite curves of
every four-curve loop agree (the loop stays a regular grid).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from curvenet.core.geometry import arc_length, arc_length_params, resample_polyline
from curvenet.core.tolerances import DIVISION_GUARD

__all__ = ["curve_pieces", "equalise_strips", "PIECE_LENGTH", "PIECE_TURN", "TURN_SEGMENTS",
           "TURN_SCALES", "PIECE_ROUNDING"]

#: Adaptive pieces: a curve gets one more piece of ``N`` segments per this many times the
#: median curve length ...
PIECE_LENGTH = 2.0
#: ... and per this much turning (degrees) seen at the scale of the pieces ...
PIECE_TURN = 120.0
#: ... a scale of ``s`` pieces being the curve resampled at ``TURN_SEGMENTS * s``
#: segments (twice the default resolution per piece), for ``s`` up to :data:`TURN_SCALES`
#: (32 segments). A curve needs more than ``s`` pieces when it turns by more than
#: ``PIECE_TURN * s`` at that scale. Seen only at 32 segments, the wobble of a hand-drawn
#: 90 degree arc summed to 125 degrees (under 95 at 8), and one quad strip of a regular
#: layout got twice the control points of its neighbours, which the fair fit turns into
#: a bulge; seen only at 8, detail finer than a piece would be aliased away.
TURN_SEGMENTS = 8
TURN_SCALES = 4
#: Ratios within this of an integer count as that integer (equal curves get equal pieces).
PIECE_ROUNDING = 1e-9


def _turning(curve: np.ndarray, n: int) -> float:
    """Total turning (degrees) of ``curve`` resampled at ``n`` equal-arc segments.

    Scaled by ``n / (n - 1)``: the ``n - 1`` joints of a circular arc's resample turn by
    ``(n - 1) / n`` of its angle, so an arc measures its angle at any ``n``.
    """
    d = np.diff(resample_polyline(curve, n), axis=0)
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), DIVISION_GUARD)
    return float(np.degrees(np.arccos(np.clip((d[1:] * d[:-1]).sum(1), -1, 1))).sum()
                 * n / (n - 1))


def _turnings(curves: list, n: int, params=None) -> np.ndarray:
    """:func:`_turning` of many curves at once: ``(C,) float64``, bit for bit the same.

    Parameters
    ----------
    curves : list of (m_i, 3) float64, m_i >= 2
    n : int
        Segments of the resample.
    params : list of (m_i,) float64, optional
        :func:`~curvenet.core.geometry.arc_length_params` of each curve (computed when
        not given; pass them to share them between calls).

    Notes
    -----
    Every curve is resampled at the same ``n + 1`` parameters, so the resamples stack
    into one ``(C, n + 1, 3)`` array; only the segment lookup (one ``searchsorted``)
    runs per curve. The arithmetic is elementwise and the sums run along contiguous
    last axes, as in :func:`~curvenet.core.geometry.interpolate_polyline` and
    :func:`_turning`.
    """
    if not curves:
        return np.zeros(0)
    params = [arc_length_params(c) for c in curves] if params is None else params
    s = np.linspace(0.0, 1.0, int(n) + 1)
    sizes = np.array([len(c) for c in curves], np.int64)
    start = np.cumsum(sizes) - sizes
    j = np.stack([np.clip(np.searchsorted(cum, np.clip(s, cum[0], cum[-1]), side="right") - 1,
                          0, len(cum) - 2) for cum in params]) + start[:, None]   # (C, n + 1)
    lo = np.stack([np.clip(s, cum[0], cum[-1]) for cum in params])             # (C, n + 1)
    cum, pts = np.concatenate(params), np.concatenate(curves)
    seg = cum[j + 1] - cum[j]
    t = np.where(seg > 0, (lo - cum[j]) / np.where(seg > 0, seg, 1.0), 0.0)
    r = pts[j] + t[..., None] * (pts[j + 1] - pts[j])                           # (C, n + 1, 3)
    r[:, 0], r[:, -1] = pts[start], pts[start + sizes - 1]
    d = np.diff(r, axis=1)                                                      # (C, n, 3)
    d /= np.maximum(np.linalg.norm(d, axis=2, keepdims=True), DIVISION_GUARD)
    turn = np.degrees(np.arccos(np.clip((d[:, 1:] * d[:, :-1]).sum(2), -1, 1)))  # (C, n - 1)
    return turn.sum(1) * n / (n - 1)


def _turns_pieces(curves: list) -> np.ndarray:
    """Pieces each curve (``(m_i, 3)``, ``m_i >= 2``) asks for: ``(C,) int64``.

    At scale ``s`` (1 .. TURN_SCALES) a curve is resampled at ``TURN_SEGMENTS * s``
    segments; when it turns by more than ``PIECE_TURN * s`` there, ``s`` pieces cannot
    follow it and the scale asks for ``ceil(turning / PIECE_TURN)``; otherwise it asks
    for nothing (coarser scales decide whether fewer are enough). Stroke wobble below a
    piece's scale therefore adds nothing to a curve that the coarse scales find smooth.
    """
    need = np.ones(len(curves), np.int64)
    params = [arc_length_params(c) for c in curves]
    for s in range(1, TURN_SCALES + 1):
        t = _turnings(curves, TURN_SEGMENTS * s, params) / PIECE_TURN
        over = t > s * (1 + PIECE_ROUNDING)
        need[over] = np.maximum(need[over], np.ceil(t[over] - PIECE_ROUNDING).astype(np.int64))
    return need


def curve_pieces(curves: list, closed: np.ndarray) -> np.ndarray:
    """Pieces (of ``N`` control segments each) per curve for adaptive resolution.

    ``max(1, ceil(length / (PIECE_LENGTH * median length)), turning pieces)``, at least 2
    for a closed curve; the turning pieces are what the curve's turning asks for at the
    scales of one to :data:`TURN_SCALES` pieces (:func:`_turns_pieces`).

    Returns
    -------
    (C,) int64
    """
    lengths = np.array([arc_length(c) for c in curves])
    med = float(np.median(lengths)) if len(lengths) else 1.0
    turn = _turns_pieces([np.asarray(c, dtype=np.float64) for c in curves])
    # a curve exactly PIECE_LENGTH medians long (rounding noise aside) stays one piece
    m = np.maximum(np.ceil(lengths / (PIECE_LENGTH * max(med, DIVISION_GUARD)) - PIECE_ROUNDING),
                   turn)
    m = np.maximum(m, 1).astype(np.int64)
    return np.where(closed, np.maximum(m, 2), m)


def equalise_strips(m: np.ndarray, loops: list) -> np.ndarray:
    """Raise piece counts so opposite curves of every four-curve loop agree.

    Opposite curves of four-curve loops are joined into classes (the quad strips of
    the layout); every curve of a class takes the class maximum, so those loops stay
    regular ``p x q`` grids instead of falling back to a centre split.
    """
    C = len(m)
    pairs = [(lp[k][0], lp[k + 2][0]) for lp in loops if len(lp) == 4 for k in (0, 1)]
    if not pairs:
        return m
    pr = np.array(pairs, dtype=np.int64)
    g = sp.coo_matrix((np.ones(len(pr)), (pr[:, 0], pr[:, 1])), shape=(C, C))
    _, lab = connected_components(g, directed=False)
    best = np.zeros(lab.max() + 1, dtype=np.int64)
    np.maximum.at(best, lab, m)
    return best[lab]
