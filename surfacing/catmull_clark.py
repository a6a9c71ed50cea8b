"""Catmull-Clark subdivision of quad meshes as sparse matrices, with boundary and crease rules.

One step maps the old vertices ``V (n, 3)`` to the new ones ``S @ V`` with a sparse
``S (n + e + f, n)``. New vertex order: the ``n`` old vertices (vertex points), then
one edge point per edge (in :func:`edge_topology` order), then one face point per face.
Each quad ``(a, b, c, d)`` with edge points ``ab, bc, cd, da`` and face point ``F``
becomes four quads, in this order::

    d ---- cd ---- c          (a, ab, F, da)
    |      |       |          (b, bc, F, ab)
    da --- F ---- bc          (c, cd, F, bc)
    |      |       |          (d, da, F, cd)
    a ---- ab ---- b

so orientation is kept. Rules (Catmull & Clark 1978; DeRose et al. 1998 for sharp
creases):

* face point: average of the face's vertices;
* smooth edge (two faces, not sharp): ``(v0 + v1 + F0 + F1) / 4``;
  sharp edge (marked, boundary, or three or more faces): midpoint;
* smooth vertex of valence ``n``: ``(Q + 2 R + (n - 3) V) / n`` (``Q`` mean face
  point, ``R`` mean edge midpoint); crease vertex (exactly two sharp edges):
  ``(a + 6 V + b) / 8``; corner (three or more sharp edges, or marked): fixed.

A vertex with a single sharp edge (a dart) uses the smooth rule. Open boundaries and
non-manifold edges are sharp, so each manifold piece is subdivided with the shared
curve as its boundary (cubic B-spline rule along the curve).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

__all__ = ["EdgeTopology", "edge_topology", "edge_index", "sharp_mask", "vertex_classes",
           "crease_neighbours", "SubdivisionStep", "subdivision_step", "subdivide",
           "euler_characteristic"]

SMOOTH, CREASE, CORNER = 0, 1, 2


@dataclass(frozen=True)
class EdgeTopology:
    """Undirected edges of a quad mesh.

    Attributes
    ----------
    edges : (e, 2) int64
        Sorted vertex pairs ``(lo, hi)``, sorted by key ``lo * n + hi``.
    face_edges : (f, 4) int64
        ``face_edges[f, k]`` is the edge from corner ``k`` to corner ``k + 1``.
    face_count : (e,) int64
        Number of faces on each edge.
    n_vertices : int
    """

    edges: np.ndarray
    face_edges: np.ndarray
    face_count: np.ndarray
    n_vertices: int

    @cached_property
    def keys(self) -> np.ndarray:
        return self.edges[:, 0] * self.n_vertices + self.edges[:, 1]


def edge_topology(quads: np.ndarray, n_vertices: int) -> EdgeTopology:
    """Edge list, face-to-edge map and per-edge face count of a quad mesh.

    Parameters
    ----------
    quads : (f, 4) int64
    n_vertices : int
    """
    quads = np.asarray(quads, dtype=np.int64)
    a = quads.ravel()
    b = np.roll(quads, -1, axis=1).ravel()
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    keys = lo * n_vertices + hi
    uniq, inv = np.unique(keys, return_inverse=True)
    edges = np.stack([uniq // n_vertices, uniq % n_vertices], axis=1)
    count = np.bincount(inv, minlength=len(uniq)).astype(np.int64)
    return EdgeTopology(edges, inv.reshape(-1, 4).astype(np.int64), count, int(n_vertices))


def edge_index(topo: EdgeTopology, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Index of the undirected edge ``(a[i], b[i])``, or -1 where there is none.

    Parameters
    ----------
    topo : EdgeTopology
    a, b : (k,) int64

    Returns
    -------
    (k,) int64
    """
    a, b = np.asarray(a, dtype=np.int64), np.asarray(b, dtype=np.int64)
    keys = np.minimum(a, b) * topo.n_vertices + np.maximum(a, b)
    tk = topo.keys
    pos = np.searchsorted(tk, keys)
    pos = np.clip(pos, 0, max(len(tk) - 1, 0))
    ok = (len(tk) > 0) & (tk[pos] == keys) if len(tk) else np.zeros(len(keys), bool)
    return np.where(ok, pos, -1)


def sharp_mask(topo: EdgeTopology, sharp_edges) -> np.ndarray:
    """Sharp-edge mask: boundary and non-manifold edges, plus the marked ones.

    Parameters
    ----------
    topo : EdgeTopology
    sharp_edges : (k, 2) int array_like or None
        Vertex pairs of edges marked sharp; pairs that are not edges are ignored.

    Returns
    -------
    (e,) bool
        Indexed like ``topo.edges``.
    """
    sharp = topo.face_count != 2
    if sharp_edges is not None and len(sharp_edges):
        se = np.asarray(sharp_edges, dtype=np.int64).reshape(-1, 2)
        idx = edge_index(topo, se[:, 0], se[:, 1])
        sharp[idx[idx >= 0]] = True
    return sharp


