"""The tolerance-based snapping of :func:`curvenet.snap.snap` (``mode="rough"``).

Private module; the steps and constants are documented in :mod:`curvenet.snap`.
All lengths below are absolute (``tol = snap_tol * diagonal``).
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import maximum_filter1d
from scipy.spatial import cKDTree

from .network import CurveNetwork

__all__ = ["UnionFind", "dedup", "snap_rough"]


# --------------------------------------------------------------------------- small tools
class UnionFind:
    """Array union-find over ``n`` items (path halving, smaller root wins)."""

    def __init__(self, n):
        self.parent = np.arange(n)

    def find(self, i):
        p = self.parent
        while p[i] != i:
            p[i] = p[p[i]]
            i = p[i]
        return i

    def union(self, a, b):
        ra, rb = self.find(a), self.find(b)
        if ra != rb:
            self.parent[max(ra, rb)] = min(ra, rb)

    def union_pairs(self, pairs):
        for a, b in pairs:
            self.union(a, b)

    def labels(self):
        return np.array([self.find(i) for i in range(len(self.parent))], dtype=np.int64)


def dedup(poly, eps):
    """Drop points within ``eps`` of their predecessor (the last point is kept)."""
    poly = np.asarray(poly, dtype=np.float64)
    if len(poly) < 2:
        return poly
    d = np.linalg.norm(np.diff(poly, axis=0), axis=1)
    keep = np.concatenate([[True], d > eps])
    out = poly[keep]
    if not keep[-1] and len(out) > 1:
        out[-1] = poly[-1]
    return out


def _arclength(poly):
    """Cumulative arc length ``(n,)`` of an ``(n, 3)`` polyline."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(poly, axis=0), axis=1))])


def _interp(poly, cum, s):
    """Points ``(k, 3)`` at arc parameters ``s`` ``(k,)`` (clamped to the polyline)."""
    s = np.clip(np.asarray(s, dtype=np.float64), 0.0, cum[-1])
    j = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(cum) - 2)
    seg = cum[j + 1] - cum[j]
    t = np.where(seg > 0, (s - cum[j]) / np.where(seg > 0, seg, 1.0), 0.0)
    return poly[j] + t[:, None] * (poly[j + 1] - poly[j])


def _bump(x):
    """C1 bump ``(1 - x^2)^2`` for ``|x| < 1``, else 0: value 1 and slope 0 at 0."""
    x = np.minimum(np.abs(x), 1.0)
    return (1.0 - x * x) ** 2


def _smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def _resample(curve, n):
    cum = _arclength(curve)
    return _interp(curve, cum, np.linspace(0.0, cum[-1], n))


# --------------------------------------------------------------------------- state
class _Strokes:
    """Working strokes: polylines, arc lengths, source ids and labels."""

    def __init__(self):
        self.polys, self.cums, self.srcs, self.labels = [], [], [], []

    def add(self, poly, srcs, label):
        self.polys.append(poly)
        self.cums.append(_arclength(poly))
        self.srcs.append(tuple(sorted(set(srcs))))
        self.labels.append(label)

    def set(self, k, poly):
        self.polys[k] = poly
        self.cums[k] = _arclength(poly)

    def __len__(self):
        return len(self.polys)

    def length(self, k):
        return self.cums[k][-1]


def _sample(st, h):
    """Uniform samples: points (M,3), stroke id (M,), arc param (M,), unit tangent (M,3)."""
    pts, sid, ss, tan = [], [], [], []
    for k in range(len(st)):
        L = st.length(k)
        n = max(2, int(np.ceil(L / h)) + 1)
        s = np.linspace(0.0, L, n)
        p = _interp(st.polys[k], st.cums[k], s)
        t = np.gradient(p, axis=0)
        t /= np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-300)  # guard 0-length
        pts.append(p)
        sid.append(np.full(n, k))
        ss.append(s)
        tan.append(t)
    return (np.concatenate(pts), np.concatenate(sid), np.concatenate(ss), np.concatenate(tan))


