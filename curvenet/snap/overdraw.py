"""Overdraw consolidation of the tolerance-based snapping (steps 3 and 7 of :mod:`curvenet.snap`).

Private module, split from :mod:`curvenet.snap.rough` by topic: a stroke drawn
over (part of) another one is cut out of the guest and averaged into the host; a
stroke whose end runs back along its own beginning (a ring drawn past its start)
becomes one closed loop, the two stretches averaged (:func:`close_loops`);
parallel edges left between the same two vertices (slivers) are averaged.
All lengths are absolute (``tol = snap_tol * diagonal``).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .strokes import Strokes, bump, clean, own_ends, smoothstep
from ..core.geometry import cumulative_length, interpolate_polyline, resample_polyline
from ..core.tolerances import DIVISION_GUARD

__all__ = ["consolidate", "close_loops", "merge_slivers"]

#: Least area a lap drawn past its start encloses, per unit of its length, times ``tol``
#: (the magnitude of its vector area, so any loop's largest projected area): a circle of
#: radius ``tol`` has ``0.5``. A stroke folded over itself (a thin scribble, two short
#: strokes consolidated into a Z) encloses next to none.
_LOOP_AREA = 0.5


def consolidate(st, samples, con, tol, h, opts, report):
    """Average each overdrawn stretch into its host and cut it out of the guest."""
    Q, _, ss, _, start, _ = samples
    idx = np.flatnonzero(con["overlap"])
    span = np.minimum(con["a1"] - con["a0"], con["b1"] - con["b0"])[idx]
    idx = idx[np.argsort(-span, kind="stable")]
    busy = set()
    removed = set()
    new = []
    for c in idx:
        a, b = int(con["a"][c]), int(con["b"][c])
        if a in busy or b in busy:
            continue
        busy.update((a, b))
        cov_a = (con["a1"][c] - con["a0"][c]) / max(st.length(a), DIVISION_GUARD)
        cov_b = (con["b1"][c] - con["b0"][c]) / max(st.length(b), DIVISION_GUARD)
        if cov_a > cov_b or (cov_a == cov_b and a > b):
            guest, host = a, b
            g0, g1, h0, h1 = con["a0"][c], con["a1"][c], con["b0"][c], con["b1"][c]
        else:
            guest, host = b, a
            g0, g1, h0, h1 = con["b0"][c], con["b1"][c], con["a0"][c], con["a1"][c]
        # the guest is covered only where its closest host sample is not a host end:
        # a guest running on past the host's end is a continuation, not overdraw
        hm = slice(start[host], start[host + 1])
        hs = ss[hm]
        lo_g = start[guest] + np.searchsorted(ss[start[guest]:start[guest + 1]], g0 - tol)
        hi_g = start[guest] + np.searchsorted(ss[start[guest]:start[guest + 1]], g1 + tol,
                                              side="right")
        gm = slice(lo_g, hi_g)
        dist, nn = cKDTree(Q[hm]).query(Q[gm])
        cov = (dist <= tol) & (hs[nn] > 0.5 * h) & (hs[nn] < st.length(host) - 0.5 * h)
        if not cov.any():
            continue
        g0, g1 = ss[gm][cov].min(), ss[gm][cov].max()
        gp, gc = st.polys[guest], st.cums[guest]
        gq, gsv = Q[gm], ss[gm]
        gtree = cKDTree(gq)
        hp, hc = st.polys[host].copy(), st.cums[host]
        Lh = hc[-1]
        st.srcs[host] = tuple(sorted(set(st.srcs[host]) | set(st.srcs[guest])))
        if st.labels[guest] == "crease":
            st.labels[host] = "crease"
        # guest pieces outside [g0, g1]: one that continues the host past a host end
        # lying inside the overlap is joined to the host, however short; other pieces
        # stay as strokes if at least `trim * tol` long.
        head_in, tail_in = h0 <= h, h1 >= Lh - h
        join = {}
        for lo, hi, side in ((0.0, g0, "left"), (g1, gc[-1], "right")):
            if hi - lo <= 0.5 * h:
                continue
            pa = interpolate_polyline(gp, np.array([g0 if side == "left" else g1]), cum=gc)[0]
            if tail_in and "tail" not in join and np.linalg.norm(hp[-1] - pa) <= 2.0 * tol:
                join["tail"] = side
            elif head_in and "head" not in join and np.linalg.norm(hp[0] - pa) <= 2.0 * tol:
                join["head"] = side
            elif hi - lo >= opts.trim * tol:
                new.append((_cut(gp, gc, lo, hi), st.srcs[guest], st.labels[guest]))
        # host over the overlap: moved halfway onto the guest (the average), tapered to 0
        # over `ramp` at a free end, and cross-faded to 1 (onto the guest) at a joined end
        a0 = 0.0 if "head" in join else h0
        a1 = Lh if "tail" in join else h1
        inside = (hc >= a0) & (hc <= a1)
        if inside.any():
            x = hc[inside]
            ramp = max(min(2.0 * tol, 0.5 * (h1 - h0)), DIVISION_GUARD)  # guard: empty overlap
            lo_f = (1.0 + smoothstep((h0 + ramp - x) / ramp) if "head" in join
                    else smoothstep((x - h0) / ramp))
            hi_f = (1.0 + smoothstep((x - h1 + ramp) / ramp) if "tail" in join
                    else smoothstep((h1 - x) / ramp))
            beta = np.minimum(0.5 * lo_f * hi_f, 1.0)
            _, nn = gtree.query(hp[inside])
            hp[inside] += beta[:, None] * (gq[nn] - hp[inside])
        before, after = [], []
        if "tail" in join:
            gt = gsv[gtree.query(hp[-1])[1]]
            if join["tail"] == "right" and gt < gc[-1]:
                after = [_cut(gp, gc, gt, gc[-1])[1:]]
            elif join["tail"] == "left" and gt > 0:
                after = [_cut(gp, gc, 0.0, gt)[::-1][1:]]
        if "head" in join:
            gh = gsv[gtree.query(hp[0])[1]]
            if join["head"] == "right" and gh < gc[-1]:
                before = [_cut(gp, gc, gh, gc[-1])[::-1][:-1]]
            elif join["head"] == "left" and gh > 0:
                before = [_cut(gp, gc, 0.0, gh)[:-1]]
        poly = clean(np.vstack(before + [hp] + after), 0.05 * tol)
        if before or after:  # a guest piece continues the host: maybe past its own start
            loop = _close_loop(poly, cumulative_length(poly), tol)
            poly = poly if loop is None else loop
        st.set(host, poly)
        removed.add(guest)
        report["overdraw_consolidations"] += 1
    if not busy:
        return st
    out = Strokes()
    for k in range(len(st)):
        if k not in removed:
            out.add(st.polys[k], st.srcs[k], st.labels[k], st.cums[k])
    for p, s, lab in new:
        out.add(p, s, lab)
    return out


def close_loops(st, samples, tol, h, opts, report):
    """Merge every stroke whose end runs back along its own beginning into one closed loop.

    Parameters
    ----------
    st : Strokes
        Edited in place (:meth:`Strokes.set`) for each stroke merged.
    samples : tuple
        :func:`curvenet.snap.strokes.sample` of ``st`` at spacing ``h``.
    tol, h : float
        Absolute snapping tolerance and sample spacing.
    opts : SnapOptions
        ``overdraw_angle`` bounds the angle between the two stretches; ``blend`` the
        reach of the join.
    report : dict
        ``report["overdrawn_loops"]`` is increased by the number merged.

    Returns
    -------
    int
        Strokes merged.

    Notes
    -----
    A stroke of length ``L`` is a loop drawn past its start when, with ``a``, ``b``
    from :func:`curvenet.snap.strokes.own_ends` (the windows are the first and last
    :data:`~curvenet.snap.strokes.LOOP_OVERLAP` of ``L``):

    * its last point lies within ``tol`` of its first stretch, at ``a`` past the
      start, and its first point within ``tol`` of its last stretch, at ``b``;
    * the overlap is more than one sample spacing on both sides (``a > h``,
      ``L - b > h``; less is a closed stroke, left to the closing of ends within
      ``tol``) and the lap ``b`` is longer than ``4 tol`` (as a closed stroke);
    * the stretches ``[0, a]`` and ``[b, L]`` are side by side: every sample of
      each lies within ``tol`` of the other (a spiral drifts apart, a hook turns
      away), and they run the same way, the mean cosine of the tangents of nearest
      samples at least ``cos(overdraw_angle)`` (a stroke doubling back is no loop);
    * the lap ``[0, b]`` goes round something: its vector area is at least
      :data:`_LOOP_AREA` ``tol b`` (a thin scribble, or a stroke folded over itself
      in a Z, three strands side by side, encloses next to none).

    The loop is the average of the two stretches (each point of ``[0, a]`` moved
    halfway to its closest point on ``[b, L]``), closed through the stroke from ``a``
    to ``b``, whose two ends are moved onto the average's ends by the C1 bumps of
    the junction step, ``(1 - x^2)^2`` over ``R = min(blend tol, 0.45 (b - a))``
    (a step across the overlap's ends would kink where the two stretches lie far
    apart over a short overlap). Its first and last points are the same, so it
    snaps as a closed stroke. Checking the candidates loops over strokes (the few
    whose ends pass the first test), each with vectorised KD-tree queries.

    References
    ----------
    Abbasinejad, Joshi, Amenta, "Surface patches from unorganized space curves",
    SGP 2011, Sec. 6.1: curves are snapped in pairs ("two curves intersect when
    they pass within a user-defined threshold"), and what that missed was fixed by
    hand; a stroke drawn over its own beginning is not among its cases. This
    extends the overdraw merge from a second stroke over a first one to a stroke
    over itself (issue 33).
    """
    Q, _, ss, tan, start, flat = samples
    a, d_last, b, d_first = own_ends(samples)
    cand = np.flatnonzero((d_last <= tol) & (d_first <= tol) & (a > h) & (flat.L - b > h)
                          & (b > 4.0 * tol))
    cos_od = np.cos(np.radians(opts.overdraw_angle))
    merged = 0
    moved = []
    for k in cand.tolist():
        run = slice(start[k], start[k + 1])
        head, tail = ss[run] <= a[k], ss[run] >= b[k]
        qh, qt = Q[run][head], Q[run][tail]
        dh, nn = cKDTree(qt).query(qh)
        dt, _ = cKDTree(qh).query(qt)
        if max(dh.max(), dt.max()) > tol or np.einsum(
                "ij,ij->i", tan[run][head], tan[run][tail][nn]).mean() < cos_od:
            continue
        lap = Q[run][ss[run] <= b[k]] - Q[run][0]
        area = 0.5 * np.linalg.norm(np.cross(lap[:-1], lap[1:]).sum(axis=0))  # vector area
        if area < _LOOP_AREA * tol * b[k]:
            continue  # a stroke folded over itself, a thin scribble
        st.set(k, _merge_own(st.polys[k], st.cums[k], a[k], b[k], qt, tol, opts.blend))
        moved.append((k, np.vstack([qh, qt]),
                      0.5 * np.vstack([_project(qh, qt) - qh, _project(qt, qh) - qt])))
        merged += 1
    if moved:
        _follow(st, samples, moved, tol, opts.blend)
    report["overdrawn_loops"] += merged
    return merged


def _follow(st, samples, moved, tol, blend):
    """Move the ends of other strokes that touch a merged loop's stretches along with them.

    ``samples``: those of :func:`close_loops` (before the merge); ``moved``: per loop,
    its stroke id, the samples ``(n, 3)`` of its two stretches before the merge and
    their displacements ``(n, 3)`` onto the average. An end of another stroke (not
    itself merged) within ``tol`` of those samples, which the average leaves farther
    than ``tol`` from the loop and which touches no other stroke nor its own other end
    (an end still in touch, closing a gap or a ring's seam, or at a crossing, stays), is
    moved by the displacement of the nearest sample, tapered along its stroke by the C1
    bump of the junction step over ``R = min(blend tol, 0.45 L)``: a stroke that
    touched only the run past the start stays in touch with the loop (cassie 02-2-1: a
    stroke starting 0.95 tol from a ring's run past its start was 1.1 tol from the
    average, and dangled).
    """
    done = {k for k, _, _ in moved}
    others = [j for j in range(len(st)) if j not in done]
    if not others:
        return
    ends = np.array([[st.polys[j][0], st.polys[j][-1]] for j in others]).reshape(-1, 3)
    shift = np.zeros_like(ends)
    best = np.full(len(ends), np.inf)
    after = np.full(len(ends), np.inf)
    for _, pts, disp in moved:
        d, nn = cKDTree(pts).query(ends, distance_upper_bound=tol)
        take = d < best
        best[take] = d[take]
        shift[take] = disp[nn[take]]
        after = np.minimum(after, cKDTree(pts + disp).query(ends)[0])
    lost = np.flatnonzero(np.isfinite(best) & (after > tol))
    if not lost.size:
        return
    Q, sid = samples[0], samples[1]
    free = ~np.isin(sid, list(done))
    tree = cKDTree(Q[free])
    fsid = sid[free]
    for q in lost.tolist():
        j, at_end = others[q // 2], q % 2 == 1
        if (np.any(fsid[tree.query_ball_point(ends[q], tol)] != j)
                or np.linalg.norm(ends[q] - ends[q ^ 1]) <= tol):
            continue  # in touch with another stroke or its own other end: it stays
        poly, cum = st.polys[j], st.cums[j]
        x = (cum[-1] - cum) if at_end else cum
        R = max(min(blend * tol, 0.45 * cum[-1]), DIVISION_GUARD)  # guard: zero-length stroke
        st.set(j, poly + bump(x / R)[:, None] * shift[q])


def _close_loop(poly, cum, tol):
    """Cut back an end that runs on past the stroke's own start; None if not a loop.

    A polyline longer than ``4 tol`` is a loop when some point of its last ``3 tol``
    comes within ``tol`` of its start, heading the way the start does (within 60
    degrees; a stroke doubling back over its start is no loop). It is cut at the
    closest such point, so a loop that runs past its start (a host extended by a
    guest piece) leaves at most a gap, as a closed stroke does.
    """
    if cum[-1] <= 4.0 * tol:
        return None
    tail = np.flatnonzero(cum >= cum[-1] - 3.0 * tol)
    d = np.linalg.norm(poly[tail] - poly[0], axis=1)
    q = int(tail[np.argmin(d)])
    if d.min() > tol:
        return None
    head = poly[np.searchsorted(cum, tol)] - poly[0]
    back = poly[q] - poly[np.searchsorted(cum, cum[q] - tol)]
    if head @ back <= 0.5 * np.linalg.norm(head) * np.linalg.norm(back):
        return None
    return poly[:q + 1]


def _merge_own(poly, cum, a, b, tail, tol, blend):
    """Closed loop ``(m, 3)`` of a stroke whose stretch ``[b, L]`` runs along ``[0, a]``.

    ``tail``: samples ``(t, 3)`` of ``[b, L]``, the first at ``b``. See :func:`close_loops`.
    """
    head = _cut(poly, cum, 0.0, a)
    avg = head + 0.5 * (_project(head, tail) - head)
    middle = _cut(poly, cum, a, b)
    s = cumulative_length(middle)
    R = max(min(blend * tol, 0.45 * s[-1]), DIVISION_GUARD)  # guard: b - a >= L / 2 > 2 tol
    middle = (middle + bump(s / R)[:, None] * (avg[-1] - middle[0])
              + bump((s[-1] - s) / R)[:, None] * (avg[0] - middle[-1]))
    loop = np.vstack([middle, avg[1:]])
    loop[-1] = loop[0]
    return clean(loop, 0.05 * tol)


def _project(points, line):
    """Closest points ``(n, 3)`` of polyline ``line (t, 3)``, ``t >= 2``, to ``points (n, 3)``:
    on the two segments beside the nearest vertex of ``line``."""
    _, nn = cKDTree(line).query(points)
    best, best_d = line[nn], np.linalg.norm(line[nn] - points, axis=1)
    for j in (np.maximum(nn - 1, 0), np.minimum(nn, len(line) - 2)):  # segments j -> j + 1
        d = line[j + 1] - line[j]
        t = np.clip(np.einsum("ij,ij->i", points - line[j], d)
                    / np.maximum(np.einsum("ij,ij->i", d, d), DIVISION_GUARD), 0.0, 1.0)
        q = line[j] + t[:, None] * d
        dq = np.linalg.norm(q - points, axis=1)
        better = dq < best_d
        best[better], best_d[better] = q[better], dq[better]
    return best


def _cut(poly, cum, a, b):
    """Sub-polyline ``(m, 3)`` between arc parameters ``a < b``, exact end points."""
    inner = (cum > a) & (cum < b)
    ends = interpolate_polyline(poly, np.array([a, b]), cum=cum)
    return np.vstack([ends[:1], poly[inner], ends[1:]])


def merge_slivers(edges, tol):
    """Average parallel edges (same end vertices) whose curves stay within ``2 tol``."""
    count = 0
    groups = {}
    for e_id, e in enumerate(edges):
        if e[0] != e[1]:
            groups.setdefault((min(e[0], e[1]), max(e[0], e[1])), []).append(e_id)
    dead = set()
    for (u, _v), ids in sorted(groups.items()):
        for x in range(len(ids)):
            for y in range(x + 1, len(ids)):
                ex, ey = ids[x], ids[y]
                if ex in dead or ey in dead:
                    continue
                cx, cy = (resample_polyline(edges[k][2] if edges[k][0] == u else edges[k][2][::-1],
                                            63) for k in (ex, ey))
                if np.linalg.norm(cx - cy, axis=1).max() <= 2.0 * tol:
                    avg = 0.5 * (cx + cy)
                    e = edges[ex]
                    label = "crease" if "crease" in (e[4], edges[ey][4]) else "boundary"
                    if e[0] != u:
                        avg = avg[::-1]
                    edges[ex] = (e[0], e[1], avg, tuple(sorted(set(e[3]) | set(edges[ey][3]))),
                                 label)
                    dead.add(ey)
                    count += 1
    return [e for i, e in enumerate(edges) if i not in dead], count
