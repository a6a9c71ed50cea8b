"""Wireframes whose truth is known: plane sections of implicit surfaces, as curve networks.

A designer who draws a closed shape with a few strokes draws, roughly, sections:
rings and meridians. :func:`section_network` cuts an implicit surface ``F(x) = 0``
with planes (each section is traced by marching squares on the plane, its points
refined onto the surface), finds where sections of different planes cross (each
crossing solved exactly on the line the two planes share) and splits the sections
there into curves between shared junctions: a clean network, every curve on the
surface. The truth is the surface itself (:func:`implicit_mesh`, marching cubes).

The shapes of the genus benchmark (``benchmarks/bench_genus.py``): spheres from great
circles (:func:`great_circles`), capsules with rings (:func:`capsule`), a double torus
of two blended tori (:func:`double_torus`), tori cut by horizontal planes at any
heights and by half-planes at any angles (:func:`torus_sections`: rings and meridians
spaced unevenly); evenly spaced rings and meridians are
:func:`curvenet.datasets.shapes.torus`.

Examples
--------
>>> s = great_circles(3)
>>> s.network.number_of_vertices, s.network.number_of_edges, s.genus
(6, 12, 0)
"""

from __future__ import annotations

from functools import partial

import numpy as np
from scipy.spatial import cKDTree

from ..core.tolerances import DIVISION_GUARD
from ..model.network import CurveNetwork
from .shapes import AnalyticShape

__all__ = ["section_network", "implicit_mesh", "great_circles", "capsule", "double_torus",
           "torus_sections", "torus_sdf", "smooth_union"]

#: Grid cells per side of the sections traced on each plane.
SECTION_CELLS = 400
#: Newton steps that move traced points and crossings onto the surface.
NEWTON_STEPS = 8


def _grad(F, p, h):
    """Central-difference gradient of ``F`` at points ``(n, 3)``."""
    e = np.eye(3) * h
    return np.stack([(F(p + e[k]) - F(p - e[k])) / (2 * h) for k in range(3)], axis=1)


def _onto(F, p, h, normal=None):
    """Points moved onto ``F = 0`` by Newton steps along the gradient (within the plane of
    ``normal`` when given)."""
    p = np.array(p, np.float64)
    for _ in range(NEWTON_STEPS):
        g = _grad(F, p, h)
        if normal is not None:
            g = g - (g @ normal)[:, None] * normal
        p = p - (F(p) / np.maximum((g * g).sum(axis=1), DIVISION_GUARD))[:, None] * g
    return p


def _frame(normal):
    n = np.asarray(normal, np.float64)
    n = n / np.linalg.norm(n)
    a = np.eye(3)[int(np.argmin(np.abs(n)))]
    e1 = np.cross(n, a)
    e1 /= np.linalg.norm(e1)
    return n, e1, np.cross(n, e1)


def _sections(F, plane, lo, hi, cells):
    """Closed or open polylines of ``F = 0`` on one plane ``(point, normal[, keep])``."""
    from skimage.measure import find_contours
    p0, (n, e1, e2) = np.asarray(plane[0], np.float64), _frame(plane[1])
    corners = np.array(np.meshgrid(*zip(lo, hi), indexing="ij")).reshape(3, -1).T - p0
    u, v = corners @ e1, corners @ e2
    us, vs = np.linspace(u.min(), u.max(), cells), np.linspace(v.min(), v.max(), cells)
    U, V = np.meshgrid(us, vs, indexing="ij")
    grid = p0 + U[..., None] * e1 + V[..., None] * e2                     # (c, c, 3)
    vals = F(grid.reshape(-1, 3)).reshape(U.shape)
    h = (us[1] - us[0]) / 4
    out = []
    for c in find_contours(vals, 0.0):
        pts = (p0 + np.interp(c[:, 0], np.arange(cells), us)[:, None] * e1
               + np.interp(c[:, 1], np.arange(cells), vs)[:, None] * e2)
        closed = np.allclose(c[0], c[-1])
        pts = _onto(F, pts, h, n)
        if closed:
            pts[-1] = pts[0]
        if len(plane) < 3 or plane[2](pts.mean(axis=0)):
            out.append((pts, closed))
    return out, n, p0


def _crossings(F, poly, plane_a, plane_b, h):
    """Where ``poly`` (on plane a) crosses plane b: ``(segment index, point)`` each, the
    point solved on the line the planes share."""
    (na, _), (nb, pb) = plane_a, plane_b
    d = (poly - pb) @ nb
    seg = np.flatnonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)
    t = d[seg] / (d[seg] - d[seg + 1])
    guess = poly[seg] + t[:, None] * (poly[seg + 1] - poly[seg])
    u = np.cross(na, nb)
    u /= np.linalg.norm(u)
    x = guess
    for _ in range(NEWTON_STEPS):           # Newton along the line the planes share
        g = _grad(F, x, h) @ u
        x = x - (F(x) / np.where(np.abs(g) > DIVISION_GUARD, g, DIVISION_GUARD))[:, None] * u
    return seg, x


