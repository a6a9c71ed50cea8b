"""Faces with holes: the CAD-like oracles, hole detection, multiply-connected surfacing."""

import json

import numpy as np
import pytest
import trimesh

from curvenet.datasets import shapes
from curvenet.cycles.find import cycle_to_loop, find_patches
from curvenet.cycles.holes import hole_patches
from curvenet.cycles.loops import signed_volume
from curvenet.io.network import read_patches, write_patches
from curvenet.model.patchset import Patch, PatchSet

CAD = sorted(shapes.CAD_SHAPES)

#: true area of each CAD shape's surface (closed form)
AREAS = {
    "washer": 2 * np.pi * (1 - 0.25) + 2 * np.pi * (1 + 0.5) * 0.2,
    "holed_plate": 2 * (6 - 2 * np.pi * 0.09 - 0.8) + 10 * 0.2 + 2 * 2 * np.pi * 0.3 * 0.2
    + 3.6 * 0.2,
    "hex_nut": 2 * (1.5 * np.sqrt(3) - np.pi * 0.25) + 6 * 0.8 + 2 * np.pi * 0.5 * 0.8,
    "flange": 2 * np.pi * (2.25 - 0.25 - 4 * 0.0225) + 2 * np.pi * (1.5 + 0.5 + 4 * 0.15) * 0.3,
    "boss_box": 2 * 4 + 4 * 2 + 2 * np.pi * 0.5 * 0.6,
    "l_bracket": 2 * 1.41 + 10 * 2 + 2 * np.pi * 0.3 * 0.3 - 2 * np.pi * 0.09,
}


@pytest.fixture(scope="module", params=CAD)
def cad(request):
    return shapes.CAD_SHAPES[request.param]()


def _all_loops(s):
    return s.faces + [lp for hs in s.holes for lp in hs]


def test_cad_shape_is_consistent(cad):
    net = cad.network
    use = {}
    for loop in _all_loops(cad):
        ends = [(net.edges[e].u, net.edges[e].v)[:: 1 if f else -1] for e, f in loop]
        assert all(b == c for (_, b), (c, _) in zip(ends, ends[1:] + ends[:1]))
        for e, f in loop:
            use.setdefault(e, []).append(f)
    # a closed oriented surface: every curve walked twice, in opposite directions
    assert all(len(v) == 2 and v[0] != v[1] for v in use.values())
    assert len(use) == net.number_of_edges
    n_holes = sum(len(h) for h in cad.holes)
    chi = net.number_of_vertices - net.number_of_edges + len(cad.faces) - n_holes
    assert chi == 2 - 2 * cad.genus
    assert signed_volume(net, _all_loops(cad)) > 0
    ref = cad.reference_mesh(3)
    assert ref.area == pytest.approx(AREAS[cad.name], rel=2e-3)
    pts = np.concatenate([e.curve for e in net.edges])
    _, dist, _ = trimesh.proximity.closest_point(ref, pts[::3])
    assert dist.max() < 1e-3 * np.linalg.norm(ref.extents)


def test_cad_patches_are_exact(cad):
    ps = find_patches(cad.network)
    got = sorted((p.edges, tuple(sorted(p.holes))) for p in ps.patches)
    want = sorted((tuple(sorted(e for e, _ in f)), tuple(h))
                  for f, h in zip(cad.faces, cad.face_holes()))
    assert got == want
    # every hole loop's own disc was dropped: a wall continues through each of them
    assert len(ps.report["holes"]) == sum(len(h) for h in cad.holes)
    assert not any(h["disc_kept"] for h in ps.report["holes"])


def test_boss_cap_stays_a_disc():
    s = shapes.boss_box()
    ps = find_patches(s.network)
    cap = [p for p in ps.patches
           if np.allclose(np.concatenate([s.network.edges[e].curve for e in p.edges])[:, 2], 1.6)]
    assert len(cap) == 1 and cap[0].holes == ()


def test_hole_detection_off_keeps_simple_cycles():
    s = shapes.washer()
    ps = find_patches(s.network, holes=False)
    assert all(not p.holes for p in ps.patches) and ps.report["holes"] == []
    assert len(ps.patches) == len(s.faces) + 2


