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
import scipy.sparse as sp
from scipy.interpolate import BSpline

from .catmull_clark import edge_index, edge_topology, sharp_mask, subdivision_step
from .limit import limit_matrix

__all__ = ["ControlNet", "BSplinePiece", "BSplineSet", "piece_grids", "refine_grid",
           "extract_bsplines", "uniform_knots", "clamp_uniform", "evaluate", "project",
           "DEFAULT_LEVEL", "EXACT_TOL"]

#: Subdivision steps before the pieces are read off as B-splines.
DEFAULT_LEVEL = 3
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
        ``angle`` (G1, largest normal angle, degrees), ``deviation`` (largest
        distance of exact limit points along it to the faces).
    report : dict
        ``level``, ``sample_levels``, ``diagonal`` (model units), ``n_pieces``,
        ``n_exact``, ``max_deviation``, ``pieces_per_patch`` (patches of more than one
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
    diagonal (two patches on the same loop), a third vertex ``b``:
    ``find(a, c, b=None) -> face or -1``."""
    k02 = np.minimum(quads[:, 0], quads[:, 2]) * n + np.maximum(quads[:, 0], quads[:, 2])
    k13 = np.minimum(quads[:, 1], quads[:, 3]) * n + np.maximum(quads[:, 1], quads[:, 3])
    keys = np.concatenate([k02, k13])
    face = np.tile(np.arange(len(quads)), 2)
    order = np.argsort(keys, kind="stable")
    keys, face = keys[order], face[order]
    last = len(keys) - 1

    def find(a, c, b=None):
        k = np.minimum(a, c) * n + np.maximum(a, c)
        pos = np.clip(np.searchsorted(keys, k), 0, last)
        f = np.where(keys[pos] == k, face[pos], -1)
        if b is not None:
            nxt = np.minimum(pos + 1, last)
            alt = (keys[nxt] == k) & (nxt != pos) & ~(quads[f] == np.asarray(b)[..., None]).any(-1)
            f = np.where(alt, face[nxt], f)
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
    H[1::2, 1::2] = n + ne + find(G[:-1, :-1].ravel(), G[1:, 1:].ravel(),
                                  G[1:, :-1].ravel()).reshape(p, q)
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


def clamp_uniform(poles: np.ndarray, m: int, axis: int) -> tuple:
    """Re-express uniform unclamped cubic poles along ``axis`` with clamped knots.

    Same spline on ``[0, m]``, same number of poles; the clamped end poles are the
    end points of the surface, so pieces sharing a boundary curve share its poles.

    Returns
    -------
    poles : same shape
    knots : (m + 7,) float64 -- ``0, 0, 0, 0, 1, ..., m - 1, m, m, m, m``
    """
    t = np.r_[[0.0] * 3, np.arange(m + 1, dtype=np.float64), [float(m)] * 3]
    g = (t[1:-3] + t[2:-2] + t[3:-1]) / 3.0                  # Greville abscissae
    A_new = BSpline.design_matrix(g, t, 3).toarray()
    R = np.linalg.solve(A_new, _design(g, m))                 # (m + 3, m + 3)
    return np.moveaxis(np.tensordot(R, np.moveaxis(poles, axis, 0), axes=1), 0, axis), t


def evaluate(piece: BSplinePiece, u, v, derivatives: bool = False):
    """Points (and ``du``, ``dv``) of a piece at parameters ``u, v (k,)``.

    Returns
    -------
    (k, 3) float64, or a tuple of three when ``derivatives``.
    """
    u, v = np.asarray(u, np.float64), np.asarray(v, np.float64)
    nu, nv = len(piece.knots_u) - 4, len(piece.knots_v) - 4
    flat = piece.poles.reshape(nu, -1)

    def pair(A, B):                       # sparse (k, nu) basis in u, dense (k, nv) in v
        return (np.asarray(A @ flat).reshape(len(u), nv, 3) * B.toarray()[:, :, None]).sum(1)
    Bu, Bv = _basis(u, piece.knots_u, 0), _basis(v, piece.knots_v, 0)
    if not derivatives:
        return pair(Bu, Bv)
    Du, Dv = _basis(u, piece.knots_u, 1), _basis(v, piece.knots_v, 1)
    return pair(Bu, Bv), pair(Du, Bv), pair(Bu, Dv)


def _basis(x: np.ndarray, t: np.ndarray, derivative: int):
    """Sparse cubic B-spline basis ``(k, len(t) - 4)`` at ``x``, or its first derivative.

    The derivative of a cubic with poles ``c`` is the quadratic on ``t[1:-1]`` with
    poles ``3 (c[i + 1] - c[i]) / (t[i + 4] - t[i + 1])``.
    """
    if derivative == 0:
        return BSpline.design_matrix(x, t, 3)
    n = len(t) - 4
    w = 3.0 / (t[4:n + 3] - t[1:n])
    D = sp.diags([-w, w], [0, 1], shape=(n - 1, n))
    return BSpline.design_matrix(x, t[1:-1], 2) @ D


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

    def __init__(self, V, Q, sharp_edges):
        self.V, self.Q = V, Q
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
    """Outer ring beside the border ``Gs[:, 0]`` (inner row ``Gs[:, 1]``).

    Returns ``(points (m + 1, 3), ids (m + 1,), sharp (m,), conflict (m + 1,))``;
    ids are -1 for phantom points ``2 P_0 - P_1``.
    """
    V = lv.V
    a, b = Gs[:-1, 0], Gs[1:, 0]
    own = lv.find(a, Gs[1:, 1], b)
    oa, ob, sharp = lv.across(a, b, own)
    ghost = 2.0 * V[Gs[:, 0]] - V[Gs[:, 1]]
    m = len(a)
    right = np.r_[oa, -2]            # candidate of vertex i from edge (i, i + 1)
    left = np.r_[-2, ob]             # ... from edge (i - 1, i)
    sh_r = np.r_[sharp, False]
    sh_l = np.r_[False, sharp]
    has_r = np.r_[np.ones(m, bool), False]
    has_l = np.r_[False, np.ones(m, bool)]

    def cand(ids, sh):
        return np.where(sh[:, None], ghost, V[np.maximum(ids, 0)])
    pr, pl = cand(right, sh_r), cand(left, sh_l)
    both = has_r & has_l
    conflict = both & ((sh_r != sh_l) | (~sh_r & (right != left)))
    pts = np.where(has_r[:, None], pr, pl)
    pts[conflict] = 0.5 * (pr[conflict] + pl[conflict])
    ids = np.where(has_r, np.where(sh_r, -1, right), np.where(sh_l, -1, left))
    ids[conflict] = -1
    return pts, ids, sharp, conflict


def _extended(lv: _Level, G: np.ndarray):
    """Uniform B-spline poles ``(M + 3, N + 3, 3)`` of a piece grid, and whether
    every outer-ring point was found unambiguously."""
    V = lv.V
    M, N = G.shape[0] - 1, G.shape[1] - 1
    E = np.zeros((M + 3, N + 3, 3))
    ids = np.full((M + 3, N + 3), -1, dtype=np.int64)
    E[1:-1, 1:-1] = V[G]
    ids[1:-1, 1:-1] = G
    clean = True
    sharp_at = {}
    for name, Gs, Ev, Iv in (("b", G, E[1:-1, 0], ids[1:-1, 0]),
                             ("t", G[:, ::-1], E[1:-1, -1], ids[1:-1, -1]),
                             ("l", G.T, E[0, 1:-1], ids[0, 1:-1]),
                             ("r", G[::-1].T, E[-1, 1:-1], ids[-1, 1:-1])):
        pts, oid, sharp, conflict = _side(lv, Gs)
        Ev[:], Iv[:] = pts, oid
        sharp_at[name] = (sharp[0], sharp[-1])
        clean &= not conflict.any()
    # corners: views with the corner at [0, 0]
    for Ev, Iv, Gv, s_j, s_i in (
            (E, ids, G, sharp_at["b"][0], sharp_at["l"][0]),
            (E[::-1], ids[::-1], G[::-1], sharp_at["b"][1], sharp_at["r"][0]),
            (E[:, ::-1], ids[:, ::-1], G[:, ::-1], sharp_at["t"][0], sharp_at["l"][1]),
            (E[::-1, ::-1], ids[::-1, ::-1], G[::-1, ::-1], sharp_at["t"][1],
             sharp_at["r"][1])):
        if s_j:                                  # row j = -1 is phantom
            Ev[0, 0] = 2.0 * Ev[0, 1] - Ev[0, 2]
            continue
        if s_i:                                  # column i = -1 is phantom
            Ev[0, 0] = 2.0 * Ev[1, 0] - Ev[2, 0]
            continue
        x, y, c = Iv[0, 1], Iv[1, 0], Gv[0, 0]
        f = lv.find(np.array([x]), np.array([y]), np.array([c]))[0] if min(x, y) >= 0 else -1
        if f >= 0 and c in lv.Q[f]:
            q = lv.Q[f]
            k = int(np.flatnonzero(q == c)[0])
            d = q[(k + 2) % 4]
            Ev[0, 0], Iv[0, 0] = V[d], d
        else:
            Ev[0, 0] = Ev[0, 1] + Ev[1, 0] - Ev[1, 1]
            clean = False
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
    lv = _Level(V, Q, se)
    lv.sharp_edges, lv.corners = se, cr
    return [p for p, _ in pieces], lv, grids, limit_matrix(Q, len(V), se, cr) @ V


def _local_samples(lv: _Level, spans: list, levels: int) -> np.ndarray:
    """Exact limit samples ``(len(spans), 2^levels + 1, 2^levels + 1, 3)`` over faces.

    ``spans`` are 2 x 2 id grids of faces of ``lv``. Only those faces and the faces
    around them are subdivided: the limit surface over a face depends on its one-ring
    alone, so the submesh's own (sharp) border does not reach the samples.
    """
    H = np.stack(spans)                                          # (k, 2, 2)
    bad_faces = lv.find(H[:, 0, 0], H[:, 1, 1], H[:, 1, 0])
    near = np.zeros(lv.n, bool)
    near[lv.Q[bad_faces].ravel()] = True
    Q = lv.Q[near[lv.Q].any(axis=1)]
    V, se, cr = lv.V, lv.sharp_edges, lv.corners
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


def _spans_to_samples(spans: np.ndarray, r: int) -> np.ndarray:
    """Samples ``(r M + 1, r N + 1)`` in the closure of the marked spans ``(M, N)``."""
    M, N = spans.shape
    out = np.zeros((r * M + 1, r * N + 1), bool)
    for du in range(r + 1):
        for dv in range(r + 1):
            out[du:du + r * M:r, dv:dv + r * N:r] |= spans
    return out


def _fit_irregular(E, Bu, Bv, S, bad_span, r):
    """Refit the poles acting on irregular spans to the exact samples.

    ``E (M + 3, N + 3, 3)`` uniform poles, ``Bu (r M + 1, M + 3)``, ``Bv`` design
    matrices at the sample parameters, ``S (r M + 1, r N + 1, 3)`` exact samples,
    ``bad_span (M, N)``. The poles whose support meets a bad span are refitted to
    the samples over their whole support, so the spans next to the irregular ones
    become approximate too.
    """
    M, N = bad_span.shape
    pad = np.zeros((M + 6, N + 6), bool)         # pole a acts on spans a - 3 .. a
    pad[3:-3, 3:-3] = bad_span
    free = np.zeros((M + 3, N + 3), bool)
    for du in range(4):
        for dv in range(4):
            free |= pad[du:du + M + 3, dv:dv + N + 3]
    touched = np.zeros((M + 6, N + 6), bool)
    for du in range(4):
        for dv in range(4):
            touched[du:du + M + 3, dv:dv + N + 3] |= free
    rows = np.argwhere(_spans_to_samples(touched[3:-3, 3:-3], r))
    fr = np.argwhere(free)
    Efix = E.copy()
    Efix[fr[:, 0], fr[:, 1]] = 0.0
    fixed = _tensor(Bu, Efix, Bv)[rows[:, 0], rows[:, 1]]
    A = Bu[rows[:, 0]][:, fr[:, 0]] * Bv[rows[:, 1]][:, fr[:, 1]]
    X = np.linalg.lstsq(A, S[rows[:, 0], rows[:, 1]] - fixed, rcond=None)[0]
    E = E.copy()
    E[fr[:, 0], fr[:, 1]] = X
    return E


def extract_bsplines(net: ControlNet, level: int = DEFAULT_LEVEL, *,
                     sample_levels: int = 2) -> BSplineSet:
    """Bicubic B-spline pieces of the limit surface of ``net``, with a seam report.

    Parameters
    ----------
    net : ControlNet
    level : int
        Subdivision steps before reading off the pieces (>= 0); each piece has
        ``(2^level p + 3) x (2^level q + 3)`` poles. Higher levels shrink the
        irregular spans around extraordinary vertices.
    sample_levels : int
        Further steps for the exact limit samples that every deviation is measured
        at (``(2^sample_levels + 1)^2`` per span); irregular spans are fitted to every
        other sample (one level coarser), so the measure also sees the fit between
        its points.

    Returns
    -------
    BSplineSet
    """
    from .seams import border_samples, seam_report    # imports this module
    if int(level) != level or level < 0:
        raise ValueError(f"level: expected an integer >= 0, got {level!r}")
    if int(sample_levels) != sample_levels or sample_levels < 2:
        raise ValueError(f"sample_levels: expected an integer >= 2, got {sample_levels!r}")
    diag = net.diagonal if net.diagonal > 0 else 1.0
    patches, lv, grids, limit = _level(net, int(level))
    r = 2 ** int(sample_levels)
    nets, bad_spans, todo = [], [], []
    for G in grids:                    # uniform poles; irregular spans: corners off the limit
        M, N = G.shape[0] - 1, G.shape[1] - 1
        E, clean = _extended(lv, G)
        at = _tensor(_design(np.arange(M + 1), M), E, _design(np.arange(N + 1), N))
        off = np.linalg.norm(at - limit[G], axis=2) > EXACT_TOL * diag
        bad = off[:-1, :-1] | off[1:, :-1] | off[:-1, 1:] | off[1:, 1:]
        nets.append((E, clean))
        bad_spans.append(bad)
        todo += [G[i:i + 2, j:j + 2] for i, j in np.argwhere(bad)]
    exact_samples = iter(_local_samples(lv, todo, int(sample_levels)) if todo else ())
    pieces, border = [], []
    for pid, (patch, G, (E, clean), bad) in enumerate(zip(patches, grids, nets, bad_spans)):
        M, N = G.shape[0] - 1, G.shape[1] - 1
        exact = not bad.any()
        err = np.zeros((r * M + 1, r * N + 1))
        if not exact:
            u, v = np.arange(r * M + 1) / r, np.arange(r * N + 1) / r
            Bu, Bv = _design(u, M), _design(v, N)
            S = _tensor(Bu, E, Bv)            # exact on regular spans
            for i, j in np.argwhere(bad):
                S[i * r:(i + 1) * r + 1, j * r:(j + 1) * r + 1] = next(exact_samples)
            E = _fit_irregular(E, Bu[::2], Bv[::2], S[::2, ::2], bad, r // 2)
            err = np.linalg.norm(_tensor(Bu, E, Bv) - S, axis=2)
        poles, ku = clamp_uniform(E, M, 0)
        poles, kv = clamp_uniform(poles, N, 1)
        pc = BSplinePiece(poles, ku, kv, int(patch), exact and clean, 0.0)
        if not exact:                    # distance to the surface, not to the same (u, v)
            i, j = np.nonzero(_spans_to_samples(bad, r))
            err[i, j] = np.minimum(err[i, j], project(pc, S[i, j], u[i], v[j])[2])
        pc.deviation = float(err.max() / diag)
        pieces.append(pc)
        border.append(border_samples(pid, G, r, err / diag, lv.n))
    seams = seam_report(pieces, border, net)
    dev = max((p.deviation for p in pieces), default=0.0)
    per_patch: dict = {}
    for p in pieces:
        per_patch[p.patch] = per_patch.get(p.patch, 0) + 1
    report = {"level": int(level), "sample_levels": int(sample_levels), "diagonal": diag,
              "n_pieces": len(pieces), "n_exact": sum(p.exact for p in pieces),
              "max_deviation": float(dev),
              "pieces_per_patch": {int(k): int(c) for k, c in per_patch.items() if c > 1}}
    return BSplineSet(pieces, seams, report)
