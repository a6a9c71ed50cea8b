"""Subdivision levels of a control net, with the quad grids of its pieces tracked through them.

Each loop's control quads form one ``p x q`` grid (four-sided loops) or ``T`` grids
around a centre (split loops); these are the *pieces* (:func:`piece_grids`). A
Catmull-Clark step maps a grid ``(p + 1, q + 1)`` to ``(2 p + 1, 2 q + 1)``
(:func:`refine_grid`), so after ``level`` steps a piece is an ``M x N`` grid
(``M = 2^level p``). Where every vertex of a face is regular the limit surface over it
is the uniform bicubic B-spline of its 4 x 4 neighbourhood (Catmull & Clark 1978;
across sharp edges the phantom row ``2 P_0 - P_1`` reproduces the crease rules, DeRose
et al. 1998): :func:`extended_poles_many` reads those poles off a level, the grid's own
points and the ring just outside it.

Near irregular vertices (:func:`irregular_vertices`) the limit surface is not
polynomial; :func:`local_samples` gives exact limit points there by subdividing only
the faces around them (:func:`submesh`).

Arrays in, arrays out: this module knows no graph.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .catmull_clark import (CORNER, CREASE, SMOOTH, edge_index, edge_topology, sharp_mask,
                            subdivision_step, vertex_classes)
from .limit import limit_matrix

__all__ = ["ControlNet", "Level", "piece_grids", "diag_lookup", "refine_grid",
           "subdivide_grids", "subdivide_net", "extended_poles", "extended_poles_many",
           "submesh", "local_samples", "irregular_vertices"]


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


def diag_lookup(quads: np.ndarray, n: int):
    """Face of a quad given one of its diagonals.

    Parameters
    ----------
    quads : (f, 4) int64
    n : int
        Vertex count.

    Returns
    -------
    callable
        ``find(a, c, b=None, d=None) -> (k,) int64``: the face with diagonal
        ``(a, c)``, -1 where none. Where two quads share that diagonal (two patches on
        the same loop, or folded onto each other at a valence-two vertex), the one
        that also has the vertices ``b`` (and ``d``) where given.
    """
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
        :func:`diag_lookup` of ``quads`` (reused across grids).

    Returns
    -------
    (2 p + 1, 2 q + 1) int64
    """
    n, ne = topo.n_vertices, len(topo.edges)
    find = find or diag_lookup(quads, n)
    p, q = G.shape[0] - 1, G.shape[1] - 1
    H = np.empty((2 * p + 1, 2 * q + 1), dtype=np.int64)
    H[0::2, 0::2] = G
    H[1::2, 0::2] = n + edge_index(topo, G[:-1].ravel(), G[1:].ravel()).reshape(p, q + 1)
    H[0::2, 1::2] = n + edge_index(topo, G[:, :-1].ravel(), G[:, 1:].ravel()).reshape(p + 1, q)
    H[1::2, 1::2] = n + ne + find(G[:-1, :-1].ravel(), G[1:, 1:].ravel(), G[1:, :-1].ravel(),
                                  G[:-1, 1:].ravel()).reshape(p, q)
    return H


def subdivide_grids(V, Q, sharp_edges, corners, grids, levels: int):
    """``levels`` Catmull-Clark steps of a mesh, with the grids ``grids`` on it refined along.

    Parameters
    ----------
    V : (n, 3) float64, Q : (f, 4) int64, sharp_edges : (s, 2) int64, corners : (n,) bool
    grids : list of (p + 1, q + 1) int64
    levels : int

    Returns
    -------
    V, Q, sharp_edges, corners, grids
        The subdivided mesh and the grids on it (``(2^levels p + 1, 2^levels q + 1)``).
    """
    for _ in range(levels):
        st = subdivision_step(Q, len(V), sharp_edges, corners)
        find = diag_lookup(Q, len(V))
        grids = [refine_grid(G, Q, st.topo, find) for G in grids]
        V, Q, sharp_edges, corners = st.S @ V, st.quads, st.sharp_edges, st.corners
    return V, Q, sharp_edges, corners, grids


class Level:
    """One subdivision level: positions, quads and the lookups the outer ring needs.

    Parameters
    ----------
    V : (n, 3) float64
    Q : (f, 4) int64
    sharp_edges : (s, 2) int64
    corners : (n,) bool
    """

    def __init__(self, V, Q, sharp_edges, corners):
        self.V, self.Q = V, Q
        self.sharp_edges, self.corners = sharp_edges, corners
        n = self.n = len(V)
        self.topo = edge_topology(Q, n)
        self.sharp = sharp_mask(self.topo, sharp_edges)
        self.find = diag_lookup(Q, n)
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


