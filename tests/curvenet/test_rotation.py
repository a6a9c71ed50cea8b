"""Faces of the rotation system the junctions imply (curvenet.cycles.rotation), and the
patch finder's choice between them and the cycle basis."""

from __future__ import annotations

import numpy as np
import pytest

from curvenet.cycles import find_patches
from curvenet.cycles.rotation import embedded_faces
from curvenet.datasets import sections, shapes
from curvenet.model.network import CurveNetwork


def _found(ps):
    return {tuple(sorted(p.edges)) for p in ps.patches}


@pytest.mark.parametrize("m, n", [(3, 2), (4, 2), (3, 4), (5, 3), (6, 4)])
@pytest.mark.parametrize("minor", [0.25, 0.6])
def test_sparse_tori_give_exactly_their_faces(m, n, minor):
    shape = shapes.torus(1.0, minor, n_u=m, n_v=n)
    faces = embedded_faces(shape.network)
    assert sorted(faces.edge_sets) == shape.face_edge_sets()
    assert faces.simple.all() and faces.genus == [1] and faces.report["conflicts"] == 0
    # the patch finder keeps them: every curve bounds exactly two patches
    assert _found(find_patches(shape.network)) == set(shape.face_edge_sets())


def _split(net, edges):
    """``net`` with each curve of ``edges`` split at its middle sample (a junction of two
    curves, as where a closed stroke's ends meet)."""
    out = CurveNetwork(np.array(net.positions))
    for i, e in enumerate(net.edges):
        if i not in edges:
            out.add_edge(e.u, e.v, e.curve, label=e.label)
            continue
        k = len(e.curve) // 2
        mid = out.add_vertex(e.curve[k])
        out.add_edge(e.u, mid, e.curve[:k + 1], label=e.label)
        out.add_edge(mid, e.v, e.curve[k:], label=e.label)
    return out


@pytest.mark.parametrize("make", [lambda: shapes.torus(1.0, 0.4, n_u=3, n_v=4),
                                  lambda: sections.great_circles(3),
                                  lambda: shapes.capped_cylinder(n_around=4, n_height=3)])
def test_a_face_split_by_junctions_of_two_curves_is_kept(make):
    """The faces of a closed surface are one GF(2) relation: the heaviest is left out of
    the independent set and comes back as the closing patch of the hole it leaves. Two
    sides of one face split (junctions of two curves, as where a closed stroke's ends
    met) make it the only face of that many curves; the closing rules looked only as
    far as the longest face kept and left a hole (a torus, a sphere of three great
    circles, a capped cylinder: one face short)."""
    shape = make()
    faces = [p.edges for p in find_patches(shape.network).patches]   # its faces, tested above
    face = max(faces, key=len)
    net = _split(shape.network, set(face[:2]))
    ps = find_patches(net)
    uses = np.bincount([e for p in ps.patches for e in p.edges], minlength=net.number_of_edges)
    assert ps.report["mode"] == "faces"
    assert len(ps.patches) == len(faces) and (uses == 2).all()
    assert max(len(p.edges) for p in ps.patches) == len(face) + 2


def test_the_basis_alone_caps_the_meridians_of_a_sparse_torus():
    # Abbasinejad's mode: a meridian (2 curves) is shorter than every face (4 curves)
    shape = shapes.torus(n_u=4, n_v=2)
    basis = find_patches(shape.network, mode="basis")
    assert _found(basis) != set(shape.face_edge_sets())
    uses = np.bincount([e for p in basis.patches for e in p.edges],
                       minlength=shape.network.number_of_edges)
    assert (uses >= 3).any()                         # walls inside the tube
    auto = find_patches(shape.network)
    defect = auto.report["embedding"]["defect"]
    assert auto.report["mode"] == "faces" and defect["faces"] == 0 < defect["basis"]


@pytest.mark.parametrize("name", ["box", "l_prism", "house", "sphere", "ellipsoid",
                                  "capped_cylinder", "grid_box"])
