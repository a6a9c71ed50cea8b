"""Clean curve networks of analytic shapes, with their true patches and true surfaces.

These are the oracles of the test suite and the benchmarks: each
:class:`AnalyticShape` carries a clean :class:`~curvenet.model.network.CurveNetwork`
whose curves lie exactly on a known surface, the true patches as oriented
loops, and a dense reference mesh of that surface.

Conventions
-----------
* Curves are sampled with ``samples`` points (default 33) including both ends.
* ``faces`` are loops of ``(edge_id, forward)``; ``forward`` means the edge is
  walked from ``u`` to ``v``. For closed shapes the loops are oriented so that
  their normals (right-hand rule) point outwards; neighbouring faces walk a
  shared manifold edge in opposite directions.
* Edges on sharp features of the true surface (box edges, cylinder rims) carry
  the label ``"crease"``; all others ``"boundary"``.

Examples
--------
>>> s = grid_box(4)
>>> s.network.number_of_edges, len(s.faces)
(192, 96)
>>> s.network.cycle_rank() == len(s.faces) - 1   # a closed genus-0 surface
True
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import cadnet
from ..core.geometry import cumulative_length, interpolate_polyline
from ..cycles.find import orient_patches
from ..model.network import CurveNetwork
from ..model.sketch import Sketch

__all__ = [
    "AnalyticShape", "box", "grid_box", "l_prism", "house", "two_boxes", "latlong_sphere",
    "ellipsoid", "capped_cylinder", "torus", "saddle_grid", "grid_sheet", "SHAPES",
    "sample_curves", "random_motion",
    "washer", "holed_plate", "hex_nut", "flange", "boss_box", "l_bracket", "CAD_SHAPES",
]


@dataclass
class AnalyticShape:
    """A clean network on a known surface.

    Attributes
    ----------
    name : str
    network : CurveNetwork
    faces : list of list of (int, bool)
        True patches as oriented loops of ``(edge_id, forward)``.
    closed : bool
        Whether the true surface is closed (a solid's boundary).
    genus : int
        Genus of the true surface (closed shapes).
    reference : callable
        ``reference(subdivisions) -> trimesh.Trimesh``; use :meth:`reference_mesh`.
    holes : list of list of list of (int, bool)
        Per face, its inner boundary loops (empty for a disc); a hole is walked
        against its face's outer loop. Empty list: no face has holes.
    """

    name: str
    network: CurveNetwork
    faces: list
    closed: bool
    genus: int = 0
    reference: object = field(default=None, repr=False)
    holes: list = field(default_factory=list)

    def face_holes(self) -> list:
        """Per face, its holes as sorted tuples of edge ids (``[]`` for a disc)."""
        hs = self.holes or [[] for _ in self.faces]
        return [sorted(tuple(sorted(e for e, _ in lp)) for lp in h) for h in hs]

    def reference_mesh(self, subdivisions: int = 5):
        """Dense triangle mesh of the true surface (``trimesh.Trimesh``).

        ``subdivisions`` sets the density (icosphere level for spheres, about
        ``2**subdivisions * 8`` segments around for the other curved shapes);
        flat shapes are exact at any level.
        """
        return self.reference(subdivisions)

    def sketch(self) -> Sketch:
        """One stroke per network edge, labelled as the edge."""
        net = self.network
        return Sketch([e.curve for e in net.edges], [e.label for e in net.edges],
                      {"shape": self.name})

    def face_edge_sets(self) -> list:
        """True faces as sorted tuples of edge ids (the form patch finders return)."""
        return sorted(tuple(sorted(e for e, _ in loop)) for loop in self.faces)


# --------------------------------------------------------------------------- helpers
def _segment(a, b, samples):
    t = np.linspace(0.0, 1.0, samples)[:, None]
    return (1.0 - t) * np.asarray(a, float) + t * np.asarray(b, float)


def _trimesh(vertices, faces):
    import trimesh
    return trimesh.Trimesh(np.asarray(vertices, float), np.asarray(faces, np.int64), process=True)


def _orient(net: CurveNetwork, faces) -> list:
    """Consistently oriented loops, closed surfaces outward.

    See :func:`curvenet.cycles.orient_patches`.
    """
    return orient_patches(net, [[e for e, _ in loop] for loop in faces])


def _polygon_mesh(points_per_face):
    """Fan triangulation of planar star-shaped polygons around their centroids."""
    verts, tris = [], []
    base = 0
    for p in points_per_face:
        p = np.asarray(p, float)
        n = len(p)
        verts.append(p)
        verts.append(p.mean(axis=0)[None])
        i = np.arange(n)
        tris.append(np.stack([base + i, base + (i + 1) % n, np.full(n, base + n)], axis=1))
        base += n + 1
    return _trimesh(np.concatenate(verts), np.concatenate(tris))


def _polyhedron(name, vertices, vertex_faces, *, samples, crease=True, closed=True):
    """Network whose edges are the straight sides of planar polygonal faces."""
    vertices = np.asarray(vertices, float)
    net = CurveNetwork(vertices.copy())
    ids: dict = {}
    faces = []
    for cyc in vertex_faces:
        loop = []
        for a, b in zip(cyc, cyc[1:] + cyc[:1]):
            key = (min(a, b), max(a, b))
            if key not in ids:
                ids[key] = net.add_edge(key[0], key[1], _segment(vertices[key[0]], vertices[key[1]],
                                                                 samples),
                                        label="crease" if crease else "boundary")
            loop.append((ids[key], a == key[0]))
        faces.append(loop)
    faces = _orient(net, faces)
    polys = [vertices[list(c)] for c in vertex_faces]
    return AnalyticShape(name, net, faces, closed, 0, lambda _s: _polygon_mesh(polys))


# --------------------------------------------------------------------------- polyhedra
def grid_box(n: int = 1, *, size=(1.0, 1.0, 1.0), samples: int = 33) -> AnalyticShape:
    """Axis-aligned box whose six sides are ``n x n`` grids of straight curves.

    ``12 * n`` box-edge curves are creases; ``6 n^2`` faces; ``12 n (n + 1) - 12 n``
    curves in all (192 for ``n = 4``, 972 for ``n = 9``).
    """
    size = np.asarray(size, float)
    net = CurveNetwork(np.zeros((0, 3)))
    vid: dict = {}

    def vertex(ijk):
        if ijk not in vid:
            vid[ijk] = net.add_vertex(np.asarray(ijk, float) / n * size)
        return vid[ijk]

    eid: dict = {}

    def edge(a, b):
        key = (min(a, b), max(a, b))
        if key not in eid:
            axis = next(d for d in range(3) if a[d] != b[d])
            on_box_edge = all(a[d] in (0, n) for d in range(3) if d != axis)
            u, v = vertex(key[0]), vertex(key[1])
            eid[key] = net.add_edge(u, v, _segment(net.positions[u], net.positions[v], samples),
                                    label="crease" if on_box_edge else "boundary")
        return eid[key], a == key[0]

    faces = []
    for axis in range(3):
        a1, a2 = [d for d in range(3) if d != axis]
        for side in (0, n):
            for i in range(n):
                for j in range(n):
                    corners = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        c = [0, 0, 0]
                        c[axis], c[a1], c[a2] = side, i + di, j + dj
                        corners.append(tuple(c))
                    faces.append([edge(corners[k], corners[(k + 1) % 4]) for k in range(4)])
    faces = _orient(net, faces)

    def reference(_s):
        import trimesh
        m = trimesh.creation.box(extents=size)
        m.apply_translation(size / 2)
        return m

    return AnalyticShape(f"grid_box{n}" if n > 1 else "box", net, faces, True, 0, reference)


def box(*, size=(1.0, 1.0, 1.0), samples: int = 33) -> AnalyticShape:
    """Axis-aligned box: 8 vertices, 12 crease curves, 6 faces."""
    return grid_box(1, size=size, samples=samples)


def l_prism(*, height: float = 1.0, samples: int = 33) -> AnalyticShape:
    """L-shaped prism (the L ``[0,2]x[0,1] U [0,1]x[0,2]`` extruded by ``height``): 8 faces."""
    ring = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    verts = np.concatenate([np.c_[ring, np.zeros(6)], np.c_[ring, np.full(6, height)]])
    faces = [list(range(6)), list(range(6, 12))]
    faces += [[i, (i + 1) % 6, (i + 1) % 6 + 6, i + 6] for i in range(6)]
    return _polyhedron("l_prism", verts, faces, samples=samples)


def house(*, samples: int = 33) -> AnalyticShape:
    """Unit cube with a gable roof (ridge at height 1.5): 7 faces, two of them pentagons."""
    verts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                      [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1],
                      [0.5, 0, 1.5], [0.5, 1, 1.5]], float)
    faces = [[0, 1, 2, 3], [0, 1, 5, 8, 4], [3, 2, 6, 9, 7], [1, 2, 6, 5], [0, 3, 7, 4],
             [4, 8, 9, 7], [5, 6, 9, 8]]
    return _polyhedron("house", verts, faces, samples=samples)


def two_boxes(*, samples: int = 33) -> AnalyticShape:
    """Two unit cubes stacked along z sharing the face ``z = 1``: 11 faces.

    The shared face's four curves are used by three faces each (non-manifold).
    The reference surface is the union of both cubes' boundaries, the shared
    face included.
    """
    verts = np.array([[x, y, z] for z in (0, 1, 2) for y in (0, 1) for x in (0, 1)], float)

    def quad(a, b, c, d):
        return [a, b, d, c]

    faces = []
    for z0 in (0, 4, 8):
        faces.append(quad(z0 + 0, z0 + 1, z0 + 2, z0 + 3))
    for z0 in (0, 4):
        faces += [quad(z0 + 0, z0 + 1, z0 + 4, z0 + 5), quad(z0 + 2, z0 + 3, z0 + 6, z0 + 7),
                  quad(z0 + 0, z0 + 2, z0 + 4, z0 + 6), quad(z0 + 1, z0 + 3, z0 + 5, z0 + 7)]
    return _polyhedron("two_boxes", verts, faces, samples=samples)


# --------------------------------------------------------------------------- parametric
def _param_shape(name, F, nu, nv, *, periodic_u, poles, samples, closed, genus, reference,
                 periodic_v=False, caps=False, crease_rows=()):
    """Network of the iso-parameter curves of ``F(u, v)`` on an ``nu x nv`` grid.

    ``F`` maps arrays ``u, v`` in [0, 1] to points ``(..., 3)``. ``poles`` collapses
    the rows ``v = 0`` and ``v = 1`` to single vertices; ``caps`` adds the rows
    ``v = 0`` and ``v = 1`` as two extra (flat) faces.
    """
    net = CurveNetwork(np.zeros((0, 3)))
    vid: dict = {}

    def vkey(i, j):
        j = j % nv if periodic_v else j
        if poles and j in (0, nv):
            return ("pole", j)
        return (i % nu if periodic_u else i, j)

    def vertex(i, j):
        k = vkey(i, j)
        if k not in vid:
            vid[k] = net.add_vertex(F(np.array(i / nu), np.array(j / nv)))
        return vid[k]

    t = np.linspace(0.0, 1.0, samples)
    eid: dict = {}

    def edge(kind, i, j):
        """Edge from grid point (i, j) one step along u ('u') or v ('v'); returns (id, fwd)."""
        key = (kind, i % nu if periodic_u else i, j % nv if periodic_v else j)
        if key not in eid:
            i0, j0 = key[1], key[2]
            if kind == "u":
                pts = F((i0 + t) / nu, np.full_like(t, j0 / nv))
                a, b = vertex(i0, j0), vertex(i0 + 1, j0)
            else:
                pts = F(np.full_like(t, i0 / nu), (j0 + t) / nv)
                a, b = vertex(i0, j0), vertex(i0, j0 + 1)
            label = "crease" if kind == "u" and j0 in crease_rows else "boundary"
            eid[key] = net.add_edge(a, b, pts, label=label)
        return eid[key], True

    faces = []
    for j in range(nv):
        for i in range(nu):
            loop = []
            if not (poles and j == 0):
                loop.append(edge("u", i, j))
            loop.append(edge("v", i + 1, j))
            if not (poles and j + 1 == nv):
                e, _ = edge("u", i, j + 1)
                loop.append((e, False))
            e, _ = edge("v", i, j)
            loop.append((e, False))
            faces.append(loop)
    if caps:
        faces.append([edge("u", i, 0) for i in range(nu)])
        faces.append([(edge("u", i, nv)[0], True) for i in range(nu)])
    faces = _orient(net, faces)
    return AnalyticShape(name, net, faces, closed, genus, reference)


def _grid_mesh(F, n_u, n_v):
    """Dense triangulated parameter grid of ``F`` over [0, 1]^2 (seams not welded)."""
    u, v = np.meshgrid(np.linspace(0, 1, n_u + 1), np.linspace(0, 1, n_v + 1), indexing="ij")
    pts = F(u.ravel(), v.ravel())
    idx = np.arange((n_u + 1) * (n_v + 1)).reshape(n_u + 1, n_v + 1)
    a, b, c, d = idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]
    tris = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                           np.stack([a, c, d], -1).reshape(-1, 3)])
    return _trimesh(pts, tris)


def ellipsoid(radii=(1.0, 0.8, 0.6), *, n_lat: int = 4, n_lon: int = 6,
              samples: int = 33) -> AnalyticShape:
    """Lat-long network on the ellipsoid ``sum (x_i / r_i)^2 = 1``.

    ``n_lat`` latitude bands (``n_lat - 1`` parallels), ``n_lon`` meridians; the
    faces touching the poles are three-sided.
    """
    radii = np.asarray(radii, float)

    def F(u, v):
        th, ph = 2 * np.pi * np.asarray(u), np.pi * (np.asarray(v) - 0.5)
        return np.stack([np.cos(ph) * np.cos(th), np.cos(ph) * np.sin(th), np.sin(ph)],
                        -1) * radii

    def reference(s):
        import trimesh
        m = trimesh.creation.icosphere(subdivisions=s, radius=1.0)
        m.apply_scale(radii)
        return m

    name = "sphere" if np.allclose(radii, radii[0]) else "ellipsoid"
    return _param_shape(name, F, n_lon, n_lat, periodic_u=True, poles=True, samples=samples,
                        closed=True, genus=0, reference=reference)


def latlong_sphere(radius: float = 1.0, *, n_lat: int = 4, n_lon: int = 6,
                   samples: int = 33) -> AnalyticShape:
    """Lat-long network on a sphere of ``radius`` (see :func:`ellipsoid`)."""
    return ellipsoid((radius,) * 3, n_lat=n_lat, n_lon=n_lon, samples=samples)


def capped_cylinder(radius: float = 0.5, height: float = 1.0, *, n_around: int = 4,
                    n_height: int = 2, samples: int = 33) -> AnalyticShape:
    """Cylinder of ``radius`` and ``height`` along z with flat caps.

    ``n_around`` rulings, ``n_height + 1`` circles split into ``n_around`` arcs;
    the two rim circles are creases; each cap is one ``n_around``-sided face.
    """
    def F(u, v):
        th = 2 * np.pi * np.asarray(u)
        return np.stack([radius * np.cos(th), radius * np.sin(th), height * np.asarray(v)], -1)

    def reference(s):
        import trimesh
        m = trimesh.creation.cylinder(radius=radius, height=height, sections=8 * 2 ** s)
        m.apply_translation([0, 0, height / 2])
        return m

    return _param_shape("capped_cylinder", F, n_around, n_height, periodic_u=True, poles=False,
                        samples=samples, closed=True, genus=0, reference=reference, caps=True,
                        crease_rows=(0, n_height))


def torus(major: float = 1.0, minor: float = 0.4, *, n_u: int = 6, n_v: int = 4,
          samples: int = 33) -> AnalyticShape:
    """Torus around z: ``n_u`` meridian circles and ``n_v`` parallel circles; genus 1."""
    def F(u, v):
        a, b = 2 * np.pi * np.asarray(u), 2 * np.pi * np.asarray(v)
        r = major + minor * np.cos(b)
        return np.stack([r * np.cos(a), r * np.sin(a), minor * np.sin(b)], -1)

    def reference(s):
        return _grid_mesh(F, 16 * 2 ** s, 8 * 2 ** s)

    return _param_shape("torus", F, n_u, n_v, periodic_u=True, periodic_v=True, poles=False,
                        samples=samples, closed=True, genus=1, reference=reference)


def saddle_grid(n: int = 4, *, k: float = 0.5, samples: int = 33) -> AnalyticShape:
    """Open ``n x n`` grid of iso-curves on the saddle ``z = k (x^2 - y^2)``, ``|x|, |y| <= 1``."""
    def F(u, v):
        x, y = 2 * np.asarray(u) - 1, 2 * np.asarray(v) - 1
        return np.stack([x, y, k * (x * x - y * y)], -1)

    return _param_shape("saddle", F, n, n, periodic_u=False, poles=False, samples=samples,
                        closed=False, genus=0,
                        reference=lambda s: _grid_mesh(F, 16 * 2 ** s, 16 * 2 ** s))


def grid_sheet(n: int = 3, *, samples: int = 33) -> AnalyticShape:
    """Open planar ``n x n`` grid in the square ``[0, 1]^2`` at ``z = 0``."""
    def F(u, v):
        u = np.asarray(u, float)
        return np.stack([u, np.asarray(v, float) + 0 * u, 0 * u], -1)

    return _param_shape("grid_sheet", F, n, n, periodic_u=False, poles=False, samples=samples,
                        closed=False, genus=0, reference=lambda s: _grid_mesh(F, 4, 4))


# --------------------------------------------------------------------------- CAD-like
def _cad(name, builder, genus):
    net, faces, holes, reference = builder.shape_parts()
    return AnalyticShape(name, net, faces, True, genus, reference, holes)


def _plate(b, outer, holes, thickness, frame=None):
    """Prism of ``outer`` with through holes: two holed planar faces and their walls."""
    frame = frame or cadnet.Frame()
    (bo, bop), (to, top) = b.wall(outer, frame, 0.0, thickness)
    bottoms, tops = [(bo, bop)], [(to, top)]
    for h in holes:
        bh, th = b.wall(h, frame, 0.0, thickness)
        bottoms.append(bh)
        tops.append(th)
    b.planar_face(bottoms)
    b.planar_face(tops)


def washer(outer: float = 1.0, inner: float = 0.5, thickness: float = 0.2, *,
           samples: int = 33) -> AnalyticShape:
    """Flat washer: two annular faces (one hole each), outer and bore walls of 4 quads; genus 1."""
    b = cadnet.CadBuilder(samples)
    _plate(b, cadnet.circle((0, 0), outer), [cadnet.circle((0, 0), inner)], thickness)
    return _cad("washer", b, 1)


def holed_plate(*, samples: int = 33) -> AnalyticShape:
    """3 x 2 x 0.2 plate with two round holes (r 0.3) and a 0.8 x 1 rectangular window; genus 3."""
    b = cadnet.CadBuilder(samples)
    holes = [cadnet.circle((0.7, 0.55), 0.3), cadnet.circle((0.7, 1.45), 0.3),
             cadnet.polygon([(1.7, 0.5), (2.5, 0.5), (2.5, 1.5), (1.7, 1.5)])]
    _plate(b, cadnet.polygon([(0, 0), (3, 0), (3, 2), (0, 2)]), holes, 0.2)
    return _cad("holed_plate", b, 3)


def hex_nut(across_corners: float = 2.0, bore: float = 0.5, height: float = 0.8, *,
            samples: int = 33) -> AnalyticShape:
    """Hexagonal nut with a through bore whose wall has three seams (three quads); genus 1."""
    b = cadnet.CadBuilder(samples)
    a = np.pi / 3 * np.arange(6)
    hexagon = cadnet.polygon(list(across_corners / 2 * np.c_[np.cos(a), np.sin(a)]))
    _plate(b, hexagon, [cadnet.circle((0, 0), bore, n_arcs=3, phase=np.pi / 2)], height)
    return _cad("hex_nut", b, 1)


def flange(radius: float = 1.5, bore: float = 0.5, bolts: int = 4, *,
           samples: int = 33) -> AnalyticShape:
    """Disc flange (thickness 0.3) with a bore and ``bolts`` bolt holes (r 0.15 at r 1.0)."""
    b = cadnet.CadBuilder(samples)
    a = 2 * np.pi * (np.arange(bolts) + 0.5) / bolts
    holes = [cadnet.circle((0, 0), bore)] + [
        cadnet.circle((np.cos(t), np.sin(t)), 0.15, phase=t) for t in a]
    _plate(b, cadnet.circle((0, 0), radius), holes, 0.3)
    return _cad("flange", b, 1 + bolts)


def boss_box(*, samples: int = 33) -> AnalyticShape:
    """2 x 2 x 1 box with a cylindrical boss (r 0.5, height 0.6) on top; the cap is a disc."""
    b = cadnet.CadBuilder(samples)
    square = cadnet.polygon([(0, 0), (2, 0), (2, 2), (0, 2)])
    frame = cadnet.Frame()
    (bo, bop), (to, top) = b.wall(square, frame, 0.0, 1.0)
    boss = cadnet.circle((1, 1), 0.5)
    (base, basep), cap = b.wall(boss, frame, 1.0, 1.6)
    b.planar_face([(bo, bop)])
    b.planar_face([(to, top), (base, basep)])
    b.planar_face([cap])
    return _cad("boss_box", b, 0)


def l_bracket(*, samples: int = 33) -> AnalyticShape:
    """L-bracket (legs 3 and 2 long, 0.3 thick, 2 wide) with a round hole (r 0.3) through
    the upright leg; genus 1."""
    b = cadnet.CadBuilder(samples)
    upright = cadnet.Frame((0, 0, 0), (0, -1, 0), (0, 0, 1))  # the plane x = 0, normal -x
    outer_rim, inner_rim = b.wall(cadnet.circle((1.0, 1.2), 0.3), upright, 0.0, -0.3)
    side = cadnet.Frame((0, 0, 0), (1, 0, 0), (0, 0, 1))      # profile in xz, extruded along -y
    ell = cadnet.polygon([(0, 0), (3, 0), (3, 0.3), (0.3, 0.3), (0.3, 2), (0, 2)])
    front, back = b.wall(ell, side, 0.0, 2.0, holes={5: [outer_rim], 3: [inner_rim]})
    b.planar_face([front])
    b.planar_face([back])
    return _cad("l_bracket", b, 1)


#: CAD-like solids whose faces have holes (not in :data:`SHAPES`, whose faces are discs).
CAD_SHAPES = {
    "washer": washer,
    "holed_plate": holed_plate,
    "hex_nut": hex_nut,
    "flange": flange,
    "boss_box": boss_box,
    "l_bracket": l_bracket,
}

SHAPES = {
    "box": box,
    "l_prism": l_prism,
    "house": house,
    "two_boxes": two_boxes,
    "grid_box": lambda: grid_box(3),
    "sphere": latlong_sphere,
    "ellipsoid": ellipsoid,
    "capped_cylinder": capped_cylinder,
    "torus": torus,
    "saddle": saddle_grid,
    "grid_sheet": grid_sheet,
}


def random_motion(rng):
    """A random similarity (turn, scale in [0.1, 100], shift), for inputs in no special pose.

    Parameters
    ----------
    rng : numpy.random.Generator

    Returns
    -------
    callable
        ``move(points)``: (n, 3) array_like -> (n, 3) float64 moved points.

    Examples
    --------
    >>> move = random_motion(np.random.default_rng(0))
    >>> a, b = move([[0, 0, 0], [1, 0, 0]])
    >>> c, d = move([[0, 0, 0], [0, 1, 0]])
    >>> bool(np.isclose(np.linalg.norm(b - a), np.linalg.norm(d - c)))
    True
    """
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.linalg.det(q))
    scale = float(10.0 ** rng.uniform(-1, 2))
    shift = rng.normal(size=3) * scale

    def move(p):
        return scale * np.asarray(p, np.float64) @ q.T + shift

    return move


def sample_curves(curves, spacing: float, *, noise: float = 0.0, uneven: float = 1.0,
                  rng=None) -> np.ndarray:
    """Unordered samples along polylines (test and benchmark inputs).

    Parameters
    ----------
    curves : list of (k_i, 3) array_like
        Polylines, e.g. ``[e.curve for e in network.edges]``.
    spacing : float
        Mean distance between consecutive samples along a curve.
    noise : float
        Root-mean-square length of the Gaussian displacement added to each
        sample (each coordinate gets standard deviation ``noise / sqrt(3)``).
    uneven : float
        Ratio of the highest to the lowest sampling density along each curve
        (``1``: uniform); the densest stretch sits at a random place.
    rng : numpy.random.Generator or int, optional

    Returns
    -------
    (N, 3) float64 ndarray
        Shuffled samples.
    """
    rng = np.random.default_rng(rng)
    a = (uneven - 1.0) / (uneven + 1.0)
    out = []
    for cv in curves:  # loop over curves; samples are vectorised
        cv = np.asarray(cv, dtype=np.float64)
        s = cumulative_length(cv)
        n = max(2, int(round(s[-1] / spacing)))
        u = (np.arange(n) + rng.uniform()) / n
        phase = rng.uniform(0, 2 * np.pi)
        t = u + a * (np.sin(2 * np.pi * u + phase) - np.sin(phase)) / (2 * np.pi)
        out.append(interpolate_polyline(cv, t * s[-1], cum=s))
    pts = np.concatenate(out)
    pts = pts + rng.normal(0.0, noise / np.sqrt(3.0), pts.shape) if noise > 0 else pts
    return rng.permutation(pts)
