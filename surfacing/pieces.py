"""How many control segments each curve gets (Orbay & Kara 2011, Sec. 4.2, adaptive).

The paper samples every curve with the same user-set ``N`` segments. Long or winding
curves of real networks need more: :func:`piece_counts` gives each curve a number of
*pieces* of ``N`` segments, from its length and from how much it turns at the scale of
the pieces, and :func:`equalise_pieces` raises the counts so that opposite curves of
every four-curve loop agree (the loop stays a regular grid) and so that curves that
continue each other through a regular junction keep their densities of control points
(pieces per length) within :data:`DENSITY_RATIO`, as far as a curve's own turning
allows (a piece per ``PIECE_TURN / DENSITY_RATIO`` degrees).

Why the continuations: the fit's fairness operator (:func:`surfacing.fit.fairness_matrix`,
the umbrella Laplacian) measures a curve's bending per control segment, so it reads a
jump of density along a curve as a jump of curvature and bends the surface to smooth it
out. A torus drawn as three meridians and three rings has meridian pieces turning by
120 degrees, exactly :data:`PIECE_TURN`; drawn by hand, some of them turn a little more
and get two pieces where their continuations have one, and the least-squares fit came
out flattened between the rings. The raise is
bounded by what the curve's own turning would ask for at a threshold lowered by the same
ratio: the pieces' threshold becomes a band inside which the continuations decide. Raised
without that bound, straight curves of hand-drawn sketches took the density of the
winding ones they continue, and their fits followed more of the strokes' wobble (a
sewing machine's body came out wrinkled).
"""

from __future__ import annotations

import heapq

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from curvenet.core.geometry import arc_length, arc_length_params, resample_polyline
from curvenet.core.tolerances import DIVISION_GUARD

__all__ = ["piece_counts", "equalise_pieces", "continuations",
           "PIECE_LENGTH", "PIECE_TURN", "TURN_SEGMENTS", "TURN_SCALES", "PIECE_ROUNDING",
           "DENSITY_RATIO", "BALANCE_ROUNDS"]

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
#: Curves that continue each other through a regular junction keep densities (pieces per
#: length) within this factor: the rounding of ``n`` against ``n + 1`` pieces for ``n >=
#: 2`` is allowed, one piece against two is not. Exact equality would ratchet up: curves
#: of slightly different lengths cannot have equal integer densities.
DENSITY_RATIO = 1.5
#: Rounds of :func:`equalise_pieces`' balancing of four-sided loops whose sides are made
#: of several curves (each round: every such loop once, then the continuations).
BALANCE_ROUNDS = 4


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


def _scale_turnings(curves: list) -> np.ndarray:
    """Turning (degrees) of each curve (``(m_i, 3)``, ``m_i >= 2``) resampled at
    ``TURN_SEGMENTS * s`` segments, ``s`` = 1 .. TURN_SCALES: ``(TURN_SCALES, C) float64``."""
    curves = [np.asarray(c, dtype=np.float64) for c in curves]
    params = [arc_length_params(c) for c in curves]
    return np.array([_turnings(curves, TURN_SEGMENTS * s, params)
                     for s in range(1, TURN_SCALES + 1)]).reshape(TURN_SCALES, len(curves))


def _turns_pieces(turnings: np.ndarray, turn: float) -> np.ndarray:
    """Pieces each curve asks for at a piece per ``turn`` degrees: ``(C,) int64``.

    ``turnings`` is :func:`_scale_turnings`. At scale ``s`` a curve that turns by more
    than ``turn * s`` cannot be followed by ``s`` pieces, and the scale asks for
    ``ceil(turning / turn)``; otherwise it asks for nothing (coarser scales decide
    whether fewer are enough). Stroke wobble below a piece's scale therefore adds
    nothing to a curve that the coarse scales find smooth.
    """
    need = np.ones(turnings.shape[1], np.int64)
    for s, row in enumerate(turnings, start=1):
        t = row / turn
        over = t > s * (1 + PIECE_ROUNDING)
        need[over] = np.maximum(need[over], np.ceil(t[over] - PIECE_ROUNDING).astype(np.int64))
    return need


