"""Bands of revolution: analytic seam patches meshed as rings about their axis.

A CAD part's bore wall, a pin's pointed tip and a dome are one face of a surface of
revolution, bounded by one loop: its parallels (circles about the axis) and a seam, a
meridian walked up and back. The Catmull-Clark surface of such a loop is a poor start
where the seam ends at the axis (a cone's apex, a sphere's pole): two of its sides
collapse to a point, the fitted surface folds there, and no projection onto the cone
or sphere unfolds it. Such a patch is the surface between its parallels, over one
turn; :func:`mesh_bands` meshes it so: one ring of vertices at the height of every
output vertex of the seam (the seam vertex rotated about the axis), the parallels'
own output vertices as the end rings (shared with the neighbouring patches, so the
mesh stays welded), a single vertex at an apex or pole, and consecutive rings zipped
into triangles by angle. The mesh is then the face the CAD output writes (the
surface between its two heights, :mod:`curvenet.cad.faces`), so both agree.
"""

from __future__ import annotations

import numpy as np

from .analytic import AnalyticSurface
from .arcs import fit_circle, in_axis_frame
from .flat import replace_faces

__all__ = ["band_frame", "mesh_bands"]

#: Kinds whose seam patches :func:`mesh_bands` meshes (surfaces of revolution).
REVOLVED = ("cylinder", "cone", "sphere", "torus")


def _seam(loop):
    """The curve a loop walks twice (its seam), or None."""
    ids = [c for c, _ in loop]
    twice = {c for c in ids if ids.count(c) == 2}
    return next(iter(twice)) if len(twice) == 1 else None


def band_frame(surface: AnalyticSurface, boundary, curves, tol: float):
    """Axis of a seam patch of a surface of revolution bounded by parallels, or None.

    Parameters
    ----------
    surface : AnalyticSurface
    boundary : list of list of (int, bool)
        The patch's loops: one, walking its seam twice.
    curves : list of (m_i, 3) float64
    tol : float
        Model units: how far the parallels' samples may lie off one circle about the
        axis, and the seam's off one meridian.

    Returns
    -------
    (origin (3,), axis (3,), seam curve id) or None
        None when the patch is not such a band (holes, no seam, a curve that is no
        parallel, a seam that is no meridian).
    """
    if surface is None or surface.kind not in REVOLVED or len(boundary) != 1:
        return None
    seam = _seam(boundary[0])
    if seam is None:
        return None
    rims = [np.asarray(curves[c], np.float64) for c in {c for c, _ in boundary[0]} - {seam}]
    if not rims:
        return None
    origin, axis = np.asarray(surface.origin, np.float64), np.asarray(surface.axis, np.float64)
    if surface.kind == "sphere":         # its axis is the parallels' normal through the centre
        got = fit_circle(rims[0])
        if got is None:
            return None
        axis = got[1]
    for c in rims:
        z, rho, _ = _cylindrical(c, origin, axis)
        if np.ptp(z) > tol or np.ptp(rho) > tol:
            return None
    s = np.asarray(curves[seam], np.float64)
    _, rho, ang = _cylindrical(s, origin, axis)
    off = rho * np.abs(np.angle(np.exp(1j * (ang - ang[np.argmax(rho)]))))
    if off.max() > tol:
        return None
    return origin, axis, seam


def _cylindrical(p, origin, axis):
    """Height along the axis, distance from it and angle about it (any fixed frame) of
    points ``p`` (n, 3): three (n,) float64."""
    x, y, z, _, _ = in_axis_frame(np.asarray(p, np.float64), axis, origin)
    return z, np.hypot(x, y), np.arctan2(y, x)


