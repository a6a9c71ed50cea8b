"""Geometric primitives shared by the graph code and both backends.

Polylines: validation, arc length, interpolation at arc-length parameters,
resampling; triangle meshes: face normals and areas, boundary edges, area-uniform
random sampling (trimesh's :func:`trimesh.sample.sample_surface`), a curved 1-to-4
subdivision. Everything takes and returns numpy arrays; nothing here imports torch or
another curvenet module (the neural backend converts the samples to tensors itself).

Notes
-----
A polyline is an ``(n, d) float64`` array of ``n >= 2`` points (``d = 3`` for
strokes and curves); its arc-length parameter at point ``i`` is the summed
length of the segments before it. Every function is vectorised over points.
"""

from __future__ import annotations

import numpy as np

from .errors import InvalidParameterError

from .tolerances import DIVISION_GUARD, ZERO_LENGTH

__all__ = [
    "as_polyline",
    "cumulative_length",
    "arc_length",
    "arc_length_params",
    "interpolate_polyline",
    "densify_polylines",
    "segment_closest",
    "sample_at",
    "resample_polyline",
    "densify_polyline",
    "face_normals_areas",
    "face_edges",
    "mesh_edges",
    "harmonic_fill",
    "boundary_edges",
    "subdivide_curved",
    "sample_surface",
    "fit_plane",
    "bbox_diagonal",
]


def bbox_diagonal(points) -> float:
    """Length of the diagonal of the axis-aligned bounding box of ``points`` ``(n, d)``,
    or of a list of such arrays (their points together); 0 for no points.

    The unit of the package's relative tolerances (a fraction of "the diagonal").

    Examples
    --------
    >>> bbox_diagonal(np.array([[0.0, 0, 0], [3, 4, 0]]))
    5.0
    >>> bbox_diagonal([np.zeros((1, 3)), np.array([[0.0, 0, 12]])])
    12.0
    """
    if isinstance(points, (list, tuple)) and points and np.ndim(points[0]) == 2:
        points = np.concatenate([np.asarray(p, np.float64) for p in points])
    p = np.asarray(points, np.float64)
    if p.size == 0:
        return 0.0
    return float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))


# --------------------------------------------------------------------------- polylines
def as_polyline(points, *, name: str = "polyline", min_points: int = 2) -> np.ndarray:
    """Validate and convert one polyline (a stroke, a curve, a boundary).

    Parameters
    ----------
    points : array_like, (n, 3)
        Finite points; an empty input counts as ``(0, 3)``.
    name : str
        Names the parameter in error messages (``"strokes[4]"``).
    min_points : int
        Fewest points accepted.

    Returns
    -------
    (n, 3) float64 ndarray
        A C-contiguous copy.

    Raises
    ------
    InvalidParameterError
        Not numbers, a number beyond the float range, wrong shape, fewer than
        ``min_points`` points, or a NaN/inf coordinate.

    Examples
    --------
    >>> as_polyline([[0, 0, 0], [1, 0, 0]]).dtype
    dtype('float64')
    """
    try:
        arr = np.array(points, dtype=np.float64, copy=True)
    except (TypeError, ValueError):
        raise InvalidParameterError(f"{name}: points are not numbers") from None
    except OverflowError:  # an integer beyond the float range (JSON allows any)
        raise InvalidParameterError(f"{name}: a coordinate is too large for a float") from None
    if arr.size == 0:
        arr = arr.reshape(0, 3)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise InvalidParameterError(f"{name}: expected an (n, 3) array, got shape {arr.shape}")
    if arr.shape[0] < min_points:
        raise InvalidParameterError(
            f"{name}: needs at least {min_points} points, got {arr.shape[0]}")
    if not np.isfinite(arr).all():
        raise InvalidParameterError(f"{name}: contains NaN or infinite coordinates")
    return np.ascontiguousarray(arr)


def cumulative_length(polyline: np.ndarray) -> np.ndarray:
    """Arc length from the first point to each point.

    Parameters
    ----------
    polyline : (n, d) float64

    Returns
    -------
    (n,) float64
        ``0`` first, the total length last, non-decreasing.

    Examples
    --------
    >>> cumulative_length(np.array([[0.0, 0], [3, 4], [3, 5]])).tolist()
    [0.0, 5.0, 6.0]
    """
    p = np.asarray(polyline, dtype=np.float64)
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])


def arc_length(polyline: np.ndarray) -> float:
    """Total length of a polyline (``cumulative_length(polyline)[-1]``).

    Examples
    --------
    >>> arc_length(np.array([[0.0, 0, 0], [1, 0, 0], [1, 2, 0]]))
    3.0
    """
    return float(cumulative_length(polyline)[-1])


