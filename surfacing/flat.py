"""Flat patches: meshed in their plane by a constrained Delaunay triangulation.

A patch whose boundary curves (outer loop and holes) lie in a plane, within
:data:`FLAT_TOL` of the diagonal, is a piece of that plane however its outline
winds: the smooth Catmull-Clark surface of such a loop can fold over itself
inside the plane (an L-shaped outline, the sectors around a hole). Its output
is therefore a quality constrained Delaunay triangulation (Shewchuk's
*Triangle*, through the ``triangle`` package) of its boundary loops in the
plane: the boundary vertices are the output vertices the surface has along the
patch's curves, shared with the neighbouring patches, and no point is added on
the boundary, so the mesh stays welded; inner vertices get about the spacing of
those boundary vertices, which the Catmull-Clark level already chose from the
target edge length. Every output vertex of a flat patch lies in its plane (a
vertex shared by several flat patches on the intersection of their planes,
nearest to where the surface put it).
"""

from __future__ import annotations

import numpy as np

from curvenet.core.geometry import bbox_diagonal, fit_plane

__all__ = ["FLAT_TOL", "flat_planes", "flatten_planar", "mesh_flat", "loop_points",
           "curve_ids", "replace_faces"]

#: A patch is flat when its boundary points lie this close to a plane (fraction of the diagonal).
FLAT_TOL = 1e-6


def loop_points(curves, loop):
    """Points of a closed loop of ``(curve index, forward)``, each junction once: (m, 3).

    Any per-curve arrays walk the same way: output vertex ids along each curve give
    the ids around the loop, (m,).
    """
    return np.concatenate([(curves[c] if f else curves[c][::-1])[:-1] for c, f in loop])


def curve_ids(boundary) -> list:
    """The curves of a patch's loops ``[[(curve index, forward), ...], ...]``, each once,
    in increasing order."""
    return sorted({c for lp in boundary for c, _ in lp})


def flat_planes(curves, boundaries, tol: float = FLAT_TOL):
    """Which patches are flat, and their planes ``n . x = d``.

    Parameters
    ----------
    curves, boundaries
        As for :func:`surfacing.sectors.surface_boundaries`.
    tol : float
        Flatness of a boundary, fraction of the curves' bounding-box diagonal.

    Returns
    -------
    flat : (p,) bool
    normals : (p, 3) float64
        Unit normals of the fitted planes.
    offsets : (p,) float64
    """
    diag = bbox_diagonal(list(curves)) or 1.0
    normals = np.zeros((len(boundaries), 3))
    offsets = np.zeros(len(boundaries))
    flat = np.zeros(len(boundaries), bool)
    for k, b in enumerate(boundaries):
        pts = np.concatenate([loop_points(curves, lp) for lp in b])
        c, n, _ = fit_plane(pts)
        flat[k] = np.abs((pts - c) @ n).max() <= tol * diag
        normals[k], offsets[k] = n, n @ c
    return flat, normals, offsets


def flatten_planar(vertices, faces, face_patch, flat, normals, offsets):
    """Put the vertices of the flat patches' faces in their planes.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (f, 3) int64
    face_patch : (f,) int64
        Patch of each face.
    flat, normals, offsets
        From :func:`flat_planes`.

    Returns
    -------
    (n, 3) float64
        A copy; a vertex of several flat patches lands on the intersection of
        their planes nearest to it (least squares).
    """
    V = np.array(vertices, dtype=np.float64)
    fp = np.asarray(face_patch)
    sel = flat[fp]
    if not sel.any():
        return V
    import scipy.sparse as sp
    f, p = np.asarray(faces)[sel], fp[sel]
    inc = sp.csr_matrix((np.ones(f.size), (f.ravel(), np.repeat(p, 3))),
                        shape=(len(V), len(flat)))
    inc.sum_duplicates()
    inc.data[:] = 1.0
    rows = np.flatnonzero(np.diff(inc.indptr))
    counts = np.diff(inc.indptr)[rows]
    K = int(counts.max())
    N = np.zeros((len(rows), K, 3))
    d = np.zeros((len(rows), K))
    slot = np.arange(inc.nnz) - np.repeat(inc.indptr[rows], counts)
    r = np.repeat(np.arange(len(rows)), counts)
    N[r, slot], d[r, slot] = normals[inc.indices], offsets[inc.indices]
    x = V[rows]
    resid = np.einsum("mkj,mj->mk", N, x) - d
    G = np.linalg.pinv(np.einsum("mkj,mlj->mkl", N, N))
    V[rows] = x - np.einsum("mkj,mkl,ml->mj", N, G, resid)
    return V


def _with_own_points(V, chains, curves, boundaries, patches):
    """Vertices and per-curve vertex ids, the curves of ``patches`` that have no output
    vertices getting their own points as new vertices."""
    chains = list(chains) if chains is not None else [None] * len(curves)
    add = []
    n = len(V)
    for k in patches:
        for c, _ in (it for lp in boundaries[k] for it in lp):
            if chains[c] is None:
                chains[c] = n + np.arange(len(curves[c]))
                n += len(curves[c])
                add.append(np.asarray(curves[c], dtype=np.float64))
    return np.concatenate([V, *add]), chains


