"""Mesh decimation for pictures: vertex clustering on a uniform grid."""

from __future__ import annotations

import numpy as np

from ..core.geometry import bbox_diagonal
from ..core.tolerances import COINCIDENT_REL

__all__ = ["decimate_clustering"]


def decimate_clustering(vertices, faces, max_faces: int, *, return_index: bool = False):
    """Reduce a triangle mesh to at most ``max_faces`` faces by vertex clustering.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64
    max_faces : int
    return_index : bool
        Also return the input face each output face comes from.

    Returns
    -------
    vertices : (V', 3) float64
    faces : (F', 3) int64
        ``F' <= max_faces``; unchanged input when ``F <= max_faces``.
    index : (F',) int64
        Only with ``return_index``: the input face of each output face.

    Notes
    -----
    Vertices are merged per cell of a uniform grid (Rossignac & Borrel 1993) placed at
    the bounding-box minimum; the merged vertex is the cell's mean. Faces that collapse
    (two corners in one cell) are dropped, duplicates kept once; orientation is kept.
    The cell size starts at ``sqrt(2 A / max_faces)`` (a surface of area ``A`` meshed
    at spacing ``h`` has about ``2 A / h^2`` triangles) and grows until the count fits.
    Good enough for a picture, not for geometry processing.
    """
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if len(f) <= max_faces:
        return (v, f, np.arange(len(f))) if return_index else (v, f)
    tri = v[f]
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                axis=1).sum()
    lo = v.min(axis=0)
    diag = bbox_diagonal(v)
    h = max(np.sqrt(2.0 * area / max_faces), COINCIDENT_REL * diag)
    for _ in range(20):
        keys = np.floor((v - lo) / h).astype(np.int64)  # (V, 3)
        _, inverse = np.unique(keys, axis=0, return_inverse=True)
        inverse = inverse.ravel()
        nf = inverse[f]  # (F, 3)
        ok = (nf[:, 0] != nf[:, 1]) & (nf[:, 1] != nf[:, 2]) & (nf[:, 0] != nf[:, 2])
        nf = nf[ok]
        # drop duplicate triangles (same corners, any rotation or orientation)
        _, first = np.unique(np.sort(nf, axis=1), axis=0, return_index=True)
        index = np.flatnonzero(ok)[np.sort(first)]
        nf = nf[np.sort(first)]
        if len(nf) <= max_faces:
            break
        h *= 1.05 * np.sqrt(len(nf) / max_faces)
    count = np.bincount(inverse).astype(np.float64)
    nv = np.stack([np.bincount(inverse, weights=v[:, k]) for k in range(3)], axis=1)
    nv /= count[:, None]
    used, nf = np.unique(nf, return_inverse=True)
    if return_index:
        return nv[used], nf.reshape(-1, 3), index
    return nv[used], nf.reshape(-1, 3)
