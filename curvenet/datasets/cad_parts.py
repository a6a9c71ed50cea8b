"""Mechanical parts built with OpenCascade itself: the CAD test set and its truth.

A few parametric families of the parts people draw (plates with bores and
counterbores, bosses, slots, hex nuts, flanges, washers, L-brackets, stepped shafts,
filleted and chamfered blocks, knobs with a rounded rim, domed and pointed pins), each
made with OpenCascade's primitives (``BRepPrimAPI``), Booleans (``BRepAlgoAPI``),
fillets and chamfers (``BRepFilletAPI``), revolutions and prisms. Every part's
dimensions are drawn from one seeded generator within ranges fixed per family, so
the set is reproducible and never tuned part by part (:func:`cad_parts`).

:func:`part_network` samples a solid's B-rep edges as the input curves (one network
curve per edge, the seams of periodic faces included, degenerate edges at poles and
apexes dropped); :mod:`curvenet.datasets.cad_truth` holds what the part is (faces,
their kinds and areas, volume, a fine triangulation) and scores a result against it.

Everything here needs OpenCascade (``cadquery-ocp``, the ``[cad]`` extra) and imports
it inside the functions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.geometry import bbox_diagonal
from ..model.network import CurveNetwork

__all__ = ["CadPart", "cad_parts", "part_network", "FAMILIES", "EDGE_SAMPLES"]

#: Samples per network curve: a straight edge gets the fewest, a curved edge one per
#: this fraction of the part's diagonal, within the bounds.
EDGE_SAMPLES = (9, 65)
_SAMPLE_STEP = 1.0 / 120.0


@dataclass
class CadPart:
    """One part of the set.

    Attributes
    ----------
    name : str
        ``family-k``.
    family : str
    params : dict
        The drawn dimensions (floats, ints, bools).
    shape : TopoDS_Shape
        The OpenCascade solid.
    """

    name: str
    family: str
    params: dict
    shape: object


# --------------------------------------------------------------------------- builders
def _ax(p=(0.0, 0.0, 0.0), d=(0.0, 0.0, 1.0)):
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    return gp_Ax2(gp_Pnt(*map(float, p)), gp_Dir(*map(float, d)))


def _box(x0, y0, z0, dx, dy, dz):
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Pnt
    return BRepPrimAPI_MakeBox(gp_Pnt(float(x0), float(y0), float(z0)), float(dx), float(dy),
                               float(dz)).Shape()


def _cyl(p, r, h, d=(0.0, 0.0, 1.0)):
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    return BRepPrimAPI_MakeCylinder(_ax(p, d), float(r), float(h)).Shape()


def _cone(p, r1, r2, h, d=(0.0, 0.0, 1.0)):
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCone
    return BRepPrimAPI_MakeCone(_ax(p, d), float(r1), float(r2), float(h)).Shape()


def _cut(a, *bs):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    for b in bs:
        a = BRepAlgoAPI_Cut(a, b).Shape()
    return _unified(a)


def _fuse(a, *bs):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse
    for b in bs:
        a = BRepAlgoAPI_Fuse(a, b).Shape()
    return _unified(a)


def _unified(shape):
    """Coplanar / co-cylindrical faces a Boolean split merged back (``ShapeUpgrade``)."""
    from OCP.ShapeUpgrade import ShapeUpgrade_UnifySameDomain
    u = ShapeUpgrade_UnifySameDomain(shape, True, True, True)
    u.Build()
    return u.Shape()


def _edges(shape, keep):
    """Edges of ``shape`` whose sampled points ``(9, 3)`` pass ``keep``."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp
    from OCP.TopoDS import TopoDS
    from OCP.OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as ShapeMap
    m = ShapeMap()
    TopExp.MapShapes_s(shape, TopAbs_EDGE, m)
    out = []
    for i in range(1, m.Size() + 1):
        e = TopoDS.Edge(m.FindKey(i))
        a = BRepAdaptor_Curve(e)
        t = np.linspace(a.FirstParameter(), a.LastParameter(), 9)
        pts = np.array([[q.X(), q.Y(), q.Z()] for q in (a.Value(float(s)) for s in t)])
        if keep(pts):
            out.append(e)
    return out


def _fillet(shape, r, keep):
    from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
    mk = BRepFilletAPI_MakeFillet(shape)
    for e in _edges(shape, keep):
        mk.Add(float(r), e)
    return mk.Shape()


def _chamfer(shape, d, keep):
    from OCP.BRepFilletAPI import BRepFilletAPI_MakeChamfer
    mk = BRepFilletAPI_MakeChamfer(shape)
    for e in _edges(shape, keep):
        mk.Add(float(d), e)
    return mk.Shape()