#: Boundary vertices closer than this (fraction of the patch's extent) make the CDT refuse.
_MERGED = 1e-9


def _triangulate(xy, rings, spacing):
    """Quality CDT of the loops ``rings`` (index arrays into ``xy``, outer first) keeping
    every boundary vertex and segment; returns (vertices (m, 2), triangles (t, 3)) with
    the inputs first, or None when two boundary vertices (nearly) coincide or loops cross
    (Triangle fails, or splits a boundary segment).

    A first triangulation without added points finds the triangles inside the holes,
    whose centres tell Triangle which regions to leave out of the refinement.
    """
    import triangle
    from matplotlib.path import Path
    from scipy.spatial import cKDTree
    seg = np.concatenate([np.stack([r, np.roll(r, -1)], 1) for r in rings])
    if len(np.unique(np.concatenate(rings))) < len(seg):
        return None             # a loop through a point twice (a seam walked there and
        #                         back): Triangle's refinement may never end on it
    lo, scale = xy.min(axis=0), float(np.ptp(xy, axis=0).max())
    xy = (xy - lo) / scale      # Triangle reads the area switch as plain decimals
    if cKDTree(xy).query_pairs(_MERGED, output_type="ndarray").size:
        return None             # loops that touch: Triangle would merge (or crash on) them
    pslg = {"vertices": xy, "segments": seg}
    area = max(np.sqrt(3.0) / 4.0 * (spacing / scale) ** 2, 1e-15)
    try:
        if len(rings) > 1:
            coarse = triangle.triangulate(pslg, "pQ")
            if "triangles" not in coarse:   # crossing segments: some builds return no mesh
                return None
            cen = coarse["vertices"][coarse["triangles"]].mean(axis=1)
            out = np.zeros(len(cen), bool)
            for r in rings[1:]:
                out |= Path(xy[r]).contains_points(cen)
            if out.any():
                pslg["holes"] = cen[out]
        got = triangle.triangulate(pslg, f"pqYYQa{area:.17f}")
    except RuntimeError:        # "Triangulation failed": crossing segments it may not split
        return None
    if "triangles" not in got:
        return None
    P, T = got["vertices"] * scale + lo, got["triangles"]
    m = len(P)
    edges = np.sort(np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]]), axis=1)
    bound = np.sort(seg, axis=1)
    if not np.isin(bound[:, 0] * m + bound[:, 1], edges[:, 0] * m + edges[:, 1]).all():
        return None
    return P, T


def mesh_flat(vertices, faces, face_patch, chains, curves, boundaries, flat, normals, offsets,
              *, edge_length: float | None = None, max_faces: int | None = None):
    """Replace the faces of every flat patch by a CDT of its boundary in its plane.

    Parameters
    ----------
    vertices : (n, 3) float64
        Output vertices, those of flat patches already in their planes
        (:func:`flatten_planar`).
    faces : (f, 3) int64
    face_patch : (f,) int64
        Patch of each face (index into ``boundaries``); the faces of a flat patch
        give the orientation of its new triangles.
    chains : list of (k_c,) int64 or None
        Output vertex ids along each curve, first point to last (None: the curve
        has none, its own points are used).
    curves : list of (m_i, 3) float64
    boundaries : list of list of list of (int, bool)
    flat, normals, offsets
        From :func:`flat_planes`.
    edge_length : float or None
        Inner edge length (absolute); a patch whose boundary vertices are farther
        apart uses their mean spacing. None: the mean spacing of the boundary vertices.
    max_faces : int or None
        The inner edge length grows, for all flat patches alike, until the whole
        output is expected to stay under this many triangles.

    Returns
    -------
    vertices : (n', 3) float64
        Unreferenced vertices removed.
    faces : (f', 3) int64
    face_patch : (f',) int64
    meshed : (p,) bool
        The flat patches now meshed in-plane (a patch whose CDT would lose a
        boundary segment keeps its faces).
    """
    F, FP = np.asarray(faces), np.asarray(face_patch)
    todo = np.flatnonzero(flat)
    V, chains = _with_own_points(np.asarray(vertices, dtype=np.float64), chains, curves,
                                 boundaries, todo)
    frames = [_plane_frame(V, [loop_points(chains, lp) for lp in boundaries[k]], normals[k])
              for k in todo]
    budget = None if max_faces is None else max_faces - int((~flat[FP]).sum())
    cdts = _cdts(frames, _spacings(frames, edge_length, budget), budget)
    meshed = np.zeros(len(boundaries), bool)
    new_v, new_f = [], []
    n_next = len(V)
    for k, fr, got in zip(todo, frames, cdts):
        if got is None:
            continue
        P, T = got
        inner = P[len(fr["ids"]):] @ fr["axes"] + offsets[k] * normals[k]
        tri = np.concatenate([fr["ids"], n_next + np.arange(len(inner))])[T]
        n_next += len(inner)
        old = FP == k
        facing = _orient(V, F[old]) if old.any() else _newell(V[fr["ids"][fr["rings"][0]]])
        if facing @ normals[k] < 0:
            tri = tri[:, ::-1]
        meshed[k] = True
        new_v.append(inner)
        new_f.append(tri)
    V, F, FP = replace_faces(V, F, FP, np.flatnonzero(meshed), new_v, new_f)
    used = np.zeros(len(V), bool)
    used[F.ravel()] = True
    remap = np.cumsum(used) - 1
    return V[used], remap[F], FP, meshed