def section_network(F, planes, bounds, *, cells: int = SECTION_CELLS,
                    samples: int | None = None) -> CurveNetwork:
    """The curve network of the plane sections of ``F = 0``.

    Parameters
    ----------
    F : callable
        ``F(points (n, 3)) -> (n,)``, negative inside; smooth near the surface.
    planes : list of (point (3,), normal (3,)) or (point, normal, keep)
        The cutting planes; any two should meet the surface transversally. ``keep``,
        a predicate of a section's centroid ``(3,)``, drops the sections it refuses
        (a half-plane, in effect).
    bounds : ((3,), (3,))
        A box that holds the surface.
    cells : int
        Grid cells per side of each plane's tracing.
    samples : int, optional
        Points per curve (resampled by arc length); None keeps the traced points.

    Returns
    -------
    CurveNetwork
        Junctions where sections of two planes cross (shared exactly), one edge per
        stretch of section between junctions; a section that meets none is a loop.
    """
    lo, hi = (np.asarray(b, np.float64) for b in bounds)
    diag = float(np.linalg.norm(hi - lo))
    traced = []
    for k, plane in enumerate(planes):
        polys, _, _ = _sections(F, plane, lo, hi, cells)
        traced += [(k, poly, closed) for poly, closed in polys]
    frames = [(_frame(pl[1])[0], np.asarray(pl[0], np.float64)) for pl in planes]
    h = diag * 1e-5
    cuts = [[] for _ in traced]                      # per section: (segment, point)
    for i, (ki, pi, _) in enumerate(traced):
        for kj in range(len(planes)):
            if np.linalg.norm(np.cross(frames[ki][0], frames[kj][0])) > 1e-9:
                seg, x = _crossings(F, pi, frames[ki], frames[kj], h)
                cuts[i] += list(zip(seg.tolist(), x))
    # the same crossing found from both sections is one junction; a crossing found from
    # one side only meets a section that a half-plane left out
    pts = np.array([x for c in cuts for _, x in c]).reshape(-1, 3)
    label = np.arange(len(pts))
    for a, b in sorted(map(tuple, cKDTree(pts).query_pairs(1e-6 * diag,
                                                            output_type="ndarray"))):
        label[label == label[b]] = label[a]
    owner = np.repeat(np.arange(len(cuts)), [len(c) for c in cuts])
    uniq, inv = np.unique(label, return_inverse=True)
    shared = np.array([len(set(owner[inv == j])) >= 2 for j in range(len(uniq))], bool)
    index = np.cumsum(shared) - 1                     # junction id of each shared group
    net = CurveNetwork(np.array([pts[inv == j].mean(axis=0) for j in np.flatnonzero(shared)])
                       .reshape(-1, 3))
    offset = 0
    for (k, poly, closed), c in zip(traced, cuts):
        groups = inv[offset:offset + len(c)]
        offset += len(c)
        ok = shared[groups]
        # resampled points lie on the traced polyline's chords: put them back on F = 0
        _split(net, poly, closed, [x for x, keep in zip(c, ok) if keep], index[groups[ok]],
               samples, partial(_onto, F, h=h, normal=frames[k][0]))
    return net


def _split(net, poly, closed, cuts, ids, samples, onto):
    """Add one section's curves to ``net``, cut at its junctions; ``onto`` moves points
    ``(n, 3)`` back onto the surface within the section's plane."""
    from ..core.geometry import cumulative_length
    if not cuts:
        if closed:
            v = net.add_vertex(poly[0])
            net.add_edge(v, v, _resample(poly, samples, onto))
        return
    cum = cumulative_length(poly)
    seg = np.array([s for s, _ in cuts])
    x = np.array([p for _, p in cuts])
    frac = np.linalg.norm(x - poly[seg], axis=1) / np.maximum(
        np.linalg.norm(poly[seg + 1] - poly[seg], axis=1), DIVISION_GUARD)
    at = cum[seg] + frac * (cum[seg + 1] - cum[seg])
    order = np.argsort(at)
    at, x, ids = at[order], x[order], np.asarray(ids)[order]
    if closed:
        L = cum[-1]
        bounds = list(zip(at, np.r_[at[1:], at[0] + L], ids, np.r_[ids[1:], ids[:1]]))
        poly2 = np.concatenate([poly, poly[1:]])
        cum2 = np.concatenate([cum, cum[1:] + L])
    else:
        bounds = list(zip(at[:-1], at[1:], ids[:-1], ids[1:]))
        poly2, cum2 = poly, cum
    for a, b, u, v in bounds:
        inner = poly2[(cum2 > a) & (cum2 < b)]
        piece = np.concatenate([net.positions[u][None], inner, net.positions[v][None]])
        if len(piece) >= 2 and cumulative_length(piece)[-1] > 0:
            net.add_edge(int(u), int(v), _resample(piece, samples, onto))