def test_a_disc_drawn_inside_a_face_is_kept():
    """A circle inside a square with nothing attached: the square gets a hole, the disc stays."""
    from curvenet.model.network import CurveNetwork
    net = CurveNetwork(np.zeros((0, 3)))
    sq = [net.add_vertex(p) for p in ([0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0])]
    t = np.linspace(0, 1, 17)[:, None]
    outer = [net.add_edge(a, b, (1 - t) * net.positions[a] + t * net.positions[b])
             for a, b in zip(sq, sq[1:] + sq[:1])]
    c = [net.add_vertex(p) for p in ([1.5, 1, 0], [0.5, 1, 0])]
    a = np.pi * t
    arc = np.c_[1 + 0.5 * np.cos(a), 1 + 0.5 * np.sin(a), 0 * a]
    lower = np.c_[1 - 0.5 * np.cos(a), 1 - 0.5 * np.sin(a), 0 * a]
    inner = [net.add_edge(c[0], c[1], arc), net.add_edge(c[1], c[0], lower)]
    patches, report = hole_patches(net, [Patch(outer), Patch(inner)])
    assert [p.holes for p in patches] == [(tuple(inner),), ()]
    assert report == [{"face": 0, "loop": inner, "disc_kept": True, "source": "auto"}]
    # lifted out of the square's plane, the circle is no hole
    for i in inner:
        net.edges[i].curve = net.edges[i].curve + [0, 0, 0.1]
    net.positions[c] += [0, 0, 0.1]
    patches, report = hole_patches(net, [Patch(outer), Patch(inner)])
    assert report == [] and all(not p.holes for p in patches)


def test_a_loop_on_a_sheet_where_surfaces_meet_stays_a_disc():
    """The square shares a side with two more patches (a fin where three surfaces meet):
    it is a sheet, not a solid's face, so the circle on it (a fin base) is no hole."""
    from curvenet.model.network import CurveNetwork
    net = CurveNetwork(np.zeros((0, 3)))
    sq = [net.add_vertex(p) for p in ([0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0])]
    t = np.linspace(0, 1, 17)[:, None]

    def straight(a, b):
        return net.add_edge(a, b, (1 - t) * net.positions[a] + t * net.positions[b])
    outer = [straight(a, b) for a, b in zip(sq, sq[1:] + sq[:1])]
    c = [net.add_vertex(p) for p in ([1.5, 1, 0], [0.5, 1, 0])]
    a = np.pi * t
    inner = [net.add_edge(c[0], c[1], np.c_[1 + 0.5 * np.cos(a), 1 + 0.5 * np.sin(a), 0 * a]),
             net.add_edge(c[1], c[0], np.c_[1 - 0.5 * np.cos(a), 1 - 0.5 * np.sin(a), 0 * a])]
    fins = []
    for z in (1.0, -1.0):
        apex = net.add_vertex([1, -0.5, z])
        fins.append(Patch([outer[0], straight(sq[1], apex), straight(apex, sq[0])]))
    patches, report = hole_patches(net, [Patch(outer), Patch(inner), *fins])
    assert report == [] and all(not p.holes for p in patches)
    # with one fin the square's sides are manifold again: the circle is a hole
    patches, report = hole_patches(net, [Patch(outer), Patch(inner), fins[0]])
    assert [p.holes for p in patches] == [(tuple(inner),), (), ()]


def _tube_on_plate(samples=17):
    """A 2 x 2 x 0.5 plate with a tube (r 0.6, bore r 0.3) standing on it, the bore going
    through tube and plate: the bore's curve where the tube meets the plate lies inside
    the tube's footprint, a hole of the plate's top face whose disc is dropped (issue 31,
    the ABC part stopped with KeyError)."""
    from curvenet.datasets import cadnet
    b = cadnet.CadBuilder(samples)
    frame = cadnet.Frame()
    square = cadnet.polygon([(0, 0), (2, 0), (2, 2), (0, 2)])
    (bottom, bottom_p), (top, top_p) = b.wall(square, frame, 0.0, 0.5)
    bore_low, _ = b.wall(cadnet.circle((1, 1), 0.3), frame, 0.0, 0.5)
    foot, rim = b.wall(cadnet.circle((1, 1), 0.6), frame, 0.5, 1.2)
    _, bore_top = b.wall(cadnet.circle((1, 1), 0.3), frame, 0.5, 1.2)
    b.planar_face([(bottom, bottom_p), bore_low])
    b.planar_face([(top, top_p), foot])
    b.planar_face([rim, bore_top])
    return shapes._cad("tube_on_plate", b, 1)


