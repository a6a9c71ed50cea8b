"""The extracted zero set faired onto its strokes: a stroke-constrained bi-Laplacian filter.

Not in the paper. The zero set of the integrated f carries the Monte-Carlo noise of the
splats as lumps a few grid cells wide, and sits off rough strokes where the field's
smoothing pulled it in between them. :func:`attach_to_strokes` moves the mesh vertices
``X`` to the minimiser of

    ``|L X|^2_{M^-1} + alpha |X - V|^2_M + beta sum_s |B_s X - s|^2``

with ``L`` the cotangent Laplacian and ``M`` the Voronoi mass matrix of the extracted
mesh ``V`` (libigl), ``B_s`` the barycentric row of the closest surface point of each
stroke sample ``s`` within ``reach`` grid cells: a linear low-pass of the surface (its
response to a ripple of wavenumber ``k`` is ``1 / (1 + k^4 / alpha)``, so
``alpha = (2 pi / (cutoff h))^4`` removes ripples shorter than ``cutoff`` cells ``h``
and keeps the shape at larger scales without the shrinking of Laplacian smoothing)
that also pulls the surface onto the strokes near it. ``beta = weight alpha h^2``: a
stroke sample every cell weighs ``weight`` times a vertex's area term.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

__all__ = ["attach_to_strokes"]


def _barycentric(tri: np.ndarray, p: np.ndarray) -> np.ndarray:
    """(k, 3) barycentric coordinates of points ``p`` (k, 3) in triangles ``tri`` (k, 3, 3)."""
    e0, e1, d = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0], p - tri[:, 0]
    d00, d01, d11 = (e0 * e0).sum(1), (e0 * e1).sum(1), (e1 * e1).sum(1)
    d20, d21 = (d * e0).sum(1), (d * e1).sum(1)
    den = np.maximum(d00 * d11 - d01 * d01, np.finfo(np.float64).tiny)
    b1 = (d11 * d20 - d01 * d21) / den
    b2 = (d00 * d21 - d01 * d20) / den
    return np.stack([1.0 - b1 - b2, b1, b2], axis=1)


def attach_to_strokes(V, F, strokes, h: float, *, cutoff: float, weight: float,
                      reach: float = 3.0) -> tuple[np.ndarray, dict]:
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
    reach : float
        Stroke samples farther than this many cells from the surface are left out.

    Returns
    -------
    X : (n, 3) float64
        The new vertex positions (``F`` unchanged).
    report : dict
        ``samples`` (stroke samples drawn, one per cell of stroke length) and ``pulled``
        (those within reach).
    """
    import igl

    from curvenet.core.geometry import densify_polyline
    V = np.asarray(V, np.float64)
    F = np.asarray(F, np.int64)
    L = igl.cotmatrix(V, F)
    m = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
    m = np.maximum(m, 1e-12 * m.max())
    alpha = (2.0 * np.pi / (cutoff * h)) ** 4
    S = np.concatenate([densify_polyline(np.asarray(s, np.float64), h) for s in strokes])
    d2, fi, closest = igl.point_mesh_squared_distance(S, V, F)
    near = np.sqrt(np.maximum(d2, 0.0)) < reach * h
    S, fi = S[near], fi[near]
    bc = _barycentric(V[F[fi]], closest[near])
    B = sp.csr_matrix((bc.ravel(), (np.repeat(np.arange(len(S)), 3), F[fi].ravel())),
                      shape=(len(S), len(V)))
    beta = weight * alpha * h * h
    A = (L.T @ sp.diags(1.0 / m) @ L + alpha * sp.diags(m) + beta * (B.T @ B)).tocsc()
    rhs = alpha * (m[:, None] * V) + beta * (B.T @ S)
    # symmetric positive definite: a symmetric ordering and no pivoting (Cholesky's fill)
    lu = splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
              options={"SymmetricMode": True})
    X = np.asarray(lu.solve(rhs), np.float64).reshape(V.shape)
    return X, {"samples": int(len(near)), "pulled": int(near.sum())}
