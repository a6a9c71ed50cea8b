"""One elementary surface shared by a region of patches drawn by hand.

A torus drawn with a few meridians and rings, or a sphere with a few great circles, has
faces that span a large part of the surface. Drawn exactly, each face's boundary fixes
its torus or sphere (:func:`surfacing.analytic.fit_analytic`, to the exact tolerance).
Drawn by hand, or recovered from points, no boundary lies that close to anything, and
alone a rough face cannot tell: a small spherical face lies as close to a cone, and
most free-form faces of real sketches lie near some elementary surface. The faces then
come out as the fit leaves them, flattened between far-apart curves.

Neighbouring faces settle it. The curves of a connected region of several curved
patches lie together on one elementary surface, within the drawing's noise, only when
the region is part of that surface: on a free-form body none comes near all of them.
:func:`shared_surfaces` fits a cylinder, cone, sphere and torus to the whole region's
curves and keeps the simplest within :data:`SHARED_RMS` (root mean square) and
:data:`SHARED_MAX` (largest distance) on which every curve drawn exactly (a line or a
circle, as networks made with CAD tools have) lies within the exact tolerance: a
drawing that precise has no noise to allow for (flowrep espresso's knobs, drawn as
circles and straight chords, lie near spheres and tori and are none). A patch of the
region whose own boundary lies closer to a plane than to that surface keeps its fit
(the simplest surface of its boundary wins, as in :func:`surfacing.analytic.
fit_analytic`), and so does one whose loops wind around the surface's axis or a
torus's tube, which bound no piece of it (a cap whose rim goes round a cylinder, a disc
in a meridian circle). :func:`onto_shared` then puts the interior of each other patch
on the surface, carrying the strokes' signed distances to it into the interior
harmonically, so the mesh still meets every stroke where it was drawn.

Arrays in, arrays out: this module knows no graph and no CAD kernel.

Notes
-----
Not in the papers. Abbasinejad et al. and Zhuang et al. stop at the cycles, Orbay and
Kara fit each patch to its own boundary: on sparse networks of closed shapes the
boundary alone does not fix the face (issue 30).
"""

from __future__ import annotations

import numpy as np

from curvenet.core.geometry import bbox_diagonal, fit_plane, harmonic_fill, mesh_edges

from .analytic import ANALYTIC_TOL, fit_kinds
from .arcs import fit_circle, straight, turns
from .flat import curve_ids, loop_points

__all__ = ["shared_surfaces", "onto_shared", "explain_shared", "vertex_patch", "interior_patch",
           "SHARED_RMS", "SHARED_MAX", "SHARED_PATCHES", "SHARED_KINDS"]

#: Root mean square distance of a region's curve samples to its surface, fraction of the
#: diagonal: about the drawing's own noise (a smooth wobble of 0.3% of the diagonal at
#: its peak has an RMS near 0.2%).
SHARED_RMS = 3e-3
#: Largest distance of any of them (a stroke's end drawn past its junction, a loop's
#: overdrawn end), fraction of the diagonal.
SHARED_MAX = 1e-2
#: Fewest curved patches in a region: fewer faces leave too few curves to tell the
#: kinds apart within the noise (a torus drawn with 3 meridians and 2 rings has 6).
SHARED_PATCHES = 6
#: Kinds tried, simplest first; the first within both tolerances is kept (two equal
#: coaxial circles lie on a cylinder and on a sphere: the cylinder wins). Planes are the
#: flat patches' (:func:`surfacing.flat.flat_planes`).
SHARED_KINDS = ("cylinder", "cone", "sphere", "torus")
#: A drawn curve within this fraction of its extent of a circle gives axis guesses...
GUESS_TOL = 5e-2
#: ...the closest this many of them (their planes are met in pairs).
GUESS_CURVES = 8


def _regions(boundaries, curved) -> list:
    """Patch indices (int64 arrays) of the connected regions of the ``curved`` patches,
    joined through shared curves."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    ids = np.flatnonzero(curved)
    rows, cols = [], []
    for k in ids:
        cs = curve_ids(boundaries[k])
        rows += [k] * len(cs)
        cols += list(cs)
    if not rows:
        return []
    n = len(boundaries)
    inc = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, max(cols) + 1)).tocsr()
    adj = inc @ inc.T
    _, lab = connected_components(adj, directed=False)
    return [r for r in (ids[lab[ids] == v] for v in np.unique(lab[ids])) if len(r)]


def _samples(curves, boundary) -> np.ndarray:
    """The samples (n, 3) of a patch's curves, each curve once."""
    return np.concatenate([curves[c] for c in curve_ids(boundary)])