def _resample(poly, samples, onto):
    if samples is None:
        return poly
    from ..core.geometry import resample_polyline
    out = onto(resample_polyline(poly, samples - 1))
    out[0], out[-1] = poly[0], poly[-1]
    return out


def implicit_mesh(F, bounds, resolution: int = 160):
    """The surface ``F = 0`` as a triangle mesh (marching cubes), ``trimesh.Trimesh``."""
    import trimesh
    from skimage.measure import marching_cubes
    lo, hi = (np.asarray(b, np.float64) for b in bounds)
    axes = [np.linspace(lo[k], hi[k], resolution) for k in range(3)]
    X = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
    vals = F(X.reshape(-1, 3)).reshape(X.shape[:3])
    spacing = tuple((hi - lo) / (resolution - 1))
    v, f, _, _ = marching_cubes(vals, 0.0, spacing=spacing)
    return trimesh.Trimesh(v + lo, f, process=True)


def torus_sdf(centre=(0.0, 0.0, 0.0), major: float = 1.0, minor: float = 0.4):
    """Signed distance to a torus around the z axis through ``centre``: a callable."""
    c = np.asarray(centre, np.float64)

    def F(p):
        q = np.asarray(p, np.float64) - c
        rho = np.hypot(q[:, 0], q[:, 1])
        return np.hypot(rho - major, q[:, 2]) - minor
    return F


def smooth_union(fs, k: float = 12.0):
    """Soft minimum ``-log(sum exp(-k f_i)) / k`` of implicit functions: a blended union."""
    def F(p):
        vals = np.stack([f(p) for f in fs])
        m = vals.min(axis=0)
        return m - np.log(np.exp(-k * (vals - m)).sum(axis=0)) / k
    return F


def _shape(name, F, planes, bounds, genus, samples):
    net = section_network(F, planes, bounds, samples=samples)
    return AnalyticShape(name, net, [], True, genus,
                         reference=lambda s: implicit_mesh(F, bounds, 40 * 2 ** min(s, 3)))


def great_circles(n: int = 3, *, normals=None, radius: float = 1.0,
                  samples: int = 33) -> AnalyticShape:
    """A sphere drawn as great circles: ``n`` of them (3: the octants; 4: the
    cuboctahedron's), or one per row of ``normals (k, 3)`` (their planes' normals; in
    general position the faces have three or more sides, some small)."""
    if normals is None:
        normals = {3: np.eye(3),
                   4: np.array([[1, 1, 1], [1, 1, -1], [1, -1, 1], [-1, 1, 1]], float)}[n]
    normals = np.asarray(normals, np.float64)
    b = 1.2 * radius
    return _shape(f"sphere_{len(normals)}_circles", lambda p: np.linalg.norm(p, axis=1) - radius,
                  [((0, 0, 0), nrm) for nrm in normals], ((-b,) * 3, (b,) * 3), 0, samples)


def capsule(*, radius: float = 0.5, length: float = 1.0, rings: int = 3, meridians: int = 2,
            samples: int = 33) -> AnalyticShape:
    """A capsule along z (a cylinder with hemispherical ends) drawn as ``rings``
    horizontal sections and ``meridians`` vertical sections through its axis."""
    def F(p):
        q = np.asarray(p, np.float64)
        z = np.clip(q[:, 2], -length / 2, length / 2)
        return np.linalg.norm(q - np.c_[0 * z, 0 * z, z], axis=1) - radius

    zs = np.linspace(-length / 2, length / 2, rings + 2)[1:-1] if rings > 1 else [0.0]
    planes = [((0, 0, z), (0, 0, 1)) for z in zs]
    planes += [((0, 0, 0), (np.cos(a), np.sin(a), 0))
               for a in np.pi * (np.arange(meridians) + 0.5) / meridians]
    b = radius * 1.2
    return _shape(f"capsule_{rings}x{meridians}", F, planes,
                  ((-b, -b, -length / 2 - b), (b, b, length / 2 + b)), 0, samples)


