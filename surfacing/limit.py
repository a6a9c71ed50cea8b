"""Catmull-Clark limit position and tangent masks as sparse matrices (Halstead et al. 1993).

``limit_matrix`` gives ``L`` with limit positions ``L @ P`` at the control vertices;
``tangent_matrices`` gives ``T1, T2`` with two limit tangents ``T1 @ P``, ``T2 @ P``
at smooth vertices, so the limit normal is ``(T1 P) x (T2 P)`` normalised.

Masks (quad meshes; ``n`` = valence, ``e_k`` edge neighbours and ``f_k`` diagonal
neighbours in counter-clockwise order around the vertex, ``f_k`` between ``e_k`` and
``e_{k+1}``):

* smooth vertex, position: ``(n^2 V + 4 sum e_k + sum f_k) / (n (n + 5))``
  (Orbay & Kara 2011, Fig. 7a; weights normalised to sum to one);
* smooth vertex, tangents: ``sum alpha_k e_k + beta_k f_k`` with
  ``alpha_k = cos(2 pi k / n)`` and
  ``beta_k = (sqrt(4 + cos(pi/n)^2) - cos(pi/n)) / 4 * cos((2 pi k + pi) / n)``
  (Eq. 1-2), and the same with ``sin`` for the second tangent;
* crease / boundary vertex: ``(a + 4 V + b) / 6`` along its two sharp edges
  (the limit of the cubic B-spline rule);
* corner: ``V``.

Notes
-----
The smooth masks are exact whenever the vertex's incident edges are all smooth
(the subdivision of its one-ring is then the standard one). Darts (one sharp edge)
use the smooth masks, which are then an approximation. Tangents are returned only
for smooth vertices with a closed one-ring; :func:`limit_normals` falls back to the
area-weighted normal of the limit-position mesh elsewhere.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from curvenet.core.tolerances import DIVISION_GUARD

from .catmull_clark import (CREASE, SMOOTH, crease_neighbours, edge_topology, sharp_mask,
                            vertex_classes)

__all__ = ["limit_matrix", "tangent_matrices", "limit_normals", "quad_vertex_normals"]


def limit_matrix(quads, n_vertices: int, sharp_edges=None, corners=None) -> sp.csr_matrix:
    """Sparse limit-position matrix ``L (n, n)``: limit points are ``L @ P``.

    Parameters
    ----------
    quads : (f, 4) int64
    n_vertices : int
    sharp_edges : (s, 2) int64, optional
    corners : (n,) bool, optional

    Returns
    -------
    scipy.sparse.csr_matrix, rows summing to one

    References
    ----------
    Halstead, Kass & DeRose 1993; Orbay & Kara 2011, Sec. 4.3.1, Fig. 7a.
    """
    quads = np.asarray(quads, dtype=np.int64)
    n = int(n_vertices)
    topo = edge_topology(quads, n)
    sharp = sharp_mask(topo, sharp_edges)
    cls = vertex_classes(topo, sharp, corners)
    val = np.bincount(topo.edges.ravel(), minlength=n).astype(np.float64)
    smooth = cls == SMOOTH
    rows, cols, vals = [], [], []
    vs = np.flatnonzero(smooth)
    rows.append(vs)
    cols.append(vs)
    vals.append(val[vs] / (val[vs] + 5.0))
    for side in (0, 1):
        v, w = topo.edges[:, side], topo.edges[:, 1 - side]
        m = smooth[v]
        rows.append(v[m])
        cols.append(w[m])
        vals.append(4.0 / (val[v[m]] * (val[v[m]] + 5.0)))
    cv = quads.ravel()
    diag = np.roll(quads, -2, axis=1).ravel()
    m = smooth[cv]
    rows.append(cv[m])
    cols.append(diag[m])
    vals.append(1.0 / (val[cv[m]] * (val[cv[m]] + 5.0)))
    c, a, b = crease_neighbours(topo, sharp, cls)
    rows += [c, c, c]
    cols += [c, a, b]
    vals += [np.full(len(c), 4.0 / 6.0), np.full(len(c), 1.0 / 6.0), np.full(len(c), 1.0 / 6.0)]
    cn = np.flatnonzero((cls != SMOOTH) & (cls != CREASE))
    rows.append(cn)
    cols.append(cn)
    vals.append(np.ones(len(cn)))
    return sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(n, n)).tocsr()


def _ordered_rings(quads: np.ndarray, n: int, vertices: np.ndarray, valence: np.ndarray):
    """Counter-clockwise corner rings around ``vertices``.

    Returns ``(ok, ring_face, ring_corner)`` with ``ring_*`` of shape
    ``(len(vertices), max_valence)``; ``ok`` marks vertices whose walk closed after
    exactly ``valence`` steps.
    """
    nf = len(quads)
    a = quads.ravel()
    b = np.roll(quads, -1, axis=1).ravel()
    keys = a * n + b                                   # half-edge a -> b at corner (f, k)
    order = np.argsort(keys)
    skeys = keys[order]
    corner_ids = np.arange(4 * nf)
    prev = np.roll(quads, 1, axis=1).ravel()           # F[f, k-1]
    # next corner CCW around a: the corner of the half-edge a -> prev(a) in the next face
    want = a * n + prev
    pos = np.clip(np.searchsorted(skeys, want), 0, len(skeys) - 1)
    rot = np.where(skeys[pos] == want, order[pos], -1)
    # first corner of each vertex
    first = np.full(n, -1, dtype=np.int64)
    first[a[::-1]] = corner_ids[::-1]
    start = first[vertices]
    kmax = int(valence.max()) if len(valence) else 0
    ring = np.full((len(vertices), kmax), -1, dtype=np.int64)
    cur = start.copy()
    ok = cur >= 0
    for k in range(kmax):
        active = ok & (k < valence)
        ring[active, k] = cur[active]
        nxt = np.where(active, rot[np.maximum(cur, 0)], cur)
        ok &= ~(active & (nxt < 0))
        cur = np.where(active, nxt, cur)
    ok &= cur == start
    return ok, ring // 4, ring % 4


def tangent_matrices(quads, n_vertices: int, sharp_edges=None, corners=None):
    """Sparse limit-tangent matrices ``T1, T2 (n, n)`` (Eq. 1-2 of Orbay & Kara 2011).

    Parameters
    ----------
    quads : (f, 4) int64
        Consistently oriented (counter-clockwise seen from the side the normal
        points to).
    n_vertices : int
    sharp_edges, corners : see :func:`limit_matrix`

    Returns
    -------
    T1, T2 : scipy.sparse.csr_matrix
        Rows are zero except at smooth vertices with a closed one-ring.
    has_tangent : (n,) bool

    Notes
    -----
    ``T1`` uses the cosine weights of Eq. 1-2, ``T2`` the same weights with sines
    (the mask rotated a quarter turn), so ``T1 P x T2 P`` points to the side from
    which the faces run counter-clockwise.
    """
    quads = np.asarray(quads, dtype=np.int64)
    n = int(n_vertices)
    topo = edge_topology(quads, n)
    sharp = sharp_mask(topo, sharp_edges)
    cls = vertex_classes(topo, sharp, corners)
    val = np.bincount(topo.edges.ravel(), minlength=n)
    vs = np.flatnonzero(cls == SMOOTH)
    ok, rf, rc = _ordered_rings(quads, n, vs, val[vs])
    vs, rf, rc = vs[ok], rf[ok], rc[ok]
    nv = val[vs].astype(np.float64)[:, None]           # (m, 1)
    kmax = rf.shape[1] if len(vs) else 0
    k = np.arange(kmax)[None, :].astype(np.float64)   # (1, K)
    valid = k < nv
    e_nb = quads[np.maximum(rf, 0), (rc + 1) % 4]     # (m, K) edge neighbour e_k
    f_nb = quads[np.maximum(rf, 0), (rc + 2) % 4]     # (m, K) diagonal f_k
    cpi = np.cos(np.pi / nv)
    beta_s = (np.sqrt(4.0 + cpi ** 2) - cpi) / 4.0
    ang_e = 2.0 * np.pi * k / nv
    ang_f = (2.0 * np.pi * k + np.pi) / nv
    out = []
    for trig in (np.cos, np.sin):
        we = trig(ang_e)
        wf = beta_s * trig(ang_f)
        rows = np.concatenate([np.broadcast_to(vs[:, None], e_nb.shape)[valid]] * 2)
        cols = np.concatenate([e_nb[valid], f_nb[valid]])
        vals = np.concatenate([we[valid], wf[valid]])
        out.append(sp.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr())
    has = np.zeros(n, bool)
    has[vs] = True
    return out[0], out[1], has


def quad_vertex_normals(vertices: np.ndarray, quads: np.ndarray) -> np.ndarray:
    """Area-weighted unit vertex normals of a quad mesh (each quad as two triangles).

    Returns
    -------
    (n, 3) float64; zero rows for isolated vertices.
    """
    V = np.asarray(vertices, dtype=np.float64)
    q = np.asarray(quads, dtype=np.int64)
    fn = np.cross(V[q[:, 2]] - V[q[:, 0]], V[q[:, 3]] - V[q[:, 1]])   # 2 x vector area
    N = np.zeros_like(V)
    for k in range(4):
        np.add.at(N, q[:, k], fn)
    ln = np.linalg.norm(N, axis=1, keepdims=True)
    return N / np.maximum(ln, DIVISION_GUARD)


def limit_normals(P, quads, T1, T2, has_tangent, L=None) -> np.ndarray:
    """Unit limit normals at the control vertices.

    Uses the tangent masks where available, else the area-weighted normal of the
    mesh of limit positions ``L @ P`` (or of ``P`` when ``L`` is None).

    Returns
    -------
    (n, 3) float64
    """
    P = np.asarray(P, dtype=np.float64)
    N = np.cross(T1 @ P, T2 @ P)
    ln = np.linalg.norm(N, axis=1, keepdims=True)
    N = N / np.maximum(ln, DIVISION_GUARD)
    fallback = ~has_tangent | (ln[:, 0] <= 0)
    if fallback.any():
        Q = P if L is None else L @ P
        N[fallback] = quad_vertex_normals(Q, quads)[fallback]
    return N