def arc_length_params(polyline: np.ndarray) -> np.ndarray:
    """Normalised cumulative arc length of a polyline.

    Parameters
    ----------
    polyline : (n, d) float64

    Returns
    -------
    t : (n,) float64
        ``t[0] = 0``, ``t[-1] = 1``, non-decreasing. A curve of length at most
        :data:`~curvenet.core.tolerances.ZERO_LENGTH` gets uniform parameters
        ``index / (n - 1)``.
    """
    cum = cumulative_length(polyline)
    total = cum[-1]
    if total <= ZERO_LENGTH:
        return np.linspace(0.0, 1.0, len(cum))
    return cum / total


def interpolate_polyline(polyline: np.ndarray, s, *, cum=None,
                         extrapolate: bool = False) -> np.ndarray:
    """Points of a polyline at arc-length parameters ``s`` (linear interpolation).

    Parameters
    ----------
    polyline : (n, d) float64, n >= 2
    s : (k,) float64
        Parameters in the units of ``cum``.
    cum : (n,) float64, optional
        Non-decreasing parameter of each point; default :func:`cumulative_length`.
        Pass :func:`arc_length_params` for normalised parameters.
    extrapolate : bool
        Continue the first and last segments linearly past the ends; otherwise
        ``s`` is clamped to ``[cum[0], cum[-1]]``.

    Returns
    -------
    (k, d) float64

    Notes
    -----
    A zero-length segment is never interpolated inside: ``s`` there equals its
    start parameter and the result is its start point.

    Examples
    --------
    >>> line = np.array([[0.0, 0, 0], [2, 0, 0]])
    >>> interpolate_polyline(line, [0.5, 3.0])[:, 0].tolist()
    [0.5, 2.0]
    >>> interpolate_polyline(line, [3.0], extrapolate=True)[:, 0].tolist()
    [3.0]
    """
    p = np.asarray(polyline, dtype=np.float64)
    cum = cumulative_length(p) if cum is None else np.asarray(cum, dtype=np.float64)
    s = np.asarray(s, dtype=np.float64)
    if not extrapolate:
        s = np.clip(s, cum[0], cum[-1])
    j = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(cum) - 2)
    seg = cum[j + 1] - cum[j]
    t = np.where(seg > 0, (s - cum[j]) / np.where(seg > 0, seg, 1.0), 0.0)
    return p[j] + t[:, None] * (p[j + 1] - p[j])


def sample_at(polyline: np.ndarray, t) -> np.ndarray:
    """Points of a polyline at normalised arc-length parameters ``t`` in ``[0, 1]``.

    Parameters
    ----------
    polyline : (n, d) float64
    t : (k,) float64
        Clamped to ``[0, 1]``; see :func:`arc_length_params` for a zero-length curve.

    Returns
    -------
    (k, d) float64
    """
    return interpolate_polyline(polyline, t, cum=arc_length_params(polyline))


def resample_polyline(polyline: np.ndarray, n_segments: int) -> np.ndarray:
    """Resample a polyline into ``n_segments`` pieces of equal arc length.

    Parameters
    ----------
    polyline : (n, d) float64
    n_segments : int, >= 1

    Returns
    -------
    (n_segments + 1, d) float64
        First and last points are exactly ``polyline[0]`` and ``polyline[-1]``.

    Examples
    --------
    >>> resample_polyline(np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0]]), 4).tolist()[2]
    [1.0, 0.0, 0.0]
    """
    p = np.asarray(polyline, dtype=np.float64)
    out = sample_at(p, np.linspace(0.0, 1.0, int(n_segments) + 1))
    out[0], out[-1] = p[0], p[-1]
    return out


def densify_polyline(polyline: np.ndarray, max_step: float) -> np.ndarray:
    """Insert points so that consecutive points are at most ``max_step`` apart.

    Every segment is split into ``ceil(length / max_step)`` equal pieces (at least
    one); the original points are kept.

    Parameters
    ----------
    polyline : (n, d) float64
    max_step : float, > 0

    Returns
    -------
    (m, d) float64
        The input itself when ``n < 2``.

    Examples
    --------
    >>> densify_polyline(np.array([[0.0, 0, 0], [1, 0, 0]]), 0.4)[:, 0].tolist()
    [0.0, 0.3333333333333333, 0.6666666666666666, 1.0]
    """
    p = np.asarray(polyline, dtype=np.float64)
    if len(p) < 2:
        return p
    seg = np.diff(p, axis=0)                                              # (n - 1, d)
    steps = np.maximum(np.ceil(np.linalg.norm(seg, axis=1) / max_step).astype(np.int64), 1)
    seg_id = np.repeat(np.arange(len(seg)), steps)
    start = np.cumsum(steps) - steps
    t = (np.arange(steps.sum()) - start[seg_id]) / steps[seg_id]          # 0, 1/k, ...
    return np.concatenate([p[seg_id] + t[:, None] * seg[seg_id], p[-1:]])


