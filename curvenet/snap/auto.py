"""The snapping tolerance chosen from the sketch (``snap_tol="auto"``), and the density guard.

Private module; :func:`curvenet.snap.snap` calls :func:`auto_tolerance` when the
tolerance is ``"auto"`` (the default; the result arbitrates between the measured
tolerance and the default, see ``curvenet.snap._snap_auto``) and
:func:`check_density` before the tolerance-based snapping.

How the tolerance is chosen
---------------------------
1. Every stroke is resampled every ``0.2%`` of the diagonal (coarser when that
   would exceed :data:`_MAX_POINTS` samples).
2. **End distances.** For each stroke end, the distance to the nearest sample of
   any other stroke. Ends meant to join another stroke (a gap, an undershoot, a T)
   lie close to it; free ends lie far from everything. A stroke whose two ends
   each lie within a quarter of its length of the other end's stretch (its first
   or last :data:`~curvenet.snap.strokes.LOOP_OVERLAP`: a closed stroke, or a loop
   drawn past its start) counts those distances too: its ends join each other or
   its own beginning. Sorted, the distances show the two
   populations as a jump: the largest ratio between consecutive distances
   below :data:`AUTO_MAX` separates them, and the tolerance is placed above the
   joins (``1.2 x`` the largest) and below the free ends (``/ 1.2``).
   Without a clear jump (ratio under 1.5) the tolerance is
   :data:`curvenet.snap.DEFAULT_SNAP_TOL`, which is also the floor: a sketch
   whose ends all join within less still snaps as it did with the default.
3. **Parallel strokes.** For samples every ``1%`` of the diagonal, the distance
   to the second nearest other stroke running parallel beside it (tangents
   within 25 degrees, offset mostly across the tangent): a line of a grid has
   parallel neighbours on both sides, an overdrawn curve has one copy on top.
   The median over all samples is the spacing of the sketch's parallel curves
   (a dense grid's cell size). The
   tolerance is capped at :data:`_CAP` times it, so that neighbouring grid
   lines are never taken as one curve drawn twice, nor their junctions merged.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..core.errors import InvalidParameterError
from .strokes import Strokes, own_ends, sample

__all__ = ["AUTO_MAX", "SketchTooDense", "auto_tolerance", "check_density"]

#: Largest tolerance ``auto`` chooses, fraction of the diagonal.
AUTO_MAX = 0.06
_STEP = 0.002          # resampling step of the measurements, fraction of the diagonal
_PAR_STEP = 0.01       # spacing of the parallel-distance probes, fraction of the diagonal
_MAX_POINTS = 1_000_000
_MAX_PROBES = 20_000   # parallel-distance probes at most (evenly spread)
_K = 48                # neighbours looked at per query
_MIN_RATIO = 1.5       # smallest jump that separates joins from free ends
_PAR_COS = np.cos(np.radians(25.0))
#: Largest tolerance as a fraction of the spacing of parallel strokes. Snapping acts
#: over several tolerances (trims 2, overdraw 4), so half the spacing over-merges: a
#: rough 30 x 30 saddle grid (spacing 2.2% of the diagonal) snaps exactly up to a
#: fifth of it (tests/curvenet/test_snap.py).
_CAP = 0.2
#: Most sample pairs within the tolerance that snapping materialises (memory bound).
MAX_PAIRS = 12_000_000


def auto_tolerance(strokes, diag, default):
    """Choose the snapping tolerance from the strokes.

    Parameters
    ----------
    strokes : list of (n_k, 3) float64
        Boundary and crease strokes (repeated points removed).
    diag : float
        Bounding-box diagonal.
    default : float
        Tolerance (fraction of ``diag``) used without a clear separation; also the floor.

    Returns
    -------
    (float, str)
        The tolerance as a fraction of ``diag``, and one clause saying why.
    """
    st = Strokes()
    for k, p in enumerate(strokes):
        st.add(p, (k,), "boundary")
    total = sum(st.length(k) for k in range(len(st)))
    h = max(_STEP * diag, total / _MAX_POINTS)
    samples = sample(st, h)
    Q, sid, _, tan, start, _ = samples
    tree = cKDTree(Q)
    reach = 0.1 * diag
    k = min(_K, len(Q))
    # 2. end distances
    ends = np.concatenate([start[:-1], start[1:] - 1])
    dist, nn = tree.query(Q[ends], k=k, distance_upper_bound=reach)
    dist, nn = dist.reshape(len(ends), k), nn.reshape(len(ends), k)
    other = np.isfinite(dist) & (sid[np.minimum(nn, len(Q) - 1)] != sid[ends][:, None])
    d_end = np.where(other, dist, np.inf).min(axis=1)
    # a closed stroke's end joins its own other end, the end of a loop drawn past its
    # start its own beginning (or, both, another stroke they end near)
    _, d_last, _, d_first = own_ends(samples)
    lengths = np.array([st.length(q) for q in range(len(strokes))])
    loop = np.tile(lengths > 4.0 * np.maximum(d_last, d_first), 2)
    d_end = np.minimum(d_end, np.where(loop, np.concatenate([d_first, d_last]), np.inf)) / diag
    # 3. parallel spacing
    step = max(int(round(_PAR_STEP * diag / h)), len(Q) // _MAX_PROBES, 1)
    probe = np.arange(0, len(Q), step)
    k = min(2 * _K, len(Q))
    pd, pn = tree.query(Q[probe], k=k, distance_upper_bound=reach)
    pd, pn = pd.reshape(len(probe), k), pn.reshape(len(probe), k)
    pj = np.minimum(pn, len(Q) - 1)
    off = Q[pj] - Q[probe][:, None, :]
    along = np.abs(np.einsum("ij,ikj->ik", tan[probe], off))
    par = (np.isfinite(pd) & (sid[pj] != sid[probe][:, None])
           & (np.abs(np.einsum("ij,ikj->ik", tan[probe], tan[pj])) >= _PAR_COS)
           & (along <= 0.5 * pd))  # beside the probe, not a stroke continuing it
    # the second nearest parallel stroke: a grid line has neighbours on both sides,
    # an overdrawn curve one copy
    first = sid[pj[np.arange(len(probe)), np.argmax(par, axis=1)]]
    second = par & (sid[pj] != first[:, None])
    spacing = float(np.median(np.where(second, pd, np.inf).min(axis=1))) / diag
    cap = min(AUTO_MAX, _CAP * spacing)
    return _choose(np.sort(d_end), default, cap, spacing)


def _choose(d, default, cap, spacing):
    """Tolerance and reason from sorted end distances ``d`` (fractions), the cap and spacing."""
    lo_floor = 0.25 * _STEP
    idx = np.flatnonzero(d * 1.2 <= AUTO_MAX)
    best, at = 0.0, -1
    if idx.size:
        ratio = np.append(d[1:], np.inf)[idx] / np.maximum(d[idx], 2 * _STEP)
        last = len(ratio) - 1 - int(np.argmax(ratio[::-1]))  # the largest jump, farthest out
        best, at = float(ratio[last]), int(idx[last])
    if at >= 0 and best >= _MIN_RATIO:
        joins, nxt = d[at], (d[at + 1] if at + 1 < len(d) else np.inf)
        tol = max(1.2 * joins, default)
        if np.isfinite(nxt):
            tol = min(tol, nxt / 1.2) if nxt / 1.2 >= 1.2 * joins else tol
        why = (f"{at + 1} of {len(d)} stroke ends lie within {joins:.2%} of another stroke"
               + (f", the next {nxt:.2%} away" if np.isfinite(nxt) else ", none farther"))
    else:
        tol = default
        why = f"no clear gap between joining and free stroke ends: default {default:.2%}"
    tol = min(tol, AUTO_MAX)
    if tol > cap:
        tol = max(cap, lo_floor)
        why += f"; capped at {_CAP:g} x the {spacing:.2%} spacing of parallel strokes"
    return float(tol), why


class SketchTooDense(InvalidParameterError):
    """Too many sample pairs within the tolerance to snap within the memory bound."""


def check_density(samples, tol, snap_tol):
    """Refuse, before any pair is built, a sketch whose close sample pairs exceed :data:`MAX_PAIRS`.

    The count is estimated from up to 20,000 evenly spread samples
    (``cKDTree.query_ball_point(..., return_length=True)``, no lists built).
    """
    Q = samples[0]
    step = max(1, len(Q) // 20_000)
    probe = Q[::step]
    per = cKDTree(Q).query_ball_point(probe, tol, return_length=True)
    estimate = float(np.sum(per - 1)) * len(Q) / max(len(probe), 1) / 2.0
    if estimate > MAX_PAIRS:
        raise SketchTooDense(
            f"sketch too dense to snap at snap_tol {snap_tol:.4g}: about {estimate:,.0f} "
            f"sample pairs lie within the tolerance (limit {MAX_PAIRS:,}); give a smaller "
            f"snap tolerance or fewer overlapping strokes")