def piece_counts(curves: list, closed: np.ndarray) -> tuple:
    """Pieces (of ``N`` control segments each) per curve for adaptive resolution, the
    most a continuation may raise them to, and the curves' lengths.

    Pieces: ``max(1, ceil(length / (PIECE_LENGTH * median length)), turning pieces)``,
    at least 2 for a closed curve; the turning pieces are what the curve's turning asks
    for at the scales of one to :data:`TURN_SCALES` pieces (:func:`_turns_pieces`), a
    piece per :data:`PIECE_TURN` degrees. The most: the same at a piece per
    ``PIECE_TURN / DENSITY_RATIO`` degrees (:func:`equalise_pieces`). The turnings are
    measured once for both.

    Returns
    -------
    pieces, most : (C,) int64
    lengths : (C,) float64
    """
    lengths = np.array([arc_length(c) for c in curves])
    med = float(np.median(lengths)) if len(lengths) else 1.0
    # a curve exactly PIECE_LENGTH medians long (rounding noise aside) stays one piece
    by_length = np.ceil(lengths / (PIECE_LENGTH * max(med, DIVISION_GUARD)) - PIECE_ROUNDING)
    turnings = _scale_turnings(curves)
    out = []
    for turn in (PIECE_TURN, PIECE_TURN / DENSITY_RATIO):
        m = np.maximum(np.maximum(by_length, _turns_pieces(turnings, turn)), 1).astype(np.int64)
        out.append(np.where(closed, np.maximum(m, 2), m))
    return out[0], out[1], lengths


def _strips(C: int, loops: list) -> np.ndarray:
    """Strip label ``(C,) int64`` of each curve: opposite curves of four-curve loops
    joined (the quad strips of the layout)."""
    pairs = [(lp[k][0], lp[k + 2][0]) for lp in loops if len(lp) == 4 for k in (0, 1)]
    if not pairs:
        return np.arange(C, dtype=np.int64)
    pr = np.array(pairs, dtype=np.int64)
    g = sp.coo_matrix((np.ones(len(pr)), (pr[:, 0], pr[:, 1])), shape=(C, C))
    return connected_components(g, directed=False)[1].astype(np.int64)


