"""Snap rough 3D strokes into a curve network (Abbasinejad et al. 2011, Sec. 6.1).

The paper's pre-process: "two curves intersect when they pass within a
user-defined threshold, and [we] place the intersection at the closest point
... the curves are automatically snapped together, with the displacement
interpolated across the edge to avoid introducing sharp bends ... Dangling
edges (with a vertex of degree one) were removed ... we interpret sharp corners
within a curve as vertices of degree two." This module implements that and the
extra cases VR strokes need (T-junctions, gaps, overshoots, overdraw).

Pipeline of :func:`snap` (``mode="rough"``)
-------------------------------------------
1. Keep ``boundary`` and ``crease`` strokes, drop repeated points, drop strokes
   shorter than ``min_length * tol``; ``tol = snap_tol * diagonal``.
2. Sample every stroke uniformly in arc length (spacing ``tol / 4``) and find
   all sample pairs of different strokes within ``tol`` with one KD-tree
   (``scipy.spatial.cKDTree.query_pairs``). Pairs are grouped per stroke pair
   into *contacts* (runs along the first stroke).
3. Loops drawn past their start (issue 33): a stroke whose end runs back along its
   own beginning (its last point within ``tol`` of its first 15%, its first
   point within ``tol`` of its last 15%, the two stretches side by side within
   ``tol`` all along and running the same way within ``overdraw_angle``, the lap
   between enclosing an area, see :func:`curvenet.snap.overdraw.close_loops`)
   becomes one closed loop, the two stretches averaged and the lap's ends bent onto
   the average with the C1 bumps of step 6. Checked again after each overdraw
   round (a ring drawn in two pieces, the second run past the first's start, is
   one stroke by then). A stroke that spirals (its ends farther than ``tol`` from
   the other end's stretch) or folds back over itself stays as drawn. An end of
   another stroke that touched only the stretches, and that the average leaves out
   of reach, moves with them (C1 bump).
   Overdraw: a contact longer than ``overdraw_length * tol`` on both strokes,
   with tangents within ``overdraw_angle``, is one curve drawn twice. The
   stroke more covered by it (the guest) loses the overlapping stretch; the
   host moves halfway onto the guest there (an average, tapered at both ends),
   so no sliver cycle remains. Repeated until no overdraw is left. A contact
   that touches both ends of a nearly closed stroke (a short stroke drawn over
   its opening) is split where it jumps between them; a host that a guest piece
   extends past its own start, its end within ``tol`` of the start in its last
   ``3 tol``, is cut back there (a run past the start too short for the loop rule
   above, under a sample spacing, is otherwise left overlapping its start).
4. Every other contact is a junction candidate at its closest sample pair:
   the midpoint for a crossing or two ends (gap), the point on the other stroke
   for an end touching a stroke interior (T-junction). A stroke whose two ends
   are within ``tol`` is closed. An end within ``tol`` of its own stroke's interior,
   farther than ``2 pi tol`` from it along the stroke and ``trim * tol`` from the
   other end, is a T-junction there too (a stem drawn on round a ring in one stroke:
   a "P"), unless the other end touches the stroke too (an "alpha") or the stroke's
   last ``overdraw_length * tol`` runs beside that interior (a spiral, a fold).
   Candidates within ``tol`` of each other are
   merged (connected components) into one junction at their mean, and so are
   junctions within ``1.5 tol`` along one stroke, closest first; a gap (two
   stroke ends) that has joined a junction does not pull in a second one, nor
   do two junctions that strokes pass through merge along a short stroke that
   runs from one to the other; nor does a closed stroke's seam (its two ends
   meeting) that has joined a junction the stroke passes through pull in a
   second one along the stroke (a ring stopping short between two crossings
   would chain them); nor do two meetings of other strokes along it (two rings
   close together, each crossing a meridian) whose strokes share none and stay
   more than :data:`curvenet.snap.merge.APART` tol apart there.
5. Corners: where a stroke turns by more than ``corner_angle`` between the
   chords ``tol * corner_window`` before and after a point (local maximum),
   and no junction is within ``2 tol``, it gets a degree-2 vertex. Each chord end
   is the stroke's mean over a quarter of the chord either side, so that per-sample
   jitter (which tilts chords between single points) does not make corners. Where ``tol``
   is wider than :data:`DEFAULT_SNAP_TOL` (a tolerance measured from wide gaps, not
   from how tightly the strokes curve), the turn is the smaller of that and its mean
   with the turn over chords ``corner_window`` times the default tolerance: a circle
   turns half as much over half the chord, a corner as much, so a circle as tight
   as the wide window is not cut into corners.
6. Each stroke is moved onto its junctions with displacement bumps
   ``d_j (1 - x^2)^2``, ``x = |s - s_j| / R_j`` (C1, zero slope at the junction,
   so no kink; ``R_j <= blend * tol`` and at most 0.45 of the distance to the
   neighbouring junctions on the stroke, so a junction point lands exactly),
   then cut at the junctions. A free end piece shorter than ``trim * tol`` past
   the last junction is an overshoot and is trimmed; longer ones stay as
   dangling edges (degree-1 vertices, listed in the report).
7. Degree-2 vertices made only by stroke ends meeting smoothly (gap closing:
   join angle below ``corner_angle``; the turn over chords ``w = corner_window``
   times the smaller of ``tol`` and the default tolerance, or its mean with the turn
   over ``w / 2`` where smaller, so that a join on a curve as tight as the window is
   smooth) are dissolved, unless the joined curve turns sharply once within ``2 tol``
   of the join and farther than ``corner_window * tol`` from its ends (a corner the
   per-stroke search could not see, too close to a stroke end; nearer the ends, the
   bumps onto their junctions bend it): the vertex moves there.
   Parallel edges between the same vertices closer than ``2 tol`` (left-over
   overdraw) are averaged; a junction left of degree 2 by that is dissolved as above.

``mode="exact"`` (chosen by ``mode="auto"`` when every stroke end coincides,
to ``1e-9`` of the diagonal, with a point of another stroke or with its own
other end, as in an exported clean network) builds the graph from coincident
points only: the same graph as :func:`curvenet.io.read_network_obj`, with no
tolerance, no corner split and no smoothing. Deviation from the paper, whose
threshold "varies because different models are more or less carefully drawn":
exactly connected input is taken as the most carefully drawn case.

Scale invariance: every length is ``tol``-relative, so millimetre, metre and
unit-box inputs give the same network up to scale. Deterministic: no random
numbers; ties are broken by stroke and sample order.

Not handled (documented gaps): a stroke crossing itself in its interior stays
one piece there; a stroke drawn round two or more times (an overlap over 15% of its
length) stays as drawn.

Departure from Abbasinejad et al. (Sec. 6.1): the paper snaps pairs of curves
("two curves intersect when they pass within a user-defined threshold") and
fixed by hand in Maya what that missed; ILoveSketch strokes rarely overlap
themselves. VR designers draw a ring in one stroke and carry on past its start
(issue 33): a pair rule never sees a stroke against itself, and the run past the
start stays a dangling curve or doubles the patches beside it. Step 3 extends the
overdraw merge to a stroke over its own beginning.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np
from scipy.spatial import cKDTree

from ..core.geometry import bbox_diagonal, densify_polylines, segment_closest
from ..core.tolerances import (COINCIDENT_REL, DEFAULT_SNAP_TOL, DIVISION_GUARD,
                               DUPLICATE_POINT_REL, check_snap_tol)
from ..core.errors import InvalidParameterError
from .merge import components, first_items
from .strokes import dedup
from ..model.network import CurveNetwork, indexed_network
from ..model.sketch import Sketch

__all__ = ["SnapOptions", "DEFAULT_SNAP_TOL", "snap", "prune_dangling", "dangling_vertices",
           "summary_line"]

#: Strokes that pass within this fraction of the diagonal of each other, farther than
#: CROSSING_AWAY from every point they share, cross: the sketch is snapped with a
#: tolerance even when every stroke end coincides with another stroke. Exported networks
#: keep their curves at least 8e-4 of the diagonal apart away from their junctions (the
#: 29 public ones); strokes drawn across each other on one surface come within 7e-5.
CROSSING_REL = 2e-4
CROSSING_AWAY = 0.02
#: ...and meet at more than this angle (degrees): curves that run on together are no
#: crossing.
CROSSING_ANGLE = 20.0
#: Sample spacing of the crossing test, fraction of the diagonal.
CROSSING_STEP = 0.005
#: Samples whose neighbours the crossing test gathers at a time (bounds its memory).
_CROSSING_CHUNK = 20_000

#: Counters present in every ``network.report`` (see :func:`snap`).
_COUNTERS = ("crossings", "t_junctions", "gap_merges", "closed_strokes", "overdrawn_loops",
             "trimmed_overshoots", "overdraw_consolidations", "corners", "dissolved_joins",
             "slivers_merged", "strokes_dropped_short", "strokes_trimmed_away")


@dataclass(frozen=True)
class SnapOptions:
    """Tolerances of :func:`snap`; lengths are multiples of ``tol = snap_tol * diagonal``.

    Attributes
    ----------
    snap_tol : float or "auto"
        Fraction of the bounding-box diagonal, or ``"auto"`` (the default): chosen
        from the sketch (see :mod:`curvenet.snap.auto`).
    corner_angle : float
        Degrees; a turn sharper than this within a stroke is a degree-2 vertex,
        and two stroke ends meeting at a sharper angle stay a vertex.
    corner_window : float
        Chord length (times ``tol``) on each side used to measure a turn; above
        the default tolerance, curvature is discounted over ``corner_window`` times
        the default (see step 5 of :mod:`curvenet.snap`).
    trim : float
        Free end pieces past a junction shorter than ``trim * tol`` are trimmed.
    blend : float
        Largest radius (times ``tol``) of the displacement blending bump.
    overdraw_length : float
        Shortest overlap (times ``tol``) treated as overdraw.
    overdraw_angle : float
        Degrees; largest tangent angle between two overdrawn strokes.
    min_length : float
        Strokes shorter than ``min_length * tol`` are dropped.
    mode : {'auto', 'rough', 'exact'}
    """

    snap_tol: float | str = "auto"
    corner_angle: float = 45.0
    corner_window: float = 1.5
    trim: float = 2.0
    blend: float = 6.0
    overdraw_length: float = 4.0
    overdraw_angle: float = 25.0
    min_length: float = 1.0
    mode: str = "auto"

    def validate(self) -> "SnapOptions":
        """Raise :class:`InvalidParameterError` naming any out-of-range option."""
        if self.snap_tol != "auto":
            check_snap_tol(self.snap_tol)
        if not 0 < self.corner_angle <= 180:
            raise InvalidParameterError(f"corner_angle must be in (0, 180] degrees, "
                                        f"got {self.corner_angle!r}")
        if not 0 < self.overdraw_angle < 90:
            raise InvalidParameterError(f"overdraw_angle must be in (0, 90) degrees, "
                                        f"got {self.overdraw_angle!r}")
        for name in ("corner_window", "trim", "blend", "overdraw_length", "min_length"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise InvalidParameterError(f"{name} must be a finite number >= 0, got {v!r}")
        if self.mode not in ("auto", "rough", "exact"):
            raise InvalidParameterError(f"mode must be 'auto', 'rough' or 'exact', "
                                        f"got {self.mode!r}")
        return self


# --------------------------------------------------------------------------- public
def _prepare(sketch, opts):
    """Strokes used for snapping: (strokes, source ids, labels, diag, dropped count)."""
    if not isinstance(sketch, Sketch):
        raise InvalidParameterError(
            f"sketch must be a curvenet.Sketch, got {type(sketch).__name__}")
    use = [i for i, lab in enumerate(sketch.labels) if lab != "construction"]
    if not use:
        raise InvalidParameterError("sketch has no boundary or crease strokes to snap")
    diag = bbox_diagonal([sketch.strokes[i] for i in use])
    if not diag > 0:
        raise InvalidParameterError("sketch has zero extent (all points coincide)")
    strokes, src, labels = [], [], []
    dropped = 0
    for i, s in zip(use, dedup([sketch.strokes[i] for i in use], DUPLICATE_POINT_REL * diag)):
        if len(s) < 2:
            dropped += 1
            continue
        strokes.append(s)
        src.append(i)
        labels.append(sketch.labels[i])
    return strokes, src, labels, diag, dropped


class _Points:
    """The strokes' points one after another, their KD-tree and (when first asked) the pairs
    of points that coincide (within :data:`COINCIDENT_REL` of the diagonal): built once for
    the exactness test, the crossing test and the exact graph."""

    def __init__(self, strokes, diag):
        self.counts = np.array([len(s) for s in strokes])
        self.pts = np.concatenate(strokes)
        self.sid = np.repeat(np.arange(len(strokes)), self.counts)
        self.tree = cKDTree(self.pts)
        self.eps = COINCIDENT_REL * diag
        self._pairs = None

    @property
    def pairs(self):
        """``(P, 2) int64``, ``i < j``: the coinciding point pairs."""
        if self._pairs is None:
            self._pairs = self.tree.query_pairs(self.eps, output_type="ndarray")
        return self._pairs


def _arc_to(pts, sid, marks):
    """Arc length along its own stroke from each point to the nearest of ``marks`` (sorted
    point indices) on that stroke, ``inf`` where the stroke has none: ``(n,) float64``,
    never less than the straight distance to that mark."""
    n = len(pts)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    at = np.arange(n)
    out = np.full(n, np.inf)
    for k, sign in ((np.searchsorted(marks, at, side="right") - 1, 1.0),
                    (np.searchsorted(marks, at, side="left"), -1.0)):
        ok = (k >= 0) & (k < len(marks))
        m = marks[np.clip(k, 0, len(marks) - 1)]
        ok &= sid[m] == sid
        out[ok] = np.minimum(out[ok], sign * (s[ok] - s[m[ok]]))
    return out


def _crosses(strokes, diag, points: _Points) -> bool:
    """Whether two strokes cross (pass within :data:`CROSSING_REL` of the diagonal of each
    other at an angle, away from the points they share): then they are drawn, not
    exported.

    Sample pairs of different strokes within ``2 CROSSING_STEP`` of each other are tested
    where the first of the pair lies :data:`CROSSING_AWAY` or farther from every shared
    point; pairs are gathered only around such points, at most :data:`_CROSSING_CHUNK`
    of them at a time, so the many pairs around junctions are never formed. A point
    within ``CROSSING_AWAY`` of a shared point along its own stroke is near without a
    search. ``points`` (of the same strokes) are reused when the sampling adds none.
    """
    step = CROSSING_STEP * diag
    away = CROSSING_AWAY * diag
    pts, counts = densify_polylines(strokes, step)
    sid = np.repeat(np.arange(len(strokes)), counts)
    last = np.cumsum(counts) - 1
    if len(points.pts) == len(pts):
        tree, shared = points.tree, points.pairs
    else:
        tree = cKDTree(pts)
        shared = tree.query_pairs(points.eps, output_type="ndarray")
    shared = shared[sid[shared[:, 0]] != sid[shared[:, 1]]]
    far = np.arange(len(pts))
    if len(shared):
        marks = np.unique(shared[:, 0])
        far = np.flatnonzero(_arc_to(pts, sid, marks) >= away * (1 - 1e-9))
        if len(far):
            d = cKDTree(np.unique(pts[marks], axis=0)).query(pts[far])[0]
            far = far[d >= away]
    cos_max = np.cos(np.radians(CROSSING_ANGLE))
    for lo in range(0, len(far), _CROSSING_CHUNK):
        ids = far[lo:lo + _CROSSING_CHUNK]
        near = cKDTree(pts[ids]).sparse_distance_matrix(tree, 2 * step, output_type="ndarray")
        first, second = ids[near["i"]], near["j"].astype(np.int64)
        keep = (second > first) & (sid[first] != sid[second])
        i, j = (np.minimum(q, last[sid[q]] - 1) for q in (first[keep], second[keep]))
        s, t = segment_closest(pts[i], pts[i + 1], pts[j], pts[j + 1])
        a, b = pts[i + 1] - pts[i], pts[j + 1] - pts[j]
        gap = np.linalg.norm(pts[i] + s[:, None] * a - pts[j] - t[:, None] * b, axis=1)
        cos = np.abs(np.einsum("ij,ij->i", a, b)) / np.maximum(
            np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1), DIVISION_GUARD)
        if np.any((gap < CROSSING_REL * diag) & (cos < cos_max)):
            return True
    return False


def _is_exact(strokes, diag, points: _Points):
    """Whether every stroke end coincides with a point of another stroke or its own end,
    and no two strokes cross elsewhere (:func:`_crosses`)."""
    pts, sid, counts, tree, eps = points.pts, points.sid, points.counts, points.tree, points.eps
    last = np.cumsum(counts) - 1
    first = last - counts + 1
    closed = np.linalg.norm(pts[first] - pts[last], axis=1) <= eps
    ends = np.concatenate([first, last])
    kq = min(8, len(pts))
    dist, nn = tree.query(pts[ends], k=kq, distance_upper_bound=eps)
    nn = nn.reshape(len(ends), kq)
    hit = np.isfinite(dist.reshape(len(ends), kq))
    other = hit & (sid[np.minimum(nn, len(pts) - 1)] != sid[ends][:, None])
    attached = other.any(axis=1) | np.concatenate([closed, closed])
    if hit.all(axis=1).any():  # 8 coincident points or more: fall back to a ball query
        for q in np.flatnonzero(hit.all(axis=1)):
            near = tree.query_ball_point(pts[ends[q]], eps)
            attached[q] = bool(np.any(sid[near] != sid[ends[q]]))
    return bool(attached.all()) and (len(strokes) > 1 or bool(closed.all())) \
        and not _crosses(strokes, diag, points)


def _snap_exact(strokes, src, labels, diag, points: _Points):
    """Graph of exactly coincident points (no tolerance); see module docstring."""
    pts = points.pts
    ids = components(len(pts), points.pairs)
    verts = pts[first_items(ids)]  # each group at its first point
    offs = np.concatenate([[0], np.cumsum(points.counts)])
    polys = [ids[offs[k]:offs[k + 1]] for k in range(len(strokes))]
    net = indexed_network(verts, polys, labels, src)
    net.report = dict.fromkeys(_COUNTERS, 0)
    net.report.update(mode="exact", warnings=[],
                      closed_strokes=sum(1 for e in net.edges if e.u == e.v))
    return net


def snap(sketch: Sketch, *, snap_tol: float | str | None = "auto", corner_angle: float = 45.0,
         options: SnapOptions | None = None, **kwargs) -> CurveNetwork:
    """Snap a sketch's strokes into a curve network.

    Parameters
    ----------
    sketch : Sketch
        ``construction`` strokes are ignored; ``crease`` labels go to the edges.
    snap_tol : float or "auto"
        Snapping distance as a fraction of the bounding-box diagonal of the
        boundary and crease strokes. ``"auto"`` (the default; ``None`` means
        the same) chooses it from the sketch: above the distances at which
        stroke ends nearly meet another stroke, below those of free ends and
        below half the spacing of parallel strokes, never under
        :data:`DEFAULT_SNAP_TOL` = 0.025 unless that spacing requires it
        (:mod:`curvenet.snap.auto`). ``report["snap_tol_reason"]`` says why.
    corner_angle : float
        Turn (degrees, default 45) above which a stroke gets a degree-2 corner
        vertex and two stroke ends meeting stay a vertex. The paper gives no
        value; 45 keeps the 60-degree corners of the saddle-grid boundary.
    options : SnapOptions, optional
        All tolerances at once. ``snap_tol`` and ``corner_angle`` override it
        when they differ from their defaults; any other :class:`SnapOptions`
        field given as a keyword (``trim=3.0``, ``mode="rough"`` ...) always does.

    Returns
    -------
    CurveNetwork
        Vertices: junctions, corners and free ends. Edge curves run ``u -> v``
        and list their source stroke ids (indices into ``sketch.strokes``).
        ``report`` (dict): ``mode``, ``tol`` (absolute), ``diagonal``,
        ``junctions`` (vertices of degree >= 3), ``t_junctions``,
        ``crossings``, ``gap_merges``, ``closed_strokes``, ``overdrawn_loops``
        (strokes whose end ran back along their own beginning, merged into one
        loop), ``trimmed_overshoots``,
        ``overdraw_consolidations``, ``corners``, ``dissolved_joins``,
        ``slivers_merged``, ``dangling_ends`` (count) and ``dangling_vertices``
        (ids), ``strokes_used``, ``strokes_dropped_short`` (fewer than two
        distinct points, or shorter than ``min_length * tol``),
        ``strokes_trimmed_away`` (short strokes whose every piece was a trimmed
        overshoot: no edge lists them), ``warnings`` (list). Every boundary or
        crease stroke is in some edge's ``strokes`` or counted in one of the
        last two.

    Raises
    ------
    InvalidParameterError
        A tolerance out of range, no usable strokes, or zero extent.

    Notes
    -----
    See the module docstring for the steps and their constants. Vertex order
    (rough mode): junctions (by the stroke pair of the first contact that made
    them), then corners, then free ends, each in stroke order; edges in stroke
    order, a stroke's pieces from its start. Exact mode numbers vertices as
    :func:`curvenet.io.read_network_obj` does, by first point index.

    References
    ----------
    Abbasinejad, Joshi, Amenta, "Surface patches from unorganized space
    curves", SGP 2011, Sec. 6.1 (pre-processing).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(-1, 1, 21)[:, None]
    >>> a = np.hstack([t, 0 * t, 0 * t]); b = np.hstack([0 * t, t, 0.01 + 0 * t])
    >>> net = snap(Sketch([a, b]))          # a near-crossing: one junction
    >>> net.number_of_vertices, net.number_of_edges, net.report["junctions"]
    (5, 4, 1)
    """
    base = options or SnapOptions()
    fields = asdict(base)
    unknown = set(kwargs) - set(fields)
    if unknown:
        raise InvalidParameterError(f"unknown snap option(s) {sorted(unknown)}; "
                                    f"use {sorted(fields)}")
    if snap_tol is None:
        snap_tol = "auto"
    if options is None or snap_tol != "auto":
        fields["snap_tol"] = snap_tol
    if options is None or corner_angle != 45.0:
        fields["corner_angle"] = corner_angle
    fields.update(kwargs)
    try:
        opts = SnapOptions(**{k: (v if k == "mode" or (k == "snap_tol" and v == "auto")
                                  else float(v))
                              for k, v in fields.items()}).validate()
    except (TypeError, ValueError) as err:
        if isinstance(err, InvalidParameterError):
            raise
        raise InvalidParameterError(f"snap options: {err}") from None
    strokes, src, labels, diag, dropped = _prepare(sketch, opts)
    if not strokes:
        raise InvalidParameterError("no stroke has two distinct points")
    mode = opts.mode
    points = _Points(strokes, diag) if mode in ("auto", "exact") else None
    if mode == "auto":
        mode = "exact" if _is_exact(strokes, diag, points) else "rough"
    if mode == "exact":
        why = "exact: every stroke end coincides with another stroke (no tolerance)"
        opts = replace(opts, snap_tol=0.0 if opts.snap_tol == "auto" else opts.snap_tol)
        net = _snap_exact(strokes, src, labels, diag, points)
        net.report.update(_common_report(net, diag, opts, len(strokes), dropped, why))
        return net
    if opts.snap_tol == "auto":
        net, opts, why = _snap_auto(strokes, src, labels, diag, opts)
    else:
        from .rough import snap_rough
        net, why = snap_rough(strokes, src, labels, diag, opts), "given"
    present = {s for e in net.edges for s in e.strokes}
    net.report["strokes_trimmed_away"] = (sum(1 for s in src if s not in present)
                                          - net.report["strokes_dropped_short"])
    net.report["strokes_dropped_short"] += dropped
    net.report.update(_common_report(net, diag, opts, len(strokes), None, why))
    return net


def _snap_auto(strokes, src, labels, diag, opts):
    """Rough snapping at the tolerance the sketch suggests, arbitrated by the result.

    The tolerance measured by :func:`curvenet.snap.auto.auto_tolerance` replaces
    :data:`DEFAULT_SNAP_TOL` only if the network it gives is structurally no
    worse and better in one respect: no fewer independent cycles (the cycle
    rank, an upper bound on the patches) and no more dangling ends. A larger
    tolerance that merges small features loses cycles and is refused; a smaller
    one that leaves gaps open adds dangling ends and is refused. At equal cycles it
    is taken when it has fewer dangling ends because it merges more loops drawn
    past their start (``report["overdrawn_loops"]``): a ring whose run past its
    start lies beyond the default closes through a stroke crossing both stretches,
    with the same cycles, and leaves the run as a dangling curve (issue 33). Fewer
    dangling ends alone at equal cycles is not enough: on the public sketches it
    cost patches (cassie 06-1-1, 22 -> 21).

    Returns (network, options with the tolerance used, reason).
    """
    from .auto import SketchTooDense, auto_tolerance
    from .rough import snap_rough
    tol, why = auto_tolerance(strokes, diag, DEFAULT_SNAP_TOL)
    base = replace(opts, snap_tol=DEFAULT_SNAP_TOL)
    if tol == DEFAULT_SNAP_TOL:
        return snap_rough(strokes, src, labels, diag, base), base, f"auto: {why}"
    cand = replace(opts, snap_tol=tol)
    net_c = snap_rough(strokes, src, labels, diag, cand)
    try:
        net_0 = snap_rough(strokes, src, labels, diag, base)
    except SketchTooDense:
        return net_c, cand, f"auto: {why}; the default is too dense to snap"

    def score(net):
        deg = np.bincount(net.endpoints.ravel(), minlength=net.number_of_vertices)
        return net.cycle_rank(), int((deg == 1).sum()), net.report["overdrawn_loops"]

    (r_c, d_c, o_c), (r_0, d_0, o_0) = score(net_c), score(net_0)
    if d_c <= d_0 and (r_c > r_0 or (r_c == r_0 and d_c < d_0 and o_c > o_0)):
        return net_c, cand, (f"auto: {why}; against the default {DEFAULT_SNAP_TOL:.1%}: "
                             f"cycles {r_0} -> {r_c}, dangling ends {d_0} -> {d_c}")
    return net_0, base, (f"auto: default; {tol:.2%} was measured ({why}) but gives cycles "
                         f"{r_0} -> {r_c}, dangling ends {d_0} -> {d_c}")


def _common_report(net, diag, opts, used, dropped, why):
    rep = {"tol": opts.snap_tol * diag, "diagonal": diag, "snap_tol": opts.snap_tol,
           "snap_tol_reason": why,
           "vertices": net.number_of_vertices, "edges": net.number_of_edges}
    deg = np.bincount(net.endpoints.ravel(), minlength=net.number_of_vertices)
    dv = np.flatnonzero(deg == 1)
    rep["junctions"] = int((deg >= 3).sum())
    rep["dangling_ends"] = int(dv.size)
    rep["dangling_vertices"] = dv.tolist()
    rep["strokes_used"] = used
    if dropped is not None:
        rep["strokes_dropped_short"] = dropped
    rep.setdefault("warnings", net.report.get("warnings", []))
    rep["summary"] = summary_line({**net.report, **rep})
    return rep


def summary_line(report: dict) -> str:
    """One line saying what snapping did: tolerance and why, junctions, merges, dangling ends."""
    r = report
    if r.get("mode") == "exact":
        tol = r["snap_tol_reason"]
    else:
        tol = f"tolerance {r['snap_tol']:.2%} of the diagonal ({r['snap_tol_reason']})"
    merges = (f"{r.get('gap_merges', 0)} gaps closed, {r.get('t_junctions', 0)} T-junctions, "
              f"{r.get('crossings', 0)} crossings, {r.get('overdraw_consolidations', 0)} "
              f"overdraws merged, {r.get('overdrawn_loops', 0)} loops drawn past their start "
              f"closed, {r.get('trimmed_overshoots', 0)} overshoots trimmed")
    return (f"snap: {tol}; {r['vertices']} vertices, {r['edges']} curves, "
            f"{r['junctions']} junctions; {merges}; {r['dangling_ends']} dangling ends")


def dangling_vertices(network: CurveNetwork) -> np.ndarray:
    """Ids ``(k,) int64`` of vertices with exactly one incident edge end."""
    deg = np.bincount(network.endpoints.ravel(), minlength=network.number_of_vertices)
    return np.flatnonzero(deg == 1)


def prune_dangling(network: CurveNetwork) -> CurveNetwork:
    """Remove dangling edges repeatedly until no degree-1 vertex is left.

    Returns a new network (vertices renumbered in their old order, isolated
    vertices dropped); ``report["pruned_edges"]`` counts the removed edges.
    This is the paper's "Dangling edges (with a vertex of degree one) were
    removed" (Sec. 6.1), kept separate so that :func:`snap` can flag them first.
    """
    keep = np.ones(network.number_of_edges, dtype=bool)
    ends = network.endpoints
    while True:
        deg = np.bincount(ends[keep].ravel(), minlength=network.number_of_vertices)
        bad = keep & ((deg[ends[:, 0]] == 1) | (deg[ends[:, 1]] == 1))
        if not bad.any():
            break
        keep &= ~bad
    used = np.unique(ends[keep].ravel())
    new_id = -np.ones(network.number_of_vertices, dtype=np.int64)
    new_id[used] = np.arange(len(used))
    out = CurveNetwork(network.positions[used])
    for e, k in zip(network.edges, keep):
        if k:
            out.add_edge(int(new_id[e.u]), int(new_id[e.v]), e.curve, strokes=e.strokes,
                         label=e.label)
    out.report = dict(network.report)
    out.report["pruned_edges"] = int((~keep).sum())
    return out
