"""Catmull-Clark limit surface as bicubic B-spline patches, one per quad-grid piece.

Each loop's control quads form one ``p x q`` grid (four-sided loops) or ``T`` grids
around a centre (split loops); these are the *pieces*. After ``level`` subdivision
steps a piece is an ``M x N`` grid (``M = 2^level p``). Where every vertex of a face
is regular (valence four, or a crease/boundary vertex with two faces on each side,
or a corner with one) the limit surface over that face is exactly the uniform
bicubic B-spline of its 4 x 4 neighbourhood (Catmull & Clark 1978; across sharp
edges the phantom row ``2 P_0 - P_1`` reproduces the crease rules, DeRose et al.
1998). So each piece is one B-spline surface with ``(M + 3) x (N + 3)`` poles: the
piece's own control points plus the ring of vertices just outside it.

Near irregular vertices (extraordinary valence, darts, T-junctions) the limit
surface is not polynomial. Spans whose corners miss the exact limit positions are
irregular; the poles acting on them are fitted by least squares to exact limit
points over their support (the irregular spans' one-ring subdivided further, see
:func:`_local_samples`), and the remaining deviation is measured as the distance of
finer exact limit points to the surface, not assumed. Everything else is exact to
rounding. The continuity report per seam is :mod:`.seams`.

Arrays in, arrays out: this module knows no graph and no CAD kernel.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import BSpline

from .catmull_clark import (CORNER, CREASE, SMOOTH, edge_index, edge_topology, sharp_mask,
                            subdivision_step, vertex_classes)
from .graded import DEFAULT_GRADE, MAX_GRADE, corner_chains, fit_graded, span_points, submesh
from .limit import limit_matrix

__all__ = ["ControlNet", "BSplinePiece", "BSplineSet", "piece_grids", "refine_grid",
           "extract_bsplines", "uniform_knots", "clamp_uniform", "evaluate", "project",
           "DEFAULT_LEVEL", "DEFAULT_TOLERANCE", "EXACT_TOL"]

#: Subdivision steps before the pieces are read off as B-splines.
DEFAULT_LEVEL = 3
#: Target deviation of the fitted pieces, fraction of the diagonal.
DEFAULT_TOLERANCE = 2e-5
#: Spans whose limit samples deviate more than this fraction of the diagonal from the
#: uniform B-spline are irregular (exact spans agree to rounding, about 1e-15).
EXACT_TOL = 1e-10


@dataclass
class ControlNet:
    """The fitted level-0 control mesh with everything subdivision needs.

    Attributes
    ----------
    vertices : (n, 3) float64
    quads : (f, 4) int64
        Consistently oriented; each patch's quads in the row-major order of its grids
        (see :func:`piece_grids`).
    face_patch : (f,) int64
    sharp_edges : (s, 2) int64
    corners : (n,) bool
    curve_vids : list of (k + 1,) int64
        Control vertices along each network curve.
    diagonal : float
    """

    vertices: np.ndarray
    quads: np.ndarray
    face_patch: np.ndarray
    sharp_edges: np.ndarray
    corners: np.ndarray
    curve_vids: list = field(default_factory=list)
    diagonal: float = 1.0


@dataclass
class BSplinePiece:
    """One clamped bicubic B-spline surface.

    Attributes
    ----------
    poles : (a, b, 3) float64
    knots_u : (a + 4,) float64, knots_v : (b + 4,) float64
        Clamped knot vectors (end knots repeated four times), parameters in spans of
        the subdivided grid: ``u`` in ``[0, M]``, ``v`` in ``[0, N]``.
    patch : int
        Loop index.
    exact : bool
        True when no span needed fitting.
    deviation : float
        Largest distance to the exact limit samples, fraction of the diagonal.
    """

    poles: np.ndarray
    knots_u: np.ndarray
    knots_v: np.ndarray
    patch: int
    exact: bool
    deviation: float


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


def piece_grids(quads: np.ndarray, face_patch: np.ndarray) -> list:
    """Recover the quad grids of every patch from the control mesh's face order.

    A grid ``G (p + 1, q + 1)`` owns the quads
    ``(G[i, j], G[i + 1, j], G[i + 1, j + 1], G[i, j + 1])`` in row-major order, the
    order :mod:`.controlmesh` writes them in.

    Returns
    -------
    list of (patch, G (p + 1, q + 1) int64)

    Raises
    ------
    ValueError
        If a patch's quads are not a sequence of such grids.
    """
    quads = np.asarray(quads, dtype=np.int64)
    out = []
    for j in np.unique(face_patch):
        qs = quads[np.flatnonzero(face_patch == j)]
        brk = np.flatnonzero(qs[1:, 0] != qs[:-1, 3]) + 1
        rows = np.split(qs, brk)
        grids: list = [[rows[0]]]
        for r in rows[1:]:
            prev = grids[-1][-1]
            if len(r) == len(prev) and r[0, 0] == prev[0, 1]:
                grids[-1].append(r)
            else:
                grids.append([r])
        for g in grids:
            R = np.stack(g)                                  # (p, q, 4)
            p, q = R.shape[:2]
            G = np.empty((p + 1, q + 1), dtype=np.int64)
            G[:p, :q] = R[:, :, 0]
            G[p, :q] = R[-1, :, 1]
            G[:p, q] = R[:, -1, 3]
            G[p, q] = R[-1, -1, 2]
            if not np.array_equal(_grid_quads(G), R.reshape(-1, 4)):
                raise ValueError(f"patch {j}: its quads are not row-major grids")
            out.append((int(j), G))
    return out


def _grid_quads(G):
    return np.stack([G[:-1, :-1].ravel(), G[1:, :-1].ravel(), G[1:, 1:].ravel(),
                     G[:-1, 1:].ravel()], axis=1)


def _diag_lookup(quads: np.ndarray, n: int):
    """Face of a quad given a diagonal ``(a, c)`` and, where two quads share that
    diagonal (two patches on the same loop, or folded onto each other at a
    valence-two vertex), its other vertices ``b`` and ``d`` where known:
    ``find(a, c, b=None, d=None) -> face or -1``."""
    k02 = np.minimum(quads[:, 0], quads[:, 2]) * n + np.maximum(quads[:, 0], quads[:, 2])
    k13 = np.minimum(quads[:, 1], quads[:, 3]) * n + np.maximum(quads[:, 1], quads[:, 3])
    keys = np.concatenate([k02, k13])
    face = np.tile(np.arange(len(quads)), 2)
    order = np.argsort(keys, kind="stable")
    keys, face = keys[order], face[order]
    last = len(keys) - 1

    def find(a, c, b=None, d=None):
        k = np.minimum(a, c) * n + np.maximum(a, c)
        pos = np.clip(np.searchsorted(keys, k), 0, last)
        f = np.where(keys[pos] == k, face[pos], -1)
        if b is not None:
            has = (quads[f] == np.asarray(b)[..., None]).any(-1)
            if d is not None:
                has &= (quads[f] == np.asarray(d)[..., None]).any(-1)
            nxt = np.minimum(pos + 1, last)
            f = np.where((keys[nxt] == k) & (nxt != pos) & ~has, face[nxt], f)
        return f
    return find


def refine_grid(G: np.ndarray, quads: np.ndarray, topo, find=None) -> np.ndarray:
    """The grid ``G`` one Catmull-Clark step later (see :mod:`.catmull_clark` order).

    Parameters
    ----------
    G : (p + 1, q + 1) int64
    quads : (f, 4) int64
        The mesh ``G`` lives on (before the step).
    topo : EdgeTopology
        Its edges (``SubdivisionStep.topo``).
    find : callable, optional
        :func:`_diag_lookup` of ``quads`` (reused across grids).

    Returns
    -------
    (2 p + 1, 2 q + 1) int64
    """
    n, ne = topo.n_vertices, len(topo.edges)
    find = find or _diag_lookup(quads, n)
    p, q = G.shape[0] - 1, G.shape[1] - 1
    H = np.empty((2 * p + 1, 2 * q + 1), dtype=np.int64)
    H[0::2, 0::2] = G
    H[1::2, 0::2] = n + edge_index(topo, G[:-1].ravel(), G[1:].ravel()).reshape(p, q + 1)
    H[0::2, 1::2] = n + edge_index(topo, G[:, :-1].ravel(), G[:, 1:].ravel()).reshape(p + 1, q)
    H[1::2, 1::2] = n + ne + find(G[:-1, :-1].ravel(), G[1:, 1:].ravel(), G[1:, :-1].ravel(),
                                  G[:-1, 1:].ravel()).reshape(p, q)
    return H


def uniform_knots(m: int) -> np.ndarray:
    """Unclamped uniform cubic knots ``-3 .. m + 3`` for ``m`` spans on ``[0, m]``."""
    return np.arange(-3, m + 4, dtype=np.float64)


def _tensor(Bu: np.ndarray, E: np.ndarray, Bv: np.ndarray) -> np.ndarray:
    """Grid evaluation ``sum_ab Bu[r, a] E[a, b] Bv[c, b]`` -> ``(r, c, 3)``."""
    T = np.tensordot(Bu, E, axes=(1, 0))                      # (r, b, 3)
    return np.tensordot(T, Bv, axes=(1, 1)).transpose(0, 2, 1)


def _design(x, m: int) -> np.ndarray:
    return BSpline.design_matrix(np.asarray(x, np.float64), uniform_knots(m), 3).toarray()


def clamp_uniform(poles: np.ndarray, m: int, axis: int, breaks=None) -> tuple:
    """Re-express uniform unclamped cubic poles along ``axis`` with clamped knots.

    Same spline on ``[0, m]``; the clamped end poles are the end points of the
    surface, so pieces sharing a boundary curve share its poles.

    Parameters
    ----------
    poles : (..., m + 3, ...) float64
    m : int
    axis : int
    breaks : (b,) float64, optional
        Breakpoints from 0 to m that include ``0, 1, ..., m`` (default exactly
        those); extra ones refine the knot vector (knot insertion: the same spline).

    Returns
    -------
    poles : ``len(breaks) + 2`` along ``axis``
    knots : (len(breaks) + 6,) float64 -- ``0, 0, 0, breaks, m, m, m``
    """
    b = np.arange(m + 1, dtype=np.float64) if breaks is None else np.asarray(breaks, np.float64)
    t = np.r_[[0.0] * 3, b, [float(m)] * 3]
    g = (t[1:-3] + t[2:-2] + t[3:-1]) / 3.0                  # Greville abscissae
    A_new = BSpline.design_matrix(g, t, 3).toarray()
    R = np.linalg.solve(A_new, _design(g, m))                 # (len(b) + 2, m + 3)
    return np.moveaxis(np.tensordot(R, np.moveaxis(poles, axis, 0), axes=1), 0, axis), t


def evaluate(piece: BSplinePiece, u, v, derivatives: bool = False):
    """Points (and ``du``, ``dv``) of a piece at parameters ``u, v (k,)``.

    Returns
    -------
    (k, 3) float64, or a tuple of three when ``derivatives``.
    """
    u, v = np.asarray(u, np.float64), np.asarray(v, np.float64)
    if not len(u):
        z = np.zeros((0, 3))
        return (z, z, z) if derivatives else z
    iu, bu = _basis(u, piece.knots_u, 0)
    iv, bv = _basis(v, piece.knots_v, 0)
    P = piece.poles[iu[:, :, None], iv[:, None, :]]            # (k, 4, 4, 3)

    def pair(A, B):
        return np.einsum("ka,kb,kabc->kc", A, B, P)
    if not derivatives:
        return pair(bu, bv)
    du, dv = _basis(u, piece.knots_u, 1)[1], _basis(v, piece.knots_v, 1)[1]
    return pair(bu, bv), pair(du, bv), pair(bu, dv)


def _basis(x: np.ndarray, t: np.ndarray, derivative: int):
    """Non-zero cubic B-spline basis functions at ``x``: columns and values ``(k, 4)``,
    or the values' first derivatives on the same columns (Cox-de Boor, Piegl &
    Tiller, The NURBS Book, A2.2 and eq. 2.9).
    """
    x = np.asarray(x, np.float64)
    n = len(t) - 4
    s = np.clip(np.searchsorted(t, x, side="right") - 1, 3, n - 1)       # t[s] <= x < t[s+1]
    left = x[:, None] - t[s[:, None] + 1 - np.arange(1, 4)]             # x - t[s + 1 - j]
    right = t[s[:, None] + np.arange(1, 4)] - x[:, None]                # t[s + j] - x
    N = np.ones((len(x), 1))
    for j in range(1, 4):
        nxt = np.zeros((len(x), j + 1))
        for r in range(j):
            tmp = N[:, r] / (right[:, r] + left[:, j - r - 1])
            nxt[:, r] += right[:, r] * tmp
            nxt[:, r + 1] = left[:, j - r - 1] * tmp
        N = nxt
        if j == 2:
            quad = N                        # the quadratics, for the derivative
    cols = s[:, None] - 3 + np.arange(4)
    if derivative == 0:
        return cols, N
    # N'_(i,3) = 3 N_(i,2) / (t[i+3] - t[i]) - 3 N_(i+1,2) / (t[i+4] - t[i+1]);
    # quad[:, b] is N_(s-2+b, 2)
    den = t[cols + 3] - t[cols]
    w = np.where(den > 0, 3.0 / np.where(den > 0, den, 1.0), 0.0)     # 3 / (t[i+3] - t[i])
    q = np.zeros((len(x), 5))
    q[:, 1:4] = quad
    return cols, w * q[:, :4] - np.c_[w[:, 1:], np.zeros(len(x))] * q[:, 1:]


def project(piece: BSplinePiece, points, u0, v0, iterations: int = 8):
    """Closest points of a piece to ``points (k, 3)`` by Gauss-Newton from ``(u0, v0)``.

    Parameters stay in the piece's domain (a point beyond a border projects onto it).

    Returns
    -------
    u, v : (k,) float64
    distance : (k,) float64
    """
    p = np.asarray(points, np.float64)
    u, v = np.array(u0, np.float64), np.array(v0, np.float64)
    hi_u, hi_v = piece.knots_u[-1], piece.knots_v[-1]
    for _ in range(iterations):
        S, Su, Sv = evaluate(piece, u, v, derivatives=True)
        r = S - p
        a, b, c = (Su * Su).sum(1), (Su * Sv).sum(1), (Sv * Sv).sum(1)
        gu, gv = (Su * r).sum(1), (Sv * r).sum(1)
        det = np.maximum(a * c - b * b, 1e-300)
        u = np.clip(u - (c * gu - b * gv) / det, 0.0, hi_u)
        v = np.clip(v - (a * gv - b * gu) / det, 0.0, hi_v)
    return u, v, np.linalg.norm(evaluate(piece, u, v) - p, axis=1)


class _Level:
    """One subdivision level: positions, quads and the lookups the outer ring needs."""

    def __init__(self, V, Q, sharp_edges, corners):
        self.V, self.Q = V, Q
        self.sharp_edges, self.corners = sharp_edges, corners
        n = self.n = len(V)
        self.topo = edge_topology(Q, n)
        self.sharp = sharp_mask(self.topo, sharp_edges)
        self.find = _diag_lookup(Q, n)
        a, b = Q.ravel(), np.roll(Q, -1, axis=1).ravel()
        keys = np.minimum(a, b) * n + np.maximum(a, b)
        order = np.argsort(keys, kind="stable")
        self.keys = keys[order]
        self.a = a[order]
        self.face = np.repeat(np.arange(len(Q)), 4)[order]
        self.out_a = np.roll(Q, 1, axis=1).ravel()[order]     # c_{k-1}: beside c_k
        self.out_b = np.roll(Q, -2, axis=1).ravel()[order]    # c_{k+2}: beside c_{k+1}

    def across(self, a, b, own):
        """Vertices beside ``a`` and ``b`` in the face across edge ``(a, b)`` from
        face ``own``: ``(oa, ob, sharp)``, -1 where the edge is sharp."""
        k = np.minimum(a, b) * self.n + np.maximum(a, b)
        lo = np.searchsorted(self.keys, k)
        e = edge_index(self.topo, a, b)
        sharp = self.sharp[e]
        other = np.where(self.face[np.minimum(lo, len(self.keys) - 1)] == own, lo + 1, lo)
        other = np.minimum(other, len(self.keys) - 1)
        same = self.a[other] == a
        oa = np.where(same, self.out_a[other], self.out_b[other])
        ob = np.where(same, self.out_b[other], self.out_a[other])
        return np.where(sharp, -1, oa), np.where(sharp, -1, ob), sharp


def _side(lv: _Level, Gs: np.ndarray):
    """Outer ring beside the borders ``Gs[:, :, 0]`` (inner rows ``Gs[:, :, 1]``) of
    ``k`` grids ``Gs (k, m + 1, 2)``.

    Returns ``(points (k, m + 1, 3), ids (k, m + 1), sharp (k, m), conflict (k, m + 1))``;
    ids are -1 for phantom points ``2 P_0 - P_1``.
    """
    V = lv.V
    k, m = Gs.shape[0], Gs.shape[1] - 1
    a, b = Gs[:, :-1, 0].ravel(), Gs[:, 1:, 0].ravel()
    own = lv.find(a, Gs[:, 1:, 1].ravel(), b, Gs[:, :-1, 1].ravel())
    oa, ob, sharp = (x.reshape(k, m) for x in lv.across(a, b, own))
    ghost = 2.0 * V[Gs[:, :, 0]] - V[Gs[:, :, 1]]
    no, yes = np.zeros((k, 1), bool), np.ones((k, m), bool)
    right = np.concatenate([oa, np.full((k, 1), -2)], 1)   # vertex i's from edge (i, i + 1)
    left = np.concatenate([np.full((k, 1), -2), ob], 1)    # ... from edge (i - 1, i)
    sh_r, sh_l = np.concatenate([sharp, no], 1), np.concatenate([no, sharp], 1)
    has_r, has_l = np.concatenate([yes, no], 1), np.concatenate([no, yes], 1)

    def cand(ids, sh):
        return np.where(sh[..., None], ghost, V[np.maximum(ids, 0)])
    pr, pl = cand(right, sh_r), cand(left, sh_l)
    conflict = has_r & has_l & ((sh_r != sh_l) | (~sh_r & (right != left)))
    pts = np.where(has_r[..., None], pr, pl)
    pts[conflict] = 0.5 * (pr[conflict] + pl[conflict])
    ids = np.where(has_r, np.where(sh_r, -1, right), np.where(sh_l, -1, left))
    ids[conflict] = -1
    return pts, ids, sharp, conflict


def _extended(lv: _Level, G: np.ndarray):
    """Uniform B-spline poles ``(M + 3, N + 3, 3)`` of a piece grid, and whether
    every outer-ring point was found unambiguously (:func:`_extended_many`)."""
    E, clean = _extended_many(lv, G[None])
    return E[0], bool(clean[0])


def _extended_many(lv: _Level, G: np.ndarray):
    """Uniform B-spline poles ``(k, M + 3, N + 3, 3)`` of grids ``G (k, M + 1, N + 1)``:
    the grids' points and the ring of vertices just outside (phantom across sharp
    edges); and ``clean (k,)``: every outer-ring point found unambiguously."""
    V = lv.V
    k, M, N = G.shape[0], G.shape[1] - 1, G.shape[2] - 1
    E = np.zeros((k, M + 3, N + 3, 3))
    ids = np.full((k, M + 3, N + 3), -1, dtype=np.int64)
    E[:, 1:-1, 1:-1] = V[G]
    ids[:, 1:-1, 1:-1] = G
    clean = np.ones(k, bool)
    sharp_at = {}
    for name, Gs, Ev, Iv in (("b", G, E[:, 1:-1, 0], ids[:, 1:-1, 0]),
                             ("t", G[:, :, ::-1], E[:, 1:-1, -1], ids[:, 1:-1, -1]),
                             ("l", G.transpose(0, 2, 1), E[:, 0, 1:-1], ids[:, 0, 1:-1]),
                             ("r", G[:, ::-1].transpose(0, 2, 1), E[:, -1, 1:-1],
                              ids[:, -1, 1:-1])):
        pts, oid, sharp, conflict = _side(lv, Gs)
        Ev[:], Iv[:] = pts, oid
        sharp_at[name] = (sharp[:, 0], sharp[:, -1])
        clean &= ~conflict.any(axis=1)
    # corners: views with the corner at [:, 0, 0]
    rows = np.arange(k)
    for Ev, Iv, Gv, s_j, s_i in (
            (E, ids, G, sharp_at["b"][0], sharp_at["l"][0]),
            (E[:, ::-1], ids[:, ::-1], G[:, ::-1], sharp_at["b"][1], sharp_at["r"][0]),
            (E[:, :, ::-1], ids[:, :, ::-1], G[:, :, ::-1], sharp_at["t"][0],
             sharp_at["l"][1]),
            (E[:, ::-1, ::-1], ids[:, ::-1, ::-1], G[:, ::-1, ::-1], sharp_at["t"][1],
             sharp_at["r"][1])):
        Ev[s_j, 0, 0] = 2.0 * Ev[s_j, 0, 1] - Ev[s_j, 0, 2]       # row j = -1 is phantom
        col = ~s_j & s_i                                           # column i = -1 is phantom
        Ev[col, 0, 0] = 2.0 * Ev[col, 1, 0] - Ev[col, 2, 0]
        x, y, c = Iv[:, 0, 1], Iv[:, 1, 0], Gv[:, 0, 0]
        f = np.where((x >= 0) & (y >= 0), lv.find(np.maximum(x, 0), np.maximum(y, 0), c), -1)
        q = lv.Q[np.maximum(f, 0)]
        hit = q == c[:, None]
        found = ~s_j & ~s_i & (f >= 0) & hit.any(axis=1)
        d = q[rows, (np.argmax(hit, axis=1) + 2) % 4]
        Ev[found, 0, 0], Iv[found, 0, 0] = V[d[found]], d[found]
        lost = ~s_j & ~s_i & ~found
        Ev[lost, 0, 0] = Ev[lost, 0, 1] + Ev[lost, 1, 0] - Ev[lost, 1, 1]
        clean &= ~lost
    return E, clean


def _level(net: ControlNet, level: int):
    """Subdivide ``level`` times, tracking every piece's grid.

    Returns ``(patches, lv, grids, limit, corners)``: patch of each piece, the
    level's :class:`_Level`, the pieces' grids, the exact limit positions of the
    level's vertices and its corner flags.
    """
    V, Q = np.asarray(net.vertices, np.float64), np.asarray(net.quads, np.int64)
    se = np.asarray(net.sharp_edges, np.int64).reshape(-1, 2)
    cr = np.asarray(net.corners, bool)
    pieces = piece_grids(Q, net.face_patch)
    grids = [G for _, G in pieces]
    for _ in range(level):
        st = subdivision_step(Q, len(V), se, cr)
        find = _diag_lookup(Q, len(V))
        grids = [refine_grid(G, Q, st.topo, find) for G in grids]
        V, Q, se, cr = st.S @ V, st.quads, st.sharp_edges, st.corners
    lv = _Level(V, Q, se, cr)
    return [p for p, _ in pieces], lv, grids, limit_matrix(Q, len(V), se, cr) @ V


def _local_samples(lv: _Level, spans: list, levels: int) -> np.ndarray:
    """Exact limit samples ``(len(spans), 2^levels + 1, 2^levels + 1, 3)`` over faces.

    ``spans`` are 2 x 2 id grids of faces of ``lv``. Only those faces and the faces
    around them are subdivided: the limit surface over a face depends on its one-ring
    alone, so the submesh's own (sharp) border does not reach the samples.
    """
    V, Q, se, cr, H = submesh(lv, np.stack(spans))
    grids = list(H)
    for _ in range(levels):
        st = subdivision_step(Q, len(V), se, cr)
        find = _diag_lookup(Q, len(V))
        grids = [refine_grid(G, Q, st.topo, find) for G in grids]
        V, Q, se, cr = st.S @ V, st.quads, st.sharp_edges, st.corners
    ids = np.stack(grids)
    used = np.unique(ids)
    L = limit_matrix(Q, len(V), se, cr)[used]
    lut = np.zeros(len(V), np.int64)
    lut[used] = np.arange(len(used))
    return (L @ V)[lut[ids]]


def _sites(lv: _Level, grids: list, offs: list, limit: np.ndarray, tol: float):
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
    irregular = _irregular(lv)
    where = [(pid, i, j) for pid, off in enumerate(offs)
             for i, j in np.argwhere(off[:-1, :-1] | off[1:, :-1] | off[:-1, 1:] | off[1:, 1:])]
    if not where:
        return np.zeros((0, 6), np.int64), [], np.zeros((0, 4, 4, 3))
    spans = np.array([grids[p][i:i + 2, j:j + 2] for p, i, j in where])
    E4s = _extended_many(lv, spans)[0]
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


def _irregular(lv: _Level) -> np.ndarray:
    """Vertices whose limit rule is not the uniform bicubic one: valence other than
    four (smooth), darts, creases with other than two faces a side, corners of more
    than one face."""
    cls = vertex_classes(lv.topo, lv.sharp, lv.corners)
    val = np.bincount(lv.topo.edges.ravel(), minlength=lv.n)
    n_sharp = np.bincount(lv.topo.edges[lv.sharp].ravel(), minlength=lv.n)
    regular = (((cls == SMOOTH) & (val == 4) & (n_sharp == 0))
               | ((cls == CREASE) & ((val == 3) | (val == 4))) | ((cls == CORNER) & (val == 2)))
    return ~regular


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
                     tolerance: float = DEFAULT_TOLERANCE) -> BSplineSet:
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

    Returns
    -------
    BSplineSet
    """
    from .seams import border_samples, seam_report    # imports this module
    for name, val, lo in (("level", level, 1), ("sample_levels", sample_levels, 2),
                          ("grade", grade, 0), ("max_grade", max_grade, grade)):
        if int(val) != val or val < lo:
            raise ValueError(f"{name}: expected an integer >= {lo}, got {val!r}")
    diag = net.diagonal if net.diagonal > 0 else 1.0
    patches, lv, grids, limit = _level(net, int(level))
    r = 2 ** int(sample_levels)
    nets, offs = [], []
    for G in grids:                    # uniform poles; irregular: vertices off the limit
        M, N = G.shape[0] - 1, G.shape[1] - 1
        E, clean = _extended(lv, G)
        at = _tensor(_design(np.arange(M + 1), M), E, _design(np.arange(N + 1), N))
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
