"""Working strokes of the rough snapping and the small polyline tools its steps share.

:class:`Strokes` holds the polylines being snapped with their arc lengths, source ids
and labels; :func:`sample` draws uniform arc-length samples of all of them at once
(with the :class:`Flat` lookup table). All lengths are absolute.
"""

from __future__ import annotations

import numpy as np

from ..core.geometry import cumulative_length
from ..core.tolerances import DIVISION_GUARD

__all__ = ["dedup", "clean", "bump", "smoothstep", "Strokes", "Flat", "sample", "LOOP_OVERLAP",
           "own_ends"]

#: Longest stretch, as a fraction of a stroke's length, that its end may run back along its
#: own beginning and still be one loop drawn past its start (issue 33: designers run on by up
#: to a tenth of the ring, 9% of the stroke; this leaves half as much again and stays far
#: below the half of a second turn. A quarter also took a hook consolidated with a line for
#: a loop in the public sketch cassie 05-0-2, which lost a patch).
LOOP_OVERLAP = 0.15


# --------------------------------------------------------------------------- small tools
def dedup(polys, eps) -> list:
    """Each polyline without the points within ``eps`` of their predecessor (its last point
    is kept, in place of the last one kept if need be); polylines of under two points as
    they are. ``polys``: list of ``(n_k, 3)``; returns a list of ``(m_k, 3) float64``,
    every polyline's at once."""
    sizes = np.array([len(p) for p in polys], np.int64)
    pts = np.concatenate([np.asarray(p, dtype=np.float64).reshape(-1, 3) for p in polys])
    keep = np.ones(len(pts), bool)
    keep[1:] = np.linalg.norm(np.diff(pts, axis=0), axis=1) > eps
    first = np.cumsum(sizes) - sizes
    keep[first[sizes > 0]] = True
    out = pts[keep]
    kept = np.add.reduceat(keep, first[sizes > 0]) if len(pts) else np.zeros(0, np.int64)
    counts = np.zeros(len(polys), np.int64)
    counts[sizes > 0] = kept
    last = first + sizes - 1
    fix = (sizes >= 2) & ~keep[np.maximum(last, 0)] & (counts > 1)
    out[(np.cumsum(counts) - 1)[fix]] = pts[last[fix]]
    return np.split(out, np.cumsum(counts)[:-1])


def clean(poly, eps):
    """Drop interior points closer than ``eps`` to their predecessor; ends stay exact.

    Removes the needle segments that joins and cuts can leave (their direction is
    noise and shows as a kink). A run of such points shorter than ``eps`` is dropped
    whole, which only lengthens one segment; a longer run (a stroke sampled more
    densely than ``eps``) keeps its first point past every ``eps`` of arc length from
    the point before the run, so that its shape stays (dropped whole, a small circle
    drawn densely would become its chord).
    """
    if len(poly) <= 2:
        return poly
    poly = np.asarray(poly)
    step = np.linalg.norm(np.diff(poly, axis=0), axis=1)
    keep = np.ones(len(poly), dtype=bool)
    keep[1:-1] = step[:-1] >= eps
    cum = np.concatenate([[0.0], np.cumsum(step)])
    anchor = np.maximum.accumulate(np.where(keep, np.arange(len(poly)), 0))
    nxt = np.minimum.accumulate(np.where(keep, np.arange(len(poly)), len(poly) - 1)[::-1])[::-1]
    since = cum - cum[anchor]
    bins = np.floor(since / eps)
    first = np.zeros(len(poly), dtype=bool)
    first[1:] = (bins[1:] > bins[:-1]) & (anchor[1:] == anchor[:-1])
    keep |= first & (cum[nxt] - cum >= eps)
    idx = np.flatnonzero(keep)
    if len(idx) > 2 and np.linalg.norm(poly[-1] - poly[idx[-2]]) < eps:
        keep[idx[-2]] = False
    return poly[keep]


def bump(x):
    """C1 bump ``(1 - x^2)^2`` for ``|x| < 1``, else 0: value 1 and slope 0 at 0."""
    x = np.minimum(np.abs(x), 1.0)
    return (1.0 - x * x) ** 2


def smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


# --------------------------------------------------------------------------- state
class Strokes:
    """Working strokes: polylines, arc lengths, source ids and labels."""

    def __init__(self):
        self.polys, self.cums, self.srcs, self.labels = [], [], [], []

    def add(self, poly, srcs, label, cum=None):
        self.polys.append(poly)
        self.cums.append(cumulative_length(poly) if cum is None else cum)
        self.srcs.append(tuple(sorted(set(srcs))))
        self.labels.append(label)

    def set(self, k, poly):
        self.polys[k] = poly
        self.cums[k] = cumulative_length(poly)

    def __len__(self):
        return len(self.polys)

    def length(self, k):
        return self.cums[k][-1]


