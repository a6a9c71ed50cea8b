"""Catmull-Clark limit surface as bicubic B-spline patches, one per quad-grid piece.

After ``level`` subdivision steps each piece of the control net (:mod:`.levels`) is
one B-spline surface with ``(M + 3) x (N + 3)`` poles: the piece's own control points
plus the ring of vertices just outside it, exact wherever the limit is the uniform
bicubic spline (every vertex of a face regular).

Near irregular vertices (extraordinary valence, darts, T-junctions) the limit
surface is not polynomial. Spans whose corners miss the exact limit positions are
irregular; the poles acting on them are fitted by least squares to exact limit
points over graded knots (:mod:`.graded`), and the remaining deviation is measured
as the distance of finer exact limit points to the surface, not assumed. Everything
else is exact to rounding. The continuity report per seam is :mod:`.seams`.

Arrays in, arrays out: this module knows no graph and no CAD kernel.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .graded import DEFAULT_GRADE, MAX_GRADE, corner_chains, fit_graded
from .levels import (ControlNet, Level, extended_poles, extended_poles_many, irregular_vertices,
                     subdivide_net)
from .seams import border_samples, seam_report
from .splines import (EXACT_TOL, BSplinePiece, clamp_uniform, evaluate, project, span_points,
                      tensor_grid, uniform_design)

__all__ = ["extract_bsplines", "BSplineSet", "ControlNet", "BSplinePiece", "evaluate", "project",
           "DEFAULT_LEVEL", "DEFAULT_TOLERANCE"]

#: Subdivision steps before the pieces are read off as B-splines.
DEFAULT_LEVEL = 3
#: Target deviation of the fitted pieces, fraction of the diagonal.
DEFAULT_TOLERANCE = 2e-5


@dataclass
class BSplineSet:
    """B-spline pieces of a control net and the continuity report.

    Attributes
    ----------
    pieces : list of BSplinePiece
    seams : list of dict
        One per pair of pieces sharing a border: ``pieces``, ``patches``, ``curves``
        (network curves along it), ``crease`` (sharp: a crease, or a curve of three
        or more patches), ``manifold`` (no other piece borders
        it), ``flipped`` (the two faces are oriented oppositely; ``angle`` is then
        taken between one normal and the other's opposite), ``gap`` (G0, largest
        distance of one border to the other face, fraction of the diagonal),
        ``angle`` (G1, largest normal angle along it, degrees, the pieces' corners
        left out), ``corner_angle`` (at the pieces' corners: a corner vertex or a
        tangential corner is not a G1 property of the seam), ``deviation`` (largest
        distance of exact limit points along it to the faces).
    report : dict
        ``level``, ``sample_levels``, ``grade``, ``grades_used``, ``diagonal`` (model
        units), ``n_pieces``, ``n_exact``, ``max_deviation``, ``pieces_per_patch``
        (patches of more than one
        piece).
    """

    pieces: list
    seams: list
    report: dict


def _sites(lv: Level, grids: list, offs: list, limit: np.ndarray, tol: float):
    """One site per span with a corner off the limit.

    Such a span either has one irregular corner (its own ``4 x 4`` ring still misses
    the limit there) or none (only the piece's shared outer ring was ambiguous
    beside an irregular border vertex; its own ring is exact).

    Returns
    -------
    sites : (k, 6) int64
        ``piece, i, j`` (span ``[i, i + 1] x [j, j + 1]``), the irregular corner
        ``ci, cj`` (grid vertex; -1 when none) and an index into ``corner_spans``
        (irregular) or ``own`` (regular).
    corner_spans : list of (2, 2) int64
        Ids with the irregular corner at ``[0, 0]``.
    own : (r, 4, 4, 3) float64
        Exact uniform poles of the regular ones.

    Raises
    ------
    ValueError
        If a span has several irregular corners (level 0).
    """
    w = np.array([1.0, 4.0, 1.0]) / 6.0
    irregular = irregular_vertices(lv)
    where = [(pid, i, j) for pid, off in enumerate(offs)
             for i, j in np.argwhere(off[:-1, :-1] | off[1:, :-1] | off[:-1, 1:] | off[1:, 1:])]
    if not where:
        return np.zeros((0, 6), np.int64), [], np.zeros((0, 4, 4, 3))
    spans = np.array([grids[p][i:i + 2, j:j + 2] for p, i, j in where])
    E4s = extended_poles_many(lv, spans)[0]
    at = np.stack([np.stack([np.einsum("a,b,kabc->kc", w, w, E4s[:, a:a + 3, b:b + 3])
                             for b in (0, 1)], 1) for a in (0, 1)], 1)
    offc = np.linalg.norm(at - limit[spans], axis=3) > tol
    rows, corner_spans, own = [], [], []
    for (pid, i, j), S, E4, oc in zip(where, spans, E4s, offc):
        corner = np.argwhere(oc)
        if len(corner) > 1:                  # a ring shared with another vertex
            corner = corner[irregular[S[corner[:, 0], corner[:, 1]]]]
        if len(corner) > 1:
            raise ValueError(f"piece {pid}: span ({i}, {j}) has several irregular "
                             f"corners; subdivide at least once (level >= 1)")
        if len(corner):
            a, b = corner[0]
            rows.append((pid, i, j, i + a, j + b, len(corner_spans)))
            corner_spans.append(S[::1 - 2 * a, ::1 - 2 * b])
        else:
            rows.append((pid, i, j, -1, -1, len(own)))
            own.append(E4)
    return (np.array(rows, np.int64).reshape(-1, 6), corner_spans,
            np.array(own).reshape(-1, 4, 4, 3))


def _exact_in(sites, chains, own, pid: int, M: int, N: int):
    """``exact(u, v)``: limit points at parameters of piece ``pid`` in its sites' spans."""
    at = np.full((M, N), -1, np.int64)
    mine = np.flatnonzero(sites[:, 0] == pid)
    at[sites[mine, 1], sites[mine, 2]] = mine

    def exact(u, v):
        k = at[np.clip(np.floor(u).astype(np.int64), 0, M - 1),
               np.clip(np.floor(v).astype(np.int64), 0, N - 1)]
        s = sites[k]
        ev = s[:, 3] >= 0
        out = np.empty((len(k), 3))
        out[ev] = chains.limit(s[ev, 5], np.abs(u[ev] - s[ev, 3]), np.abs(v[ev] - s[ev, 4]))
        out[~ev] = span_points(own[s[~ev, 5]], u[~ev] - s[~ev, 1], v[~ev] - s[~ev, 2])
        return out
    return exact


