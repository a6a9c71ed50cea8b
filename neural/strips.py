"""SharpNet feature strips along crease strokes (Niu et al. 2025, Appendix A, Sec. 3.3).

A crease stroke becomes a feature set M: a strip surface along the stroke that
approximates the medial surface near the sharp edge. A SharpNet SDF with these strips
as features is C0 exactly on the strips, so its zero set can have a true crease where
a strip crosses it (:func:`neural.crease_refit.crease_refine`).

- :func:`guide_directions` -- per-vertex guiding directions from per-edge ones (the
  Appendix A energy with a squared relaxation, solved in closed form);
- :func:`stroke_guides_from_mesh` -- per-edge guides of a stroke estimated from the
  current surface's normals on both sides (the bisector of the two sides);
- :func:`strip_from_polyline` -- the strip M (each vertex offset by +-w along its guide);
- :func:`crease_feature_set` -- strips for all crease strokes, channels split by
  :func:`neural.sharpnet.edge_coloring` of the stroke graph (Sec. 3.3);
- :func:`segment_strip_2d` -- the 2D analogue (a segment through a polygon corner along
  its bisector).

Arrays in, arrays out (numpy); torch comes in only with :mod:`neural.sharpnet`'s edge
colouring, imported inside :func:`crease_feature_set`.

References
----------
Niu et al. 2025, "SharpNet", Appendix A (strips), Sec. 3.3 (splitting).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from curvenet.core.geometry import arc_length, resample_polyline
from curvenet.core.tolerances import NORM_EPS

__all__ = ["GUIDE_LAMBDA", "guide_directions", "stroke_guides_from_mesh", "strip_from_polyline",
           "segment_strip_2d", "crease_feature_set", "resample_by_step"]

#: lambda of the Appendix A energy (the paper leaves its value open).
GUIDE_LAMBDA = 0.5


def _unit(v, eps=NORM_EPS):
    v = np.asarray(v, dtype=np.float64)
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), eps)


def guide_directions(points, edge_guides, *, lam: float = GUIDE_LAMBDA) -> np.ndarray:
    """Vertex guiding directions of a polyline from its per-edge guides (Appendix A).

    Parameters
    ----------
    points : (n, 3) float64
        Polyline vertices (n >= 2).
    edge_guides : (n - 1, 3) float64
        Unit guide of each edge ``e_i = (p_i, p_{i+1})``, orthogonal to it, in the bisector
        plane of its two sides.
    lam : float
        Weight of the pull towards the mean edge guide.

    Returns
    -------
    (n, 3) float64
        Unit vertex guides. End vertices take their edge's guide. Interior vertices minimise
        ``sum_e (g . b_e)^2 + lam |g - mean_e g_e|^2`` with ``b_e = g_e x e / |e|`` the normal
        of edge e's bisector plane, then normalise: ``g = lam (B + lam I)^-1 mean g_e``,
        ``B = sum b_e b_e^T``.

    Notes
    -----
    Deviation: the paper's energy uses ``|g . b_e|`` and ``|g - mean|`` on the unit sphere;
    the squared relaxation has this closed form and the same minimiser when the bisector
    planes meet in a line (the case the paper targets).
    """
    p = np.asarray(points, dtype=np.float64)
    ge = _unit(edge_guides)
    n = len(p)
    if n < 2 or ge.shape != (n - 1, 3):
        raise ValueError(f"need n >= 2 points and (n - 1, 3) edge guides, got {p.shape}, "
                         f"{ge.shape}")
    # sign consistency along the polyline (the strip must not twist)
    for i in range(1, n - 1):
        if ge[i] @ ge[i - 1] < 0:
            ge[i] = -ge[i]
    e = _unit(np.diff(p, axis=0))
    b = _unit(np.cross(ge, e))  # (n-1, 3) bisector-plane normals
    out = np.empty((n, 3))
    out[0], out[-1] = ge[0], ge[-1]
    if n > 2:
        mean = 0.5 * (ge[:-1] + ge[1:])  # (n-2, 3)
        bb = (b[:-1, :, None] * b[:-1, None, :]) + (b[1:, :, None] * b[1:, None, :])
        mat = bb + lam * np.eye(3)[None]
        g = np.linalg.solve(mat, lam * mean[..., None])[..., 0]
        out[1:-1] = g
    return _unit(out)


def _tangents(p):
    d = np.diff(p, axis=0)
    return _unit(d)


def stroke_guides_from_mesh(points, vertices, faces, *, radius: float) -> np.ndarray:
    """Per-edge guides of a stroke from the surface normals on both of its sides.

    Parameters
    ----------
    points : (n, 3) float64
        Stroke polyline.
    vertices : (V, 3) float64, faces : (F, 3) int
        The current surface (e.g. the flow-aligned fit), consistently oriented.
    radius : float
        Faces whose centroid lies within ``radius`` of an edge midpoint contribute.

    Returns
    -------
    (n - 1, 3) float64
        Unit guides ``n1 + n2`` made orthogonal to the edge, where n1, n2 are the mean unit
        normals of the two sides (2-means of the face normals whose centroids lie within
        ``radius`` of the edge midpoint). For a crease this is the bisector of the two sides,
        pointing outside (Appendix A); a rounded surface gives the same direction. Where the
        two sides cancel the normal of the nearest face is used.
    """
    p = np.asarray(points, dtype=np.float64)
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    tri = v[f]
    cen = tri.mean(1)
    fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])  # area-weighted normals
    area = np.linalg.norm(fn, axis=1)
    tree = cKDTree(cen)
    mid = 0.5 * (p[1:] + p[:-1])
    t = _tangents(p)
    lists = tree.query_ball_point(mid, radius)
    _, nearest = tree.query(mid)
    out = np.empty((len(mid), 3))
    unit_fn = _unit(fn)
    for i, li in enumerate(lists):  # one small clustering per stroke edge (not per point)
        g = _two_sided_mean(unit_fn[li], area[li]) if len(li) else unit_fn[nearest[i]]
        g = g - (g @ t[i]) * t[i]
        if np.linalg.norm(g) < 1e-3:  # both sides cancel (a sheet folded flat): nearest face
            g = unit_fn[nearest[i]] - (unit_fn[nearest[i]] @ t[i]) * t[i]
        out[i] = g
    return _unit(out)


def _two_sided_mean(normals, weights, iters: int = 8):
    """Sum of the unit mean normals of the two sides (2-means on the normals).

    Seeded with the two most different normals; each side counts once whatever its number
    of faces, so an uneven triangulation does not tilt the bisector.
    """
    dots = normals @ normals.T
    i, j = np.unravel_index(np.argmin(dots), dots.shape)
    if dots[i, j] > 0.999:  # one side only (flat): its mean normal
        return (weights[:, None] * normals).sum(0)
    a, b = normals[i], normals[j]
    for _ in range(iters):
        side = (normals @ a) >= (normals @ b)
        if side.all() or not side.any():
            break
        a = _unit((weights[side, None] * normals[side]).sum(0))
        b = _unit((weights[~side, None] * normals[~side]).sum(0))
    return a + b


def strip_from_polyline(points, guides, width: float) -> tuple[np.ndarray, np.ndarray]:
    """Strip surface along a polyline: each vertex offset by ``+-width`` along its guide.

    Parameters
    ----------
    points : (n, 3) float64
    guides : (n, 3) float64
        Unit vertex guides (see :func:`guide_directions`).
    width : float
        Half-width w of the strip (Appendix A).

    Returns
    -------
    vertices : (2n, 3) float64
        ``points - w g`` (rows 0..n-1) then ``points + w g``.
    triangles : (2(n - 1), 3) int64
        Two triangles per polyline edge.
    """
    p = np.asarray(points, dtype=np.float64)
    g = _unit(guides)
    if p.shape != g.shape or p.ndim != 2 or len(p) < 2:
        raise ValueError(f"points and guides must both be (n >= 2, d), got {p.shape}, {g.shape}")
    if not (width > 0):
        raise ValueError(f"width must be positive, got {width!r}")
    n = len(p)
    verts = np.concatenate([p - width * g, p + width * g])
    i = np.arange(n - 1)
    tris = np.concatenate([np.stack([i, i + 1, n + i], 1), np.stack([i + 1, n + i + 1, n + i], 1)])
    return verts, tris.astype(np.int64)


def segment_strip_2d(corner, direction, width: float, *, pieces: int = 2
                     ) -> tuple[np.ndarray, np.ndarray]:
    """2D analogue of a strip: a segment through ``corner`` along ``direction``, ``+-width``.

    Parameters
    ----------
    corner : (2,) float64
        The crease point (a corner of a planar curve).
    direction : (2,) float64
        Guide (the corner's angle bisector).
    width : float
        Half-length.
    pieces : int
        Number of segments.

    Returns
    -------
    vertices : (pieces + 1, 2) float64, segments : (pieces, 2) int64
    """
    c = np.asarray(corner, dtype=np.float64)
    d = _unit(direction)
    s = np.linspace(-width, width, pieces + 1)
    verts = c[None] + s[:, None] * d[None]
    segs = np.stack([np.arange(pieces), np.arange(1, pieces + 1)], 1)
    return verts, segs.astype(np.int64)


def resample_by_step(p, step: float) -> np.ndarray:
    """A polyline resampled in equal arc-length pieces of at most ``step``.

    Parameters
    ----------
    p : (n, d) float64
    step : float
        Longest piece (same units as ``p``).

    Returns
    -------
    (k + 1, d) float64
        ``k = max(1, ceil(length / step))`` pieces (one for a zero-length stroke).
    """
    return resample_polyline(p, max(1, math.ceil(arc_length(p) / step)))


def _stroke_graph(strokes, tol):
    """End points merged within ``tol`` -> (edges (m, 2)) for the edge colouring."""
    ends = np.concatenate([[s[0], s[-1]] for s in strokes])
    tree = cKDTree(ends)
    pairs = tree.query_pairs(tol, output_type="ndarray")
    parent = np.arange(len(ends))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b in pairs:
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    roots = np.array([find(i) for i in range(len(ends))])
    _, ids = np.unique(roots, return_inverse=True)
    return ids.reshape(-1, 2)


def _extend(p, length):
    """Polyline extended at both ends by ``length`` along its end tangents."""
    if length <= 0:
        return p
    a = _unit(p[0] - p[min(2, len(p) - 1)])
    b = _unit(p[-1] - p[max(len(p) - 3, 0)])
    return np.concatenate([[p[0] + length * a], p, [p[-1] + length * b]])


def crease_feature_set(strokes, vertices, faces, *, width: float, spacing: float,
                       guide_radius: float, junction_tol: float | None = None,
                       extend: float | None = None):
    """Strips along crease strokes, guided by the surface, split into channels.

    Parameters
    ----------
    strokes : list of (n_i, 3) float64
        Crease strokes (same coordinates as the mesh).
    vertices, faces : the current surface.
    width : float
        Strip half-width.
    spacing : float
        Resampling step along the strokes (strip element size).
    guide_radius : float
        Neighbourhood of :func:`stroke_guides_from_mesh`.
    junction_tol : float, optional
        Stroke ends closer than this meet at a junction (default ``2 * spacing``).
    extend : float, optional
        Each stroke is prolonged by this much along its end tangents (default ``width``):
        the gradient of a feature function is log-singular on the strip's border dM, so the
        strip's ends must not cross the surface at corners or at gaps of split strokes.

    Returns
    -------
    verts : (k, 3) float64, tris : (m, 3) int64, channels : (m,) int64
        All strips; each stroke's triangles get the colour of the stroke in the stroke graph
        (strokes meeting at a junction get different channels, Sec. 3.3).
    """
    if not strokes:
        raise ValueError("crease_feature_set needs at least one crease stroke")
    from .sharpnet import edge_coloring

    tol = 2.0 * spacing if junction_tol is None else junction_tol
    colors = edge_coloring(_stroke_graph(strokes, tol), junctions_only=True)
    vs, ts, cs = [], [], []
    base = 0
    for k, s in enumerate(strokes):
        p = resample_by_step(_extend(np.asarray(s, dtype=np.float64),
                              width if extend is None else extend), spacing)
        if len(p) < 2:
            continue
        ge = stroke_guides_from_mesh(p, vertices, faces, radius=guide_radius)
        g = guide_directions(p, ge)
        v, t = strip_from_polyline(p, g, width)
        vs.append(v)
        ts.append(t + base)
        cs.append(np.full(len(t), colors[k], dtype=np.int64))
        base += len(v)
    return np.concatenate(vs), np.concatenate(ts), np.concatenate(cs)