def _contacts(samples, tol, h, st, opts):
    """Group close sample pairs of different strokes into contacts.

    Returns a structured dict of arrays, one entry per contact: strokes ``a < b``,
    extents on each, closest pair ``(i, j)`` (sample indices), ``overlap`` flag.
    """
    Q, sid, ss, tan = samples
    pairs = cKDTree(Q).query_pairs(tol, output_type="ndarray")
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
    start = np.flatnonzero(brk)
    comp = np.cumsum(brk) - 1
    a0 = np.minimum.reduceat(ss[i], start)
    a1 = np.maximum.reduceat(ss[i], start)
    b0 = np.minimum.reduceat(ss[j], start)
    b1 = np.maximum.reduceat(ss[j], start)
    cosang = np.abs(np.einsum("ij,ij->i", tan[i], tan[j]))
    mean_cos = np.add.reduceat(cosang, start) / np.diff(np.append(start, len(i)))
    dist = np.linalg.norm(Q[i] - Q[j], axis=1)
    best = np.lexsort((dist, comp))
    first = np.concatenate([[True], comp[best][1:] != comp[best][:-1]])
    bi = best[first]
    lo = opts.overdraw_length * tol
    lengths = np.array([st.length(k) for k in range(len(st))])
    sa, sb = a[start], b[start]
    end_a = (a0 <= h) | (a1 >= lengths[sa] - h)
    end_b = (b0 <= h) | (b1 >= lengths[sb] - h)
    long_run = ((a1 - a0) >= lo) & ((b1 - b0) >= lo)
    # two strokes that continue each other with a short overlap (end inside end)
    end_to_end = end_a & end_b & ((a1 - a0) >= tol) & ((b1 - b0) >= tol)
    overlap = (long_run | end_to_end) & (mean_cos >= np.cos(np.radians(opts.overdraw_angle)))
    return {"a": sa, "b": sb, "i": i[bi], "j": j[bi], "a0": a0, "a1": a1,
            "b0": b0, "b1": b1, "overlap": overlap, "dist": dist[bi]}


# --------------------------------------------------------------------------- overdraw
def _consolidate(st, samples, con, tol, h, opts, report):
    """Average each overdrawn stretch into its host and cut it out of the guest."""
    Q, sid, ss, _ = samples
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
        cov_a = (con["a1"][c] - con["a0"][c]) / max(st.length(a), 1e-300)
        cov_b = (con["b1"][c] - con["b0"][c]) / max(st.length(b), 1e-300)
        if cov_a > cov_b or (cov_a == cov_b and a > b):
            guest, host = a, b
            g0, g1, h0, h1 = con["a0"][c], con["a1"][c], con["b0"][c], con["b1"][c]
        else:
            guest, host = b, a
            g0, g1, h0, h1 = con["b0"][c], con["b1"][c], con["a0"][c], con["a1"][c]
        # host: move halfway onto the guest over [h0, h1], tapered over `ramp` at both ends
        gm = (sid == guest) & (ss >= g0 - tol) & (ss <= g1 + tol)
        gtree = cKDTree(Q[gm])
        hp, hc = st.polys[host], st.cums[host]
        inside = (hc >= h0) & (hc <= h1)
        if inside.any():
            _, nn = gtree.query(hp[inside])
            ramp = max(min(2.0 * tol, 0.5 * (h1 - h0)), 1e-300)
            w = _smoothstep((hc[inside] - h0) / ramp) * _smoothstep((h1 - hc[inside]) / ramp)
            hp = hp.copy()
            hp[inside] += 0.5 * w[:, None] * (Q[gm][nn] - hp[inside])
            st.set(host, hp)
        st.srcs[host] = tuple(sorted(set(st.srcs[host]) | set(st.srcs[guest])))
        if st.labels[guest] == "crease":
            st.labels[host] = "crease"
        # guest: the pieces outside [g0, g1]. A piece that continues the host past
        # the host's end (the end lies inside the overlap) is appended to the host,
        # however short; other pieces stay as strokes if at least `trim * tol` long.
        gp, gc = st.polys[guest], st.cums[guest]
        hp, hc = st.polys[host], st.cums[host]
        keep_min = opts.trim * tol
        for lo, hi, attach_at_start in ((0.0, g0, False), (g1, gc[-1], True)):
            if hi - lo <= 0.5 * h:
                continue
            piece = _cut(gp, gc, lo, hi)
            if not attach_at_start:
                piece = piece[::-1]  # now starts at the overlap
            pa = piece[0]
            if h1 >= hc[-1] - h and np.linalg.norm(hp[-1] - pa) <= 2.0 * tol:
                hp = np.vstack([hp, piece])
                st.set(host, hp)
                hc = st.cums[host]
            elif h0 <= h and np.linalg.norm(hp[0] - pa) <= 2.0 * tol:
                hp = np.vstack([piece[::-1], hp])
                st.set(host, hp)
                hc = st.cums[host]
            elif hi - lo >= keep_min:
                new.append((piece, st.srcs[guest], st.labels[guest]))
        removed.add(guest)
        report["overdraw_consolidations"] += 1
    if not busy:
        return st
    out = _Strokes()
    for k in range(len(st)):
        if k not in removed:
            out.add(st.polys[k], st.srcs[k], st.labels[k])
    for p, s, lab in new:
        out.add(p, s, lab)
    return out