def test_genus_zero_shapes_give_their_faces_as_the_basis_does(name):
    shape = shapes.SHAPES[name]()
    faces = embedded_faces(shape.network)
    assert sorted(faces.edge_sets) == shape.face_edge_sets() and faces.genus == [0]
    # both selections are the true faces, a closed surface: auto takes the faces on the tie
    ps = find_patches(shape.network)
    assert ps.report["embedding"]["defect"] == {"basis": 0, "faces": 0}
    assert ps.report["mode"] == "faces" and _found(ps) == set(shape.face_edge_sets())
    assert _found(find_patches(shape.network, mode="basis")) == set(shape.face_edge_sets())


def test_an_open_sheet_has_its_faces_and_its_rim():
    shape = shapes.grid_sheet(3)
    faces = embedded_faces(shape.network)
    rim = [f for f in faces.edge_sets if f not in set(shape.face_edge_sets())]
    assert len(faces.loops) == 10 and len(rim) == 1 and len(rim[0]) == 12
    # the rim is no patch: closing considers no cycle longer than the faces kept
    assert _found(find_patches(shape.network)) == set(shape.face_edge_sets())


def test_faces_do_not_depend_on_vertex_or_edge_order():
    shape = shapes.torus(n_u=3, n_v=4)
    net = shape.network
    rng = np.random.default_rng(1)
    vperm = rng.permutation(net.number_of_vertices)
    eperm = rng.permutation(net.number_of_edges)
    moved = CurveNetwork(net.positions[np.argsort(vperm)])
    for i in eperm:
        e = net.edges[i]
        moved.add_edge(int(vperm[e.u]), int(vperm[e.v]), e.curve)
    back = {tuple(sorted(int(eperm[i]) for i in f)) for f in embedded_faces(moved).edge_sets}
    assert back == set(shape.face_edge_sets())


def test_free_ends_bound_no_face():
    shape = shapes.torus(n_u=4, n_v=2)
    net = shape.network
    tip = net.add_vertex(net.positions[0] + [0.0, 0.0, 0.5])
    net.add_edge(0, tip, np.linspace(net.positions[0], net.positions[tip], 5))
    faces = embedded_faces(net)
    assert faces.report["dangling"] == 1 and not faces.core[-1]
    assert sorted(faces.edge_sets) == shape.face_edge_sets()


@pytest.mark.parametrize("shape, genus", [(sections.great_circles(3), 0),
                                          (sections.great_circles(4), 0),
                                          (sections.capsule(), 0),
                                          (sections.double_torus(), 2)])
def test_section_wireframes_embed_with_their_genus(shape, genus):
    faces = embedded_faces(shape.network)
    assert faces.simple.all() and faces.genus == [genus]
    net = shape.network
    # every section lies on the surface and meets the others at shared junctions
    ref = shape.reference_mesh(2)  # marching cubes on 160^3: errors ~1e-4 of the diagonal
    from curvenet.core.distance import point_surface_distance
    d = point_surface_distance(np.concatenate([e.curve for e in net.edges]), ref.vertices,
                               ref.faces)[0]
    assert d.max() < 5e-3 * net.diagonal
    deg = np.bincount(net.endpoints.ravel(), minlength=net.number_of_vertices)
    assert (deg == 4).all()


def test_spanning_tree_is_scipys_forest_also_where_costs_tie():
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import minimum_spanning_tree
    from curvenet.cycles.rotation import _spanning_tree
    rng = np.random.default_rng(5)
    for _ in range(200):
        n = int(rng.integers(2, 30))
        a, b = rng.integers(0, n, (2, int(rng.integers(1, 3 * n))))
        code = np.unique(np.minimum(a, b) * n + np.maximum(a, b))
        lo, hi = code // n, code % n
        keep = lo < hi
        lo, hi = lo[keep], hi[keep]
        perm = rng.permutation(len(lo))                      # any input order
        lo, hi = lo[perm], hi[perm]
        cost = 1.0 + rng.integers(0, 3, len(lo)) / 4         # many ties
        r, c = _spanning_tree(lo, hi, cost, n)
        t = minimum_spanning_tree(coo_matrix((cost, (lo, hi)), shape=(n, n)).tocsr()).tocoo()
        assert sorted(zip(r.tolist(), c.tolist())) == sorted(zip(t.row.tolist(), t.col.tolist()))