def vertex_classes(topo: EdgeTopology, sharp: np.ndarray, corners=None) -> np.ndarray:
    """Classify vertices as SMOOTH (0), CREASE (1) or CORNER (2).

    Parameters
    ----------
    topo : EdgeTopology
    sharp : (e,) bool
        Sharp-edge mask (marked, boundary or non-manifold).
    corners : (n,) bool, optional
        Vertices forced to be corners.

    Notes
    -----
    Corner: three or more sharp edges, marked, or not on any face. Crease: exactly two
    sharp edges. Smooth: otherwise (a dart, one sharp edge, is smooth).
    """
    n = topo.n_vertices
    se = topo.edges[sharp]
    n_sharp = np.bincount(se.ravel(), minlength=n)
    used = np.zeros(n, bool)
    used[topo.edges.ravel()] = True
    cls = np.full(n, SMOOTH, dtype=np.int64)
    cls[n_sharp == 2] = CREASE
    corner = (n_sharp >= 3) | ~used
    if corners is not None:
        corner |= np.asarray(corners, dtype=bool)
    cls[corner] = CORNER
    return cls


def crease_neighbours(topo: EdgeTopology, sharp: np.ndarray, cls: np.ndarray):
    """For each CREASE vertex, its two neighbours along sharp edges.

    Parameters
    ----------
    topo : EdgeTopology
    sharp : (e,) bool
        Sharp-edge mask (:func:`sharp_mask`).
    cls : (n,) int
        Vertex classes (:func:`vertex_classes`).

    Returns
    -------
    verts, nb0, nb1 : (c,) int64
        The crease vertices in increasing order and their two sharp neighbours.
    """
    se = topo.edges[sharp]
    ends = np.concatenate([se, se[:, ::-1]])          # (2s, 2): (vertex, neighbour)
    ends = ends[cls[ends[:, 0]] == CREASE]
    order = np.argsort(ends[:, 0], kind="stable")
    ends = ends[order]                                # each crease vertex appears twice
    return ends[0::2, 0], ends[0::2, 1], ends[1::2, 1]


@dataclass(frozen=True)
class SubdivisionStep:
    """One Catmull-Clark step.

    Attributes
    ----------
    S : (n_new, n_old) scipy.sparse.csr_matrix
        New vertices = ``S @ old``.
    quads : (4 f, 4) int64
        New faces (see the module docstring for the order).
    sharp_edges : (2 s, 2) int64
        The halves of the old sharp edges.
    corners : (n_new,) bool
        Corner flags carried over (old vertices keep theirs).
    face_parent : (4 f,) int64
        Old face of each new face.
    topo : EdgeTopology
        Edges of the *old* mesh (edge point ``k`` is new vertex ``n_old + k``).
    classes : (n_old,) int64
        Vertex classes of the old mesh.
    """

    S: sp.csr_matrix
    quads: np.ndarray
    sharp_edges: np.ndarray
    corners: np.ndarray
    face_parent: np.ndarray
    topo: EdgeTopology
    classes: np.ndarray


