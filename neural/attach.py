"""The extracted zero set faired onto its strokes: a stroke-constrained bi-Laplacian filter.

Not in the paper. The zero set of the integrated f carries the Monte-Carlo noise of the
splats as lumps a few grid cells wide, and sits off rough strokes where the field's
smoothing pulled it in between them. :func:`attach_to_strokes` takes the lumps out and
the surface onto its strokes in two steps, each a linear low-pass with ``L`` the
cotangent Laplacian and ``M`` the Voronoi mass matrix of the extracted mesh ``V``
(libigl):

1. the shape: ``Y`` minimises ``|L Y|^2_{M^-1} + alpha |Y - V|^2_M``, whose response to
   a ripple of wavenumber ``k`` is ``1 / (1 + k^4 / alpha)``; ``alpha = (2 pi / (cutoff
   h))^4`` removes ripples shorter than ``cutoff`` cells ``h`` and keeps the shape at
   larger scales without the shrinking of Laplacian smoothing. Away from the strokes
   that pull (step 2) no data holds the shape, and the lumps there are the widest: per
   vertex, the cutoff grows from its value within ``cutoff / 2 pi`` cells of a pulled
   stroke sample (the filter's own reach) to :data:`SPREAD` times it at ``cutoff / 2``
   cells and beyond (``alpha`` scaled by ``SPREAD^-4t``, ``t`` linear in the distance
   in between);
2. the way onto the strokes: ``X = Y + D`` minimises ``|L D|^2_{M^-1} + alpha_2 |D|^2_M
   + sum_s beta_s |B_s X - t_s|^2``, with ``B_s`` the barycentric row of the closest
   surface point of each stroke sample ``s`` within ``reach`` grid cells of ``V`` and
   ``alpha_2`` the same low-pass at :data:`SPREAD` times the cutoff: the displacement
   that brings the surface onto its strokes is smoother than the shape itself. With a
   ``band`` (below), where the shape is wide, this cutoff grows up to :data:`FLAT`
   times more, per vertex, but never past the circumference ``pi / |H|`` of the
   cylinder of the shape's mean curvature ``H`` (``|M^-1 L Y| / 2``, averaged over the
   filter's reach): across a tube thinner than the cutoff the pulls on either side
   differ, and a displacement smoother than the tube cannot follow them (it pulls the
   tube in). The longer cutoff weakens the pull (``beta`` below) with the area term;
   the band's hold brings back the samples it lets go farther than the band, and
   without a band nothing would (a hybrid fill's exact anchors).

Done in one step (the pull added to the first energy, as this module first did), the
pull of each stroke sample dents the surface within the first low-pass's reach, about
``cutoff / 2 pi`` cells, the size of the ball the roughness measure fits a quadric in:
a seam of small dents along every stroke. Spread over twice the cutoff, the same pull
bends the surface over a wider area and leaves no dent.

Every sample first pulls with ``beta = weight alpha_2 h^2`` (a stroke sample every cell
weighs ``weight`` times a vertex's area term of step 2, ``alpha_2`` taken at the pulled
point) towards itself (``t_s = s``). The
weaker that data term (the longer the cutoff), the weaker the pull: a low-pass long
enough to take out every lump would also let the surface sag off its strokes. So with
a ``band``, the samples the solution leaves farther than ``band`` from the surface are
then held :data:`HELD` times harder, towards the point at ``band`` from them on the
way to the surface (a squared hinge on the distance, by iterated reweighting): the
surface follows a stroke only as closely as the band asks, and the noise of a rough
stroke within it is smoothed away like the lumps.

With ``normals``, a step 0 comes first: the area-weighted vertex normals of ``V`` are
low-passed by the same filter at ``normals`` cells (renormalised), and the vertices move
so that each face turns towards the mean of its vertices' filtered normals, by the
vertex-position update of Sun et al. (2007; a linear-time iteration, each round moving
every vertex towards the planes through its faces' centroids across the filtered
normals). Filtering normals and fitting positions to them is Taubin's (2001) scheme for
removing ripples without shrinking: a round tube or a sphere keeps its normals under
the low-pass (they average to themselves, up to length) wherever the cutoff is shorter
than its circumference, where the position low-pass of step 1 pulls it in by ``1 / (1 +
k^4 / alpha)``. Its rounds take out the lumps longer than step 1's cutoff, which step 1
alone could only reach at the cost of that shrinking. Where the surface turns within
the filter's reach (a tube thinner than the cutoff, the two sides of a thin part, a
fold), the unit normals average to a short vector whose direction is not the
surface's; following it folds triangles over. So each face follows its filtered normal
only as far as the filtered normals of its corners stay long (:data:`TRUSTED`), and a
vertex none of whose faces is trusted stays where it is.

References
----------
Taubin, "Linear anisotropic mesh filtering", IBM Research Report RC22213, 2001.
Sun, Rosin, Martin, Langbein, "Fast and effective feature-preserving mesh denoising",
IEEE TVCG 13(5), 2007 (the vertex-position update).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu
from scipy.spatial import cKDTree

from curvenet.core.geometry import face_normals_areas
from curvenet.core.tolerances import DIVISION_GUARD

__all__ = ["attach_to_strokes", "fill_order", "normal_faired", "FLAT", "HELD", "NORMAL_ROUNDS",
           "SPREAD", "TRUSTED"]

#: How much harder a stroke sample outside the band pulls than the others.
HELD = 1000.0
#: The displacement onto the strokes is low-passed at this many times the shape's cutoff.
SPREAD = 2.0
#: Where the surface is flat enough, the displacement's cutoff grows up to this many times
#: its value (see step 2 of the module notes).
FLAT = 2.0
#: Solves after the first, each holding the samples still outside the band.
_HOLD_ROUNDS = 2
#: Vertex-update rounds of step 0 per cell of its cutoff: a round moves a vertex by what
#: its one ring says, so a ripple ``normals`` cells long needs rounds in proportion.
NORMAL_ROUNDS = 1.5
#: Step 0 trusts a face's filtered normal not at all below the first length of its
#: corners' filtered unit normals, in full above the second, linearly in between.
TRUSTED = (0.7, 0.9)


def _barycentric(tri: np.ndarray, p: np.ndarray) -> np.ndarray:
    """(k, 3) barycentric coordinates of points ``p`` (k, 3) in triangles ``tri`` (k, 3, 3)."""
    e0, e1, d = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0], p - tri[:, 0]
    d00, d01, d11 = (e0 * e0).sum(1), (e0 * e1).sum(1), (e1 * e1).sum(1)
    d20, d21 = (d * e0).sum(1), (d * e1).sum(1)
    den = np.maximum(d00 * d11 - d01 * d01, np.finfo(np.float64).tiny)
    b1 = (d11 * d20 - d01 * d21) / den
    b2 = (d00 * d21 - d01 * d20) / den
    b = np.clip(np.stack([1.0 - b1 - b2, b1, b2], axis=1), 0.0, 1.0)
    total = b.sum(axis=1, keepdims=True)
    # points in their triangles: in [0, 1] up to rounding; a degenerate triangle's 1/3 each
    return np.where(total > 0, b / np.where(total > 0, total, 1.0), 1.0 / 3.0)


def fill_order(F, n: int) -> np.ndarray:
    """A fill-reducing order (n,) int64 of the bi-Laplacians of the faces ``F`` (m, 3).

    METIS's nested dissection (pymetis) of the graph of vertices within two edges of
    each other, the pattern of ``L^T M^-1 L`` and of every matrix the fairing solves:
    computed once, it serves all of one fairing's factorisations, each of which then
    leaves less fill and skips SuperLU's own minimum-degree ordering. A nested
    dissection of the one-ring graph alone is no order for them (its separators leave
    the two-ring neighbours on either side coupled: many times the fill).
    """
    import pymetis
    ring = _one_ring(F, n)
    two = (ring @ ring + ring).tocsr()
    two.setdiag(0)
    two.eliminate_zeros()
    if not two.nnz:
        return np.arange(n)
    adj = pymetis.CSRAdjacency(two.indptr.astype(np.int64), two.indices.astype(np.int64))
    return np.asarray(pymetis.nested_dissection(adjacency=adj)[0], np.int64)


def _one_ring(F, n: int):
    """The vertex adjacency (n, n) sparse float64 of the faces ``F`` (m, 3): 1 between the
    two ends of each edge, 0 elsewhere (the diagonal too)."""
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    ring = sp.csr_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
    return ((ring + ring.T) > 0).astype(np.float64)


def _factor(A, order: np.ndarray):
    """SuperLU's factors of ``A`` (n, n) sparse symmetric positive definite, its rows and
    columns taken in the fill ``order`` (n,)."""
    A = sp.csr_matrix(A)
    # the order applied to both sides and no pivoting: Cholesky's fill
    return splu(A[order][:, order].tocsc(), permc_spec="NATURAL", diag_pivot_thresh=0.0,
                options={"SymmetricMode": True})


def _solve(A, rhs, order: np.ndarray) -> np.ndarray:
    """``A^-1 rhs`` for a sparse symmetric positive definite ``A`` in the fill ``order``."""
    x = np.empty(np.shape(rhs), np.float64)
    x[order] = _factor(A, order).solve(np.asarray(rhs, np.float64)[order])
    return x


def _operators(V, F):
    """The cotangent Laplacian ``L`` (n, n) sparse, the bi-Laplacian ``L^T M^-1 L`` (n, n)
    sparse and the Voronoi areas ``m`` (n,) of ``(V, F)``."""
    import igl
    n = len(V)
    L = sp.csr_matrix(igl.cotmatrix(V, F))
    L.resize((n, n))              # libigl sizes both by the last vertex that faces use
    m = np.zeros(n)
    md = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
    m[:len(md)] = md
    m = np.maximum(m, 1e-12 * m.max())
    return L, L.T @ sp.diags(1.0 / m) @ L, m


def _mean_curvature(L, Y, m: np.ndarray, F, reach: float) -> np.ndarray:
    """|H| (n,) float64 of the smooth surface ``Y`` (n, 3): half the length of ``M^-1 L Y``
    (``L`` and the areas ``m`` of a mesh with ``Y``'s connectivity and nearly its
    shape), averaged over ``reach`` edges (``reach^2`` rounds of one-ring means, a
    diffusion of that radius)."""
    n = len(Y)
    H = 0.5 * np.linalg.norm(L @ Y, axis=1) / m
    ring = _one_ring(F, n) + sp.identity(n, format="csr")
    deg = np.asarray(ring.sum(axis=1)).ravel()
    for _ in range(int(np.ceil(reach * reach))):
        H = (ring @ H) / deg
    return H


def _unit_rows(x: np.ndarray) -> np.ndarray:
    return x / np.maximum(np.linalg.norm(x, axis=1), DIVISION_GUARD)[:, None]


def normal_faired(V, F, h: float, cutoff: float, order=None) -> np.ndarray:
    """The vertices of ``(V, F)`` moved to follow its normals low-passed at ``cutoff`` cells.

    Step 0 of :func:`attach_to_strokes` (see the module notes). ``V`` (n, 3) float64,
    ``F`` (m, 3) int64 without degenerate triangles, ``h`` the cell size, ``order`` the
    :func:`fill_order` of ``F`` (computed when not given); returns (n, 3) float64. A
    vertex of no face keeps its place.
    """
    n = len(V)
    if order is None:
        order = fill_order(F, n)
    bend, m = _operators(V, F)[1:]
    alpha = (2.0 * np.pi / (cutoff * h)) ** 4 * m
    fn, area = face_normals_areas(V, F)
    inc = sp.csr_matrix((np.ones(3 * len(F)), (F.ravel(), np.repeat(np.arange(len(F)), 3))),
                        shape=(n, len(F)))                       # vertex-face incidence
    centroid = inc.T / 3.0                                       # (m, n): corners' mean
    N = _solve(bend + sp.diags(alpha), alpha[:, None] * _unit_rows(inc @ (fn * area[:, None])),
               order)
    nf = _unit_rows(_unit_rows(N)[F].sum(axis=1))        # (m, 3) each face's target normal
    # unit normals that the filter shortens turn within its reach (a fold, a thin part):
    # a face follows its target in full only where its corners' stay long
    short = np.linalg.norm(N, axis=1)[F].min(axis=1)
    trust = np.clip((short - TRUSTED[0]) / (TRUSTED[1] - TRUSTED[0]), 0.0, 1.0)
    inc = inc @ sp.diags(trust)
    # Sun et al.'s update: x_i += sum_f w_f n_f n_f^T (c_f - x_i) / sum_f w_f, with c_f the
    # mean of f's corners and w_f its trust
    outer = (inc @ (nf[:, :, None] * nf[:, None, :]).reshape(-1, 9)).reshape(n, 3, 3)
    deg = np.maximum(np.asarray(inc.sum(axis=1)).ravel(), 1e-12)[:, None]
    X = np.array(V, np.float64)
    for _ in range(int(round(NORMAL_ROUNDS * cutoff))):
        c = centroid @ X
        X += (inc @ (nf * (nf * c).sum(axis=1, keepdims=True))
              - np.einsum("vij,vj->vi", outer, X)) / deg
    return X


def attach_to_strokes(V, F, strokes, h: float, *, cutoff: float, weight: float,
                      band: float = 0.0, reach: float = 3.0, points=None,
                      normals: float = 0.0) -> tuple[np.ndarray, dict]:
    """Fair the mesh ``(V, F)`` and pull it onto the stroke samples near it.

    Parameters
    ----------
    V : (n, 3) float64
    F : (m, 3) int64
    strokes : list of (k_i, 3) float64
        Polylines in the mesh's coordinates.
    h : float
        Grid cell size of the extraction (the unit of ``cutoff`` and ``reach``).
    cutoff : float
        Ripples shorter than this many cells are removed (> 0).
    weight : float
        Pull of the stroke samples (>= 0; 0 = the low-pass alone).
    band : float
        Distance (model units) within which every pulled sample is held; 0 = no
        holding, the pull ``weight`` alone. Ignored when ``weight`` is 0.
    reach : float
        Stroke samples farther than this many cells from ``V`` are left out.
    points : (p, 3) float64, optional
        More samples, pulled (and held) like the strokes' (a hybrid fill's anchors:
        points of the patches it meets).
    normals : float
        Cutoff (cells) of step 0, the normal low-pass the vertices follow before the
        rest; 0 = no step 0.

    Returns
    -------
    X : (n, 3) float64
        The new vertex positions (``F`` unchanged).
    report : dict
        ``samples`` (stroke samples drawn, one per cell of stroke length, and
        ``points``), ``pulled`` (those within reach) and ``held`` (those held to the
        band).
    """
    import igl

    from curvenet.core.distance import drop_degenerate
    from curvenet.core.geometry import densify_polylines
    V = np.asarray(V, np.float64)
    # marching cubes leaves a few zero-area triangles, whose cotangents are not finite:
    # the energy is taken over the others (a vertex of none keeps its place)
    F = drop_degenerate(V, np.asarray(F, np.int64))[0]
    if not len(F):
        return V.copy(), {"samples": 0, "pulled": 0, "held": 0}
    order = fill_order(F, len(V))     # every solve below has F's two-ring pattern
    if normals > 0:                                   # step 0: follow the faired normals
        V = normal_faired(V, F, h, normals, order)
        F = drop_degenerate(V, F)[0]               # a triangle the update flattened
        if not len(F):
            return V, {"samples": 0, "pulled": 0, "held": 0}
    L, bend, m = _operators(V, F)
    S = np.concatenate(([densify_polylines(strokes, h)[0]] if len(strokes) else [])
                       + ([] if points is None else [np.asarray(points, np.float64)]))
    near = np.sqrt(np.maximum(igl.point_mesh_squared_distance(S, V, F)[0], 0.0)) < reach * h
    S = S[near]
    alpha = (2.0 * np.pi / (cutoff * h)) ** 4 * m
    if weight > 0 and len(S):     # the cutoff grows to SPREAD times itself away from them
        d = cKDTree(S).query(V)[0] / h
        r0 = cutoff / (2.0 * np.pi)
        alpha *= SPREAD ** (-4.0 * np.clip((d - r0) / (cutoff / 2.0 - r0), 0.0, 1.0))
    Y = _solve(bend + sp.diags(alpha), alpha[:, None] * V, order)          # step 1: the shape
    if weight == 0 or not len(S):
        return Y, {"samples": int(len(near)), "pulled": int(len(S)), "held": 0}
    d2, fi, closest = igl.point_mesh_squared_distance(S, Y, F)
    dist = np.sqrt(np.maximum(d2, 0.0))
    # step 2, onto the strokes: the displacement's cutoff, SPREAD times the shape's, grows
    # (with a band) up to FLAT times more but stays within the circumference
    # pi / (|H| h) cells of the cylinder of the shape's mean curvature, across which the
    # pulls may differ
    c2 = np.full(len(V), SPREAD * cutoff)
    if band > 0 and FLAT > 1:
        H = _mean_curvature(L, Y, m, F, cutoff / (2.0 * np.pi))
        c2 = np.clip(np.pi / (h * np.maximum(H, 1e-300)), c2, FLAT * c2)
    alpha2 = (2.0 * np.pi / (c2 * h)) ** 4                                # (n,)
    K = bend + sp.diags(alpha2 * m)
    base = K @ Y                                   # |L (X - Y)|^2 + alpha_2 |X - Y|^2
    X, held = Y, np.zeros(len(S), bool)
    for r in range(1 + (_HOLD_ROUNDS if band > 0 else 0)):
        if r:   # the samples the last solve left outside the band join the held ones
            d2, fi, closest = igl.point_mesh_squared_distance(S, X, F)
            dist = np.sqrt(np.maximum(d2, 0.0))
            out = dist > band
            if not out[~held].any():
                break
            held |= out
        # each sample's closest point on the surface as it is now, as barycentric rows
        B = sp.csr_matrix((_barycentric(X[F[fi]], closest).ravel(),
                           (np.repeat(np.arange(len(S)), 3), F[fi].ravel())),
                          shape=(len(S), len(V)))
        # each held sample pulls to the point within `band` of it on the way to the surface
        frac = np.where(held, np.minimum(dist, band) / np.maximum(dist, 1e-300), 0.0)
        target = S + frac[:, None] * (closest - S)
        beta = weight * h * h * (B @ alpha2)          # against the area term where it pulls
        w = np.where(held, HELD * beta, beta)
        X = _solve(K + B.T @ sp.diags(w) @ B, base + B.T @ (w[:, None] * target), order)
    return X, {"samples": int(len(near)), "pulled": int(len(S)), "held": int(held.sum())}
