"""Clean-up of the snapped graph (step 7 of :mod:`curvenet.snap`): smooth joins dissolved,
corners next to them kept (left-over overdraw slivers are averaged in
:mod:`curvenet.snap.overdraw`).

Private module, split from :mod:`curvenet.snap.rough` by topic. Edges are tuples
``(u, v, curve, sources, label)``; all lengths are absolute (``tol = snap_tol *
diagonal``).
"""

from __future__ import annotations

import numpy as np

from ..core.geometry import cumulative_length, interpolate_polyline
from ..core.tolerances import DIVISION_GUARD

__all__ = ["chord_turn", "dissolve", "join_turn"]


def chord_turn(p0, p1, p2):
    """Turn in degrees ``(m,)`` between chords ``p0 -> p1`` and ``p1 -> p2`` (``(m, 3)`` each)."""
    u, v = p1 - p0, p2 - p1
    nu = np.maximum(np.linalg.norm(u, axis=1), DIVISION_GUARD)  # guard 0-length chords
    nv = np.maximum(np.linalg.norm(v, axis=1), DIVISION_GUARD)
    return np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", u, v) / (nu * nv), -1, 1)))


def _far_point(c, w):
    """The first point of polyline ``c`` at least ``w`` from ``c[0]``, else its last point."""
    far = np.flatnonzero(np.linalg.norm(c - c[0], axis=1) >= w)
    return c[far[0] if far.size else -1]


def join_turn(c1, c2, w):
    """Turn in degrees where curve ``c1`` ends and ``c2`` starts: ``t_w``, or the mean of
    ``t_w`` and ``t_h`` where that is smaller.

    ``t_w`` and ``t_h``: the turns between the chords ``w`` and ``w / 2`` long on each
    side (to the first points that far from the join, or a side's far end where it is
    shorter). A smooth join on a curve of curvature ``k`` turns by ``k w`` and ``k w /
    2``: on a curve as tight as the window (a torus's small circle) the mean tells it
    from a corner, which turns about as much at both lengths (a little less at ``w /
    2`` where it was drawn rounded; the shorter chords alone would dissolve those).
    """
    t_w, t_h = (chord_turn(*(x[None] for x in (_far_point(c1[::-1], d), c2[0],
                                                _far_point(c2, d))))[0] for d in (w, 0.5 * w))
    return float(min(t_w, 0.5 * (t_w + t_h)))


def _corner_near_join(curve, s_join, tol, w, opts):
    """Arc parameter of a lone sharp turn next to a join on the joined curve, or None.

    The per-stroke corner search cannot see a turn closer than ``corner_window *
    tol`` to a stroke end (no chord beyond it), nor one within ``2 tol`` of a
    junction. A stroke that goes round a corner and stops just past it, joined to
    the next stroke, hides its corner there; on the joined curve both chords exist.
    The turn is measured over chords ``w`` (the join chord, see :func:`dissolve`),
    over the join's ``2 tol`` plus one chord on each side, and no closer than
    ``corner_window * tol`` to the joined curve's ends: there the bumps that move
    the curve onto the junctions at its ends bend it (a short chord sees that bend
    as a turn). A corner is taken only where the turn exceeds ``corner_angle`` in one
    run there (a tight curl or a zigzag has several), peaking between ``tol / 4``
    (closer, the join itself is the turn, and it was found smooth) and ``2 tol``
    from the join.
    """
    cum = cumulative_length(curve)
    e = opts.corner_window * tol
    lo, hi = max(e, s_join - 2.0 * tol - w), min(cum[-1] - e, s_join + 2.0 * tol + w)
    if hi - lo < 0.5 * tol:
        return None
    s = np.linspace(lo, hi, int((hi - lo) / (0.05 * tol)) + 2)
    turn = chord_turn(*(interpolate_polyline(curve, x, cum=cum) for x in (s - w, s, s + w)))
    sharp = turn > opts.corner_angle
    k = int(np.argmax(turn))
    runs = np.count_nonzero(np.diff(sharp.astype(np.int8)) == 1) + int(sharp[0])
    if runs != 1 or sharp[0] or sharp[-1] or not 0.25 * tol <= abs(s[k] - s_join) <= 2.0 * tol:
        return None
    return float(s[k])


def _split(curve, s):
    """The curve cut at arc parameter ``s``: two polylines sharing the cut point."""
    cum = cumulative_length(curve)
    p = interpolate_polyline(curve, np.array([s]), cum=cum)
    return np.vstack([curve[cum < s], p]), np.vstack([p, curve[cum > s]])


def dissolve(edges, corner_ids, tol, w, opts, verts, report):
    """Join the two edges at each smooth degree-2 vertex that is not a corner.

    The join turn (:func:`join_turn`) is measured over chords ``w``: ``corner_window``
    times the smaller of ``tol`` and the default tolerance
    (:func:`curvenet.snap.rough.corner_chords`). Vertices are visited in increasing
    id, each once, with the incidence updated after each join. Where the joined
    curve turns sharply within ``2 tol`` of the join (:func:`_corner_near_join`), the
    vertex moves to that corner (``verts`` is updated in place) instead of being
    dissolved.

    Returns the new edge list; the dissolved vertices are added to
    ``report["dissolved_joins"]`` and the moved ones to ``report["corners"]``.
    """
    count = moved = 0
    inc = [set() for _ in range(len(verts))]
    for e_id, e in enumerate(edges):
        inc[e[0]].add(e_id)
        inc[e[1]].add(e_id)
    for v in range(len(verts)):
        if len(inc[v]) != 2 or v in corner_ids:
            continue
        i1, i2 = sorted(inc[v])
        e1, e2 = edges[i1], edges[i2]
        if e1[0] == e1[1] or e2[0] == e2[1]:
            continue
        c1 = e1[2] if e1[1] == v else e1[2][::-1]  # ends at v
        u1 = e1[0] if e1[1] == v else e1[1]
        c2 = e2[2] if e2[0] == v else e2[2][::-1]  # starts at v
        w2 = e2[1] if e2[0] == v else e2[0]
        if join_turn(c1, c2, w) >= opts.corner_angle:
            continue
        label = "crease" if "crease" in (e1[4], e2[4]) else "boundary"
        joined = np.vstack([c1, c2[1:]])
        srcs = tuple(sorted(set(e1[3]) | set(e2[3])))
        s_join = float(cumulative_length(c1)[-1])
        at = _corner_near_join(joined, s_join, tol, w, opts)
        if at is not None:  # the sources of the piece that holds the other stroke's part
            a, b = _split(joined, at)
            verts[v] = a[-1]
            edges[i1] = (u1, v, a, e1[3] if at <= s_join else srcs, label)
            edges[i2] = (v, w2, b, srcs if at <= s_join else e2[3], label)
            moved += 1
            continue
        edges[i1] = (u1, w2, joined, srcs, label)
        edges[i2] = None
        inc[v].clear()
        inc[w2].discard(i2)
        inc[w2].add(i1)
        inc[u1].add(i1)
        count += 1
    report["dissolved_joins"] += count
    report["corners"] += moved
    return [e for e in edges if e is not None]