def torus_sections(major: float = 1.0, minor: float = 0.4, *, heights=(0.0,),
                   angles=(0.0, 120.0, 240.0), aspect: float = 1.0, tilts=None,
                   samples: int = 33) -> AnalyticShape:
    """A torus around z drawn as horizontal sections and meridians, spaced as given.

    Parameters
    ----------
    major, minor : float
        Radii (``minor``: the tube's radius across, in the equator's plane).
    heights : sequence of float
        Heights of the horizontal cutting planes, fractions of the tube's half-height
        in (-1, 1); each plane gives two rings (0: the outer and inner equators).
    angles : sequence of float
        Degrees about z of the meridians (each the section of a half-plane).
    aspect : float
        The tube's half-height over ``minor``: 1 a round tube, else an elliptic one
        (no longer an elementary surface).
    tilts : sequence of (float, float), optional
        Per horizontal plane, its normal tilted off the axis by the first angle
        (degrees) towards the direction at the second angle about z (a plane tilted
        so little that it still meets the tube all round gives two rings that are not
        circles, and sections whose arcs of the tube differ from meridian to meridian).
    samples : int
        Points per curve.

    Examples
    --------
    >>> s = torus_sections(heights=(0.0, 0.7), angles=(0, 90, 180, 270))
    >>> s.network.number_of_edges - s.network.number_of_vertices + 2 - 2 * s.genus
    16
    >>> e = torus_sections(1.0, 0.2, angles=(0, 120, 240), aspect=2.0)  # a tall tube
    >>> p = np.concatenate([c.curve for c in e.network.edges])
    >>> rho = np.hypot(p[:, 0], p[:, 1])
    >>> bool(np.abs(np.hypot((rho - 1.0) / 0.2, p[:, 2] / 0.4) - 1.0).max() < 1e-3)
    True
    """
    if aspect <= 0:
        raise ValueError(f"aspect: expected > 0, got {aspect!r}")
    half = minor * aspect
    tilts = np.asarray(tilts if tilts is not None else [(0.0, 0.0)] * len(heights), np.float64)
    if tilts.shape != (len(heights), 2):
        raise ValueError(f"tilts: expected one (angle, direction) per height, got shape "
                         f"{tilts.shape} for {len(heights)} heights")
    tilts = np.radians(tilts)
    planes = [((0, 0, h * half), (np.sin(t) * np.cos(d), np.sin(t) * np.sin(d), np.cos(t)))
              for h, (t, d) in zip(heights, tilts)]
    for a in np.radians(np.asarray(angles, np.float64)):
        d = np.array([np.cos(a), np.sin(a), 0.0])
        planes.append(((0, 0, 0), (-d[1], d[0], 0.0), lambda c, d=d: float(c @ d) > 0))
    b = major + minor + 0.2 * major
    name = (f"torus r{minor / major:g}{f' x{aspect:g}' if aspect != 1 else ''} "
            f"h{','.join(f'{h:g}' for h in heights)} a{','.join(f'{a:g}' for a in angles)}"
            + (f" t{','.join(f'{np.degrees(t):.3g}' for t in tilts[:, 0])}"
               if tilts[:, 0].any() else ""))
    round_tube = torus_sdf((0.0, 0.0, 0.0), major, minor)

    def F(p):                   # the round tube's distance with z scaled: the same zero set
        return round_tube(np.asarray(p, np.float64) * [1.0, 1.0, 1.0 / aspect]) * min(1.0, aspect)
    return _shape(name, F, planes,
                  ((-b, -b, -half - 0.2 * major), (b, b, half + 0.2 * major)), 1, samples)


def double_torus(*, major: float = 1.0, minor: float = 0.35, meridians: int = 3,
                 rings=(0.0,), samples: int = 33) -> AnalyticShape:
    """Genus 2: two tori side by side whose tubes meet at the origin, blended
    (:func:`smooth_union`); drawn as horizontal sections at heights ``rings`` (fractions
    of ``minor``) and, per torus, ``meridians`` vertical planes through its axis (each
    gives two meridians; the one through the blended middle is left out)."""
    F = smooth_union([torus_sdf((-major, 0, 0), major, minor),
                      torus_sdf((major, 0, 0), major, minor)])
    planes = [((0, 0, h * minor), (0, 0, 1)) for h in rings]
    for side in (-1.0, 1.0):        # each torus's meridians, not the one through the blend
        for a in np.pi * (np.arange(meridians) + 0.5) / meridians:
            planes.append(((side * major, 0, 0), (np.cos(a), np.sin(a), 0),
                           lambda c, side=side: side * c[0] > 0.5 * major))
    b = major + minor + 0.3
    return _shape(f"double_torus_{len(rings)}x{meridians}", F, planes,
                  ((-major - b, -b, -minor - 0.3), (major + b, b, minor + 0.3)), 2, samples)
