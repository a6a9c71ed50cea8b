"""Soap-film patch surfaces, the baseline of Abbasinejad, Joshi & Amenta 2011 (Sec. 7).

Each loop's boundary is mapped to the unit circle by arc length, the disk is
triangulated with interior points (a hexagonal lattice at the boundary spacing,
Delaunay), the boundary points are mapped back to their 3D positions and the
interior points solve the discrete Laplace equation with the cotangent weights of
the 2D triangulation ("a linearized Laplacian problem over the triangulated 2D
domain": a linear approximation of a soap film). Patches are independent; curve
samples are shared, so adjacent patches meet along the curves.

Notes
-----
The paper uses Triangle for the disk; we use a lattice plus ``scipy.spatial.Delaunay``
(every boundary point lies on the circle, so each is a hull vertex and the
triangulation's border is exactly the boundary polygon).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.spatial import Delaunay

from curvenet.core.geometry import arc_length_params, resample_polyline
from curvenet.core.tolerances import COINCIDENT_REL, DEGENERATE_AREA_REL, DIVISION_GUARD

__all__ = ["disk_triangulation", "soapfilm_patch", "soapfilm_mesh"]


def disk_triangulation(n_boundary: int, t: np.ndarray | None = None):
    """Triangulate the unit disk with ``n_boundary`` points on the circle.

    Parameters
    ----------
    n_boundary : int, >= 3
    t : (n_boundary,) float64 in [0, 1), optional
        Boundary parameters (fraction of a turn); uniform when None.

    Returns
    -------
    uv : (n, 2) float64
        The first ``n_boundary`` rows are the boundary points, in order.
    faces : (f, 3) int64
        Counter-clockwise in the plane.
    """
    if n_boundary < 3:
        raise ValueError(f"n_boundary: expected >= 3, got {n_boundary}")
    t = np.arange(n_boundary) / n_boundary if t is None else np.asarray(t, np.float64)
    ang = 2.0 * np.pi * t
    bnd = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    h = 2.0 * np.pi / n_boundary                       # boundary spacing on the circle
    k = int(np.ceil(1.0 / h)) + 1
    i, j = np.meshgrid(np.arange(-k, k + 1), np.arange(-k, k + 1), indexing="ij")
    pts = np.stack([(i + 0.5 * (j % 2)) * h, j * h * np.sqrt(3) / 2], -1).reshape(-1, 2)
    pts = pts[np.linalg.norm(pts, axis=1) < 1.0 - 0.6 * h]
    uv = np.concatenate([bnd, pts])
    tri = Delaunay(uv).simplices.astype(np.int64)
    a, b, c = uv[tri[:, 0]], uv[tri[:, 1]], uv[tri[:, 2]]
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    tri[area < 0] = tri[area < 0][:, [0, 2, 1]]
    tri = tri[np.abs(area) > DEGENERATE_AREA_REL]  # the unit disk: scale 1
    return uv, tri


def _cotan_laplacian(uv: np.ndarray, faces: np.ndarray) -> sp.csr_matrix:
    """Cotangent Laplacian (n, n) of a planar triangulation (positive semi-definite)."""
    n = len(uv)
    rows, cols, vals = [], [], []
    for k in range(3):
        i, j, o = faces[:, (k + 1) % 3], faces[:, (k + 2) % 3], faces[:, k]
        u, v = uv[i] - uv[o], uv[j] - uv[o]
        cross = np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])
        cot = np.einsum("ij,ij->i", u, v) / np.maximum(cross, DIVISION_GUARD)
        w = 0.5 * cot
        rows += [i, j, i, j]
        cols += [j, i, i, j]
        vals += [-w, -w, w, w]
    return sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(n, n)).tocsr()


def soapfilm_patch(boundary: np.ndarray):
    """Harmonic (soap-film) surface spanning one closed boundary polyline.

    Parameters
    ----------
    boundary : (m, 3) float64
        Closed loop, last point not repeated, m >= 3.

    Returns
    -------
    vertices : (n, 3) float64
        The first m rows are ``boundary``.
    faces : (f, 3) int64
        Oriented like the boundary's traversal (counter-clockwise seen from the
        side the normal points to).

    Examples
    --------
    >>> import numpy as np
    >>> a = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    >>> V, F = soapfilm_patch(np.stack([np.cos(a), np.sin(a), 0 * a], 1))
    >>> bool(np.allclose(V[:, 2], 0))
    True

    References
    ----------
    Abbasinejad, Joshi & Amenta 2011, Sec. 7.
    """
    B = np.asarray(boundary, dtype=np.float64)
    if B.ndim != 2 or B.shape[1] != 3 or len(B) < 3:
        raise ValueError(f"boundary: expected an (m, 3) array with m >= 3, got {B.shape}")
    closed = np.concatenate([B, B[:1]])
    t = arc_length_params(closed)[:-1]
    uv, F = disk_triangulation(len(B), t)
    Lap = _cotan_laplacian(uv, F)
    m = len(B)
    X = np.zeros((len(uv), 3))
    X[:m] = B
    if len(uv) > m:
        Lii = Lap[m:, m:].tocsc()
        rhs = -(Lap[m:, :m] @ B)
        X[m:] = spla.splu(Lii).solve(np.asarray(rhs))
    return X, F


def soapfilm_mesh(curves, loops, *, resolution: int = 16):
    """Soap-film patches for all loops, welded along shared curves.

    Parameters
    ----------
    curves : list of (m_i, 3) float64
    loops : list of list of (int, bool)
    resolution : int
        Boundary segments per curve (arc-length resampling).

    Returns
    -------
    vertices : (n, 3) float64
    faces : (f, 3) int64
    face_patch : (f,) int64
    """
    if int(resolution) < 1:
        raise ValueError(f"resolution: expected >= 1, got {resolution!r}")
    samples = [resample_polyline(np.asarray(c, np.float64), int(resolution)) for c in curves]
    Vs, Fs, P = [], [], []
    off = 0
    for j, lp in enumerate(loops):
        pts = [samples[ci][:-1] if fwd else samples[ci][::-1][:-1] for ci, fwd in lp]
        B = np.concatenate(pts)
        if len(B) < 3:              # a loop of one short curve: resample finer
            B = resample_polyline(np.concatenate([B, B[:1]]), 3)[:-1]
        V, F = soapfilm_patch(B)
        Vs.append(V)
        Fs.append(F + off)
        P.append(np.full(len(F), j))
        off += len(V)
    V = np.concatenate(Vs)
    F = np.concatenate(Fs)
    # weld identical curve samples (same resampling on both sides of a shared curve)
    diag = float(np.linalg.norm(V.max(0) - V.min(0))) or 1.0
    key = np.round(V / (diag * COINCIDENT_REL)).astype(np.int64)
    _, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inv = inv.ravel()
    return V[first], inv[F], np.concatenate(P)