def _rms(s, p) -> float:
    """Root mean square distance of ``p`` (n, 3) to the surface ``s``."""
    return float(np.sqrt(np.mean(s.distance(p) ** 2)))


def _closer_than_a_plane(s, p) -> bool:
    """Whether samples ``p`` (n, 3) lie closer to ``s`` than to their own plane, by
    root mean square."""
    c, n, _ = fit_plane(p)
    return _rms(s, p) < float(np.sqrt(np.mean(((p - c) @ n) ** 2)))


def _winds(s, loops) -> bool:
    """Whether a patch's loops (each (n_i, 3) in walking order) together wind around
    the axis of ``s`` (a cylinder, cone or torus) or around a torus's tube: such loops
    bound no piece of the surface (a cap's rim goes round a cylinder; a meridian circle
    round a torus's tube), so the patch is not on it."""
    if s.kind not in ("cylinder", "cone", "torus"):
        return False
    around = tube = 0.0
    for lp in loops:
        d = np.asarray(lp, np.float64) - s.origin
        x, y, z = d @ s.xdir, d @ s.ydir, d @ s.axis
        around += turns(np.arctan2(y, x))
        if s.kind == "torus":
            tube += turns(np.arctan2(z, np.hypot(x, y) - s.radius))
    return round(around) != 0 or round(tube) != 0


def _drawn_exactly(c) -> bool:
    """Whether a curve (m, 3) is a line of 3 samples or more or a circle of 4 or more,
    within :data:`surfacing.arcs.CURVE_TOL` of its extent (fewer samples lie on one
    whatever they are)."""
    return (len(c) >= 3 and straight(c) is not None) or (len(c) >= 4
                                                         and fit_circle(c) is not None)


def shared_surfaces(curves, boundaries, *, curved, exact=None):
    """The elementary surface each region of curved patches lies on, within the noise.

    Parameters
    ----------
    curves : list of (m_i, 3) float64
    boundaries : list of list of list of (int, bool)
        Per patch ``[outer, hole_1, ...]`` loops of (curve index, forward).
    curved : (n_patches,) bool
        The patches that may share a surface (not flat).
    exact : list of AnalyticSurface or None, optional
        Per patch the surface its own boundary fixes exactly: those patches keep it.

    Returns
    -------
    surfaces : list of AnalyticSurface or None
        Per patch the region's surface (its ``residual`` the largest distance of the
        region's samples), None outside such regions and for exact patches.
    regions : list of dict
        Per region found: ``kind``, ``patches`` (list of int), ``rms`` and ``max``
        (fractions of the diagonal) and ``surface``
        (:meth:`~surfacing.analytic.AnalyticSurface.to_dict`).
    """
    curves = [np.asarray(c, np.float64) for c in curves]
    diag = bbox_diagonal(curves) or 1.0
    out: list = [None] * len(boundaries)
    found = []
    for region in _regions(boundaries, np.asarray(curved, bool)):
        if len(region) < SHARED_PATCHES:
            continue
        pts = [curves[c] for c in curve_ids([lp for k in region for lp in boundaries[k]])]
        p = np.concatenate(pts)
        drawn = [c for c in pts if _drawn_exactly(c)]
        for s in fit_kinds(pts, SHARED_KINDS, diagonal=diag, guess_tol=GUESS_TOL,
                           guess_curves=GUESS_CURVES):
            if s is None:
                continue
            rms = _rms(s, p)
            if (rms <= SHARED_RMS * diag and s.residual <= SHARED_MAX * diag
                    and all(np.abs(s.distance(c)).max() <= ANALYTIC_TOL * diag
                            for c in drawn)):
                break
        else:
            continue
        keep = [int(k) for k in region if (exact is None or exact[k] is None)
                and _closer_than_a_plane(s, _samples(curves, boundaries[k]))
                and not _winds(s, [loop_points(curves, lp) for lp in boundaries[k]])]
        if not keep:
            continue
        for k in keep:
            out[k] = s
        found.append(dict(kind=s.kind, patches=keep, rms=rms / diag, max=s.residual / diag,
                          surface=s.to_dict()))
    return out, found