def _side(lv: Level, Gs: np.ndarray):
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


def extended_poles(lv: Level, G: np.ndarray):
    """Uniform B-spline poles of one piece grid (:func:`extended_poles_many`).

    Returns
    -------
    E : (M + 3, N + 3, 3) float64
    clean : bool
    """
    E, clean = extended_poles_many(lv, G[None])
    return E[0], bool(clean[0])


def extended_poles_many(lv: Level, G: np.ndarray):
    """Uniform B-spline poles of grids: their points and the ring of vertices just outside.

    Parameters
    ----------
    lv : Level
    G : (k, M + 1, N + 1) int64
        Grids of vertex ids of ``lv``.

    Returns
    -------
    E : (k, M + 3, N + 3, 3) float64
        Poles; across sharp edges the ring holds phantom points ``2 P_0 - P_1``.
    clean : (k,) bool
        Every outer-ring point found unambiguously.
    """
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


def subdivide_net(net: ControlNet, level: int):
    """Subdivide ``net`` ``level`` times, tracking every piece's grid.

    Returns
    -------
    patches : list of int
        Patch of each piece.
    lv : Level
        The subdivided mesh.
    grids : list of (M + 1, N + 1) int64
        The pieces' grids on it.
    limit : (n, 3) float64
        Exact limit positions of its vertices.
    """
    V, Q = np.asarray(net.vertices, np.float64), np.asarray(net.quads, np.int64)
    se = np.asarray(net.sharp_edges, np.int64).reshape(-1, 2)
    cr = np.asarray(net.corners, bool)
    pieces = piece_grids(Q, net.face_patch)
    V, Q, se, cr, grids = subdivide_grids(V, Q, se, cr, [G for _, G in pieces], level)
    lv = Level(V, Q, se, cr)
    return [p for p, _ in pieces], lv, grids, limit_matrix(Q, len(V), se, cr) @ V


def submesh(lv: Level, grids: np.ndarray):
    """The faces of ``lv`` around the vertices ``grids (k, ...)``, renumbered.

    Returns
    -------
    vertices (n', 3), quads (f', 4), sharp_edges (s', 2), corners (n',), grids
        The grids in the new numbering. Subdivision of this submesh is exact on
        the faces whose one-ring it contains (its own border is sharp).
    """
    near = np.zeros(lv.n, bool)
    near[np.asarray(grids).ravel()] = True
    Q = lv.Q[near[lv.Q].any(axis=1)]
    used, Qc = np.unique(Q, return_inverse=True)
    lut = np.full(lv.n, -1, np.int64)
    lut[used] = np.arange(len(used))
    se = lut[np.asarray(lv.sharp_edges, np.int64).reshape(-1, 2)]
    return (lv.V[used], Qc.reshape(Q.shape), se[(se >= 0).all(axis=1)], lv.corners[used],
            lut[grids])


def local_samples(lv: Level, spans: list, levels: int) -> np.ndarray:
    """Exact limit samples ``(len(spans), 2^levels + 1, 2^levels + 1, 3)`` over faces.

    ``spans`` are 2 x 2 id grids of faces of ``lv``. Only those faces and the faces
    around them are subdivided: the limit surface over a face depends on its one-ring
    alone, so the submesh's own (sharp) border does not reach the samples.
    """
    V, Q, se, cr, H = submesh(lv, np.stack(spans))
    V, Q, se, cr, grids = subdivide_grids(V, Q, se, cr, list(H), levels)
    ids = np.stack(grids)
    used = np.unique(ids)
    L = limit_matrix(Q, len(V), se, cr)[used]
    lut = np.zeros(len(V), np.int64)
    lut[used] = np.arange(len(used))
    return (L @ V)[lut[ids]]


def irregular_vertices(lv: Level) -> np.ndarray:
    """Vertices whose limit rule is not the uniform bicubic one.

    Valence other than four (smooth), darts, creases with other than two faces a side,
    corners of more than one face.

    Returns
    -------
    (n,) bool
    """
    cls = vertex_classes(lv.topo, lv.sharp, lv.corners)
    val = np.bincount(lv.topo.edges.ravel(), minlength=lv.n)
    n_sharp = np.bincount(lv.topo.edges[lv.sharp].ravel(), minlength=lv.n)
    regular = (((cls == SMOOTH) & (val == 4) & (n_sharp == 0))
               | ((cls == CREASE) & ((val == 3) | (val == 4))) | ((cls == CORNER) & (val == 2)))
    return ~regular
