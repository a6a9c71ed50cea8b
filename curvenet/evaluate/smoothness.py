"""Smoothness of a surface without a reference: the roughness left by a local quadric.

A smooth surface is, within a small ball, the graph of a quadratic height function over
its tangent plane up to third-order terms; lumps, ripples and Monte-Carlo noise narrower
than the ball are not. :func:`roughness` samples the surface densely, and around each of
a set of centres fits a quadric height ``h = a + b u + c v + d u^2 + e u v + f v^2`` to
the samples within ``radius`` (in the frame of their principal axes) and reports the RMS
height residual divided by the radius. Facets of a fine mesh of a smooth surface leave
residuals of the order of the chord error (edge^2 x curvature), far below a lump's, so
the figure depends little on the triangulation (marching cubes or subdivision), and not
at all on scale. A crease or a rim inside the ball raises it too, on the few centres
near one: the median and the 90th percentile over the centres are reported.
"""

from __future__ import annotations

import numpy as np

from ..core.distance import drop_degenerate, load_mesh_arrays
from ..core.errors import InvalidParameterError
from ..core.geometry import bbox_diagonal, sample_surface

__all__ = ["roughness", "ROUGHNESS_RADIUS"]

#: Default ball radius, as a fraction of the mesh's bounding-box diagonal.
ROUGHNESS_RADIUS = 0.02
#: Fewest samples in a ball for a centre to count (a quadric has six coefficients).
_MIN_NEIGHBOURS = 24
#: Samples drawn per ball on average (the density of the cloud follows from it).
_PER_BALL = 120


def roughness(mesh, *, radius: float = ROUGHNESS_RADIUS, n_centres: int = 4000,
              seed: int = 0) -> dict:
    """Local-quadric roughness of a triangle mesh.

    Parameters
    ----------
    mesh : trimesh.Trimesh, (V, F) pair or path
        ``V`` (n, 3) float64, ``F`` (m, 3) int64.
    radius : float
        Ball radius as a fraction of the bounding-box diagonal.
    n_centres : int
        Ball centres, drawn area-uniformly on the surface.
    seed : int

    Returns
    -------
    dict
        ``median`` and ``p90``: the RMS residual of the quadric fit divided by the
        ball's radius, over the centres (dimensionless; 0 for any quadric surface);
        ``centres`` (the number of centres with enough samples), ``values`` ((c,)
        float64, each such centre's figure) and ``points`` ((c, 3) float64, those
        centres), ``radius`` (model units).

    Raises
    ------
    InvalidParameterError
        ``radius`` outside (0, 0.5] or ``n_centres`` < 1.
    """
    if not 0.0 < radius <= 0.5:
        raise InvalidParameterError(f"radius must lie in (0, 0.5], got {radius!r}")
    if int(n_centres) != n_centres or n_centres < 1:
        raise InvalidParameterError(f"n_centres must be a positive integer, got {n_centres!r}")
    from scipy.spatial import cKDTree
    V, F = load_mesh_arrays(mesh)
    F, _, areas = drop_degenerate(V, F)
    diag = bbox_diagonal(V)
    r = radius * diag
    area = float(areas.sum())
    # a cloud dense enough for about _PER_BALL samples in a flat ball of radius r
    n_points = int(min(2_000_000, max(20_000, _PER_BALL * area / (np.pi * r * r))))
    rng = np.random.default_rng(seed)
    pts = sample_surface(V, F, n_points, rng)[0]
    centres = sample_surface(V, F, int(n_centres), rng)[0]
    k = 3 * _PER_BALL
    d, idx = cKDTree(pts).query(centres, k=min(k, len(pts)))
    w = (d <= r).astype(np.float64)                           # (c, k) ball membership
    keep = w.sum(axis=1) >= _MIN_NEIGHBOURS
    w, idx = w[keep], idx[keep]
    if not len(w):
        return {"median": float("nan"), "p90": float("nan"), "centres": 0,
                "values": np.zeros(0), "points": np.zeros((0, 3)), "radius": r}
    q = pts[idx] - centres[keep][:, None, :]                  # (c, k, 3)
    cnt = w.sum(axis=1)
    mean = np.einsum("ck,ckd->cd", w, q) / cnt[:, None]
    q = q - mean[:, None, :]
    cov = np.einsum("ck,ckd,cke->cde", w, q, q) / cnt[:, None, None]
    axes = np.linalg.eigh(cov)[1]                            # ascending: normal first
    loc = np.einsum("ckd,cde->cke", q, axes) / r             # (u along axis 2, v, h)
    h, u, v = loc[..., 0], loc[..., 2], loc[..., 1]
    A = np.stack([np.ones_like(u), u, v, u * u, u * v, v * v], axis=-1)   # (c, k, 6)
    AtA = np.einsum("ck,cki,ckj->cij", w, A, A) + 1e-12 * np.eye(6)
    Atb = np.einsum("ck,cki,ck->ci", w, A, h)
    coef = np.linalg.solve(AtA, Atb[..., None])[..., 0]
    res = h - np.einsum("cki,ci->ck", A, coef)
    rms = np.sqrt(np.einsum("ck,ck->c", w, res * res) / cnt)
    return {"median": float(np.median(rms)), "p90": float(np.percentile(rms, 90)),
            "centres": int(len(rms)), "values": rms, "points": centres[keep], "radius": r}
