"""Judging a patch surface, not only its coverage: walls inside the shape, curves shared
by three or more patches.

A surface through every stroke can still be the wrong shape: a disc capping a torus's
meridian lies inside the tube the other patches bound. :func:`judge_patches` finds such
*walls* with the generalised winding number of the whole surface (Jacobson et al.
2013, libigl's fast approximation): just off a patch that belongs to the boundary of
the shape, on its two sides, the winding number is about 0 and 1 (mean 1/2, whichever
way the surface is oriented); off a wall both sides are inside (mean 1). Patches whose
mean stays near 1 are walls. Open surfaces have fractional winding numbers everywhere
and no walls.
"""

from __future__ import annotations

import numpy as np

from ..core.geometry import bbox_diagonal, face_normals_areas

__all__ = ["WALL_WINDING", "CHECK_SAMPLES", "judge_patches", "nonmanifold_curves", "wall_area"]

#: A patch is a wall when the winding number just off it, averaged over its two sides,
#: has a median magnitude above this (1 inside a closed shape, 1/2 on its boundary).
WALL_WINDING = 0.85
#: Faces sampled per patch (evenly spread over its faces).
CHECK_SAMPLES = 12
#: Offset of the samples to both sides of a patch, fraction of the diagonal.
CHECK_OFFSET = 1e-3


def judge_patches(vertices, faces, face_patch, patch_edges, n_curves: int, *,
                  creases=()) -> dict:
    """Walls and non-manifold curves of a patch surface.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64
        The surface.
    face_patch : (F,) int64
        Patch of each face (an index into ``patch_edges``).
    patch_edges : list of sequence of int
        Each patch's curves (its outer loop and its holes).
    n_curves : int
        Curves of the network.
    creases : sequence of int
        Curves labelled crease: a wall all of whose curves are creases is one the sketch
        asks for (the face two stacked boxes share) and is no defect.

    Returns
    -------
    dict
        ``walls`` (patch indices whose two sides are both inside the shape, but for the
        crease walls),
        ``winding`` (per patch, the median of the mean winding number of its two sides),
        ``nonmanifold`` (curves used by three or more patches), ``passes`` (no wall).

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box()
    >>> wall = trimesh.creation.box(extents=(0.01, 0.8, 0.8))   # a slab inside the box
    >>> v = np.vstack([box.vertices, wall.vertices])
    >>> f = np.vstack([box.faces, wall.faces + len(box.vertices)])
    >>> fp = np.r_[np.zeros(len(box.faces), int), np.ones(len(wall.faces), int)]
    >>> judge_patches(v, f, fp, [[0], [1]], 2)["walls"]
    [1]
    """
    import igl
    V = np.ascontiguousarray(vertices, np.float64)
    F = np.ascontiguousarray(faces, np.int64)
    face_patch = np.asarray(face_patch, np.int64)
    out = {"walls": [], "winding": [], "nonmanifold": nonmanifold_curves(patch_edges, n_curves),
           "passes": True}
    if not len(F):
        return out
    normals, _ = face_normals_areas(V, F)
    order = np.argsort(face_patch, kind="stable")
    starts = np.searchsorted(face_patch[order], np.arange(len(patch_edges) + 1))
    picks = [order[starts[k] + np.unique(np.linspace(0, max(starts[k + 1] - starts[k] - 1, 0),
                                                    CHECK_SAMPLES).astype(np.int64))]
             if starts[k + 1] > starts[k] else np.zeros(0, np.int64)
             for k in range(len(patch_edges))]
    sample = np.concatenate(picks)
    owner = np.repeat(np.arange(len(picks)), [len(p) for p in picks])
    eps = CHECK_OFFSET * bbox_diagonal(V)
    centre = V[F[sample]].mean(axis=1)
    w = igl.fast_winding_number(V, F, np.concatenate([centre + eps * normals[sample],
                                                      centre - eps * normals[sample]]))
    mean = np.abs(w[:len(sample)] + w[len(sample):]) / 2
    winding = [float(np.median(mean[owner == k])) if np.any(owner == k) else 0.5
               for k in range(len(patch_edges))]
    crease = np.zeros(n_curves, bool)
    crease[np.asarray(creases, np.int64)] = True
    walls = [k for k, m in enumerate(winding)
             if m > WALL_WINDING and not crease[np.asarray(patch_edges[k], np.int64)].all()]
    out.update(walls=walls, winding=winding, passes=not walls)
    return out


def nonmanifold_curves(patch_edges, n_curves: int) -> int:
    """Curves bounding three or more patches.

    Parameters
    ----------
    patch_edges : list of sequence of int
        Per patch its curve ids (``Patch.all_edges``: a seam walked twice counts twice).
    n_curves : int

    Returns
    -------
    int
    """
    uses = np.bincount(np.concatenate([np.asarray(p, np.int64) for p in patch_edges])
                       if patch_edges else np.zeros(0, np.int64), minlength=n_curves)
    return int(np.count_nonzero(uses >= 3))


def wall_area(vertices, faces, face_patch, walls) -> float:
    """Share of a surface's area on the faces of some patches.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64
    face_patch : (F,) int64
    walls : sequence of int
        Patch indices (:func:`judge_patches`' ``walls``).

    Returns
    -------
    float
        In [0, 1]; 0 for an empty surface.
    """
    _, area = face_normals_areas(np.asarray(vertices, np.float64), np.asarray(faces, np.int64))
    total = float(area.sum())
    hit = np.isin(np.asarray(face_patch), np.asarray(list(walls), np.int64))
    return float(area[hit].sum() / total) if total > 0 else 0.0