def subdivision_step(quads, n_vertices: int, sharp_edges=None, corners=None) -> SubdivisionStep:
    """Sparse subdivision matrix and refined connectivity for one Catmull-Clark step.

    Parameters
    ----------
    quads : (f, 4) int64
        Consistently oriented quads.
    n_vertices : int
    sharp_edges : (s, 2) int64, optional
        Crease edges (vertex pairs, any order). Boundary and non-manifold edges are
        sharp anyway.
    corners : (n,) bool, optional
        Vertices kept fixed (e.g. where creases meet at an angle, open-boundary corners).

    Returns
    -------
    SubdivisionStep

    Examples
    --------
    >>> import numpy as np
    >>> quads = np.array([[0, 1, 2, 3]])
    >>> st = subdivision_step(quads, 4)
    >>> st.S.shape, st.quads.shape
    ((9, 4), (4, 4))

    References
    ----------
    Catmull & Clark 1978; DeRose, Kass & Truong 1998 (sharp creases); Orbay & Kara
    2011, Sec. 4.3.1.
    """
    quads = np.asarray(quads, dtype=np.int64)
    n = int(n_vertices)
    topo = edge_topology(quads, n)
    nf, ne = len(quads), len(topo.edges)
    sharp = sharp_mask(topo, sharp_edges)
    cls = vertex_classes(topo, sharp, corners)
    rows, cols, vals = [], [], []

    # face points
    fp_row = n + ne + np.arange(nf)
    rows.append(np.repeat(fp_row, 4))
    cols.append(quads.ravel())
    vals.append(np.full(4 * nf, 0.25))

    # edge points: endpoints
    e_row = n + np.arange(ne)
    w_end = np.where(sharp, 0.5, 0.25)
    rows += [e_row, e_row]
    cols += [topo.edges[:, 0], topo.edges[:, 1]]
    vals += [w_end, w_end]
    # smooth edges: + (F0 + F1) / 4, each face point a quarter of its four vertices
    fe = topo.face_edges.ravel()                       # (4f,) edge of (face, slot)
    face_of = np.repeat(np.arange(nf), 4)
    m = ~sharp[fe]
    rows.append(np.repeat(n + fe[m], 4))
    cols.append(quads[face_of[m]].ravel())
    vals.append(np.full(4 * m.sum(), 1.0 / 16.0))

    # vertex points
    val = np.bincount(topo.edges.ravel(), minlength=n).astype(np.float64)   # edge valence
    nfv = np.bincount(quads.ravel(), minlength=n).astype(np.float64)        # face valence
    smooth = cls == SMOOTH
    vs = np.flatnonzero(smooth)
    nv_ = val[vs]
    rows.append(vs)
    cols.append(vs)
    vals.append((nv_ - 3.0) / nv_)
    # 2R / n: each incident edge (v, w) gives 1/n^2 to v and to w
    for side in (0, 1):
        v = topo.edges[:, side]
        w = topo.edges[:, 1 - side]
        mm = smooth[v]
        inv2 = 1.0 / val[v[mm]] ** 2
        rows += [v[mm], v[mm]]
        cols += [v[mm], w[mm]]
        vals += [inv2, inv2]
    # Q / n: each incident face gives 1 / (4 n n_f) to each of its four vertices
    corner_v = quads.ravel()                           # vertex at (face, corner)
    mm = smooth[corner_v]
    vv = corner_v[mm]
    wq = 1.0 / (4.0 * val[vv] * nfv[vv])
    rows.append(np.repeat(vv, 4))
    cols.append(quads[face_of[mm]].ravel())
    vals.append(np.repeat(wq, 4))
    # crease vertices
    cv, nb0, nb1 = crease_neighbours(topo, sharp, cls)
    rows += [cv, cv, cv]
    cols += [cv, nb0, nb1]
    vals += [np.full(len(cv), 0.75), np.full(len(cv), 0.125), np.full(len(cv), 0.125)]
    # corners
    cn = np.flatnonzero(cls == CORNER)
    rows.append(cn)
    cols.append(cn)
    vals.append(np.ones(len(cn)))

    n_new = n + ne + nf
    S = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(n_new, n)).tocsr()

    # refined connectivity
    F = n + ne + np.arange(nf)
    E = n + topo.face_edges                            # (f, 4): edge k from corner k to k+1
    new = np.empty((nf, 4, 4), dtype=np.int64)
    for k in range(4):
        new[:, k] = np.stack([quads[:, k], E[:, k], F, E[:, (k + 3) % 4]], axis=1)
    se = topo.edges[sharp]
    sidx = n + np.flatnonzero(sharp)
    new_sharp = np.concatenate([np.stack([se[:, 0], sidx], 1), np.stack([sidx, se[:, 1]], 1)])
    new_corners = np.zeros(n_new, bool)
    new_corners[:n] = cls == CORNER
    return SubdivisionStep(S, new.reshape(-1, 4), new_sharp, new_corners,
                           np.repeat(np.arange(nf), 4), topo, cls)


def subdivide(vertices, quads, levels: int = 1, sharp_edges=None, corners=None):
    """Apply ``levels`` Catmull-Clark steps (one-shot helper).

    Parameters
    ----------
    vertices : (n, 3) float64
    quads : (f, 4) int64
    levels : int, >= 0
    sharp_edges, corners : see :func:`subdivision_step`

    Returns
    -------
    vertices : (n_k, 3) float64
    quads : (4^k f, 4) int64
    sharp_edges : (s_k, 2) int64
    corners : (n_k,) bool
    """
    if levels < 0:
        raise ValueError(f"levels: expected >= 0, got {levels}")
    V = np.asarray(vertices, dtype=np.float64)
    Q = np.asarray(quads, dtype=np.int64)
    se = np.zeros((0, 2), np.int64) if sharp_edges is None else np.asarray(sharp_edges)
    cr = np.zeros(len(V), bool) if corners is None else np.asarray(corners, bool)
    for _ in range(levels):
        st = subdivision_step(Q, len(V), se, cr)
        V, Q, se, cr = st.S @ V, st.quads, st.sharp_edges, st.corners
    return V, Q, se, cr


def euler_characteristic(quads, n_vertices: int | None = None) -> int:
    """``V - E + F`` of a quad mesh (counting only vertices used by faces)."""
    quads = np.asarray(quads, dtype=np.int64)
    used = np.unique(quads)
    n = int(used.max()) + 1 if n_vertices is None else int(n_vertices)
    topo = edge_topology(quads, n)
    return int(len(used) - len(topo.edges) + len(quads))