# --------------------------------------------------------------------------- triangles
def densify_polylines(polylines, max_step: float):
    """:func:`densify_polyline` of many polylines at once (the same points).

    Parameters
    ----------
    polylines : list of (n_k, d) float64, n_k >= 1
    max_step : float, > 0

    Returns
    -------
    points : (m, d) float64
        The densified polylines one after the other.
    counts : (K,) int64
        Points of each.

    Examples
    --------
    >>> pts, counts = densify_polylines([np.array([[0.0, 0], [1, 0]]), np.zeros((1, 2))], 0.4)
    >>> counts.tolist(), pts[:, 0].tolist()
    ([4, 1], [0.0, 0.3333333333333333, 0.6666666666666666, 1.0, 0.0])
    """
    sizes = np.array([len(p) for p in polylines], np.int64)
    p = np.concatenate([np.asarray(q, dtype=np.float64) for q in polylines])
    last = np.cumsum(sizes) - 1
    seg = np.diff(p, axis=0)                                              # (N - 1, d)
    steps = np.maximum(np.ceil(np.linalg.norm(seg, axis=1) / max_step).astype(np.int64), 1)
    steps[last[:-1]] = 1                   # a polyline's last point, before the next's first
    seg_id = np.repeat(np.arange(len(seg)), steps)
    start = np.cumsum(steps) - steps
    t = (np.arange(steps.sum()) - start[seg_id]) / steps[seg_id]          # 0, 1/k, ...
    out = np.concatenate([p[seg_id] + t[:, None] * seg[seg_id], p[-1:]])
    # the step from each last point to the next polyline is that last point alone
    counts = np.add.reduceat(np.append(steps, 1), np.concatenate([[0], last[:-1] + 1]))
    return out, counts


def segment_closest(p0, p1, q0, q1):
    """Closest points of segment pairs, batched (Ericson, Real-Time Collision Detection 5.1.9).

    Parameters
    ----------
    p0, p1, q0, q1 : (n, 3) float64
        Segments ``p0 -> p1`` and ``q0 -> q1``.

    Returns
    -------
    s, t : (n,) float64 in [0, 1]
        The closest points are ``p0 + s (p1 - p0)`` and ``q0 + t (q1 - q0)``.
    """
    d1, d2, r = p1 - p0, q1 - q0, p0 - q0
    a = np.maximum(np.einsum("ij,ij->i", d1, d1), DIVISION_GUARD)  # guard: degenerate segments
    e = np.maximum(np.einsum("ij,ij->i", d2, d2), DIVISION_GUARD)
    b = np.einsum("ij,ij->i", d1, d2)
    c = np.einsum("ij,ij->i", d1, r)
    f = np.einsum("ij,ij->i", d2, r)
    denom = a * e - b * b
    par = denom <= 1e-12 * a * e  # parallel (sin^2 of the angle < 1e-12; local): take the start
    s = np.where(par, 0.0, np.clip((b * f - c * e) / np.where(par, 1.0, denom), 0.0, 1.0))
    t = (b * s + f) / e
    s = np.where(t < 0, np.clip(-c / a, 0, 1), np.where(t > 1, np.clip((b - c) / a, 0, 1), s))
    return s, np.clip(t, 0.0, 1.0)


