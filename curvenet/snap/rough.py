"""The tolerance-based snapping of :func:`curvenet.snap.snap` (``mode="rough"``).

Private module; the steps and constants are documented in :mod:`curvenet.snap`.
All lengths below are absolute (``tol = snap_tol * diagonal``).
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import maximum_filter1d
from scipy.spatial import cKDTree

from .auto import check_density
from .joins import chord_turn, dissolve
from .merge import components, join_near
from .overdraw import close_loops, consolidate, merge_slivers
from .strokes import Strokes, bump, clean, sample
from ..core.geometry import arc_length, interpolate_polyline, segment_closest
from ..core.tolerances import DEFAULT_SNAP_TOL, DIVISION_GUARD
from ..model.network import CurveNetwork

__all__ = ["snap_rough"]

#: Bound on the stroke samples of one snap: the sample spacing grows past tol / 4 to keep
#: the total length / spacing under it.
_MAX_SAMPLES = 2_000_000
#: Samples of changed strokes whose neighbours are sought at once (bounds the pairs held).
_PAIR_BLOCK = 100_000
#: Each end of a turn chord is the stroke's mean over +-``_CHORD_END_MEAN`` chords of arc:
#: per-sample jitter tilts the chords far less, a corner turns by its angle less a few degrees.
_CHORD_END_MEAN = 0.25


def _contacts(samples, tol, h, st, opts, since=None):
    """Group close sample pairs of different strokes into contacts.

    Parameters
    ----------
    since : (contacts, start, old) or None
        The previous round's contacts and sample starts, and per stroke its index in
        that round when it is unchanged since (its samples are then the same), else -1.
        Only the sample pairs of changed strokes are searched (all pairs when they hold
        most samples); the contacts between unchanged strokes are carried over, renumbered.

    Returns
    -------
    dict of arrays, one entry per contact, ordered by strokes ``a < b`` and the start
    on ``a``: extents on each stroke (``a0, a1, b0, b1``), closest pair ``(i, j)``
    (sample indices) and its distance ``dist``, ``overlap`` flag.
    """
    Q, sid, _, _, start = samples[:5]
    fresh = None if since is None else since[2] < 0
    if fresh is None or 2 * np.count_nonzero(fresh[sid]) > len(Q):  # most strokes changed
        return _group_pairs(cKDTree(Q).query_pairs(tol, output_type="ndarray"), samples, tol,
                            h, st, opts)
    con0, start0, old = since
    qc = np.flatnonzero(fresh[sid])  # samples of the changed strokes
    tree, parts = cKDTree(Q), []
    for lo in range(0, len(qc), _PAIR_BLOCK):  # in blocks: most pairs found are discarded
        qb = qc[lo:lo + _PAIR_BLOCK]
        near = cKDTree(Q[qb]).sparse_distance_matrix(tree, tol, output_type="ndarray")
        i, j = qb[near["i"]], near["j"].astype(np.int64)
        keep = (sid[i] != sid[j]) & (~fresh[sid[j]] | (i < j))  # each pair once
        parts.append(np.stack([i[keep], j[keep]], axis=1))
    pairs = np.concatenate(parts) if parts else np.zeros((0, 2), dtype=np.int64)
    con = _group_pairs(pairs, samples, tol, h, st, opts)
    now = np.full(len(start0) - 1, -1)
    now[old[~fresh]] = np.flatnonzero(~fresh)
    a, b = now[con0["a"]], now[con0["b"]]
    kept = np.flatnonzero((a >= 0) & (b >= 0))
    carried = {k: v[kept] for k, v in con0.items()}
    carried.update(a=a[kept], b=b[kept],
                   i=con0["i"][kept] - start0[con0["a"][kept]] + start[a[kept]],
                   j=con0["j"][kept] - start0[con0["b"][kept]] + start[b[kept]])
    both = {k: np.concatenate([carried[k], con[k]]) for k in con}
    order = np.lexsort((both["a0"], both["b"], both["a"]))
    return {k: v[order] for k, v in both.items()}


def _group_pairs(pairs, samples, tol, h, st, opts):
    """Contacts (see :func:`_contacts`) from the close sample pairs ``(p, 2)``."""
    Q, sid, ss, tan = samples[:4]
    empty = {k: np.zeros(0, dtype=np.int64) for k in ("a", "b", "i", "j")}
    if len(pairs) == 0:
        return dict(empty, overlap=np.zeros(0, bool), a0=np.zeros(0), a1=np.zeros(0),
                    b0=np.zeros(0), b1=np.zeros(0), dist=np.zeros(0))
    pairs = pairs[sid[pairs[:, 0]] != sid[pairs[:, 1]]]
    swap = sid[pairs[:, 0]] > sid[pairs[:, 1]]
    pairs[swap] = pairs[swap][:, ::-1]
    i, j = pairs[:, 0], pairs[:, 1]
    a, b = sid[i], sid[j]
    key = a * len(st) + b
    order = np.lexsort((ss[j], ss[i], key))
    i, j, a, b, key = i[order], j[order], a[order], b[order], key[order]
    if len(i) == 0:
        return dict(empty, overlap=np.zeros(0, bool), a0=np.zeros(0), a1=np.zeros(0),
                    b0=np.zeros(0), b1=np.zeros(0), dist=np.zeros(0))
    brk = np.concatenate([[True], (key[1:] != key[:-1]) | (np.diff(ss[i]) > 2.5 * h)])
    # a parallel run that touches both ends of `b`, over far more of `b` than of `a`
    # (a short stroke drawn over the opening of a nearly closed one), is split along `b`
    lengths = np.array([st.length(k) for k in range(len(st))])
    cos_od = np.cos(np.radians(opts.overdraw_angle))
    run = np.cumsum(brk) - 1
    rs = np.flatnonzero(brk)
    lo_b, hi_b = np.minimum.reduceat(ss[j], rs), np.maximum.reduceat(ss[j], rs)
    cosang = np.abs(np.einsum("ij,ij->i", tan[i], tan[j]))
    par = np.add.reduceat(cosang, rs) / np.diff(np.append(rs, len(i))) >= cos_od
    both = par & (lo_b <= h) & (hi_b >= lengths[b[rs]] - h) & (
        hi_b - lo_b > np.maximum.reduceat(ss[i], rs) - np.minimum.reduceat(ss[i], rs) + 4 * tol)
    if both.any():
        order = np.lexsort((ss[i], ss[j], run))
        i, j, a, b, run, cosang = (x[order] for x in (i, j, a, b, run, cosang))
        brk = np.concatenate([[True], (run[1:] != run[:-1])
                              | ((np.diff(ss[j]) > 2.5 * h) & both[run[1:]])])
    start = np.flatnonzero(brk)
    comp = np.cumsum(brk) - 1
    a0 = np.minimum.reduceat(ss[i], start)
    a1 = np.maximum.reduceat(ss[i], start)
    b0 = np.minimum.reduceat(ss[j], start)
    b1 = np.maximum.reduceat(ss[j], start)
    mean_cos = np.add.reduceat(cosang, start) / np.diff(np.append(start, len(i)))
    dist = np.linalg.norm(Q[i] - Q[j], axis=1)
    best = np.lexsort((dist, comp))
    first = np.concatenate([[True], comp[best][1:] != comp[best][:-1]])
    bi = best[first]
    lo = opts.overdraw_length * tol
    sa, sb = a[start], b[start]
    end_a = (a0 <= h) | (a1 >= lengths[sa] - h)
    end_b = (b0 <= h) | (b1 >= lengths[sb] - h)
    long_run = ((a1 - a0) >= lo) & ((b1 - b0) >= lo)
    # two strokes that continue each other with a short overlap (end inside end)
    end_to_end = end_a & end_b & ((a1 - a0) >= tol) & ((b1 - b0) >= tol)
    # a short stroke drawn (mostly) over a part of another one
    covered = (((a1 - a0) >= 0.8 * lengths[sa]) | ((b1 - b0) >= 0.8 * lengths[sb])) & (
        (a1 - a0) >= 2.0 * tol) & ((b1 - b0) >= 2.0 * tol)
    overlap = (long_run | end_to_end | covered) & (mean_cos >= cos_od)
    return {"a": sa, "b": sb, "i": i[bi], "j": j[bi], "a0": a0, "a1": a1,
            "b0": b0, "b1": b1, "overlap": overlap, "dist": dist[bi]}


def _overdraw_rounds(st, tol, h, opts, report):
    """Close loops drawn past their start and consolidate overdraw (up to 12 rounds) before
    junctions are sought.

    Each round first merges the strokes whose end runs back along their own beginning
    (:func:`curvenet.snap.overdraw.close_loops`: the input's, and those a consolidation
    has just extended past their start), then consolidates the overdraw between strokes.
    Returns the strokes, their samples and their contacts (none an overlap).
    """
    prev = None
    for _round in range(13):
        samples = sample(st, h)
        if _round == 0:
            check_density(samples, tol, opts.snap_tol)
        if close_loops(st, samples, tol, h, opts, report):
            samples = sample(st, h)
        since = None if prev is None else (prev[0], prev[1], _unchanged(prev[2], st.polys))
        con = _contacts(samples, tol, h, st, opts, since)
        if not con["overlap"].any():
            return st, samples, con
        if _round == 12:
            break
        prev = (con, samples[4], list(st.polys))  # consolidate edits st: keep the polylines
        st = consolidate(st, samples, con, tol, h, opts, report)
    report["warnings"].append("overdraw left after 12 rounds; treated as crossings")
    con["overlap"][:] = False
    return st, samples, con


def _unchanged(before, after):
    """Per polyline of ``after``, its index in ``before`` if it is the same object, else -1.

    Both lists must be alive (an object's id is unique only among live objects).
    """
    index = {id(p): k for k, p in enumerate(before)}
    return np.array([index.get(id(p), -1) for p in after], dtype=np.int64)


# --------------------------------------------------------------------------- junctions
def _candidates(st, samples, con, tol, h, opts):
    """Junction candidates: positions ``(m, 3)``, the two member strokes ``(m, 2) int64``
    and arc parameters on them ``(m, 2) float64`` of each, and the number of closed strokes.

    Each point contact's closest sample pair is refined to the closest points of
    the sample segments around it (four segment pairs, batched). The candidate
    sits at their midpoint, or on the other stroke when only one side is an end
    (a T-junction lands on the through stroke).
    """
    Q, sid, ss, _, start, flat = samples
    keep = np.flatnonzero(~con["overlap"])
    i, j = con["i"][keep], con["j"][keep]
    a, b = sid[i], sid[j]
    best_d = np.full(len(keep), np.inf)
    pa, pb = Q[i].copy(), Q[j].copy()
    sa, sb = ss[i].copy(), ss[j].copy()
    for di in (-1, 0):
        for dj in (-1, 0):
            ia = np.clip(i + di, start[a], start[a + 1] - 2)
            jb = np.clip(j + dj, start[b], start[b + 1] - 2)
            u, v = segment_closest(Q[ia], Q[ia + 1], Q[jb], Q[jb + 1])
            xa = Q[ia] + u[:, None] * (Q[ia + 1] - Q[ia])
            xb = Q[jb] + v[:, None] * (Q[jb + 1] - Q[jb])
            d = np.linalg.norm(xa - xb, axis=1)
            better = d < best_d
            best_d[better] = d[better]
            pa[better], pb[better] = xa[better], xb[better]
            sa[better] = (ss[ia] + u * (ss[ia + 1] - ss[ia]))[better]
            sb[better] = (ss[jb] + v * (ss[jb + 1] - ss[jb]))[better]
    end_a = (sa <= 0.5 * h) | (sa >= flat.L[a] - 0.5 * h)
    end_b = (sb <= 0.5 * h) | (sb >= flat.L[b] - 0.5 * h)
    pos = np.where((end_a & ~end_b)[:, None], pb,
                   np.where((end_b & ~end_a)[:, None], pa, 0.5 * (pa + pb)))
    closed = [k for k in range(len(st))  # closed strokes: the two ends meet
              if st.length(k) > 4.0 * tol and np.linalg.norm(st.polys[k][0] - st.polys[k][-1])
              <= tol]
    own = _own_touches(samples, tol, h, closed, opts.overdraw_length * tol, opts.trim * tol)
    ends = np.array([[st.polys[k][0], st.polys[k][-1]] for k in closed]).reshape(-1, 2, 3)
    pos = np.vstack([pos, own[0], 0.5 * (ends[:, 0] + ends[:, 1])])
    mk = np.concatenate([np.stack([a, b], axis=1), own[1], np.repeat(closed, 2).reshape(-1, 2)])
    ms = np.concatenate([np.stack([sa, sb], axis=1), own[2],
                         np.array([[0.0, st.length(k)] for k in closed]).reshape(-1, 2)])
    return pos, mk.astype(np.int64), ms.astype(np.float64), len(closed)


def _own_touches(samples, tol, h, closed, run, margin):
    """T-junctions of a stroke's end on its own interior (a ruling drawn on round its
    ring in one stroke: a "P").

    An end of a stroke that is not ``closed`` (the ids of the closed-stroke rule)
    touches its own stroke where a sample farther than ``2 pi tol`` from it along the
    stroke (a loop narrower than ``2 tol`` is a curl of the pen, not a face) and more
    than ``margin`` (``trim * tol``) from the other end lies within ``tol`` of it
    (nearer, the rest would be trimmed as an overshoot: a ring nearly closed). Only one
    end may touch: a stroke whose two ends both touch it (a ring whose run past its
    start crosses its beginning, an "alpha") stays as drawn; so does one whose last
    ``run`` (``overdraw_length * tol``) runs along that interior within ``tol`` all the
    way (drawn back over itself: a spiral's turns side by side, a fold). The junction
    lands on the interior, as a T-junction lands on the through stroke.

    Returns
    -------
    pos : (t, 3) float64; mk : (t, 2) int64 (the stroke, twice); ms : (t, 2) float64
        (the end's arc parameter, the interior's).
    """
    Q, sid, ss, _, start, flat = samples
    none = (np.zeros((0, 3)), np.zeros((0, 2), np.int64), np.zeros((0, 2)))
    k = np.setdiff1d(np.flatnonzero(flat.L > 4.0 * tol), closed)
    if len(k) == 0:
        return none
    k2 = np.repeat(k, 2)
    s_end = np.where(np.arange(len(k2)) % 2 == 0, 0.0, flat.L[k2])
    near = cKDTree(flat.interp(k2, s_end)).sparse_distance_matrix(
        cKDTree(Q), tol, output_type="ndarray")
    e, j = near["i"].astype(np.int64), near["j"].astype(np.int64)
    L = flat.L[k2[e]]
    ok = ((sid[j] == k2[e]) & (np.abs(ss[j] - s_end[e]) > 2.0 * np.pi * tol)
          & (ss[j] > margin) & (ss[j] < L - margin))
    if not ok.any():
        return none
    e, j, d = e[ok], j[ok], near["v"][ok]
    order = np.lexsort((d, e))
    first = np.concatenate([[True], e[order][1:] != e[order][:-1]])
    e, j = e[order][first], j[order][first]
    one = np.bincount(k2[e], minlength=len(flat.L))[k2[e]] == 1    # both ends: an "alpha"
    e, j = e[one], j[one]
    if len(e) == 0:
        return none
    ke, se, sj = k2[e], s_end[e], ss[j]
    # the end's last `run`, point by point, against the interior around the contact
    inward = np.where(se == 0.0, 1.0, -1.0)
    steps = np.arange(1.0, np.ceil(run / tol) + 1.0) * tol                    # (r,)
    sp = np.clip(se[:, None] + inward[:, None] * steps, 0.0, flat.L[ke][:, None])
    kr, sp = np.repeat(ke, len(steps)), sp.ravel()
    reach = run + tol
    lo = np.repeat(sj - reach, len(steps))
    hi = np.repeat(sj + reach, len(steps))
    away = np.repeat(inward, len(steps)) > 0                 # the end is the start: stay after it
    lo = np.where(away, np.maximum(lo, sp + 2.0 * tol), lo)
    hi = np.where(away, hi, np.minimum(hi, sp - 2.0 * tol))
    pts = flat.interp(kr, sp)
    beside = np.linalg.norm(
        flat.interp(kr, _closest_params(samples, kr, lo, np.maximum(hi, lo), pts, h)) - pts,
        axis=1) <= tol
    keep = ~beside.reshape(len(ke), len(steps)).all(axis=1)
    if not keep.any():
        return none
    ke, se, sj = ke[keep], se[keep], sj[keep]
    s_in = _closest_params(samples, ke, sj - h, sj + h, flat.interp(ke, se), h)
    return flat.interp(ke, s_in), np.stack([ke, ke], axis=1), np.stack([se, s_in], axis=1)


def _closest_params(samples, k, lo, hi, target, h):
    """Arc parameters in ``[lo, hi]`` of strokes ``k`` closest to ``target``, batched.

    Parameters
    ----------
    k : (m,) int64; lo, hi : (m,) float64; target : (m, 3) float64

    Returns
    -------
    (m,) float64
        The nearest sample in the window, refined on a grid of ``h / 4`` around it.
    """
    Q, sid, ss, _, start, flat = samples
    k = np.asarray(k, dtype=np.int64)
    lo = np.maximum(0.0, lo)
    hi = np.minimum(flat.L[k], hi)
    gs = ss + flat.off[sid]  # global sample parameter, increasing
    i0 = np.searchsorted(gs, lo + flat.off[k])
    i1 = np.searchsorted(gs, hi + flat.off[k], side="right")
    i0 = np.clip(i0, start[k], start[k + 1] - 1)
    i1 = np.clip(np.maximum(i1, i0 + 1), start[k] + 1, start[k + 1])
    lens = i1 - i0
    q = np.repeat(np.arange(len(k)), lens)
    idx = np.repeat(i0, lens) + (np.arange(lens.sum()) - np.repeat(np.cumsum(lens) - lens, lens))
    d = np.linalg.norm(Q[idx] - target[q], axis=1)
    order = np.lexsort((d, q))
    first = np.concatenate([[0], np.cumsum(lens)[:-1]])
    best = idx[order[first]]
    grid = np.linspace(-h, h, 9)
    fine = np.clip(ss[best][:, None] + grid[None, :], lo[:, None], hi[:, None])  # (m, 9)
    p = flat.interp(np.repeat(k, 9), fine.ravel()).reshape(-1, 9, 3)
    pick = np.argmin(np.linalg.norm(p - target[:, None, :], axis=2), axis=1)
    return fine[np.arange(len(k)), pick]


def _cluster(samples, pos, mk, ms, tol, h):
    """Merge candidates into junctions; returns (positions, per-stroke member lists).

    ``mk``, ``ms`` (m, 2): the strokes each candidate lies on and its arc parameters
    there. Per-stroke member list: sorted list of (s, junction id). Candidates within
    ``tol`` merge; so do junctions that land within ``1.5 tol`` of each other along
    one stroke (a corner whose pairwise contacts scattered), closest first, for up to
    four rounds (see :func:`curvenet.snap.merge.join_near` for the pairs that do not
    merge). Junctions are numbered by their first candidate.
    """
    m = len(pos)
    if m == 0:
        return np.zeros((0, 3)), {}
    links = (cKDTree(pos).query_pairs(tol, output_type="ndarray") if m > 1
             else np.zeros((0, 2), dtype=np.int64))  # candidates joined
    Q, sid = samples[0], samples[1]
    mc = np.repeat(np.arange(m), 2)  # the candidate of each member
    L = samples[5].L
    gap = ((ms <= 0.5 * h) | (ms >= L[mk] - 0.5 * h)).all(axis=1)  # two stroke ends only
    mk, ms = mk.ravel(), ms.ravel()
    held = {}  # first candidate of a junction -> strokes that end there only by a split
    for _ in range(4):
        cid = components(m, links)
        J = np.zeros((cid.max() + 1, 3))
        np.add.at(J, cid, pos)
        J /= np.bincount(cid, minlength=len(J))[:, None]
        # each stroke's members of one junction, in runs no more than 2 tol apart: the
        # point of the run's window on the stroke closest to the junction
        jm = cid[mc]
        order = np.lexsort((ms, mk, jm))
        k_o, s_o, j_o = mk[order], ms[order], jm[order]
        pair = np.concatenate([[True], (k_o[1:] != k_o[:-1]) | (j_o[1:] != j_o[:-1])])
        new = pair | np.concatenate([[False], np.diff(s_o) > 2.0 * tol])
        first = np.flatnonzero(new)
        last = np.append(first[1:], len(order)) - 1
        qk, qj = k_o[first], j_o[first]
        qs = (_closest_params(samples, qk, s_o[first] - tol, s_o[last] + tol, J[qj], h)
              if len(qk) else np.zeros(0))
        # per stroke by (s, junction): neighbours of different junctions closer than 1.5 tol
        by = np.lexsort((qj, qs, qk))
        qk, qs, qj = qk[by], qs[by], qj[by]
        near = (qk[1:] == qk[:-1]) & (qj[1:] != qj[:-1]) & (np.diff(qs) < 1.5 * tol)
        if not near.any():
            break
        g = np.flatnonzero(pair)  # (junction, stroke) pairs, in order: all gaps there? the
        side = np.where(s_o <= 0.5 * h, 0, np.where(s_o >= L[k_o] - 0.5 * h, 1, 2))
        lo_s, hi_s = np.minimum.reduceat(side, g), np.maximum.reduceat(side, g)
        ends = (j_o[g], k_o[g], np.logical_and.reduceat(gap[mc[order]], g),
                np.where(lo_s == hi_s, lo_s, 2))  # stroke end there: 0 start, 1 end, 2 other
        # samples within 2 tol of the near junctions, of the strokes that meet there
        js = np.unique(np.concatenate([qj[:-1][near], qj[1:][near]]))
        mine = np.flatnonzero(np.isin(sid, ends[1][np.isin(ends[0], js)]))
        around = {j: (Q[mine[i]], sid[mine[i]]) for j, i in
                  zip(js.tolist(), (np.asarray(i, dtype=np.int64) for i in
                                    cKDTree(Q[mine]).query_ball_point(J[js], 2.0 * tol)))}
        joined = join_near((np.diff(qs)[near], qk[1:][near], qj[:-1][near], qj[1:][near]),
                           cid, gap, ends, held, L, tol, around)
        if len(joined) == 0:
            break
        links = np.concatenate([links, joined])
    # one stroke, one junction, two equal parameters: keep one
    per_stroke = {}
    for k, s, jn in zip(qk.tolist(), qs.tolist(), qj.tolist()):
        out = per_stroke.setdefault(k, [])
        if out and out[-1][1] == jn and abs(out[-1][0] - s) < 0.5 * h:
            continue
        out.append((s, jn))
    return J, per_stroke


def corner_chords(tol, diag, opts):
    """Chord lengths ``(w, w0)`` of the turn measurements: ``w = corner_window * tol`` and
    ``w0 = corner_window * min(tol, DEFAULT_SNAP_TOL * diag)``.

    A tolerance above the default is measured from how far stroke ends stop from other
    strokes, not from how tightly the strokes curve; joins are judged over ``w0`` and
    the corner search discounts curvature with it (:func:`_corners`). At or below the
    default the two are equal.
    """
    return opts.corner_window * tol, opts.corner_window * min(tol, DEFAULT_SNAP_TOL * diag)


def _corners(samples, w, w0, h, opts):
    """Sharp turns: ``{stroke: [s, ...]}``, local maxima of the turn above the threshold.

    The turn at ``s`` is the angle between the chords ``p(s - w) -> p(s)`` and
    ``p(s) -> p(s + w)``, ``w = corner_window * tol``, evaluated every ``h / 2``
    on all strokes at once; ``p(x)`` is the stroke's mean over ``x +- w / 4``
    (:meth:`Flat.window_mean`), so that per-sample jitter does not make corners. Where
    ``w0 < w`` (a tolerance wider than the default, :func:`corner_chords`), it is the
    smaller of that and its mean with the turn over the chords ``w0``: a smooth curve
    turns in proportion to the chord, a corner does not, so a circle as tight as the
    wide window (a torus's small circle at a tolerance measured from wide gaps) is not
    cut into corners, while a corner rounded over more than ``w0`` still turns enough
    over ``w``.
    """
    flat = samples[5]
    ok = np.flatnonzero(flat.L > 2 * w)
    if opts.corner_angle >= 180 or ok.size == 0:
        return {}
    n = np.maximum(3, np.ceil((flat.L[ok] - 2 * w) / (0.5 * h)).astype(np.int64) + 1)
    pad = int(np.ceil(w / (0.5 * h))) + 1  # -1 entries between strokes stop the filter
    start = np.concatenate([[0], np.cumsum(n + pad)])
    kk = np.repeat(ok, n)
    rel = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
    s = w + rel * np.repeat((flat.L[ok] - 2 * w) / (n - 1), n)
    pos = rel + np.repeat(start[:-1], n)
    p0, p1, p2 = (flat.window_mean(kk, s + d, _CHORD_END_MEAN * w) for d in (-w, 0.0, w))
    ang = np.full(start[-1], -1.0)
    ang[pos] = chord_turn(p0, p1, p2)
    if w0 < w:
        t0 = chord_turn(*(flat.window_mean(kk, s + d, _CHORD_END_MEAN * w0)
                          for d in (-w0, 0.0, w0)))
        ang[pos] = np.minimum(ang[pos], 0.5 * (ang[pos] + t0))
    peak = (ang >= maximum_filter1d(ang, 2 * pad - 1, mode="nearest")) & (ang > opts.corner_angle)
    out = {}
    inv = -np.ones(start[-1], dtype=np.int64)
    inv[pos] = np.arange(len(pos))
    for q in inv[np.flatnonzero(peak)]:
        lst = out.setdefault(int(kk[q]), [])
        if not lst or s[q] - lst[-1] > w:
            lst.append(float(s[q]))
    return out


# --------------------------------------------------------------------------- assembly
def _displace_and_split(poly, cum, cuts, disp, tol, opts):
    """Move a stroke onto its junctions with C1 bumps and cut it there.

    Parameters
    ----------
    cuts : (k,) float64, increasing arc parameters
    disp : (k, 3) float64, displacement at each cut

    Returns the list of k + 1 pieces (first and last may be ``None`` when a cut
    sits at the stroke's end).
    """
    k = len(cuts)
    gaps = np.diff(np.concatenate([[-np.inf], cuts, [np.inf]]))
    R = np.minimum(opts.blend * tol, 0.45 * np.minimum(gaps[:-1], gaps[1:]))
    R = np.maximum(R, DIVISION_GUARD)  # guard: coincident cuts are removed before this point
    s_all = np.concatenate([cum, cuts])
    p_all = np.vstack([poly, interpolate_polyline(poly, cuts, cum=cum)])
    is_cut = np.concatenate([np.zeros(len(cum), bool), np.ones(k, bool)])
    # drop polyline vertices closer than tol / 10 to a cut: no needle segments there
    near = np.zeros(len(cum), bool)
    if k:
        near = np.min(np.abs(cum[:, None] - cuts[None, :]), axis=1) < 0.1 * tol
    keep = np.concatenate([~near, np.ones(k, bool)])
    s_all, p_all, is_cut = s_all[keep], p_all[keep], is_cut[keep]
    order = np.argsort(s_all, kind="stable")
    s_all, p_all, is_cut = s_all[order], p_all[order], is_cut[order]
    if k:
        wts = bump((s_all[:, None] - cuts[None, :]) / R[None, :])  # (n, k)
        p_all = p_all + wts @ disp
    cut_pos = np.flatnonzero(is_cut)
    pieces = []
    bounds = [0, *cut_pos.tolist(), len(s_all) - 1]
    for q in range(k + 1):
        lo, hi = bounds[q], bounds[q + 1]
        pieces.append(p_all[lo:hi + 1] if hi > lo else None)
    return pieces


def snap_rough(strokes, src, labels, diag, opts) -> CurveNetwork:
    """Tolerance-based snapping; see :mod:`curvenet.snap` for the steps."""
    tol = opts.snap_tol * diag
    report = {"mode": "rough", "crossings": 0, "t_junctions": 0, "gap_merges": 0,
              "closed_strokes": 0, "overdrawn_loops": 0, "trimmed_overshoots": 0,
              "overdraw_consolidations": 0, "corners": 0, "dissolved_joins": 0,
              "slivers_merged": 0, "strokes_dropped_short": 0, "warnings": []}
    st = Strokes()
    for p, s, lab in zip(strokes, src, labels):
        if arc_length(p) < opts.min_length * tol:
            report["strokes_dropped_short"] += 1
            continue
        st.add(p, (s,), lab)
    if not len(st):
        report["warnings"].append("every stroke is shorter than min_length * tol")
        net = CurveNetwork(np.zeros((0, 3)))
        net.report = report
        return net
    total = sum(st.length(k) for k in range(len(st)))
    h = max(0.25 * tol, total / _MAX_SAMPLES)
    st, samples, con = _overdraw_rounds(st, tol, h, opts, report)
    pos, mk, ms, report["closed_strokes"] = _candidates(st, samples, con, tol, h, opts)
    J, per_stroke = _cluster(samples, pos, mk, ms, tol, h)
    nj = len(J)
    verts = [p for p in J]
    corner_ids = set()
    w, w0 = corner_chords(tol, diag, opts)
    for k, found in sorted(_corners(samples, w, w0, h, opts).items()):  # degree-2 vertices
        taken = [s for s, _ in per_stroke.get(k, [])]
        for s in found:
            if all(abs(s - t) > 2.0 * tol for t in taken):
                vid = len(verts)
                verts.append(interpolate_polyline(st.polys[k], np.array([s]), cum=st.cums[k])[0])
                corner_ids.add(vid)
                per_stroke.setdefault(k, []).append((s, vid))
                report["corners"] += 1
    # classify junctions by how strokes meet there
    ends_at = np.zeros(len(verts), np.int64)
    through = np.zeros(len(verts), np.int64)
    edges = []
    verts_arr = np.array(verts).reshape(-1, 3)
    flat = samples[5]
    for k in range(len(st)):
        poly, cum = st.polys[k], st.cums[k]
        L = cum[-1]
        lst = sorted(per_stroke.get(k, []))
        cuts = np.array([s for s, _ in lst])
        ids = [j for _, j in lst]
        for s, j in lst:
            if j in corner_ids:
                continue
            if s <= 0.5 * h or s >= L - 0.5 * h:
                ends_at[j] += 1
            else:
                through[j] += 1
        disp = verts_arr[ids] - flat.interp(np.full(len(cuts), k), cuts) if ids else \
            np.zeros((0, 3))
        pieces = _displace_and_split(poly, cum, cuts, disp, tol, opts)
        lab = st.labels[k]
        for q, piece in enumerate(pieces):
            if piece is None or len(piece) < 2:
                continue
            plen = arc_length(piece)
            free_head = q == 0
            free_tail = q == len(pieces) - 1
            if (free_head or free_tail) and ids:
                if plen < opts.trim * tol:
                    report["trimmed_overshoots"] += 1
                    continue
            if plen <= 0:
                continue
            if free_head and free_tail:  # no junction on this stroke
                u = len(verts)
                verts.append(piece[0])
                v = len(verts)
                verts.append(piece[-1])
            elif free_head:
                u = len(verts)
                verts.append(piece[0])
                v = ids[0]
            elif free_tail:
                u = ids[-1]
                v = len(verts)
                verts.append(piece[-1])
            else:
                u, v = ids[q - 1], ids[q]
                if u == v and plen < opts.trim * tol:  # a tiny loop at one junction
                    report["trimmed_overshoots"] += 1
                    continue
            edges.append((u, v, piece, st.srcs[k], lab))
    for j in range(nj):
        if through[j] >= 2:
            report["crossings"] += 1
        elif through[j] == 1 and ends_at[j] >= 1:
            report["t_junctions"] += 1
        elif through[j] == 0 and ends_at[j] >= 2:
            report["gap_merges"] += 1
    edges = dissolve(edges, corner_ids, tol, w0, opts, verts, report)
    edges, report["slivers_merged"] = merge_slivers(edges, tol)
    if report["slivers_merged"]:  # a junction of slivers may be left of degree 2
        edges = dissolve(edges, corner_ids, tol, w0, opts, verts, report)
    used = sorted({e[0] for e in edges} | {e[1] for e in edges})
    new_id = {v: i for i, v in enumerate(used)}
    net = CurveNetwork(np.array([verts[v] for v in used]).reshape(-1, 3))
    for u, v, curve, srcs, lab in edges:
        net.add_edge(new_id[u], new_id[v], clean(curve, 0.05 * tol), strokes=srcs, label=lab)
    net.report = report
    return net

