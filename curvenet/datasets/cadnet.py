"""Builder of CAD-like clean networks: planar faces with holes, prism walls, ground truth.

Used by :mod:`curvenet.datasets.shapes` (washer, plate, hex nut, flange, boss, L-bracket).
A profile is a closed chain of pieces in a plane frame, each a callable
``t -> (m, 2)`` points for ``t`` in [0, 1] (a straight side or a circular
arc); the network gets one curve per piece, and the reference surface is
sampled densely from the same callables, so it is the exact surface up to
its own chord error, independent of the network's sampling.
"""

from __future__ import annotations

import numpy as np

from ..core.geometry import arc_length
from ..cycles.loops import orient_boundaries
from ..model.network import CurveNetwork
from ..model.patchset import Patch


def line(a, b):
    """Straight profile piece from ``a`` to ``b`` (2D)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return lambda t: a + np.asarray(t, float)[:, None] * (b - a)


def polygon(points):
    """Closed polygon profile: one straight piece per side."""
    pts = [np.asarray(p, float) for p in points]
    return [line(p, q) for p, q in zip(pts, pts[1:] + pts[:1])]


def circle(center, radius, n_arcs=4, phase=0.0):
    """Closed circle profile split into ``n_arcs`` equal arcs (counter-clockwise)."""
    c = np.asarray(center, float)

    def arc(k):
        def f(t):
            a = phase + 2 * np.pi * (k + np.asarray(t, float)) / n_arcs
            return c + radius * np.stack([np.cos(a), np.sin(a)], -1)
        return f
    return [arc(k) for k in range(n_arcs)]


class Frame:
    """Plane frame: ``origin + x e1 + y e2 + z n`` maps profile coordinates to 3D."""

    def __init__(self, origin=(0, 0, 0), e1=(1, 0, 0), e2=(0, 1, 0)):
        self.o = np.asarray(origin, float)
        self.e1, self.e2 = np.asarray(e1, float), np.asarray(e2, float)
        self.n = np.cross(self.e1, self.e2)

    def __call__(self, xy, z=0.0):
        xy = np.asarray(xy, float)
        return self.o + xy[..., :1] * self.e1 + xy[..., 1:2] * self.e2 + z * self.n


class CadBuilder:
    """Accumulates curves, faces (outer loop + holes) and the reference surface pieces."""

    def __init__(self, samples=33):
        self.net = CurveNetwork(np.zeros((0, 3)))
        self.samples = samples
        self._vid: dict = {}
        self._eid: dict = {}
        self.faces: list = []        # per face: [outer edge ids, hole edge ids...]
        self.ref_pieces: list = []   # callables: density -> (vertices, triangles)

    def _vertex(self, p):
        key = tuple(np.round(p, 9))
        if key not in self._vid:
            self._vid[key] = self.net.add_vertex(np.asarray(p, float))
        return self._vid[key]

    def _edge(self, f3, label):
        pts = f3(np.linspace(0.0, 1.0, self.samples))
        a, b = self._vertex(pts[0]), self._vertex(pts[-1])
        mid = tuple(np.round(pts[len(pts) // 2], 9))
        key = (min(a, b), max(a, b), mid)
        if key not in self._eid:
            self._eid[key] = self.net.add_edge(a, b, pts, label=label)
        return self._eid[key]

    def ring(self, profile, frame, z, label="crease"):
        """Edge ids of a profile placed at height ``z`` of ``frame``; returns (ids, 3D pieces)."""
        pieces = [_placed(f, frame, z) for f in profile]
        return [self._edge(g, label) for g in pieces], pieces

    def planar_face(self, rings):
        """Face bounded by ``rings`` (outer first) from :meth:`ring`; reference triangulated."""
        self.faces.append([ids for ids, _ in rings])
        self.ref_pieces.append(lambda h, rs=[p for _, p in rings]: _planar_reference(rs, h))

    def wall(self, profile, frame, z0, z1, label="boundary", holes=None):
        """Prism wall of ``profile`` between heights ``z0`` and ``z1``: one quad per piece.

        ``holes`` maps a piece index to rings (from :meth:`ring` / :meth:`wall`)
        cut out of that (straight, hence planar) quad. Returns the bottom and
        top rings.
        """
        holes = holes or {}
        bottom, bp = self.ring(profile, frame, z0)
        top, tp = self.ring(profile, frame, z1)

        def rule(f, end):
            p = frame(f(np.full(1, float(end)))[0], 0.0)
            return lambda t: p + (z0 + (z1 - z0) * np.asarray(t, float)[:, None]) * frame.n

        for k, f in enumerate(profile):
            r0, r1 = rule(f, 0), rule(f, 1)
            s0, s1 = self._edge(r0, label), self._edge(r1, label)
            if k in holes:
                quad = [bp[k], r1, _reversed(tp[k]), _reversed(r0)]
                self.planar_face([([bottom[k], s1, top[k], s0], quad), *holes[k]])
                continue
            self.faces.append([[bottom[k], s1, top[k], s0]])
            self.ref_pieces.append(lambda h, a=bp[k], b=tp[k]: _ruled_reference(a, b, h))
        return (bottom, bp), (top, tp)

    def shape_parts(self):
        """``(network, faces, holes, reference)`` with consistently oriented loops."""
        patches = [Patch(f[0], "user", tuple(f[1:])) for f in self.faces]
        bounds = orient_boundaries(self.net, patches)
        pieces = list(self.ref_pieces)

        def reference(s):
            import trimesh
            h = 1.0 / (16 * 2 ** s)
            parts = [f(h) for f in pieces]
            verts, tris, base = [], [], 0
            for v, t in parts:
                verts.append(v)
                tris.append(t + base)
                base += len(v)
            return trimesh.Trimesh(np.concatenate(verts), np.concatenate(tris), process=True)

        return self.net, [b[0] for b in bounds], [b[1:] for b in bounds], reference


def _placed(piece, frame, z):
    return lambda t: frame(piece(t), z)


def _reversed(piece):
    return lambda t: piece(1.0 - np.asarray(t, float))


def _dense(piece, h):
    """Points of a 3D piece at spacing about ``h`` (both ends)."""
    rough = piece(np.linspace(0, 1, 65))
    length = arc_length(rough)
    return piece(np.linspace(0, 1, max(2, int(np.ceil(length / h)) + 1)))


def _planar_reference(rings, h):
    """Exact triangulation of a planar region with holes (constrained by dense boundaries).

    Delaunay triangulation of the boundary samples alone (every boundary
    segment is then a Delaunay edge, samples being much closer along a
    boundary than across the region), keeping the triangles whose centroid
    lies inside the outer ring and outside every hole.
    """
    from matplotlib.path import Path
    from scipy.spatial import Delaunay
    loops = [np.concatenate([_dense(p, h)[:-1] for p in pieces]) for pieces in rings]
    pts = np.concatenate(loops)
    c = pts.mean(axis=0)
    _, _, vt = np.linalg.svd(pts - c, full_matrices=False)
    uv = (pts - c) @ vt[:2].T
    tri = Delaunay(uv).simplices
    cen = uv[tri].mean(axis=1)
    bounds = np.cumsum([0] + [len(lp) for lp in loops])
    paths = [Path(uv[bounds[i]:bounds[i + 1]]) for i in range(len(loops))]
    keep = paths[0].contains_points(cen)
    for p in paths[1:]:
        keep &= ~p.contains_points(cen)
    return pts, tri[keep]


def _ruled_reference(a, b, h):
    """Ruled strip between two 3D pieces sampled alike (a prism wall)."""
    pa = _dense(a, h)
    pb = b(np.linspace(0, 1, len(pa)))
    rough = np.linalg.norm(pb[0] - pa[0])
    m = max(2, int(np.ceil(rough / h)) + 1)
    s = np.linspace(0, 1, m)[:, None, None]
    grid = ((1 - s) * pa[None] + s * pb[None]).reshape(-1, 3)
    n = len(pa)
    idx = np.arange(m * n).reshape(m, n)
    q0, q1, q2, q3 = idx[:-1, :-1], idx[:-1, 1:], idx[1:, 1:], idx[1:, :-1]
    tris = np.concatenate([np.stack([q0, q1, q2], -1).reshape(-1, 3),
                           np.stack([q0, q2, q3], -1).reshape(-1, 3)])
    return grid, tris