def continuations(loops: list, jend: np.ndarray) -> np.ndarray:
    """Pairs of curves that continue each other through a regular junction.

    A junction is regular when exactly four ends of four different curves meet there and
    the loops join them in a ring (each end is next to two others in the loops, as at a
    crossing of two grid lines); the two ends not next to each other continue each
    other.

    Parameters
    ----------
    loops : list of list of (int, bool)
        Each loop: (curve index, traversed forward) in traversal order.
    jend : (C, 2) int64
        Junction of each curve's start and end.

    Returns
    -------
    (k, 2) int64
        Curve pairs, each once.
    """
    jend = np.asarray(jend, dtype=np.int64)
    at = jend.ravel()                                   # junction of end 2i (start), 2i + 1
    near = {}                                           # end -> ends next to it in a loop
    for lp in loops:            # the end of one curve meets the start of the next
        n = len(lp)
        for k in range(n):
            (a, fa), (b, fb) = lp[k], lp[(k + 1) % n]
            ea, eb = 2 * a + int(fa), 2 * b + int(not fb)
            if a != b:
                near.setdefault(ea, set()).add(eb)
                near.setdefault(eb, set()).add(ea)
    ends_at = np.bincount(at)
    out = []
    for x, nx in near.items():
        if ends_at[at[x]] != 4 or len(nx) != 2:
            continue
        far = set().union(*(near[e] for e in nx)) - {x}     # across x's two neighbours
        if len(far) != 1:
            continue
        y = far.pop()
        if x < y and near[y] == nx and len({x // 2, y // 2, *(e // 2 for e in nx)}) == 4:
            out.append((x // 2, y // 2))
    return np.array(out, np.int64).reshape(-1, 2)


def equalise_pieces(m: np.ndarray, loops: list, lengths: np.ndarray, jend: np.ndarray,
                    most: np.ndarray, sides=None) -> np.ndarray:
    """Raise piece counts along quad strips, across four-sided loops and between
    continuing curves.

    Opposite curves of four-curve loops are joined into classes (the quad strips of the
    layout); every curve of a class takes the class maximum, so those loops stay
    regular ``p x q`` grids instead of falling back to a centre split.

    A curve whose density is more than :data:`DENSITY_RATIO` below its continuation's
    (:func:`continuations`) takes ``ceil(length * density / DENSITY_RATIO)`` pieces, but
    never more than the continuation has (a short curve's one piece is no density to
    pass on: a curve of 1% of its neighbour's length would give the neighbour a hundred)
    nor more than ``most`` allows it; its strip follows. Raised widest first, like
    Dijkstra's search: a strip's count, once the largest left, is final (what it passes
    on is no larger), so every strip is settled once and the cost is linear in the pairs
    (up to the heap's logarithm).

    With ``sides``, a four-sided loop whose sides are made of several curves (a junction
    of two curves in the middle of a side: where a closed stroke began, a T-junction)
    is balanced too: the side with fewer pieces than its opposite side gets the
    difference, a piece at a time to its curve of the lowest density (pieces per
    length), its strip following, then the continuations again; for at most
    :data:`BALANCE_ROUNDS` rounds (a layout whose sums cannot all agree keeps the
    centre split on the loops left unbalanced).

    Parameters
    ----------
    m : (C,) int64
        Pieces per curve (:func:`piece_counts`).
    loops : list of list of (int, bool)
    lengths : (C,) float64
        Arc length of each curve.
    jend : (C, 2) int64
        Junction of each curve's start and end.
    most : (C,) int64
        The most pieces a continuation may give each curve (:func:`piece_counts`).
    sides : list of list of list of int, optional
        Per loop its sides, each a list of positions in the loop
        (:func:`surfacing.sides.group_sides`).

    Returns
    -------
    (C,) int64
    """
    m = np.asarray(m, np.int64)
    lab = _strips(len(m), loops)
    best = np.zeros(lab.max() + 1 if len(lab) else 0, dtype=np.int64)
    np.maximum.at(best, lab, m)
    length = np.maximum(np.asarray(lengths, np.float64), DIVISION_GUARD)
    most = np.asarray(most, np.int64)
    pairs = continuations(loops, jend)
    _raise_continuations(best, lab, pairs, length, most)
    split = [[[lp[i][0] for i in g] for g in sd] for lp, sd in zip(loops, sides or [])
             if len(sd) == 4 and any(len(g) > 1 for g in sd)]
    for _ in range(BALANCE_ROUNDS if split else 0):
        if not _balance_sides(best, lab, length, split):
            break
        _raise_continuations(best, lab, pairs, length, most)
    return best[lab]


def _raise_continuations(best, lab, pairs, length, most) -> None:
    """Raise ``best`` (per strip, in place) where a curve is too sparse beside its
    continuation (:func:`equalise_pieces`)."""
    if not len(pairs):
        return
    x = np.r_[pairs[:, 0], pairs[:, 1]]               # x continues y, both ways
    y = np.r_[pairs[:, 1], pairs[:, 0]]
    ratio = length[x] / length[y] / DENSITY_RATIO
    order = np.argsort(lab[y], kind="stable")
    x, ratio = x[order], ratio[order]
    cap = most[x]
    start = np.searchsorted(lab[y][order], np.arange(len(best) + 1))
    heap = [(-int(v), int(c)) for c, v in enumerate(best)]
    heapq.heapify(heap)
    while heap:
        v, c = heapq.heappop(heap)
        if -v != best[c]:
            continue                                    # raised since it was pushed
        s0, s1 = start[c], start[c + 1]
        need = np.minimum(np.minimum(np.ceil(ratio[s0:s1] * -v - PIECE_ROUNDING), -v),
                          cap[s0:s1]).astype(np.int64)
        for t, k in zip(lab[x[s0:s1]], need):
            if k > best[t]:
                best[t] = k
                heapq.heappush(heap, (-int(k), int(t)))


def _balance_sides(best, lab, length, split) -> bool:
    """One round of side balancing (:func:`equalise_pieces`): per loop (its four sides as
    curve lists), the opposite side with fewer pieces raised to the other's sum, a piece
    at a time on its sparsest curve; ``best`` (per strip) in place. Whether any rose."""
    changed = False
    for sd in split:
        for k in (0, 1):
            a, c = np.asarray(sd[k]), np.asarray(sd[k + 2])
            sa, sc = int(best[lab[a]].sum()), int(best[lab[c]].sum())
            low = a if sa < sc else c
            for _ in range(abs(sa - sc)):
                best[lab[low[np.argmin(best[lab[low]] / length[low])]]] += 1
            changed |= sa != sc
    return changed