def _zip(a, alpha, b, beta):
    """Triangles between two closed rings of vertex ids ``a``, ``b`` at increasing angles
    ``alpha``, ``beta`` (each from 0, the seam, below 2 pi): (t, 3) int64, a ring of one
    vertex (an apex) giving a fan."""
    na, nb = len(a), len(b)
    step = np.r_[alpha[1:], 2 * np.pi, beta[1:], 2 * np.pi]
    on_a = np.r_[np.ones(na, bool), np.zeros(nb, bool)]
    order = np.lexsort((~on_a, step))
    on_a = on_a[order]
    i = np.cumsum(on_a) - on_a
    j = np.cumsum(~on_a) - ~on_a
    tri = np.where(on_a[:, None],
                   np.c_[a[i % na], a[(i + 1) % na], b[j % nb]],
                   np.c_[a[i % na], b[(j + 1) % nb], b[j % nb]])
    keep = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])
    return tri[keep]


def _band(V, frame, seam_ids, rims):
    """New vertices and triangles of one band.

    ``seam_ids``: the seam's output vertex ids in order; ``rims``: per end of the seam
    (0 and -1) the output vertex ids of the parallels there, or None where the seam
    ends on the axis. Returns ``(new (k, 3) float64, triangles (t, 3) int64)``, the new
    vertices numbered from ``len(V)``. A ring has about the vertex spacing of the
    parallels along it."""
    origin, axis = frame
    _, rho_s, ang_s = _cylindrical(V[seam_ids], origin, axis)
    last = len(seam_ids) - 1
    ends, spacings = {}, []
    for k, ids in ((0, rims[0]), (last, rims[-1])):
        if ids is None:
            continue
        ids = np.unique(np.r_[ids, seam_ids[k]])
        _, rho, a = _cylindrical(V[ids], origin, axis)
        a = np.mod(a - ang_s[k], 2 * np.pi)
        a[ids == seam_ids[k]] = 0.0
        o = np.argsort(a, kind="stable")
        ends[k] = (ids[o], a[o])
        spacings.append(2 * np.pi * rho.mean() / len(ids))
    spacing = np.mean(spacings)
    rings, new, n_next = [], [], len(V)
    for k, sid in enumerate(seam_ids):
        if k in ends:
            rings.append(ends[k])
            continue
        m = 1 if k in (0, last) else max(3, int(round(2 * np.pi * rho_s[k] / spacing)))
        a = 2 * np.pi * np.arange(m) / m
        d = V[sid] - origin
        radial = d - (d @ axis) * axis
        new.append(origin + (d @ axis) * axis + np.outer(np.cos(a[1:]), radial)
                   + np.outer(np.sin(a[1:]), np.cross(axis, radial)))
        rings.append((np.r_[sid, n_next + np.arange(m - 1)], a))
        n_next += m - 1
    tris = [_zip(*rings[k], *rings[k + 1]) for k in range(len(rings) - 1)]
    return (np.concatenate(new) if new else np.zeros((0, 3))), np.concatenate(tris)


def _on_seam(V, seam_ids, seam, on_axis):
    """Put the seam's inner output vertices on its curve (at their share of the chain's
    length) and an end on the axis at the curve's end: the fitted surface folds where
    two of the patch's sides collapse, and its vertices there are no meridian. The ends
    at a parallel are shared with the neighbours and stay."""
    t = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(V[seam_ids], axis=0), axis=1))]
    u = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(seam, axis=0), axis=1))]
    if not (t[-1] > 0 and u[-1] > 0):
        return
    at = t / t[-1] * u[-1]
    P = np.stack([np.interp(at, u, seam[:, i]) for i in range(3)], axis=1)
    V[seam_ids[1:-1]] = P[1:-1]
    for k in (0, -1):
        if on_axis[k]:
            V[seam_ids[k]] = seam[k]