def _polygon_prism(xy, z0, h):
    """A prism of height ``h`` on the polygon ``xy (n, 2)`` at height ``z0``."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Pnt, gp_Vec
    poly = BRepBuilderAPI_MakePolygon()
    for x, y in np.asarray(xy, float).tolist():
        poly.Add(gp_Pnt(x, y, float(z0)))
    poly.Close()
    face = BRepBuilderAPI_MakeFace(poly.Wire()).Face()
    return BRepPrimAPI_MakePrism(face, gp_Vec(0.0, 0.0, float(h))).Shape()


def _revolved(rz):
    """The solid of revolution about z of the closed profile ``rz (n, 2)`` (radius,
    height), its first and last points on the axis."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeRevol
    from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt
    poly = BRepBuilderAPI_MakePolygon()
    for r, z in np.asarray(rz, float).tolist():
        poly.Add(gp_Pnt(r, 0.0, z))
    poly.Close()
    face = BRepBuilderAPI_MakeFace(poly.Wire()).Face()
    return _unified(BRepPrimAPI_MakeRevol(face, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)),
                                          2 * np.pi).Shape())


def _vertical(pts):
    return bool(np.ptp(pts[:, :2], axis=0).max() < 1e-9)


def _at_height(z):
    return lambda pts: bool(np.abs(pts[:, 2] - z).max() < 1e-9)


def _bores(W, D, k):
    """``k`` bore centres spread over a ``W x D`` plate (a row, or two rows)."""
    rows = 1 if k <= 2 else 2
    cols = int(np.ceil(k / rows))
    xs = (np.arange(cols) + 0.5) * W / cols
    ys = (np.arange(rows) + 0.5) * D / rows
    return np.array([(x, y) for y in ys for x in xs][:k])


# --------------------------------------------------------------------------- families
def _plate(rng):
    W, D, T = rng.uniform(3, 5), rng.uniform(2, 3), rng.uniform(0.3, 0.6)
    k = int(rng.integers(1, 5))
    r = rng.uniform(0.12, 0.22) * min(W / max(k, 2), D) / 1.0
    cb = bool(rng.integers(0, 2))
    fil = float(rng.uniform(0.15, 0.3)) if rng.integers(0, 2) else 0.0
    s = _box(0, 0, 0, W, D, T)
    if fil:
        s = _fillet(s, fil, _vertical)
    tools = []
    for x, y in _bores(W, D, k):
        tools.append(_cyl((x, y, -1), r, T + 2))
        if cb:
            tools.append(_cyl((x, y, T * 0.6), 1.6 * r, T))
    return _cut(s, *tools), dict(W=W, D=D, T=T, bores=k, r=r, counterbore=cb, fillet=fil)


def _boss(rng):
    W, D, T = rng.uniform(2, 3.5), rng.uniform(2, 3.5), rng.uniform(0.4, 0.8)
    R = rng.uniform(0.25, 0.4) * min(W, D)
    H = rng.uniform(0.4, 1.2)
    bore = bool(rng.integers(0, 2))
    s = _fuse(_box(0, 0, 0, W, D, T), _cyl((W / 2, D / 2, T), R, H))
    if bore:
        s = _cut(s, _cyl((W / 2, D / 2, -1), 0.5 * R, T + H + 2))
    return s, dict(W=W, D=D, T=T, R=R, H=H, bore=bore)


def _slot(rng):
    W, D, T = rng.uniform(3, 5), rng.uniform(1.5, 2.5), rng.uniform(0.3, 0.6)
    n = int(rng.integers(1, 3))
    r = rng.uniform(0.15, 0.25) * D / n
    L = rng.uniform(0.3, 0.5) * W
    tools = []
    for y in (np.arange(n) + 0.5) * D / n:
        x0 = (W - L) / 2
        tools += [_box(x0, y - r, -1, L, 2 * r, T + 2), _cyl((x0, y, -1), r, T + 2),
                  _cyl((x0 + L, y, -1), r, T + 2)]
    return _cut(_box(0, 0, 0, W, D, T), _fuse(*tools)), dict(W=W, D=D, T=T, slots=n, r=r, L=L)


def _hex_nut(rng):
    R, H = rng.uniform(0.8, 1.5), rng.uniform(0.5, 1.0)
    rb = rng.uniform(0.35, 0.55) * R
    ch = float(rng.uniform(0.05, 0.12)) if rng.integers(0, 2) else 0.0
    a = np.arange(6) * np.pi / 3 + rng.uniform(0, np.pi / 3)
    s = _cut(_polygon_prism(R * np.c_[np.cos(a), np.sin(a)], 0, H), _cyl((0, 0, -1), rb, H + 2))
    if ch:
        s = _chamfer(s, ch, lambda p: bool(np.abs(np.hypot(p[:, 0], p[:, 1]) - rb).max() < 1e-9))
    return s, dict(R=R, H=H, bore=rb, chamfer=ch)