def test_a_bore_through_a_tube_on_a_plate_is_its_faces():
    """The loop inside a dropped hole is no hole: where the bore's two walls meet, its disc
    goes too (each of its curves bounds both walls), and the patches are the true faces."""
    s = _tube_on_plate()
    ps = find_patches(s.network)
    got = sorted((p.edges, tuple(sorted(p.holes))) for p in ps.patches)
    want = sorted((tuple(sorted(e for e, _ in f)), tuple(h))
                  for f, h in zip(s.faces, s.face_holes()))
    assert got == want
    assert len(ps.report["holes"]) == 3 and not any(h["disc_kept"] for h in ps.report["holes"])


def _squares(net, centre, sizes, frame):
    """Concentric squares (straight curves) in the plane ``centre + x e1 + y e2``."""
    t = np.linspace(0, 1, 9)[:, None]
    loops = []
    for h in sizes:
        corners = [net.add_vertex(centre + frame @ np.array([x, y])) for x, y in
                   ((-h, -h), (h, -h), (h, h), (-h, h))]
        loops.append([net.add_edge(a, b, (1 - t) * net.positions[a] + t * net.positions[b])
                      for a, b in zip(corners, corners[1:] + corners[:1])])
    return loops


def test_a_disc_inside_a_dropped_hole_is_no_hole():
    """Square A holds B holds C, all coplanar; B's curves bound a wall too (B is a dropped
    hole of A), C's do not: C, in B's opening, is no hole and stays a disc."""
    from curvenet.model.network import CurveNetwork
    net = CurveNetwork(np.zeros((0, 3)))
    a, b, c = _squares(net, np.zeros(3), (3.0, 2.0, 1.0), np.eye(3)[:, :2])
    top = _squares(net, np.array([0, 0, 1.0]), (2.0,), np.eye(3)[:, :2])[0]
    ends = [(net.edges[e].u, net.edges[e].v) for e in b + top]
    t = np.linspace(0, 1, 9)[:, None]
    rise = [net.add_edge(u, v, (1 - t) * net.positions[u] + t * net.positions[v])
            for u, v in zip([u for u, _ in ends[:4]], [u for u, _ in ends[4:]])]
    walls = [Patch([b[k], rise[(k + 1) % 4], top[k], rise[k]]) for k in range(4)]
    patches, report = hole_patches(net, [Patch(a), Patch(b), Patch(c), *walls])
    assert [p.holes for p in patches] == [(tuple(b),), (), (), (), (), ()]
    assert [p.edges for p in patches[:2]] == [tuple(a), tuple(c)]
    assert report == [{"face": 0, "loop": b, "disc_kept": False, "source": "auto"}]


def _pairwise_holes(network, patches, tol=1e-4):
    """The first implementation: every pair of planar patches tested (the oracle)."""
    from matplotlib.path import Path

    from curvenet.core.geometry import fit_plane
    from curvenet.cycles.holes import _area2d
    from curvenet.cycles.loops import loop_points
    tol *= network.diagonal
    info = []
    for p in patches:
        pts = loop_points(network, cycle_to_loop(network, p.edges))
        c, nrm, axes = fit_plane(pts)
        verts = {network.edges[e].u for e in p.edges} | {network.edges[e].v for e in p.edges}
        info.append((pts, c, nrm, axes, float(np.abs((pts - c) @ nrm).max()) <= tol, verts))
    uses = np.bincount([e for p in patches for e in p.edges], minlength=network.number_of_edges)
    manifold = [bool((uses[list(p.edges)] <= 2).all()) for p in patches]
    parent = {}
    for i, (pi, _, _, _, planar_i, vi) in enumerate(info):
        best = None
        for j, (pj, cj, nj, aj, planar_j, vj) in enumerate(info):
            if (not planar_i or j == i or not planar_j or not manifold[j] or vi & vj
                    or np.abs((pi - cj) @ nj).max() > tol
                    or not Path((pj - cj) @ aj.T).contains_points((pi - cj) @ aj.T).all()):
                continue
            area = abs(_area2d((pj - cj) @ aj.T))
            if best is None or area < best[0]:
                best = (area, j)
        if best is not None:
            parent[i] = best[1]
    return {i: (j, bool((uses[list(patches[i].edges)] >= 2).all())) for i, j in parent.items()}