def _cut(poly, cum, a, b):
    """Sub-polyline ``(m, 3)`` between arc parameters ``a < b``, exact end points."""
    inner = (cum > a) & (cum < b)
    ends = _interp(poly, cum, np.array([a, b]))
    return np.vstack([ends[:1], poly[inner], ends[1:]])


# --------------------------------------------------------------------------- junctions
def _candidates(st, samples, con, tol, h):
    """Junction candidates: positions (m,3) and members [(stroke, s), ...] per candidate."""
    Q, sid, ss, _ = samples
    pos, members = [], []
    keep = np.flatnonzero(~con["overlap"])
    for c in keep:
        i, j = int(con["i"][c]), int(con["j"][c])
        a, b = int(sid[i]), int(sid[j])
        end_a = ss[i] <= 0.5 * h or ss[i] >= st.length(a) - 0.5 * h
        end_b = ss[j] <= 0.5 * h or ss[j] >= st.length(b) - 0.5 * h
        if end_a and not end_b:
            p = Q[j]
        elif end_b and not end_a:
            p = Q[i]
        else:
            p = 0.5 * (Q[i] + Q[j])
        pos.append(p)
        members.append([(a, float(ss[i])), (b, float(ss[j]))])
    closed = 0
    for k in range(len(st)):  # closed strokes: the two ends meet
        p = st.polys[k]
        L = st.length(k)
        if L > 4.0 * tol and np.linalg.norm(p[0] - p[-1]) <= tol:
            pos.append(0.5 * (p[0] + p[-1]))
            members.append([(k, 0.0), (k, float(L))])
            closed += 1
    return np.array(pos).reshape(-1, 3), members, closed


def _closest_param(st, k, lo, hi, target, h):
    """Arc parameter in ``[lo, hi]`` of stroke ``k`` closest to ``target`` (h-resolution)."""
    L = st.length(k)
    lo, hi = max(0.0, lo), min(L, hi)
    n = max(2, int(np.ceil((hi - lo) / (0.25 * h))) + 1)
    s = np.linspace(lo, hi, n)
    p = _interp(st.polys[k], st.cums[k], s)
    return float(s[np.argmin(np.linalg.norm(p - target, axis=1))])


def _cluster(st, pos, members, tol, h, opts):
    """Merge candidates into junctions; returns (positions, per-stroke member lists).

    Per-stroke member list: sorted list of (s, junction id). Candidates within
    ``tol`` merge; so do junctions that land within ``1.5 tol`` of each other
    along one stroke (a corner whose pairwise contacts scattered).
    """
    m = len(pos)
    uf = UnionFind(m)
    if m > 1:
        uf.union_pairs(cKDTree(pos).query_pairs(tol, output_type="ndarray").tolist())
    for _ in range(4):
        lab = uf.labels()
        roots, cid = np.unique(lab, return_inverse=True)
        J = np.zeros((len(roots), 3))
        np.add.at(J, cid, pos)
        J /= np.bincount(cid, minlength=len(roots))[:, None]
        raw = {}
        for c, mem in enumerate(members):
            for k, s in mem:
                raw.setdefault((int(cid[c]), k), []).append(s)
        per_stroke = {}
        for (jn, k), svals in sorted(raw.items()):
            svals = np.sort(np.asarray(svals))
            runs = np.split(svals, np.flatnonzero(np.diff(svals) > 2.0 * tol) + 1)
            for r in runs:
                s = _closest_param(st, k, r[0] - tol, r[-1] + tol, J[jn], h)
                per_stroke.setdefault(k, []).append((s, jn))
        changed = False
        first_member = {}  # junction -> a candidate index, to union by candidate
        for c in range(m):
            first_member.setdefault(int(cid[c]), c)
        for lst in per_stroke.values():
            lst.sort()
            for (s1, j1), (s2, j2) in zip(lst[:-1], lst[1:]):
                if j1 != j2 and s2 - s1 < 1.5 * tol:
                    ra, rb = uf.find(first_member[j1]), uf.find(first_member[j2])
                    if ra != rb:
                        uf.union(ra, rb)
                        changed = True
        if not changed:
            break
    # one stroke, one junction, two equal parameters: keep one
    for k, lst in per_stroke.items():
        out = []
        for s, jn in lst:
            if out and out[-1][1] == jn and abs(out[-1][0] - s) < 0.5 * h:
                continue
            out.append((s, jn))
        per_stroke[k] = out
    return J, per_stroke