def replace_faces(V, F, FP, patches, vertices, triangles):
    """A mesh with the faces of ``patches`` replaced.

    ``V`` (n, 3) float64, ``F`` (f, 3) int64, ``FP`` (f,) int64 the patch of each face;
    ``patches`` (p,) int; per patch its new ``vertices`` (k_i, 3), appended to ``V`` in
    order, and its ``triangles`` (t_i, 3) indexing the grown vertex array. Returns the
    new ``(V, F, FP)``, the replaced faces' vertices left in place.
    """
    keep = ~np.isin(FP, patches)
    return (np.concatenate([V, *vertices]),
            np.concatenate([F[keep], *triangles]).astype(np.int64),
            np.concatenate([FP[keep], *(np.full(len(t), k) for k, t in zip(patches, triangles))]
                           ).astype(np.int64))


def _cdts(frames, spacing, budget, tries: int = 3):
    """:func:`_triangulate` of every frame (None where it has none); while the triangles
    exceed ``budget`` (an estimate from the areas can fall short), coarser again."""
    for _ in range(tries):
        got = [None if fr is None else _triangulate(fr["xy"], fr["rings"], h)
               for fr, h in zip(frames, spacing)]
        total = sum(len(g[1]) for g in got if g is not None)
        if budget is None or total <= budget:
            break
        spacing = spacing * 1.05 * np.sqrt(total / max(budget, 1))
    return got


def _plane_frame(V, rings, normal):
    """A flat patch in its plane: dict with ``ids`` (m,) (its boundary vertices),
    ``rings`` (loops as indices into ``ids``), ``xy`` (m, 2), ``axes`` (2, 3) (in-plane
    frame, ``axes[0] x axes[1] = normal``), ``spacing`` (mean boundary edge) and ``area``
    (outer minus holes); None when the loops have no extent."""
    ids, inv = np.unique(np.concatenate(rings), return_inverse=True)
    lr = np.split(inv, np.cumsum([len(r) for r in rings])[:-1])
    P3 = V[ids]
    e1 = np.linalg.svd(P3 - P3.mean(axis=0), full_matrices=False)[2][0]
    e1 = e1 - (e1 @ normal) * normal
    spacing = float(np.mean(np.concatenate(
        [np.linalg.norm(P3[np.roll(r, -1)] - P3[r], axis=1) for r in lr])))
    if not (spacing > 0 and np.linalg.norm(e1) > 0):
        return None
    e1 /= np.linalg.norm(e1)
    axes = np.stack([e1, np.cross(normal, e1)])
    xy = P3 @ axes.T
    areas = [abs(_newell(np.c_[xy[r], np.zeros(len(r))])[2]) for r in lr]
    return {"ids": ids, "rings": lr, "xy": xy, "axes": axes, "spacing": spacing,
            "area": max(areas[0] - sum(areas[1:]), 0.0)}


#: Triangles a quality CDT makes per ``area / (sqrt(3)/4 h^2)`` (equilateral triangles of
#: side ``h``), measured on the CAD shapes: used to keep the output under ``max_faces``.
_CDT_FILL = 1.6


def _spacings(frames, edge_length, budget):
    """Inner edge length of each flat patch (see :func:`mesh_flat`): (len(frames),) float64."""
    h = np.array([0.0 if fr is None else fr["spacing"] for fr in frames])
    if edge_length is not None:
        h = np.maximum(h, edge_length)
    area = np.array([0.0 if fr is None else fr["area"] for fr in frames])
    if budget is not None and len(h):
        want = _CDT_FILL * float(np.sum(area / (np.sqrt(3.0) / 4.0 * np.maximum(h, 1e-300) ** 2)))
        if want > max(budget, 1):
            h *= np.sqrt(want / max(budget, 1))
    return h


def _newell(points):
    """Area vector of a closed polygon (m, 3): (3,) float64."""
    return 0.5 * np.cross(points, np.roll(points, -1, axis=0)).sum(axis=0)


def _orient(V, F):
    """Sum of the area-weighted normals of triangles ``F``: (3,) float64."""
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return np.cross(b - a, c - a).sum(axis=0)