def explain_shared(report) -> str | None:
    """The line ``--explain`` prints about the regions of a
    :func:`surfacing.sectors.surface_boundaries` report (its ``shared``; distances as
    fractions of the diagonal); None when there are none.

    Examples
    --------
    >>> print(explain_shared({"shared": [{"kind": "torus", "patches": [0, 1, 2, 3, 4, 5],
    ...                                   "rms": 0.0018, "max": 0.0052}]}))
    shared surface: a torus under 6 patches (its curves 0.18% RMS, 0.52% max off it)
    """
    regions = (report or {}).get("shared") or []
    if not regions:
        return None
    return "shared surface: " + "; ".join(
        f"a {r['kind']} under {len(r['patches'])} patches (its curves {r['rms']:.2%} RMS, "
        f"{r['max']:.2%} max off it)" for r in regions)


def vertex_patch(F, face_patch, n: int) -> np.ndarray:
    """Per vertex of a mesh with ``n`` vertices and faces ``F`` (m, 3) of patches
    ``face_patch`` (m,), the patch whose faces alone use it: (n,) int64, -1 where faces
    of two patches or none do."""
    patch = np.repeat(np.asarray(face_patch, np.int64), 3)
    base = int(patch.max(initial=0)) + 1
    keys = np.unique(np.asarray(F, np.int64).ravel() * base + patch)   # (vertex, patch) pairs
    vertex, patch = np.divmod(keys, base)
    count = np.bincount(vertex, minlength=n)
    owner = np.full(n, -1, np.int64)
    owner[vertex] = patch
    owner[count > 1] = -1
    return owner


def interior_patch(F, face_patch, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The edges of a mesh of ``n`` vertices (:func:`curvenet.core.geometry.mesh_edges`),
    and per vertex the patch whose interior holds it: :func:`vertex_patch`, -1 also on
    the mesh's open borders ((n,) int64)."""
    edges, uses = mesh_edges(F)
    owner = vertex_patch(F, face_patch, n)
    owner[edges[uses == 1].ravel()] = -1
    return edges, owner


def _normals(s, points, step: float) -> np.ndarray:
    """Unit normals (n, 3) of ``s`` at ``points`` on it: the gradient of its signed
    distance, by central differences of ``step``."""
    g = np.stack([s.distance(points + step * e) - s.distance(points - step * e)
                  for e in np.eye(3)], axis=1)
    return g / np.maximum(np.linalg.norm(g, axis=1, keepdims=True), 1e-300)


def onto_shared(V, F, face_patch, surfaces) -> np.ndarray:
    """Interior vertices of patches with a shared surface put on it: (n, 3) float64 (a
    copy).

    A vertex is interior when only faces of one such patch use it and it lies on no
    open border of the mesh. Per surface, the signed distances to it of the vertices
    around the interior (those on the curves, where the strokes were drawn) are carried
    in by the graph Laplacian's harmonic interpolation, and each interior vertex goes
    to its closest point of the surface, then that far along the surface's normal: the
    mesh meets the strokes, and lies on a parallel of the elementary surface that
    follows their offsets smoothly.
    """
    V = np.array(V, dtype=np.float64)
    if all(s is None for s in surfaces):
        return V
    edges, owner = interior_patch(F, face_patch, len(V))
    by_surface: dict = {}
    for k, s in enumerate(surfaces):
        if s is not None:
            by_surface.setdefault(id(s), (s, []))[1].append(k)
    step = 1e-6 * (bbox_diagonal(V) or 1.0)
    for s, patches in by_surface.values():
        inner = np.isin(owner, patches)
        ids = np.flatnonzero(inner)
        if not len(ids):
            continue
        h = harmonic_fill(edges, inner, np.where(inner, 0.0, s.distance(V)))[ids]
        P = s.project(V[ids])
        V[ids] = P + h[:, None] * _normals(s, P, step)
    return V