def _corners(st, k, tol, h, opts):
    """Arc parameters of sharp turns of stroke ``k`` (local maxima above the threshold)."""
    L = st.length(k)
    w = opts.corner_window * tol
    if L <= 2 * w or opts.corner_angle >= 180:
        return []
    n = max(3, int(np.ceil((L - 2 * w) / (0.5 * h))) + 1)
    s = np.linspace(w, L - w, n)
    poly, cum = st.polys[k], st.cums[k]
    p0, p1, p2 = (_interp(poly, cum, s - w), _interp(poly, cum, s), _interp(poly, cum, s + w))
    u, v = p1 - p0, p2 - p1
    nu = np.maximum(np.linalg.norm(u, axis=1), 1e-300)
    nv = np.maximum(np.linalg.norm(v, axis=1), 1e-300)
    ang = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", u, v) / (nu * nv), -1, 1)))
    size = 2 * int(np.ceil(w / (0.5 * h))) + 1
    peak = (ang >= maximum_filter1d(ang, size, mode="nearest")) & (ang > opts.corner_angle)
    out = []
    for q in np.flatnonzero(peak):
        if not out or s[q] - out[-1] > w:
            out.append(float(s[q]))
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
    L = cum[-1]
    k = len(cuts)
    gaps = np.diff(np.concatenate([[-np.inf], cuts, [np.inf]]))
    R = np.minimum(opts.blend * tol, 0.45 * np.minimum(gaps[:-1], gaps[1:]))
    R = np.maximum(R, 1e-300)  # guard: coincident cuts are removed before this point
    s_all = np.concatenate([cum, cuts])
    p_all = np.vstack([poly, _interp(poly, cum, cuts)])
    is_cut = np.concatenate([np.zeros(len(cum), bool), np.ones(k, bool)])
    # drop polyline vertices that coincide with a cut
    near = np.zeros(len(cum), bool)
    if k:
        near = np.min(np.abs(cum[:, None] - cuts[None, :]), axis=1) < 1e-12 * max(L, 1e-300)
    keep = np.concatenate([~near, np.ones(k, bool)])
    s_all, p_all, is_cut = s_all[keep], p_all[keep], is_cut[keep]
    order = np.argsort(s_all, kind="stable")
    s_all, p_all, is_cut = s_all[order], p_all[order], is_cut[order]
    if k:
        wts = _bump((s_all[:, None] - cuts[None, :]) / R[None, :])  # (n, k)
        p_all = p_all + wts @ disp
    cut_pos = np.flatnonzero(is_cut)
    pieces = []
    bounds = [0, *cut_pos.tolist(), len(s_all) - 1]
    for q in range(k + 1):
        lo, hi = bounds[q], bounds[q + 1]
        pieces.append(p_all[lo:hi + 1] if hi > lo else None)
    return pieces


def _tangent_at(curve, at_start, w):
    """Unit direction leaving the curve's start (or end), over a chord of length ``w``."""
    c = curve if at_start else curve[::-1]
    cum = _arclength(c)
    p = _interp(c, cum, np.array([min(w, cum[-1])]))[0]
    d = p - c[0]
    return d / max(np.linalg.norm(d), 1e-300)


