"""Curves given as unordered point samples: tell them from polylines, recover the curves.

A block of points read as one stroke is a *drawn polyline* when consecutive
points are neighbours, and *unordered samples of curves* (wireframe samples,
scanner edge points, point-set exports) when consecutive points jump far
beyond the sampling spacing. :func:`read_point_blocks` decides block by block
(:func:`jump_ratio` against :data:`JUMP_RATIO`) and replaces each unordered
block by the curves :func:`recover_curves` finds in it, so that the usual
snapping, patch finding and surfacing follow.

Recovery (:func:`recover_curves`)
---------------------------------
1. Scale. Box counting over half-octave cell sizes gives the local dimension
   ``log2(N(c) / N(2c))`` of the samples; curves are one-dimensional from
   above their spacing and noise up to the gaps between distinct curves. The
   finest run of :data:`MIN_RUN` consecutive scales with dimension in
   ``[0.7, 1.4]`` sets the cell size ``c``. No such run (a 2D scatter, a
   surface scan, a blob): :class:`NotCurvesError`.
2. Nodes. Points are averaged per grid cell of size ``c`` (noise averages
   out), then each node is projected onto the principal line of its
   neighbours within ``2 c`` where they are linear, collapsing the noisy tube
   onto its axis.
3. Thinning. Minimum spanning tree of the node graph (pairs within
   ``2.5 c``); spurs shorter than ``4 c`` are pruned; cycles the tree cut are
   closed again by the shortest node-graph edges (or leaf-to-curve links
   within ``6 c``) whose ends are more than ``12 c`` apart along the tree.
4. Curves. The graph splits into chains between nodes of degree other than
   two; junction nodes joined by chains shorter than ``3 c`` merge into one
   junction, placed at the least-squares intersection of the incoming chain
   ends' tangent lines (fitted from ``2 c`` to ``10 c`` out; quadratic where
   an end is curved); short chains that noise laid across curves converging at a
   junction (a loop back to it, or a bridge closing a triangle of short
   chains with it) are dropped; a chain closing on itself with no junction
   stays a closed loop; sharp turns (over 45 degrees within ``3 c``) split a chain into two
   curves meeting at a degree-2 vertex.

Every chain comes back as an ordered polyline whose ends are exactly the
junction points, so snapping in exact mode rebuilds the same graph. Work on
points is vectorised (grids, KD-trees, sparse graphs); Python loops run over
scales and chains only.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from .pointgraph import LINK_R, SPUR, assemble, close_cycles, prune
from .pointjunctions import junction_point
from ..core.geometry import bbox_diagonal, cumulative_length, interpolate_polyline
from ..core.tolerances import DIVISION_GUARD
from ..core.errors import InvalidParameterError, SketchFormatError
from ..model.sketch import Sketch

__all__ = ["JUMP_RATIO", "MIN_BLOCK_POINTS", "NotCurvesError", "PointCurves", "jump_ratio",
           "jump_ratios",
           "dimension_profile",
           "recover_curves", "read_point_blocks"]

#: A block is unordered when the median step between consecutive points exceeds
#: this many times the median nearest-neighbour spacing (drawn polylines: about 1).
JUMP_RATIO = 8.0

_PROBES = 200_000            # largest sample that neighbour statistics are taken on
_RUN_POINTS = 50_000         # points of the strokes whose jump ratios are taken at once

#: Blocks with fewer points are always read as polylines (too few to tell).
MIN_BLOCK_POINTS = 20

_MAX_DIM = 1.45             # highest correlation dimension read as curves
_DIM_SLACK = 0.2            # radii this close to the lowest dimension are "one-dimensional"
_CELL_FACTOR = 1.0         # cell size over the finest one-dimensional radius
_MIN_CELL = 1.0 / 600.0     # smallest cell size, fraction of the diagonal (bounds node count)
_SMOOTH_R, _CORNER_W = 2.0, 4.0   # node smoothing radius, corner window (cells)
_CORNER_ANGLE = 45.0


class NotCurvesError(SketchFormatError):
    """The points do not lie along curves (a surface scan, a scatter): nothing to recover."""


@dataclass
class PointCurves:
    """Curves recovered from unordered samples.

    Attributes
    ----------
    strokes : list of (n_i, 3) float64 ndarray
        Ordered polylines; ends shared exactly at junctions; a closed loop
        repeats its first point at the end.
    junctions : (J, 3) float64 ndarray
        Points where three or more curves meet (and sharp-turn vertices).
    cell : float
        Sampling scale ``c`` used (absolute length).
    dimension : (S, 2) float64 ndarray
        Box-counting profile: cell size, local dimension.
    report : dict
        Counters: ``points``, ``nodes``, ``curves``, ``loops``, ``junctions``,
        ``corners``, ``spurs_pruned``, ``cycles_closed``.
    """

    strokes: list
    junctions: np.ndarray
    cell: float
    dimension: np.ndarray
    report: dict = field(default_factory=dict)


# --------------------------------------------------------------------------- detection
def jump_ratio(points) -> float:
    """Median step between consecutive points over the median nearest-neighbour spacing.

    Parameters
    ----------
    points : (n, 3) array_like

    Returns
    -------
    float
        About 1 for a drawn polyline, about ``n / 3`` for points in random order.
        Nearest neighbours are taken for at most :data:`_PROBES` points (seeded).
    """
    p = np.asarray(points, dtype=np.float64)
    if len(p) < 3:
        return 1.0
    steps = np.linalg.norm(np.diff(p, axis=0), axis=1)
    probe = p if len(p) <= _PROBES else p[np.random.default_rng(0).choice(len(p), _PROBES,
                                                                          replace=False)]
    d, _ = cKDTree(p).query(probe, k=2)
    nn, steps = d[:, 1][d[:, 1] > 0], steps[steps > 0]
    if nn.size == 0 or steps.size == 0:
        return 1.0
    return float(np.median(steps) / np.median(nn))


def jump_ratios(strokes) -> np.ndarray:
    """:func:`jump_ratio` of many strokes at once: ``(K,) float64``, the same values.

    The nearest-neighbour spacings of a run of strokes (about :data:`_RUN_POINTS` points,
    which bounds the memory) come from one KD-tree, with the strokes set apart along a
    fourth axis (farther than any two points of one stroke), and the medians from one
    sort; strokes over :data:`_PROBES` points are measured one by one (their probes are
    drawn at random).
    """
    sizes = np.array([len(s) for s in strokes], np.int64)
    out = np.ones(len(strokes))
    for k in np.flatnonzero(sizes > _PROBES):
        out[k] = jump_ratio(strokes[k])
    use = np.flatnonzero((sizes >= 3) & (sizes <= _PROBES))
    cut = np.flatnonzero(np.diff(np.cumsum(sizes[use]) // _RUN_POINTS)) + 1
    for run in np.split(use, cut):
        if len(run):
            out[run] = _run_ratios([strokes[k] for k in run])
    return out


def _run_ratios(strokes) -> np.ndarray:
    """:func:`jump_ratio` of strokes of 3 to :data:`_PROBES` points, ``(K,) float64``."""
    p = np.concatenate([np.asarray(s, dtype=np.float64) for s in strokes])
    owner = np.repeat(np.arange(len(strokes)), [len(s) for s in strokes])
    apart = 4.0 * float(np.abs(p).max()) + 1.0          # over any stroke's diameter
    q = np.column_stack([p, owner * apart])
    nn = cKDTree(q).query(q, k=2)[0][:, 1]
    del q
    steps = np.linalg.norm(np.diff(p, axis=0), axis=1)
    inside = owner[1:] == owner[:-1]                    # not from one stroke to the next
    step_of, steps = owner[1:][inside], steps[inside]
    m_nn = _medians(nn[nn > 0], owner[nn > 0], len(strokes))
    m_step = _medians(steps[steps > 0], step_of[steps > 0], len(strokes))
    ok = np.isfinite(m_nn) & np.isfinite(m_step)
    out = np.ones(len(strokes))
    out[ok] = m_step[ok] / m_nn[ok]
    return out


def _medians(values, group, n: int) -> np.ndarray:
    """Median of ``values`` per ``group`` (``0 .. n - 1``), as :func:`numpy.median` takes
    it; NaN for an empty group: ``(n,) float64``."""
    order = np.lexsort((values, group))
    v = values[order]
    count = np.bincount(group, minlength=n)
    mid = np.cumsum(count) - count + count // 2
    out = np.full(n, np.nan)
    odd, even = count % 2 == 1, (count > 0) & (count % 2 == 0)
    out[odd] = v[mid[odd]]
    out[even] = (v[mid[even] - 1] + v[mid[even]]) / 2
    return out


# --------------------------------------------------------------------------- scale
def _cell_keys(p, lo, c):
    q = np.floor((p - lo) / c).astype(np.int64)
    m = q.max(axis=0) + 1
    return (q[:, 0] * m[1] + q[:, 1]) * m[2] + q[:, 2]


def dimension_profile(points, *, probes: int = 2000, seed: int = 0) -> np.ndarray:
    """Correlation dimension of a point set over half-octave radii.

    Parameters
    ----------
    points : (n, 3) array_like
    probes : int
        Number of points (drawn at random, seeded) whose neighbour counts are
        taken, among at most :data:`_PROBES` points (a seeded subsample).
    seed : int

    Returns
    -------
    (S, 2) float64 ndarray
        Rows ``(r, log2(C(2 r) / C(r)))`` from coarse to fine radii, ``C(r)``
        the mean number of other points within ``r`` of a probe; radii go down
        from a quarter of the diagonal until probes have about one neighbour.
    """
    p = np.asarray(points, dtype=np.float64)
    diag = bbox_diagonal(p) or 1.0
    rng = np.random.default_rng(seed)
    other = p if len(p) <= _PROBES else p[rng.choice(len(p), _PROBES, replace=False)]
    probe = other if len(other) <= probes else other[rng.choice(len(other), probes,
                                                                replace=False)]
    radii = diag * 2.0 ** (-np.arange(2, 44) / 2)
    counts = cKDTree(probe).count_neighbors(cKDTree(other), radii).astype(np.float64)
    counts = (counts - len(probe)) / len(probe)
    keep = np.flatnonzero(counts >= 1.0)
    if len(keep) < 3:
        return np.zeros((0, 2))
    c = counts[: keep[-1] + 1]
    return np.column_stack([radii[2: len(c)], np.log2(c[:-2] / c[2:]) / 1.0])


def _pick_cell(profile, diag):
    """Cell size: twice the finest radius of the one-dimensional regime, or None.

    The regime is the run of radii whose dimension is within :data:`_DIM_SLACK`
    of the profile's lowest value, which must itself be at most
    :data:`_MAX_DIM` (curves; a surface is about 2).
    """
    if len(profile) == 0 or profile[:, 1].min() > _MAX_DIM:
        return None
    ok = profile[:, 1] <= profile[:, 1].min() + _DIM_SLACK
    lowest = int(np.argmin(profile[:, 1]))
    fine = lowest
    while fine + 1 < len(ok) and ok[fine + 1]:
        fine += 1
    return max(_CELL_FACTOR * float(profile[fine, 0]), _MIN_CELL * diag)


# --------------------------------------------------------------------------- nodes
def _nodes(p, c):
    """Cell centroids ``(N, 3)`` and point counts ``(N,)`` at cell size ``c``."""
    key = _cell_keys(p, p.min(axis=0), c)
    _, inv, cnt = np.unique(key, return_inverse=True, return_counts=True)
    inv = inv.ravel()
    cen = np.column_stack([np.bincount(inv, weights=p[:, k]) for k in range(3)]) / cnt[:, None]
    return cen, cnt.astype(np.float64)


def _project_lines(x, w, r, rounds=2):
    """Move each node onto the principal line of its neighbours within ``r`` (where linear)."""
    for _ in range(rounds):
        pairs = cKDTree(x).query_pairs(r, output_type="ndarray")
        i = np.concatenate([pairs[:, 0], pairs[:, 1], np.arange(len(x))])
        j = np.concatenate([pairs[:, 1], pairs[:, 0], np.arange(len(x))])
        wj = w[j]
        sw = np.bincount(i, weights=wj, minlength=len(x))
        mu = np.column_stack([np.bincount(i, weights=wj * x[j, k], minlength=len(x))
                              for k in range(3)]) / sw[:, None]
        d = x[j] - mu[i]
        outer = (d[:, :, None] * d[:, None, :]).reshape(-1, 9)
        cov = np.column_stack([np.bincount(i, weights=wj * outer[:, k], minlength=len(x))
                               for k in range(9)]).reshape(-1, 3, 3) / sw[:, None, None]
        lam, vec = np.linalg.eigh(cov)
        axis = vec[:, :, 2]
        linear = lam[:, 2] > 0.85 * lam.sum(axis=1)
        rel = x - mu
        proj = mu + np.einsum("ij,ij->i", rel, axis)[:, None] * axis
        x = np.where(linear[:, None], proj, x)
    return x


def _corners(poly, w):
    """Indices of the corners of a polyline.

    A corner turns by more than :data:`_CORNER_ANGLE` between the directions
    over ``[2 w / 3, 2 w]`` before and after it, and by less than 1.5 times the
    turn over ``[w / 3, w]``: a corner's turn does not grow with the window
    (rounding by the sampling scale aside), a smooth bend's grows in proportion.
    """
    s = cumulative_length(poly)
    inside = np.flatnonzero((s > 2 * w) & (s < s[-1] - 2 * w))
    if len(inside) == 0:
        return inside

    def at(t):
        return interpolate_polyline(poly, t, cum=s)

    def turn(r):
        u, v = at(s[inside] - r / 3) - at(s[inside] - r), at(s[inside] + r) - at(s[inside] + r / 3)
        cos = np.einsum("ij,ij->i", u, v) / np.maximum(
            np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1), DIVISION_GUARD)
        return np.degrees(np.arccos(np.clip(cos, -1, 1)))

    turn, wide = turn(w), turn(2 * w)
    turn = np.where(wide < 1.5 * turn, wide, 0.0)
    sharp = inside[turn > _CORNER_ANGLE]
    if len(sharp) == 0:
        return sharp
    # one corner per run of sharp samples: the sharpest
    run = np.concatenate([[0], np.cumsum(np.diff(s[sharp]) > w)])
    t = turn[np.searchsorted(inside, sharp)]
    best = np.lexsort((-t, run))
    return np.sort(sharp[best[np.concatenate([[True], np.diff(run[best]) > 0])]])


def _smooth(p, closed, rounds=4):
    """Binomial smoothing along a polyline (ends fixed unless closed)."""
    for _ in range(rounds):
        if closed and len(p) > 3:
            q = p[:-1]
            q = 0.5 * q + 0.25 * (np.roll(q, 1, axis=0) + np.roll(q, -1, axis=0))
            p = np.vstack([q, q[:1]])
        elif len(p) > 2:
            p = np.vstack([p[:1], 0.5 * p[1:-1] + 0.25 * (p[:-2] + p[2:]), p[-1:]])
    return p


def _polylines(x, curves, cluster, c):
    """Ordered polylines whose ends are exactly the junction points; sharp turns split."""
    labels = sorted({v for cv in curves for v in cv[1:] if v >= 0})
    where = {}
    for v in labels:
        members = np.flatnonzero(cluster == v)
        ends = [cv[0] if k == 1 else cv[0][::-1] for cv in curves for k in (1, 2)
                if cv[k] == v]
        where[v] = junction_point(x, members, ends, c)
    strokes, corners = [], 0
    for nodes, a, b in curves:
        p = x[nodes]
        closed = a < 0
        if not closed:
            ja, jb = where[a], where[b]
            keep = ((np.linalg.norm(p - ja, axis=1) > c) & (np.linalg.norm(p - jb, axis=1) > c))
            keep[[0, -1]] = False
            p = np.vstack([ja, p[keep], jb])
        cut = _corners(p, _CORNER_W * c)
        if closed and len(cut):  # closed loop with corners: start it at one
            p = np.vstack([p[cut[0]:-1], p[:cut[0] + 1]])
            cut, closed = _corners(p, _CORNER_W * c), False
        corners += len(cut)
        strokes.extend(_smooth(p[i:j + 1], closed)
                       for i, j in zip(np.r_[0, cut], np.r_[cut, len(p) - 1]))
    return strokes, np.array([where[v] for v in labels]).reshape(-1, 3), corners


def recover_curves(points, *, cell: float | None = None, name: str = "points",
                   path=None) -> PointCurves:
    """Recover the curve network sampled by unordered points.

    Parameters
    ----------
    points : (n, 3) array_like
        Samples along curves, any order, any density, with noise well below
        the distance between distinct curves.
    cell : float, optional
        Sampling scale (absolute length); estimated by box counting when omitted.
    name : str
        Names the input in error messages.
    path : str, optional
        The file the points came from (named in error messages).

    Returns
    -------
    PointCurves

    Raises
    ------
    NotCurvesError
        The points are not one-dimensional at any scale (a surface scan, a 2D
        scatter), or no curve survives thinning.

    Examples
    --------
    >>> t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    >>> ring = np.column_stack([np.cos(t), np.sin(t), 0 * t])
    >>> rc = recover_curves(np.random.default_rng(0).permutation(ring))
    >>> len(rc.strokes), rc.report["loops"], bool((rc.strokes[0][0] == rc.strokes[0][-1]).all())
    (1, 1, True)
    """
    p = np.asarray(points, dtype=np.float64)
    diag = bbox_diagonal(p)
    if len(p) < MIN_BLOCK_POINTS or diag == 0.0:
        raise NotCurvesError(f"{name}: {len(p)} points spanning {diag:.3g}: too few to "
                             "recover curves from", path=path)
    profile = dimension_profile(p)
    if cell is None:
        cell = _pick_cell(profile, diag)
        if cell is None:
            dims = profile[:, 1]
            raise NotCurvesError(
                f"{name}: the {len(p)} points do not lie along curves (their dimension is "
                f"{dims.min() if len(dims) else 0:.1f} at best, curves have 1): a surface scan "
                "or a scatter, not curve samples", path=path)
    x, w = _nodes(p, cell)
    x = _project_lines(x, w, _SMOOTH_R * cell)
    pairs = cKDTree(x).query_pairs(LINK_R * cell, output_type="ndarray")
    length = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1) + 1e-9 * cell  # local: > 0
    mst = csgraph.minimum_spanning_tree(
        sparse.coo_matrix((length, (pairs[:, 0], pairs[:, 1])), shape=(len(x),) * 2)).tocoo()
    tree = np.column_stack([mst.row, mst.col]).astype(np.int64)
    tree, spurs = prune(x, tree, cell)
    closing = close_cycles(x, tree, np.linalg.norm(x[tree[:, 0]] - x[tree[:, 1]], axis=1)
                            + 1e-9 * cell, pairs, cell)
    e, more = prune(x, np.vstack([tree, closing]), cell, forks=True)
    curves, cluster, _ = assemble(x, e, cell)
    strokes, junctions, corners = _polylines(x, curves, cluster, cell)
    if not strokes:
        raise NotCurvesError(f"{name}: no curve longer than {SPUR * cell:.3g} found in "
                             f"{len(p)} points: not curve samples", path=path)
    report = {"points": len(p), "nodes": len(x), "curves": len(strokes),
              "loops": sum(cv[1] < 0 for cv in curves), "junctions": len(junctions),
              "corners": corners, "spurs_pruned": spurs + more, "cycles_closed": len(closing),
              "cell": cell, "cell_rel": cell / diag}
    return PointCurves(strokes, junctions, cell, profile, report)


# --------------------------------------------------------------------------- sketches
def read_point_blocks(sketch: Sketch, points="auto") -> Sketch:
    """Replace the strokes that are unordered point samples by the curves they sample.

    Parameters
    ----------
    sketch : Sketch
        As read from a file: each block of points is one stroke.
    points : {"auto", True, False}
        ``auto`` reads a stroke of at least :data:`MIN_BLOCK_POINTS` points as
        unordered samples when :func:`jump_ratio` exceeds :data:`JUMP_RATIO`;
        ``True`` reads every stroke so; ``False`` none.

    Returns
    -------
    Sketch
        Strokes in file order, each unordered block replaced by its recovered
        curves (with the block's label). When a block was read as points,
        ``metadata["reading"]`` says so in one line and why, and
        ``metadata["point_blocks"]`` has the :attr:`PointCurves.report` of
        each; otherwise the sketch comes back unchanged.

    Raises
    ------
    NotCurvesError
        An unordered block that does not sample curves (named, with the file).
    """
    if points not in ("auto", True, False):
        raise InvalidParameterError(f"points: {points!r} is not 'auto', True or False")
    src = sketch.source
    strokes, labels, blocks = [], [], []
    measured = [i for i, s in enumerate(sketch.strokes)
                if points is True or (points == "auto" and len(s) >= MIN_BLOCK_POINTS)]
    ratios = np.ones(len(sketch))
    ratios[measured] = jump_ratios([sketch.strokes[i] for i in measured])
    for i, (s, lab, ratio) in enumerate(zip(sketch.strokes, sketch.labels, ratios.tolist())):
        if points is True or (points == "auto" and len(s) >= MIN_BLOCK_POINTS
                              and ratio > JUMP_RATIO):
            rc = recover_curves(s, name=f"stroke {i + 1} ({len(s)} points, consecutive points "
                                f"{ratio:.0f}x the spacing apart)", path=src)
            strokes.extend(rc.strokes)
            labels.extend([lab] * len(rc.strokes))
            blocks.append((i, len(s), ratio, rc.report))
        else:
            strokes.append(s)
            labels.append(lab)
    if not blocks:
        return sketch
    why = "forced by points=True" if points is True else (
        f"consecutive points jump more than {JUMP_RATIO:g}x the spacing")
    parts = [f"stroke {i + 1} ({n} points, steps {r:.0f}x the spacing) -> {rep['curves']} "
             f"curves, {rep['junctions']} junctions" for i, n, r, rep in blocks]
    n_poly = len(sketch) - len(blocks)
    meta = dict(sketch.metadata)
    meta["reading"] = (f"point samples ({why}): " + "; ".join(parts)
                       + (f"; {n_poly} stroke(s) read as polylines" if n_poly else ""))
    meta["point_blocks"] = [dict(r, stroke=i) for i, _, _, r in blocks]
    return Sketch(strokes, labels, meta, src)
