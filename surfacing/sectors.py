"""Multiply-connected patches: planar faces with holes cut into simply-connected sectors.

The classical route (Coons patches -> Catmull-Clark) surfaces loops bounding
discs. A face bounded by an outer loop and hole loops is cut along straight
segments joining junctions of different loops, taken shortest first, never
crossing a boundary or each other, at most one per junction. When every loop
hangs on at least two cuts and no cut alone holds a loop on (the cut graph is
connected and bridgeless), every region between the cuts is a disc bounded by
a simple loop. The
regions are surfaced by :func:`surfacing.surface_loops` like any loop, and
report as one patch (``face_patch``) with their face.

Flat patches (boundary in a plane, holes or not) are surfaced over their outer
loop only and then meshed in their plane (:mod:`surfacing.flat`); the sector
cuts are for faces with holes that are not flat.
"""

from __future__ import annotations

import numpy as np

from curvenet.core.geometry import bbox_diagonal, fit_plane

from .analytic import ANALYTIC_TOL, AnalyticSurface, fit_analytic
from .api import (DEFAULT_EDGE_LENGTH, DEFAULT_MAX_FACES, DEFAULT_TOL, PatchMeshResult,
                  explain_fit, surface_loops)
from .bands import mesh_bands
from .denoise import explain_denoised, restore, smooth_curves
from .flat import FLAT_TOL, curve_ids, flat_planes, flatten_planar, loop_points, mesh_flat
from .regions import explain_shared, onto_shared, shared_surfaces, vertex_patch

__all__ = ["split_holed", "split_boundaries", "surface_boundaries", "analytic_faces",
           "explain_boundaries", "UnsplittableFace"]


def _start(curves, item):
    c, f = item
    return curves[c][0] if f else curves[c][-1]