def extract_bsplines(net: ControlNet, level: int = DEFAULT_LEVEL, *, sample_levels: int = 2,
                     grade: int = DEFAULT_GRADE, max_grade: int = MAX_GRADE,
                     tolerance: float = DEFAULT_TOLERANCE, skip=()) -> BSplineSet:
    """Bicubic B-spline pieces of the limit surface of ``net``, with a seam report.

    Parameters
    ----------
    net : ControlNet
    level : int
        Subdivision steps before reading off the pieces (>= 1); a regular piece has
        ``(2^level p + 3) x (2^level q + 3)`` poles.
    sample_levels : int
        Exact limit samples per cell side: ``2^sample_levels`` (the deviation is
        measured there); irregular pieces are fitted to every other sample, so the
        measure also sees the fit between its points.
    grade : int
        Knots ``i +- 2^-k`` (``k = 1 .. grade``) around each irregular vertex
        (:mod:`.graded`): the approximated corner cell has side ``2^-grade`` span,
        and each irregular vertex adds ``2 grade`` poles per direction.
    max_grade : int
        A piece whose deviation exceeds ``tolerance`` is refitted with one more
        grade at a time up to this (high valences shrink slowly under subdivision).
    tolerance : float
        Target deviation, fraction of the diagonal.
    skip : iterable of int
        Patches (of ``net``) whose pieces are not wanted (faces written otherwise, such
        as trimmed analytic ones): neither extracted nor in the seam report.

    Returns
    -------
    BSplineSet
    """
    for name, val, lo in (("level", level, 1), ("sample_levels", sample_levels, 2),
                          ("grade", grade, 0), ("max_grade", max_grade, grade)):
        if int(val) != val or val < lo:
            raise ValueError(f"{name}: expected an integer >= {lo}, got {val!r}")
    diag = net.diagonal if net.diagonal > 0 else 1.0
    patches, lv, grids, limit = subdivide_net(net, int(level))
    skip = {int(k) for k in skip}
    keep = [i for i, p in enumerate(patches) if int(p) not in skip]
    patches, grids = [patches[i] for i in keep], [grids[i] for i in keep]
    r = 2 ** int(sample_levels)
    if not grids:
        return BSplineSet([], [], {"level": int(level), "sample_levels": int(sample_levels),
                                   "grade": int(grade), "grades_used": [], "diagonal": diag,
                                   "n_pieces": 0, "n_exact": 0, "max_deviation": 0.0,
                                   "pieces_per_patch": {}})
    nets, offs = [], []
    for G in grids:                    # uniform poles; irregular: vertices off the limit
        M, N = G.shape[0] - 1, G.shape[1] - 1
        E, clean = extended_poles(lv, G)
        at = tensor_grid(uniform_design(np.arange(M + 1), M), E,
                         uniform_design(np.arange(N + 1), N))
        nets.append((E, clean))
        offs.append(np.linalg.norm(at - limit[G], axis=2) > EXACT_TOL * diag)
    fitted = _fit_irregular(lv, grids, nets, offs, limit, diag, int(sample_levels),
                            int(grade), int(max_grade), tolerance)
    pieces, border = [], []
    for pid, (patch, G, (E, clean)) in enumerate(zip(patches, grids, nets)):
        M, N = G.shape[0] - 1, G.shape[1] - 1
        if pid in fitted:
            poles, ku, kv, err, dev, _ = fitted[pid]
            pc = BSplinePiece(poles, ku, kv, int(patch), False, dev / diag)
        else:
            poles, ku = clamp_uniform(E, M, 0)
            poles, kv = clamp_uniform(poles, N, 1)
            pc = BSplinePiece(poles, ku, kv, int(patch), clean, 0.0)
            err = np.zeros((r * M + 1, r * N + 1))
        pieces.append(pc)
        border.append(border_samples(pid, G, r, err / diag, lv.n))
    seams = seam_report(pieces, border, net)
    dev = max((p.deviation for p in pieces), default=0.0)
    per_patch: dict = {}
    for p in pieces:
        per_patch[p.patch] = per_patch.get(p.patch, 0) + 1
    grades = [f[5] for f in fitted.values()]
    report = {"level": int(level), "sample_levels": int(sample_levels), "grade": int(grade),
              "grades_used": sorted(set(grades)), "diagonal": diag, "n_pieces": len(pieces),
              "n_exact": sum(p.exact for p in pieces), "max_deviation": float(dev),
              "pieces_per_patch": {int(k): int(c) for k, c in per_patch.items() if c > 1}}
    return BSplineSet(pieces, seams, report)