def _rims(loop, seam, chains, curves, frame, tol):
    """Per end of the seam (its first and last point) the output vertex ids of the
    parallels there, None where the seam ends on the axis (an apex, a pole); None when
    a parallel is at neither end or an end has neither."""
    origin, axis = frame
    z_end, rho_end, _ = _cylindrical(np.asarray(curves[seam])[[0, -1]], origin, axis)
    rims = [[], []]
    for c in {c for c, _ in loop} - {seam}:
        side = np.flatnonzero(np.abs(z_end - _cylindrical(curves[c], origin, axis)[0].mean())
                              <= tol)
        if len(side) != 1:
            return None
        rims[int(side[0])].append(chains[c])
    if any(bool(r) == bool(rho <= tol) for r, rho in zip(rims, rho_end)):
        return None
    return [np.concatenate(r) if r else None for r in rims]


def _runs(F, a: int, b: int):
    """Whether the first triangle of ``F`` (t, 3) with the edge ``a b`` runs it from
    ``a`` to ``b``; None when none has it."""
    has = np.flatnonzero((F == a).any(axis=1) & (F == b).any(axis=1))
    if not len(has):
        return None
    t = F[has[0]]
    return bool(((t == a) & (np.roll(t, -1) == b)).any())


def _same_way(tri, neighbours, old, rims):
    """Whether triangles ``tri`` turn the way the faces around them do: they run a rim
    edge against the neighbouring patch's face on it (a welded, consistently oriented
    mesh), else, with no neighbour there, along the way the replaced faces ``old`` ran
    it. None when neither tells."""
    for ring in (r for r in rims if r is not None and len(r) > 1):
        for a, b in ((ring[0], ring[1]), (ring[1], ring[0])):
            mine = _runs(tri, a, b)
            if mine is None:
                continue
            theirs = _runs(neighbours, a, b)
            if theirs is not None:
                return mine != theirs
            before = _runs(old, a, b)
            if before is not None:
                return mine == before
    return None


def mesh_bands(vertices, faces, face_patch, chains, curves, boundaries, surfaces, tol: float):
    """Replace the faces of every band of revolution by rings about its axis.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (f, 3) int64
    face_patch : (f,) int64
        Patch of each face (index into ``boundaries``).
    chains : list of (k_c,) int64 or None
        Output vertex ids along each curve, first point to last.
    curves : list of (m_i, 3) float64
    boundaries : list of list of list of (int, bool)
    surfaces : list of AnalyticSurface or None
        Per patch (:func:`surfacing.sectors.analytic_faces`).
    tol : float
        Model units (see :func:`band_frame`).

    Returns
    -------
    vertices : (n', 3) float64
        The input vertices (those of the replaced faces left unreferenced) and the new
        ones after them.
    faces : (f', 3) int64
    face_patch : (f',) int64
    meshed : (p,) bool
        The patches meshed as rings.
    """
    V = np.array(vertices, np.float64)
    F, FP = np.asarray(faces, np.int64), np.asarray(face_patch, np.int64)
    meshed = np.zeros(len(boundaries), bool)
    if chains is None:
        return V, F, FP, meshed
    new_v, new_f = [], []
    for k, (b, s) in enumerate(zip(boundaries, surfaces)):
        got = None if s is None else band_frame(s, b, curves, tol)
        old = FP == k
        if got is None or not old.any() or any(chains[c] is None for c, _ in b[0]):
            continue
        origin, axis, seam = got
        rims = _rims(b[0], seam, chains, curves, (origin, axis), tol)
        if rims is None:
            continue
        sid = np.asarray(chains[seam], np.int64)
        _on_seam(V, sid, np.asarray(curves[seam], np.float64), [r is None for r in rims])
        pts, tri = _band(np.concatenate([V, *new_v]), (origin, axis), sid, rims)
        around = np.concatenate([F[~old & ~meshed[FP]], *new_f])
        if _same_way(tri, around, F[old], rims) is False:
            tri = tri[:, ::-1]
        meshed[k] = True
        new_v.append(pts)
        new_f.append(tri)
    return (*replace_faces(V, F, FP, np.flatnonzero(meshed), new_v, new_f), meshed)