def _flange(rng):
    R, T = rng.uniform(1.5, 2.5), rng.uniform(0.25, 0.5)
    rh, hh = rng.uniform(0.4, 0.55) * R, rng.uniform(0.4, 1.0)
    rb = rng.uniform(0.45, 0.7) * rh
    n = int(rng.integers(3, 7))
    rc = 0.5 * (R + rh)
    rbolt = rng.uniform(0.25, 0.4) * (R - rh)
    s = _fuse(_cyl((0, 0, 0), R, T), _cyl((0, 0, T), rh, hh))
    a = np.arange(n) * 2 * np.pi / n
    tools = [_cyl((rc * np.cos(t), rc * np.sin(t), -1), rbolt, T + 2) for t in a]
    return _cut(s, _cyl((0, 0, -1), rb, T + hh + 2), *tools), dict(
        R=R, T=T, hub=rh, hub_h=hh, bore=rb, bolts=n, bolt_r=rbolt)


def _washer(rng):
    R, T = rng.uniform(0.8, 1.6), rng.uniform(0.1, 0.3)
    rb = rng.uniform(0.35, 0.6) * R
    ch = float(rng.uniform(0.2, 0.4) * T) if rng.integers(0, 2) else 0.0
    s = _cut(_cyl((0, 0, 0), R, T), _cyl((0, 0, -1), rb, T + 2))
    if ch:
        s = _chamfer(s, ch, lambda p: bool(np.abs(np.hypot(p[:, 0], p[:, 1]) - R).max() < 1e-9))
    return s, dict(R=R, T=T, bore=rb, chamfer=ch)


def _l_bracket(rng):
    W, L1, L2, T = rng.uniform(1.5, 3), rng.uniform(2, 3.5), rng.uniform(1.5, 3), \
        rng.uniform(0.3, 0.5)
    r = rng.uniform(0.12, 0.2) * W
    fil = float(rng.uniform(0.2, 0.5) * T) if rng.integers(0, 2) else 0.0
    s = _fuse(_box(0, 0, 0, L1, W, T), _box(0, 0, 0, T, W, L2))
    if fil:     # the inner corner: the edge along y at (T, ., T)
        s = _fillet(s, fil, lambda p: bool(np.abs(p[:, [0, 2]] - T).max() < 1e-9))
    s = _cut(s, _cyl((0.5 * (L1 + T), W / 2, -1), r, T + 2),
             _cyl((-1, W / 2, 0.5 * (L2 + T)), r, T + 2, d=(1, 0, 0)))
    return s, dict(W=W, L1=L1, L2=L2, T=T, r=r, fillet=fil)


def _shaft(rng):
    n = int(rng.integers(2, 4))
    radii = np.sort(rng.uniform(0.3, 1.0, n))[::-1]
    lengths = rng.uniform(0.6, 1.5, n)
    ch = float(rng.uniform(0.05, 0.15))
    z = np.r_[0.0, np.cumsum(lengths)]
    prof = [(0.0, 0.0), (radii[0] - ch, 0.0), (radii[0], ch)]
    for i in range(n):
        if i:
            prof.append((radii[i], z[i]))
        prof.append((radii[i], z[i + 1] - (ch if i == n - 1 else 0.0)))
        if i < n - 1:
            prof.append((radii[i + 1], z[i + 1]))
    prof += [(radii[-1] - ch, z[-1]), (0.0, z[-1])]
    clean = [prof[0]] + [p for p, q in zip(prof[1:], prof) if np.hypot(p[0] - q[0], p[1] - q[1])
                         > 1e-9]
    return _revolved(clean), dict(radii=radii.round(4).tolist(), lengths=lengths.round(4).tolist(),
                                  chamfer=ch)


def _rounded_block(rng):
    W, D, H = rng.uniform(1.5, 3), rng.uniform(1.5, 3), rng.uniform(0.8, 2)
    r = rng.uniform(0.1, 0.25) * min(W, D, H)
    edges = ("vertical", "top", "all")[int(rng.integers(0, 3))]
    chamfer = bool(rng.integers(0, 2))
    s = _box(0, 0, 0, W, D, H)
    keep = {"vertical": _vertical, "top": _at_height(H), "all": lambda p: True}[edges]
    s = _chamfer(s, r, keep) if chamfer else _fillet(s, r, keep)
    return s, dict(W=W, D=D, H=H, r=r, edges=edges, chamfer=chamfer)


def _knob(rng):
    R, H = rng.uniform(0.8, 1.5), rng.uniform(0.5, 1.2)
    r = rng.uniform(0.15, 0.35) * min(R, H)
    bore = float(rng.uniform(0.2, 0.4) * R) if rng.integers(0, 2) else 0.0
    s = _fillet(_cyl((0, 0, 0), R, H), r, _at_height(H))
    if bore:
        s = _cut(s, _cyl((0, 0, -1), bore, H + 2))
    return s, dict(R=R, H=H, r=r, bore=bore)