def _cross2(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _crosses(p, q, a, b, eps):
    """Whether segment ``p q`` properly crosses any of the segments ``a[i] b[i]`` (2D)."""
    d1, d2 = _cross2(q - p, a - p), _cross2(q - p, b - p)
    d3, d4 = _cross2(b - a, p - a), _cross2(b - a, q - a)
    return bool(np.any((d1 * d2 < -eps) & (d3 * d4 < -eps)))


def _frame(curves, boundary):
    pts = np.concatenate([loop_points(curves, lp) for lp in boundary])
    c, _, _ = fit_plane(pts)
    outer = loop_points(curves, boundary[0])
    n = np.cross(outer, np.roll(outer, -1, axis=0)).sum(axis=0)
    n /= np.linalg.norm(n)
    e1 = np.linalg.svd(pts - c, full_matrices=False)[2][0]
    e1 -= (e1 @ n) * n
    e1 /= np.linalg.norm(e1)
    return c, np.stack([e1, np.cross(n, e1)])


class UnsplittableFace(ValueError):
    """No set of straight cuts between junctions splits a face with holes into discs."""


def _choose_cuts(junctions, loop_of, segments, region, eps):
    """Greedy shortest valid cuts between junctions of different loops (indices into junctions).

    Every cut that crosses no boundary and no shorter cut and starts and ends
    at junctions no other cut uses is taken (short cuts between all loops make
    sectors close to convex); the face must come out cut into discs.
    """
    n_loops = int(loop_of.max()) + 1
    i, j = np.triu_indices(len(junctions), 1)
    keep = loop_of[i] != loop_of[j]
    i, j = i[keep], j[keep]
    order = np.argsort(np.linalg.norm(junctions[i] - junctions[j], axis=1), kind="stable")
    used, cuts = set(), []
    a, b = segments
    for k in order:
        p, q = junctions[i[k]], junctions[j[k]]
        if i[k] in used or j[k] in used or not region.contains_point(0.5 * (p + q)):
            continue
        if _crosses(p, q, a, b, eps):
            continue
        if cuts and _crosses(p, q, junctions[[c[0] for c in cuts]],
                             junctions[[c[1] for c in cuts]], eps):
            continue
        cuts.append((int(i[k]), int(j[k])))
        used |= {i[k], j[k]}
    if not _cut_graph_done([(loop_of[x], loop_of[y]) for x, y in cuts], n_loops):
        raise UnsplittableFace("no set of straight cuts splits the face with holes into discs")
    return cuts


def _connected(pairs, n) -> bool:
    """Whether the multigraph on ``n`` nodes with edges ``pairs`` is connected."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components
    pr = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    g = sp.coo_matrix((np.ones(len(pr)), (pr[:, 0], pr[:, 1])), shape=(n, n))
    return connected_components(g, directed=False)[0] == 1


def _cut_graph_done(pairs, n_loops) -> bool:
    """Connected, every loop on two cuts, and no cut a bridge."""
    deg = np.bincount(np.asarray(pairs).ravel(), minlength=n_loops)
    if (deg < 2).any() or not _connected(pairs, n_loops):
        return False
    return all(_connected(pairs[:k] + pairs[k + 1:], n_loops) for k in range(len(pairs)))


def split_holed(curves, boundary, first_new: int, samples: int = 17):
    """Cut one planar face with holes into simple loops.

    Parameters
    ----------
    curves : list of (m_i, 3) float64
    boundary : list of list of (int, bool)
        ``[outer, hole_1, ...]`` loops of (curve index, forward).
    first_new : int
        Curve index the first cut gets.
    samples : int
        Points per cut polyline.

    Returns
    -------
    loops : list of list of (int, bool)
        The sectors, walked like the outer loop.
    cuts : list of (samples, 3) float64
        Straight cut polylines, curve indices ``first_new, first_new + 1, ...``.

    Raises
    ------
    ValueError
        No valid set of straight cuts (a face too winding for straight cuts).
    """
    from matplotlib.path import Path
    c, axes = _frame(curves, boundary)
    items = [it for lp in boundary for it in lp]
    loop_of = np.concatenate([np.full(len(lp), k) for k, lp in enumerate(boundary)])
    j3 = np.array([_start(curves, it) for it in items])
    j2 = (j3 - c) @ axes.T
    polys = [(loop_points(curves, lp) - c) @ axes.T for lp in boundary]
    seg_a = np.concatenate(polys)
    seg_b = np.concatenate([np.roll(p, -1, axis=0) for p in polys])
    scale = float(np.ptp(seg_a, axis=0).max())
    region = Path(np.concatenate([np.vstack([p, p[:1]]) for p in polys]),
                      np.concatenate([[Path.MOVETO] + [Path.LINETO] * (len(p) - 1)
                                      + [Path.CLOSEPOLY] for p in polys]))
    cuts = _choose_cuts(j2, loop_of, (seg_a, seg_b), region, 1e-12 * scale * scale)
    t = np.linspace(0.0, 1.0, samples)[:, None]
    cut_curves = [(1 - t) * j3[a] + t * j3[b] for a, b in cuts]
    return _trace(curves, boundary, j2, axes, cuts, first_new), cut_curves


def _trace(curves, boundary, j2, axes, cuts, first_new):
    """Faces of the planar graph (loop curves + cuts) that contain a cut, walked CCW.

    Junction ``k`` is the start of the ``k``-th loop item (loops concatenated).
    """
    half = []   # (origin junction, target junction, (curve, forward), polyline from origin)
    base = 0
    for lp in boundary:
        for k, (ci, f) in enumerate(lp):
            a, b = base + k, base + (k + 1) % len(lp)
            pts = curves[ci] if f else curves[ci][::-1]
            half += [(a, b, (ci, f), pts), (b, a, (ci, not f), pts[::-1])]
        base += len(lp)
    for m, (a, b) in enumerate(cuts):
        half += [(a, b, (first_new + m, True), None), (b, a, (first_new + m, False), None)]
    twin = np.arange(len(half)) ^ 1
    for h, (a, b, item, pts) in enumerate(half):
        d = (j2[b] - j2[a]) if pts is None else (pts[min(3, len(pts) - 1)] - pts[0]) @ axes.T
        half[h] = (a, b, item, d)
    out: dict = {}
    for h, (a, _, _, _) in enumerate(half):
        out.setdefault(a, []).append(h)
    return _faces(half, twin, out, len(cuts), j2)


def _faces(half, twin, out, n_cuts, j2):
    """Walk the CCW faces; keep those through a cut with positive area."""
    first_cut = len(half) - 2 * n_cuts
    nxt = np.empty(len(half), dtype=np.int64)
    for hs in out.values():
        hs.sort(key=lambda h: np.arctan2(half[h][3][1], half[h][3][0]))
    for h, (_, b, _, _) in enumerate(half):
        ring = out[b]
        nxt[h] = ring[(ring.index(int(twin[h])) - 1) % len(ring)]
    seen = np.zeros(len(half), bool)
    loops = []
    for h0 in range(len(half)):
        if seen[h0]:
            continue
        walk, h = [], h0
        while not seen[h]:
            seen[h] = True
            walk.append(h)
            h = int(nxt[h])
        p = j2[[half[h][0] for h in walk]]
        area = _cross2(p, np.roll(p, -1, axis=0)).sum()
        if max(walk) >= first_cut and area > 0:
            loops.append([half[h][2] for h in walk])
    return loops


def split_boundaries(curves, boundaries, samples: int = 17):
    """Split every multiply-connected patch into sectors (:func:`split_holed`).

    Parameters
    ----------
    curves : list of (m_i, 3) float64
    boundaries : list of list of list of (int, bool)
        Per patch ``[outer, hole_1, ...]``; a patch with one loop is kept as is.

    Returns
    -------
    curves : list of (m_i, 3) float64
        The input curves followed by the cuts.
    loops : list of list of (int, bool)
        Simple loops to surface.
    owner : (len(loops),) int64
        Patch index of each loop.
    unsplit : list of int
        Patches no straight cuts could split (:class:`UnsplittableFace`): they are
        surfaced over their outer loop alone, as without hole detection.
    """
    curves = list(curves)
    loops, owner, unsplit = [], [], []
    for pi, b in enumerate(boundaries):
        subs = [b[0]]
        if len(b) > 1:
            try:
                subs, cuts = split_holed(curves, b, len(curves), samples)
                curves += cuts
            except UnsplittableFace:
                unsplit.append(pi)
        loops += subs
        owner += [pi] * len(subs)
    return curves, loops, np.asarray(owner, dtype=np.int64), unsplit


def analytic_faces(curves, boundaries, *, tol: float = ANALYTIC_TOL, flat=None, normals=None,
                   offsets=None) -> list:
    """The elementary surface each patch's boundary lies on (:func:`fit_analytic`).

    Parameters
    ----------
    curves : list of (m_i, 3) float64
    boundaries : list of list of list of (int, bool)
        Per patch ``[outer, hole_1, ...]``; a seam curve walked twice counts once.
    tol : float
        Fraction of the curves' diagonal.
    flat, normals, offsets : optional
        :func:`surfacing.flat.flat_planes` of the same boundaries: flat patches are
        planes without a fit.

    Returns
    -------
    list of AnalyticSurface or None
        Per patch; None for a free-form boundary.
    """
    curves = [np.asarray(c, np.float64) for c in curves]
    diag = bbox_diagonal(curves) or 1.0
    out = []
    for k, b in enumerate(boundaries):
        pts = [curves[c] for c in curve_ids(b)]
        if flat is not None and flat[k]:
            p = np.concatenate(pts)
            n = np.asarray(normals[k], np.float64)
            o = p.mean(axis=0)
            o = o - (o @ n - offsets[k]) * n
            res = float(np.abs(p @ n - offsets[k]).max())
            e = np.eye(3)[int(np.argmin(np.abs(n)))]
            e = e - (e @ n) * n
            out.append(AnalyticSurface("plane", o, n, e / np.linalg.norm(e), 0.0, 0.0, res))
            continue
        loops = [loop_points(curves, lp) for lp in b]
        out.append(fit_analytic(pts, tol=tol * diag, diagonal=diag, loops=loops))
    return out


def _on_surfaces(V, F, face_patch, surfaces, heights=None):
    """Vertices of the faces of each analytic patch that no other patch uses, projected
    onto its surface: (n, 3) float64 (a copy).

    ``heights`` (per patch ``(lo, hi)`` or None): the range along a cylinder's or
    cone's axis of the patch's boundary. Their vertices are brought within it and then
    onto the surface at the same angle about the axis (a fitted band that sagged away
    from its border circles would otherwise be projected onto the surface's
    continuation beyond them).
    """
    V = np.array(V, dtype=np.float64)
    owner = vertex_patch(F, face_patch, len(V))
    for p, s in enumerate(surfaces):
        if s is not None:
            ids = np.flatnonzero(owner == p)
            if heights is not None and heights[p] is not None and s.kind in _AXIAL:
                # at the same angle, within the border's heights, onto the surface
                d = V[ids] - s.origin
                z = np.clip(d @ s.axis, *heights[p])
                r = d - (d @ s.axis)[:, None] * s.axis
                n = np.linalg.norm(r, axis=1, keepdims=True)
                unit = np.where(n > 0, r / np.maximum(n, 1e-300), s.xdir)
                rho = s.radius + (z * np.tan(s.minor) if s.kind == "cone" else 0.0)
                V[ids] = s.origin + z[:, None] * s.axis + np.asarray(rho).reshape(-1, 1) * unit
            else:
                V[ids] = s.project(V[ids])
    return V


#: Kinds whose points are kept within their boundary's extent along the axis.
_AXIAL = ("cylinder", "cone")


def _heights(curves, boundaries, surfaces) -> list:
    """Per patch the ``(lo, hi)`` extent of its boundary samples along its cylinder's or
    cone's axis; None for other patches."""
    out = []
    for b, s in zip(boundaries, surfaces):
        if s is None or s.kind not in _AXIAL:
            out.append(None)
            continue
        p = np.concatenate([np.asarray(curves[c], np.float64) for lp in b for c, _ in lp])
        z = (p - s.origin) @ s.axis
        out.append((float(z.min()), float(z.max())))
    return out


def surface_boundaries(curves, boundaries, *, cut_samples: int = 17, flat_tol: float = FLAT_TOL,
                       analytic_tol: float | None = ANALYTIC_TOL, denoise: bool = True,
                       **options):
    """:func:`surfacing.surface_loops` for patches that may have holes; flat patches flat,
    analytic patches on their surface.

    Parameters
    ----------
    curves : list of (m_i, 3) float64
    boundaries : list of list of list of (int, bool)
        Per patch ``[outer, hole_1, ...]`` loops of (curve index, forward).
    cut_samples : int
        Points per cut polyline.
    flat_tol : float
        Flatness of a boundary, fraction of the diagonal (:func:`surfacing.flat.flat_planes`):
        flat patches are surfaced over their outer loop, then meshed in their plane
        (:func:`surfacing.flat.mesh_flat`).
    analytic_tol : float or None
        Patches whose boundary lies on a plane, cylinder, cone, sphere or torus within
        this fraction of the diagonal (:func:`analytic_faces`) get their mesh vertices
        projected onto it, those of revolution bounded by parallels and a seam meshed as
        rings about their axis (:func:`surfacing.bands.mesh_bands`); the other curved
        patches of a region whose curves share one within the drawing's noise are put
        on it (:func:`surfacing.regions.shared_surfaces`); None: neither (every face as
        the fit leaves it).
    denoise : bool
        Surface the curves with per-sample noise smoothed, then put the noise back on
        the mesh (:mod:`surfacing.denoise`, at the fit's ``tol``).
    **options
        Passed to :func:`surfacing.surface_loops` (``crease_curves``, ``resolution``, ...).

    Returns
    -------
    PatchMeshResult
        ``face_patch`` indexes ``boundaries``; ``report`` adds ``n_sectors``
        (loops surfaced), ``cuts``, ``flat_patches``, ``flat_meshed`` (those meshed
        in-plane), ``bands`` (the patches meshed as rings), ``unsplit_holes``,
        ``loop_patch`` (the patch of each loop of the control net, sectors included)
        and ``analytic``: per patch the
        :meth:`~surfacing.analytic.AnalyticSurface.to_dict` of its surface (with
        ``residual`` in model units) or None; ``shared``: per region put on one
        surface its kind, patches and residuals (:func:`surfacing.regions.
        shared_surfaces`); ``denoised``: the curves smoothed (:func:`surfacing.denoise.
        smooth_curves`); ``curves`` (when asked for) holds the input curves only.
    """
    n = len(curves)
    curves = [np.asarray(c, dtype=np.float64) for c in curves]
    # the fit and the shared surfaces take the smoothed curves, the tests for flat and exact
    # faces the drawn ones (a smoothed curve is off its smoothing by more than they allow)
    smooth, denoised = (smooth_curves(curves, options.get("tol", DEFAULT_TOL)) if denoise
                        else (curves, []))
    flat, normals, offsets = flat_planes(curves, boundaries, flat_tol)
    outer_only = [b[:1] if f else b for b, f in zip(boundaries, flat)]
    all_curves, loops, owner, unsplit = split_boundaries(smooth, outer_only, cut_samples)
    res = surface_loops(all_curves, loops, **options)
    face_patch = owner[res.face_patch]
    V = flatten_planar(res.vertices, res.faces, face_patch, flat, normals, offsets)
    surfaces = [None] * len(boundaries)
    if analytic_tol is not None:
        surfaces = analytic_faces(curves, boundaries, tol=analytic_tol, flat=flat,
                                  normals=normals, offsets=offsets)
        diag = bbox_diagonal(list(curves))
        V, F, face_patch, banded = mesh_bands(V, res.faces, face_patch, res.curve_vertices,
                                              curves, boundaries, surfaces,
                                              analytic_tol * diag)
    else:
        F, banded = res.faces, np.zeros(len(boundaries), bool)
    auto = options.get("subdiv") is None
    target = options.get("edge_length", DEFAULT_EDGE_LENGTH) * res.control_net.diagonal
    V, F, face_patch, meshed = mesh_flat(
        V, F, face_patch, res.curve_vertices, curves, boundaries, flat, normals,
        offsets, edge_length=target if auto else None,
        max_faces=max(DEFAULT_MAX_FACES, len(F)) if auto else None)
    shared: list = []
    if analytic_tol is not None:
        V = _on_surfaces(V, F, face_patch, surfaces, _heights(curves, boundaries, surfaces))
        on, shared = shared_surfaces(smooth, boundaries, curved=~flat, exact=surfaces)
        V = onto_shared(V, F, face_patch, on)
    if denoised:
        V = restore(V, F, face_patch, smooth, curves)
    report = dict(res.report, n_patches=len(boundaries), n_sectors=len(loops),
                  cuts=len(all_curves) - n, flat_patches=int(flat.sum()),
                  flat_meshed=int(meshed.sum()), bands=np.flatnonzero(banded).tolist(),
                  n_faces=len(F), unsplit_holes=unsplit,
                  loop_patch=owner.tolist(),
                  analytic=[None if s is None else s.to_dict() for s in surfaces],
                  shared=shared, denoised=denoised)
    new_curves = None if res.curves is None else res.curves[:n]
    return PatchMeshResult(V, F, report, face_patch=face_patch, curves=new_curves,
                           control_vertices=res.control_vertices,
                           control_quads=res.control_quads, control_net=res.control_net)


def explain_boundaries(report) -> list:
    """The lines ``--explain`` prints about a :func:`surface_boundaries` report: the fit
    (:func:`surfacing.api.explain_fit`), the shared surfaces (:func:`surfacing.regions.
    explain_shared`) and the smoothed curves (:func:`surfacing.denoise.explain_denoised`),
    each where it has something to say; [] for another surfacer's report (or None).

    Examples
    --------
    >>> explain_boundaries({"fit": "lsq", "shared": [], "denoised": []})
    ['fit: lsq']
    """
    lines = (explain(report) for explain in (explain_fit, explain_shared, explain_denoised))
    return [line for line in lines if line]