def _nesting(report, out):
    """Sorted ``(inner loop, outer loop, dropped)`` of a result."""
    return sorted((tuple(h["loop"]), out[h["face"]].edges, not h["disc_kept"]) for h in report)


def _pairwise_nesting(network, patches):
    """Sorted ``(inner loop, outer loop, dropped)`` of the oracle."""
    return sorted((patches[i].edges, patches[j].edges, d)
                  for i, (j, d) in _pairwise_holes(network, patches).items())


@pytest.mark.parametrize("seed", range(4))
def test_holes_match_the_pairwise_search(seed):
    """Nested squares in tilted planes, some sharing a plane, some a corner, some walled:
    the R-tree search finds the holes the all-pairs search finds."""
    from scipy.spatial.transform import Rotation

    from curvenet.model.network import CurveNetwork
    rng = np.random.default_rng(seed)
    net = CurveNetwork(np.zeros((0, 3)))
    loops = []
    for _ in range(6):
        frame = Rotation.random(random_state=rng).as_matrix()[:, :2]
        for centre in rng.uniform(-5, 5, (3, 3)):
            loops += _squares(net, centre, np.sort(rng.uniform(0.2, 2.0, 3))[::-1], frame)
        # a square in the same plane, off the others' centres; a tilted one across them
        loops += _squares(net, centre + frame @ rng.uniform(-1, 1, 2), (0.1,), frame)
        loops += _squares(net, centre, (0.5,), Rotation.random(random_state=rng).as_matrix()
                          [:, :2])
    patches = [Patch(lp) for lp in loops]
    # the largest and the smallest of each concentric three walled (listed twice, as by a
    # wall through the loop): the largest still an outer face, the smallest a dropped hole
    # (not in the third plane, whose smallest square may hold the off-centre one: the
    # oracle fails on a hole inside a dropped hole)
    patches += [Patch(loops[11 * f + 3 * g + k]) for f in range(6) for g in range(3)
                for k in (0, 2) if (g, k) != (2, 2)]
    out, report = hole_patches(net, patches)
    want = _pairwise_nesting(net, patches)
    assert len(want) > 30 and sum(d for _, _, d in want) >= 12
    assert _nesting(report, out) == want


@pytest.mark.parametrize("name", CAD)
def test_cad_holes_match_the_pairwise_search(name):
    s = shapes.CAD_SHAPES[name]()
    basis = find_patches(s.network, holes=False).patches
    out, report = hole_patches(s.network, basis)
    assert _nesting(report, out) == _pairwise_nesting(s.network, basis) != []


@pytest.mark.data
def test_submarine_fin_base_stays_a_disc(data_dir):
    """mingzou/SGA_Submarine: a fin stands on a flat plate attached along a curve shared by
    three patches; its base stays a disc (43 patches, as without hole detection)."""
    from curvenet.pipeline import patches
    f = data_dir / "networks" / "mingzou" / "SGA_Submarine.obj"
    ps = patches(f)
    assert len(ps.patches) == 43 and ps.report["holes"] == []


def test_patches_json_keeps_holes(tmp_path):
    s = shapes.washer()
    ps = find_patches(s.network)
    write_patches(tmp_path / "p.json", ps)
    back = read_patches(tmp_path / "p.json")
    assert [(p.edges, p.holes) for p in back.patches] == [(p.edges, p.holes) for p in ps.patches]
    data = json.loads((tmp_path / "p.json").read_text())
    assert data["version"] == 1
    assert sum("holes" in p for p in data["patches"]) == 2
    # a file without the field reads as before
    for p in data["patches"]:
        p.pop("holes", None)
    assert all(not p.holes for p in PatchSet.from_dict(data).patches)
    data["patches"][0]["holes"] = [[]]
    with pytest.raises(Exception, match="empty hole"):
        PatchSet.from_dict(data)