def _dissolve(edges, corner_ids, tol, opts, nverts):
    """Join the two edges at each smooth degree-2 vertex that is not a corner."""
    count = 0
    changed = True
    while changed:
        changed = False
        inc = [[] for _ in range(nverts)]
        for e_id, e in enumerate(edges):
            if e is None:
                continue
            inc[e[0]].append(e_id)
            inc[e[1]].append(e_id)
        for v in range(nverts):
            if len(inc[v]) != 2 or v in corner_ids or inc[v][0] == inc[v][1]:
                continue
            e1, e2 = edges[inc[v][0]], edges[inc[v][1]]
            c1 = e1[2] if e1[1] == v else e1[2][::-1]  # ends at v
            u1 = e1[0] if e1[1] == v else e1[1]
            c2 = e2[2] if e2[0] == v else e2[2][::-1]  # starts at v
            w2 = e2[1] if e2[0] == v else e2[0]
            w = opts.corner_window * tol
            t1 = -_tangent_at(c1, False, w)
            t2 = _tangent_at(c2, True, w)
            turn = np.degrees(np.arccos(np.clip(t1 @ t2, -1, 1)))
            if turn >= opts.corner_angle:
                continue
            label = "crease" if "crease" in (e1[4], e2[4]) else "boundary"
            edges[inc[v][0]] = (u1, w2, np.vstack([c1, c2[1:]]),
                                tuple(sorted(set(e1[3]) | set(e2[3]))), label)
            edges[inc[v][1]] = None
            count += 1
            changed = True
            break
    return [e for e in edges if e is not None], count


def _merge_slivers(edges, tol):
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
                cx = _resample(edges[ex][2] if edges[ex][0] == u else edges[ex][2][::-1], 64)
                cy = _resample(edges[ey][2] if edges[ey][0] == u else edges[ey][2][::-1], 64)
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


def snap_rough(strokes, src, labels, diag, opts) -> CurveNetwork:
    """Tolerance-based snapping; see :mod:`curvenet.snap` for the steps."""
    tol = opts.snap_tol * diag
    report = {"mode": "rough", "crossings": 0, "t_junctions": 0, "gap_merges": 0,
              "closed_strokes": 0, "trimmed_overshoots": 0, "overdraw_consolidations": 0,
              "corners": 0, "dissolved_joins": 0, "slivers_merged": 0,
              "strokes_dropped_short": 0, "warnings": []}
    st = _Strokes()
    for p, s, lab in zip(strokes, src, labels):
        if _arclength(p)[-1] < opts.min_length * tol:
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
    # overdraw first: it changes the strokes the junctions are found on
    for _round in range(12):
        samples = _sample(st, h)
        con = _contacts(samples, tol, h, st, opts)
        if not con["overlap"].any():
            break
        st = _consolidate(st, samples, con, tol, h, opts, report)
    else:
        samples = _sample(st, h)
        con = _contacts(samples, tol, h, st, opts)
        if con["overlap"].any():
            report["warnings"].append("overdraw left after 12 rounds; treated as crossings")
            con["overlap"][:] = False
    pos, members, report["closed_strokes"] = _candidates(st, samples, con, tol, h)
    J, per_stroke = _cluster(st, pos, members, tol, h, opts)
    nj = len(J)
    verts = [p for p in J]
    corner_ids = set()
    for k in range(len(st)):  # corners: degree-2 vertices, no displacement
        taken = [s for s, _ in per_stroke.get(k, [])]
        for s in _corners(st, k, tol, h, opts):
            if all(abs(s - t) > tol for t in taken):
                vid = len(verts)
                verts.append(_interp(st.polys[k], st.cums[k], np.array([s]))[0])
                corner_ids.add(vid)
                per_stroke.setdefault(k, []).append((s, vid))
                report["corners"] += 1
    # classify junctions by how strokes meet there
    ends_at = np.zeros(len(verts), np.int64)
    through = np.zeros(len(verts), np.int64)
    edges = []
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
        disp = np.array([verts[j] - _interp(poly, cum, np.array([s]))[0] for s, j in lst]
                        ).reshape(-1, 3)
        pieces = _displace_and_split(poly, cum, cuts, disp, tol, opts)
        lab = st.labels[k]
        for q, piece in enumerate(pieces):
            if piece is None or len(piece) < 2:
                continue
            plen = _arclength(piece)[-1]
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
    edges, report["dissolved_joins"] = _dissolve(edges, corner_ids, tol, opts, len(verts))
    edges, report["slivers_merged"] = _merge_slivers(edges, tol)
    used = sorted({e[0] for e in edges} | {e[1] for e in edges})
    new_id = {v: i for i, v in enumerate(used)}
    net = CurveNetwork(np.array([verts[v] for v in used]).reshape(-1, 3))
    for u, v, curve, srcs, lab in edges:
        net.add_edge(new_id[u], new_id[v], curve, strokes=srcs, label=lab)
    net.report = report
    return net


_MAX_SAMPLES = 2_000_000