class Flat:
    """All strokes concatenated, for vectorised arc-length lookups.

    Stroke ``k``'s points are ``P[first[k]:first[k] + count[k]]``; its arc
    parameter ``s`` maps to the global parameter ``s + off[k]`` on the
    concatenated polyline, where consecutive strokes are separated by a gap of
    ``sep`` (so a lookup never lands on the joining segment's interior).
    """

    def __init__(self, st):
        self.count = np.array([len(p) for p in st.polys])
        self.first = np.concatenate([[0], np.cumsum(self.count)[:-1]])
        self.P = np.concatenate(st.polys)
        self.L = np.array([c[-1] for c in st.cums])
        sep = float(self.L.sum()) + 1.0
        self.off = np.concatenate([[0.0], np.cumsum(self.L + sep)[:-1]])
        self.G = np.concatenate([c + o for c, o in zip(st.cums, self.off)])

    def interp(self, k, s):
        """Points ``(m, 3)`` at arc parameters ``s (m,)`` of strokes ``k (m,)`` (clamped)."""
        k = np.asarray(k, dtype=np.int64)
        g = np.clip(np.asarray(s, dtype=np.float64), 0.0, self.L[k]) + self.off[k]
        j = np.clip(np.searchsorted(self.G, g, side="right") - 1, 0, len(self.G) - 2)
        seg = self.G[j + 1] - self.G[j]
        t = np.clip((g - self.G[j]) / np.maximum(seg, DIVISION_GUARD), 0.0, 1.0)  # guard 0-length
        return self.P[j] + t[:, None] * (self.P[j + 1] - self.P[j])

    def window_mean(self, k, s, half, points=9):
        """Means ``(m, 3)`` of strokes ``k (m,)`` over the arcs ``s +- half`` (``s (m,)``),
        each from ``points`` evenly spaced points (clamped to the stroke)."""
        t = np.linspace(-half, half, points)
        p = self.interp(np.repeat(k, points), (np.asarray(s)[:, None] + t).ravel())
        return p.reshape(-1, points, 3).mean(axis=1)


def own_ends(samples, frac=LOOP_OVERLAP):
    """Where each stroke's ends come closest to its own other end's stretch.

    Parameters
    ----------
    samples : tuple
        The output of :func:`sample`.
    frac : float
        Length of the stretch searched at each end, a fraction of the stroke's length.

    Returns
    -------
    a, d_last, b, d_first : (S,) float64 each
        ``a``: arc parameter of the sample of the first ``frac`` of the stroke closest
        to its last point, at distance ``d_last``; ``b``: that of the sample of the last
        ``frac`` closest to its first point, at distance ``d_first``. A stroke whose end
        runs back along its own beginning has both distances small, ``a > 0`` and
        ``b < L``; a closed stroke (ends meeting) has ``a = 0`` and ``b = L``.

    Notes
    -----
    One pass over all samples (no loop over strokes): each sample's distance to its
    stroke's last and first points, masked to the two stretches (each holds the
    stroke's first or last sample), its minimum per stroke (``minimum.reduceat``) and
    the first sample that attains it.
    """
    Q, sid, ss, _, start, flat = samples
    first, last = start[:-1], start[1:] - 1
    L = flat.L[sid]
    out = []
    for mask, end in ((ss <= frac * L, last), (ss >= (1.0 - frac) * L, first)):
        d = np.where(mask, np.linalg.norm(Q - Q[end[sid]], axis=1), np.inf)
        low = np.minimum.reduceat(d, first)
        hit = np.flatnonzero(d == low[sid])
        best = hit[np.unique(sid[hit], return_index=True)[1]]
        out += [ss[best], low]
    return tuple(out)


def sample(st, h):
    """Uniform samples of every stroke at spacing <= h.

    Returns
    -------
    (Q, sid, ss, tan, start, flat) : points (M, 3), stroke id (M,), arc parameter (M,),
        unit tangent (M, 3), ``start (S + 1,)`` with stroke k's samples at
        ``start[k]:start[k + 1]``, and the :class:`Flat` arc-length table of the strokes.
    """
    flat = Flat(st)
    n = np.maximum(2, np.ceil(flat.L / h).astype(np.int64) + 1)
    start = np.concatenate([[0], np.cumsum(n)])
    sid = np.repeat(np.arange(len(n)), n)
    local = np.arange(start[-1]) - start[sid]
    ss = local * (flat.L / (n - 1))[sid]
    ss[start[1:] - 1] = flat.L  # exact ends
    Q = flat.interp(sid, ss)
    nxt = np.minimum(np.arange(len(Q)) + 1, start[sid + 1] - 1)
    prv = np.maximum(np.arange(len(Q)) - 1, start[sid])
    tan = Q[nxt] - Q[prv]
    tan /= np.maximum(np.linalg.norm(tan, axis=1, keepdims=True), DIVISION_GUARD)  # guard 0-length
    return Q, sid, ss, tan, start, flat