def face_normals_areas(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals and areas of triangles.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64

    Returns
    -------
    normals : (F, 3) float64
        Right-handed (counter-clockwise) unit normals; zero for a zero-area face.
    areas : (F,) float64
    """
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)]       # (F, 3, 3)
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])        # (F, 3)
    norm = np.linalg.norm(cross, axis=1)
    normals = cross / np.maximum(norm, DIVISION_GUARD)[:, None]           # zero area
    return normals, 0.5 * norm


def boundary_edges(faces: np.ndarray) -> np.ndarray:
    """Edges used by exactly one triangle (the boundary of a mesh).

    Parameters
    ----------
    faces : (F, 3) int

    Returns
    -------
    (E, 2) int64
        Vertex ids, the smaller first in each row, rows in lexicographic order.

    Examples
    --------
    >>> boundary_edges(np.array([[0, 1, 2], [2, 1, 3]])).tolist()
    [[0, 1], [0, 2], [1, 3], [2, 3]]
    """
    edges, count = mesh_edges(faces)
    return edges[count == 1]


def mesh_edges(faces) -> tuple[np.ndarray, np.ndarray]:
    """Each edge of a triangle mesh once, the smaller id first, rows in lexicographic
    order: (e, 2) int64; and the number of triangles using each: (e,) int64.

    Examples
    --------
    >>> edges, uses = mesh_edges(np.array([[0, 1, 2], [2, 1, 3]]))
    >>> edges.tolist(), uses.tolist()
    ([[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]], [1, 1, 2, 1, 1])
    """
    e = face_edges(faces)
    base = int(e.max(initial=0)) + 1        # one integer key per edge: a 1-D sort
    keys, uses = np.unique(e[:, 0] * base + e[:, 1], return_counts=True)
    return np.stack(np.divmod(keys, base), axis=1), uses


def face_edges(faces) -> np.ndarray:
    """(3 F, 2) int64: each triangle's edges ``ab, bc, ca`` in turn, the smaller id first
    (row ``3 i + k`` is edge ``k`` of face ``i``).

    Examples
    --------
    >>> face_edges(np.array([[2, 0, 1]])).tolist()
    [[0, 2], [0, 1], [1, 2]]
    """
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    return np.sort(f[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)


def harmonic_fill(edges, inner, values) -> np.ndarray:
    """Values at the ``inner`` vertices of a graph made harmonic (each the mean of its
    neighbours', the uniform graph Laplacian's Dirichlet problem) given the others.

    Parameters
    ----------
    edges : (e, 2) int64
        Undirected edges, each once.
    inner : (n,) bool
        Vertices whose values are solved for; every connected set of them must touch
        another vertex.
    values : (n,) or (n, k) float64
        Known values at the vertices not ``inner`` (those at ``inner`` are ignored).

    Returns
    -------
    (n,) or (n, k) float64
        A copy of ``values`` with the ``inner`` entries replaced.

    Examples
    --------
    >>> harmonic_fill(np.array([[0, 1], [1, 2], [2, 3]]), np.array([0, 1, 1, 0], bool),
    ...               np.array([0.0, 9.0, 9.0, 3.0])).tolist()
    [0.0, 1.0, 2.0, 3.0]
    """
    from scipy.sparse import coo_matrix, diags
    from scipy.sparse.linalg import spsolve
    inner = np.asarray(inner, dtype=bool)
    out = np.array(values, dtype=np.float64)
    ids = np.flatnonzero(inner)
    if not len(ids):
        return out
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    a, b = edges[inner[edges[:, 0]] | inner[edges[:, 1]]].T      # edges that touch them
    A_i = coo_matrix((np.ones(2 * len(a)), (np.r_[a, b], np.r_[b, a])),
                     shape=(len(inner),) * 2).tocsr()[ids]
    known = np.where(inner.reshape((-1,) + (1,) * (out.ndim - 1)), 0.0, out)
    L = diags(np.asarray(A_i.sum(axis=1)).ravel()) - A_i[:, ids]
    out[ids] = np.asarray(spsolve(L.tocsc(), A_i @ known)).reshape(out[ids].shape)
    return out


def subdivide_curved(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One 1-to-4 subdivision whose new vertices lie on the curved PN triangles.

    Each edge gets one new vertex: the midpoint of the cubic Hermite curve between its
    ends that leaves each end in its tangent plane (the edge of a curved point-normal
    triangle, Vlachos et al. 2001), ``(p + q) / 2 + ((e . n_q) n_q - (e . n_p) n_p) / 8``
    with ``e = q - p`` and ``n`` the angle-weighted vertex normals. On a mesh whose
    vertices lie on a smooth surface the flat midpoint is ``e^2 kappa / 8`` off it; the
    curved one is off by the error of the estimated normals times the edge, of the same
    order in ``e`` with a constant about an order smaller: the facets' chord error drops
    by that much, at four times the triangles. A flat region stays flat. The old
    vertices stay; each triangle ``(a, b, c)`` becomes ``(a, ab, ca), (b, bc, ab),
    (c, ca, bc), (ab, bc, ca)`` (orientation kept, so a watertight mesh stays watertight
    with the same Euler characteristic).

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64

    Returns
    -------
    vertices : (V + E, 3) float64
        The old vertices, then one per edge (``E`` unique edges).
    faces : (4 F, 3) int64
    """
    V = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    tri = V[f]                                                               # (F, 3, 3)
    unit, area = face_normals_areas(V, f)
    # angle-weighted vertex normals (each face's normal by its angle at the corner): on
    # the uneven triangles of marching cubes, steadier than area weights. The sine side
    # |u x w| is twice the face's area at every corner.
    u = np.roll(tri, -1, axis=1) - tri                                       # corner -> next
    w = np.roll(tri, 1, axis=1) - tri                                        # corner -> previous
    angle = np.arctan2(2.0 * area[:, None], (u * w).sum(axis=2))
    contrib = (angle[:, :, None] * unit[:, None, :]).reshape(-1, 3)
    n = np.stack([np.bincount(f.ravel(), contrib[:, k], minlength=len(V)) for k in range(3)],
                 axis=1)
    n /= np.maximum(np.linalg.norm(n, axis=1), DIVISION_GUARD)[:, None]     # unused: zero
    edges, inverse = np.unique(face_edges(f), axis=0, return_inverse=True)
    p, q = V[edges[:, 0]], V[edges[:, 1]]
    np_, nq = n[edges[:, 0]], n[edges[:, 1]]
    e = q - p
    mid = 0.5 * (p + q) + ((e * nq).sum(1)[:, None] * nq - (e * np_).sum(1)[:, None] * np_) / 8.0
    m = len(V) + inverse.reshape(-1, 3)                  # (F, 3): ab, bc, ca
    a, b, c = f.T
    ab, bc, ca = m.T
    out = np.concatenate([np.stack(t, axis=1) for t in
                          ((a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca))])
    return np.vstack([V, mid]), out


def sample_surface(vertices: np.ndarray, faces: np.ndarray, n: int, seed=None, *,
                   areas=None) -> tuple[np.ndarray, np.ndarray]:
    """Area-weighted uniform random points on a triangle mesh.

    Parameters
    ----------
    vertices : (V, 3) float64
    faces : (F, 3) int64
    n : int
        Number of points.
    seed : int, numpy.random.Generator or None
        A generator is used (and advanced) as given, so one stream can be threaded
        through several calls; an int seeds a fresh one.
    areas : (F,) float64, optional
        Triangle areas if already known (any positive multiple works: they are
        sampling weights).

    Returns
    -------
    points : (n, 3) float64
    face_index : (n,) int64
        The triangle each point lies on.

    Raises
    ------
    InvalidParameterError
        No faces, or all of them of zero area.

    Notes
    -----
    Delegates to :func:`trimesh.sample.sample_surface`: a triangle is drawn with
    probability proportional to its area, then a point uniformly inside it by
    folding a uniform point of the parallelogram spanned by two edges back into the
    triangle.

    Examples
    --------
    >>> tri = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> p, f = sample_surface(tri, np.array([[0, 1, 2]]), 100, seed=0)
    >>> bool((p.sum(axis=1) <= 1).all()), f.max()
    (True, np.int64(0))
    """
    import trimesh

    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if areas is None:
        areas = face_normals_areas(v, f)[1]
    areas = np.asarray(areas, dtype=np.float64)
    if len(f) == 0 or not areas.sum() > 0:
        raise InvalidParameterError("faces: no triangle of positive area to sample")
    mesh = trimesh.Trimesh(vertices=v, faces=f, process=False, validate=False)
    points, face_index = trimesh.sample.sample_surface(mesh, int(n), face_weight=areas,
                                                       seed=seed)
    return np.asarray(points, dtype=np.float64), np.asarray(face_index, dtype=np.int64)


# --------------------------------------------------------------------------- planes
def fit_plane(points):
    """Least-squares plane of a point set.

    Parameters
    ----------
    points : (n, 3) float64, n >= 1

    Returns
    -------
    centroid : (3,) float64
    normal : (3,) float64
        Unit normal: the direction of least spread.
    axes : (2, 3) float64
        Unit in-plane directions, of most spread first; with ``normal`` an orthonormal
        frame even when the points are fewer than three or collinear.

    Examples
    --------
    >>> c, n, axes = fit_plane(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]))
    >>> np.abs(n).round(6).tolist()
    [0.0, 0.0, 1.0]
    """
    points = np.asarray(points, dtype=np.float64)
    c = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - c, full_matrices=False)
    if len(vt) < 3:  # fewer than three points: pad with zero rows to complete the frame
        vt = np.linalg.svd(np.vstack([points - c, np.zeros((3 - len(vt), 3))]))[2]
    return c, vt[2], vt[:2]