def _pin(rng):
    R, H = rng.uniform(0.3, 0.7), rng.uniform(1.0, 2.5)
    head = ("dome", "point", "countersunk")[int(rng.integers(0, 3))]
    body = _cyl((0, 0, 0), R, H)
    if head == "dome":
        from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere
        from OCP.gp import gp_Pnt
        cap = BRepPrimAPI_MakeSphere(gp_Pnt(0, 0, H), float(R)).Shape()
        s = _fuse(body, cap)
    elif head == "point":
        s = _fuse(body, _cone((0, 0, H), R, 0.0, rng.uniform(0.5, 1.5) * R))
    else:
        s = _fuse(body, _cone((0, 0, H), R, 1.8 * R, 0.8 * R), _cyl((0, 0, H + 0.8 * R),
                                                                   1.8 * R, 0.3 * R))
    return s, dict(R=R, H=H, head=head)


#: The families and how many parts each contributes to the default set.
FAMILIES = {"plate": (_plate, 4), "boss": (_boss, 3), "slot": (_slot, 3),
            "hex_nut": (_hex_nut, 3), "flange": (_flange, 3), "washer": (_washer, 3),
            "l_bracket": (_l_bracket, 3), "shaft": (_shaft, 3),
            "block": (_rounded_block, 4), "knob": (_knob, 3), "pin": (_pin, 3)}


def cad_parts(seed: int = 0, *, families=None) -> list:
    """The CAD test set: every family's parts, dimensions drawn from ``seed``.

    Parameters
    ----------
    seed : int
        One generator per family, seeded with ``(seed, family index)``; the same seed
        gives the same parts.
    families : iterable of str, optional
        Names of :data:`FAMILIES` to build (default all).

    Returns
    -------
    list of CadPart
        In :data:`FAMILIES` order, ``name`` = ``family-k``.
    """
    want = list(FAMILIES) if families is None else list(families)
    out = []
    for fi, (fam, (make, n)) in enumerate(FAMILIES.items()):
        if fam not in want:
            continue
        rng = np.random.default_rng([seed, fi])
        for k in range(n):
            shape, params = make(rng)
            out.append(CadPart(f"{fam}-{k}", fam, params, shape))
    return out


# --------------------------------------------------------------------------- the input curves
def part_network(shape) -> CurveNetwork:
    """The B-rep edges of ``shape`` as a curve network.

    One junction per B-rep vertex, one curve per edge (closed edges, such as a full
    circle, start and end at their one vertex), sampled uniformly in the edge's
    parameter: :data:`EDGE_SAMPLES` ``[0]`` points on a straight edge, one per
    1/120 of the diagonal on a curved one (within :data:`EDGE_SAMPLES`). Degenerate
    edges (a sphere's pole, a cone's apex) are no curves.

    Returns
    -------
    CurveNetwork
        Curves in the order of OpenCascade's edge map.
    """
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GCPnts import GCPnts_AbscissaPoint
    from OCP.GeomAbs import GeomAbs_Line
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FORWARD, TopAbs_VERTEX
    from OCP.TopExp import TopExp
    from OCP.TopoDS import TopoDS
    from OCP.OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as ShapeMap
    vm, em = ShapeMap(), ShapeMap()
    TopExp.MapShapes_s(shape, TopAbs_VERTEX, vm)
    TopExp.MapShapes_s(shape, TopAbs_EDGE, em)
    pos = np.array([[p.X(), p.Y(), p.Z()] for p in (BRep_Tool.Pnt_s(TopoDS.Vertex(vm.FindKey(i)))
                                                    for i in range(1, vm.Size() + 1))])
    diag = bbox_diagonal(pos)
    net = CurveNetwork(pos)
    for i in range(1, em.Size() + 1):
        e = TopoDS.Edge(TopoDS.Edge(em.FindKey(i)).Oriented(TopAbs_FORWARD))
        if BRep_Tool.Degenerated_s(e):
            continue
        a = BRepAdaptor_Curve(e)
        t0, t1 = a.FirstParameter(), a.LastParameter()
        if a.GetType() == GeomAbs_Line:
            n = EDGE_SAMPLES[0]
        else:
            length = GCPnts_AbscissaPoint.Length_s(a)
            n = int(np.clip(np.ceil(length / (_SAMPLE_STEP * diag)) + 1, *EDGE_SAMPLES))
        pts = np.array([[q.X(), q.Y(), q.Z()] for q in
                        (a.Value(float(s)) for s in np.linspace(t0, t1, n))])
        u = vm.FindIndex(TopExp.FirstVertex_s(e)) - 1
        v = vm.FindIndex(TopExp.LastVertex_s(e)) - 1
        net.add_edge(u, v, pts)
    return net