def _classical(s):
    from curvenet.pipeline import surface
    return surface(s.network)


@pytest.mark.parametrize("name", CAD)
def test_cad_classical_fscore(name):
    from curvenet.evaluate import evaluate_mesh
    s = shapes.CAD_SHAPES[name]()
    res = _classical(s)
    assert evaluate_mesh(res.mesh, s.reference_mesh(4), n_samples=30_000)["fscore"] >= 0.99


@pytest.mark.parametrize("name", CAD)
def test_cad_flat_faces_are_flat(name):
    """Every output vertex of a planar face lies in its plane to 1e-6 of the diagonal."""
    from curvenet.cycles.loops import orient_boundaries
    from curvenet.surfacing.sectors import surface_boundaries
    s = shapes.CAD_SHAPES[name]()
    net = s.network
    ps = find_patches(net)
    curves = [e.curve for e in net.edges]
    res = surface_boundaries(curves, orient_boundaries(net, ps.patches),
                             crease_curves=[i for i, e in enumerate(net.edges)
                                            if e.label == "crease"])
    diag = net.diagonal
    n_flat = 0
    for k, p in enumerate(ps.patches):
        pts = np.concatenate([net.edges[e].curve for e in p.all_edges])
        c = pts.mean(axis=0)
        normal = np.linalg.svd(pts - c)[2][2]
        if np.abs((pts - c) @ normal).max() > 1e-9 * diag:
            continue
        n_flat += 1
        v = res.vertices[np.unique(res.faces[res.face_patch == k])]
        assert np.abs((v - c) @ normal).max() <= 1e-6 * diag
    assert n_flat == res.report["flat_patches"] == res.report["flat_meshed"] >= 2
    assert len(res.faces) <= 200_000


@pytest.mark.parametrize("name", CAD)
def test_cad_output_topology(name):
    """Welded output: a closed surface (no boundary loop) of the true genus (chi = 2 - 2g)."""
    s = shapes.CAD_SHAPES[name]()
    m = _classical(s).mesh.copy()
    m.merge_vertices()
    assert m.euler_number == 2 - 2 * s.genus
    assert len(trimesh.grouping.group_rows(m.edges_sorted, require_count=1)) == 0


def test_plane_of_a_two_point_loop_is_a_complete_frame():
    # a 2-cycle of two straight curves walks as two points; real sketches have them
    from curvenet.core.geometry import fit_plane
    c, nrm, axes = fit_plane(np.array([[0.0, 0, 0], [1.0, 0, 0]]))
    frame = np.vstack([axes, nrm])
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(c, [0.5, 0, 0])


def test_a_face_no_cut_can_split_is_surfaced_over_its_outer_loop(monkeypatch):
    # e.g. the VNS torus sketch: an equator disc with the inner equator as a hole
    import curvenet.surfacing.sectors as sh

    def refuse(*args, **kwargs):
        raise sh.UnsplittableFace("no set of straight cuts")
    monkeypatch.setattr(sh, "split_holed", refuse)
    t = np.linspace(0, 2 * np.pi, 33)[:, None]
    outer = np.hstack([2 * np.cos(t), 2 * np.sin(t), 0 * t])
    inner = np.hstack([np.cos(t), np.sin(t), 0 * t])
    boundaries = [[[(0, True)]], [[(0, True)], [(1, False)]]]
    curves, loops, owner, unsplit = sh.split_boundaries([outer, inner], boundaries)
    assert unsplit == [1] and len(curves) == 2
    assert loops == [[(0, True)], [(0, True)]] and owner.tolist() == [0, 1]


def test_many_flat_faces_stay_under_the_default_face_cap():
    """A flange with 12 bolt holes (58 patches, ABC-sized): the in-plane meshes of its two
    large flat faces are coarsened until the whole output fits in 200k triangles."""
    s = shapes.flange(bolts=12)
    res = _classical(s)
    assert len(res.patchset.patches) == 58
    assert 150_000 < len(res.mesh.faces) <= 200_000