def _fit_irregular(lv, grids, nets, offs, limit, diag, sample_levels, grade, max_grade,
                   tolerance) -> dict:
    """Graded fits of the pieces with irregular spans: ``{piece: (poles, knots_u,
    knots_v, err, deviation, grade)}`` (:func:`graded.fit_graded`, model units);
    pieces above ``tolerance`` are refitted with more grades, on deeper chains."""
    sites, spans, own = _sites(lv, grids, offs, limit, EXACT_TOL * diag)
    if not len(sites):
        return {}

    def fit(pid, g, at, chains):
        M, N = grids[pid].shape[0] - 1, grids[pid].shape[1] - 1
        mine = at[(at[:, 0] == pid) & (at[:, 3] >= 0)]
        return fit_graded(nets[pid][0], offs[pid], mine[:, 3:5],
                          _exact_in(at, chains, own, pid, M, N), grade=g,
                          r=2 ** sample_levels, tol=EXACT_TOL * diag) + (g,)
    chains = corner_chains(lv, np.stack(spans), grade, sample_levels) if spans else None
    fitted = {pid: fit(pid, grade, sites, chains) for pid in np.unique(sites[:, 0]).tolist()}
    over = [pid for pid, f in fitted.items() if f[4] > tolerance * diag]
    sel = np.flatnonzero(np.isin(sites[:, 0], over) & (sites[:, 3] >= 0))
    if max_grade > grade and len(sel):
        deep_sites = sites.copy()
        deep_sites[sel, 5] = np.arange(len(sel))
        deep = corner_chains(lv, np.stack([spans[k] for k in sites[sel, 5]]), max_grade,
                             sample_levels)
        for pid in over:
            for g in range(grade + 1, max_grade + 1):
                fitted[pid] = fit(pid, g, deep_sites, deep)
                if fitted[pid][4] <= tolerance * diag:
                    break
    return fitted
