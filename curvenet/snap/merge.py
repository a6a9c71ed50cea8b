"""Junction merging of :func:`curvenet.snap.snap` (step 4): connected components of
candidate links, and which junctions near each other along a stroke merge.

Private module, split from :mod:`curvenet.snap.rough` by topic; all lengths are
absolute (``tol = snap_tol * diagonal``).
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

__all__ = ["APART", "components", "first_items", "join_near"]

#: Junctions within 1.5 tol along a stroke stay two when the other strokes of each stay
#: more than this many tol from the other's (see :func:`join_near`). Between the two
#: populations measured: rings of a torus drawn a third of its tube's radius apart lie
#: 1.6 tol apart at the default tolerance; hand-drawn strokes 1.0-1.25 tol apart are
#: mostly one line drawn twice, which merged junctions join (benchmarks/README.md).
APART = 1.25


def join_near(near, cid, gap, ends, held, L, tol, around):
    """Candidate pairs ``(p, 2) int64`` that join the junctions of near pairs, closest first.

    ``near``: per pair of junctions ``j1, j2`` within ``1.5 tol`` along stroke ``k``, arrays
    ``(ds, k, j1, j2)``. ``cid (m,)``: junction of each candidate; ``gap (m,) bool``: the
    candidate is two stroke ends; ``ends``: per (junction, stroke) pair with members, in
    order, arrays ``(junction, stroke, only gap members, stroke end there: 0 start, 1 end,
    2 neither or both)``. A split stroke (two stroke ends meeting in a gap, nothing else)
    does not pull in a junction one piece passes through once the gap has joined a
    junction some stroke passes through: a gap between two nearby crossings would chain
    them into one. Likewise the seam of a closed stroke (its own two ends, nothing else):
    once joined to such a junction, the stroke pulls in no other junction it passes
    through there (a ring that stops short between two crossings would chain them).
    ``held`` (first candidate of a junction -> such strokes) carries over rounds and is
    updated in place. Nor do two junctions that strokes pass through merge
    along a short stroke that runs from one to the other (its start at one, its end at
    the other): a piece between two gaps, each next to a crossing, would chain the two.
    Nor do two junctions that are each a meeting without ``k`` (two more stroke ends, or a
    stroke passing through) merge along ``k`` when no stroke is at both and their other
    strokes stay more than :data:`APART` tol apart near them (``around``: junction ->
    ``(points (n, 3), strokes (n,) int64)``, the samples within 2 tol of it of the strokes
    that meet at the near junctions): two rings close together, each crossing a meridian,
    are two crossings, where a corner whose pairwise contacts scattered is one.
    """
    (ds, kk, j1, j2), (ej, ek, only, end) = near, ends
    key = ej * len(L) + ek
    per = np.bincount(ej, minlength=cid.max() + 1)
    gaps = np.bincount(ej, weights=~only, minlength=cid.max() + 1) == 0
    split = (per == 2) & gaps
    seam = (per == 1) & gaps  # a closed stroke's own two ends (candidates of one stroke)
    through = np.bincount(cid, weights=~gap) > 0  # some stroke passes through
    fi = first_items(cid)
    parent, out = {}, []
    meets = {}  # junction -> {stroke: 2 passing through, 1 an end there}, for roots
    for j, k, e in zip(ej.tolist(), ek.tolist(), end.tolist()):
        meets.setdefault(j, {})[k] = 2 if e == 2 else 1
    around = dict(around)

    def find(j):
        while parent.get(j, j) != j:
            j = parent[j]
        return j

    def gap_only(j, k):
        return only[np.searchsorted(key, j * len(L) + k)]

    def spans(k, a, b):  # stroke k starts at one junction and ends at the other
        return {int(end[np.searchsorted(key, j * len(L) + k)]) for j in (a, b)} == {0, 1}

    def apart(k, ra, rb):  # two meetings without k whose strokes stay apart
        wa = {q: w for q, w in meets.get(ra, {}).items() if q != k}
        wb = {q: w for q, w in meets.get(rb, {}).items() if q != k}
        if (min(sum(wa.values()), sum(wb.values())) < 2 or wa.keys() & wb.keys()
                or ra not in around or rb not in around):
            return False
        (pa, sa), (pb, sb) = around[ra], around[rb]
        on_k = np.vstack([pa[sa == k], pb[sb == k]])
        pa, pb = pa[np.isin(sa, list(wa))], pb[np.isin(sb, list(wb))]
        if len(on_k):  # pieces continuing k (overshoots into the gap) do not count
            k_tree = cKDTree(on_k)
            pa = pa[k_tree.query(pa)[0] > 0.5 * tol] if len(pa) else pa
            pb = pb[k_tree.query(pb)[0] > 0.5 * tol] if len(pb) else pb
        return bool(len(pa) and len(pb)
                    and cKDTree(pa).query(pb)[0].min() > APART * tol)

    for x in np.lexsort((j2, j1, kk, ds)).tolist():
        k, a, b = int(kk[x]), int(j1[x]), int(j2[x])
        ra, rb = find(a), find(b)
        ha, hb = held.get(fi[ra], set()), held.get(fi[rb], set())
        if ra == rb or (k in ha and not gap_only(b, k)) or (k in hb and not gap_only(a, k)):
            continue
        if through[ra] and through[rb] and spans(k, a, b) or apart(k, ra, rb):
            continue
        new = ha | hb
        for jx, ry in ((a, rb), (b, ra)):  # a split joins a junction some stroke passes through
            if split[jx] and through[ry]:  # (a stroke under 2 tol is all ends)
                lo = np.searchsorted(ej, jx)
                new |= {int(y) for y in ek[lo:lo + 2] if y != k and L[y] > 2.0 * tol}
            elif seam[jx] and through[ry]:  # a closed stroke's own ends: the stroke itself
                new.add(k)
        root, other = min(ra, rb), max(ra, rb)
        parent[other] = root
        through[root] = through[ra] or through[rb]
        kept = meets.setdefault(root, {})
        for q, w in meets.pop(other, {}).items():
            kept[q] = max(w, kept.get(q, 0))
        if root in around and other in around:
            (p1, s1), (p2, s2) = around[root], around.pop(other)
            around[root] = (np.vstack([p1, p2]), np.concatenate([s1, s2]))
        held[fi[root]] = new
        out.append((fi[a], fi[b]))
    return np.array(out, dtype=np.int64).reshape(-1, 2)


def first_items(comp):
    """Smallest item ``(c,) int64`` of each of the components ``comp (m,)`` numbers."""
    first = np.full(comp.max() + 1, len(comp), dtype=np.int64)
    np.minimum.at(first, comp, np.arange(len(comp)))
    return first


def components(m, links):
    """Connected components of ``m`` items joined by the pairs ``links (p, 2)``, numbered
    in the order of their smallest item (as union-find with the smaller root winning)."""
    graph = coo_matrix((np.ones(len(links)), (links[:, 0], links[:, 1])), shape=(m, m))
    _, comp = connected_components(graph, directed=False)
    _, first = np.unique(comp, return_index=True)
    rank = np.empty(len(first), dtype=np.int64)
    rank[np.argsort(first)] = np.arange(len(first))
    return rank[comp]
