import numpy as np
import pytest
import trimesh

from curvenet.datasets import shapes
from curvenet.surfacing.catmull_clark import edge_topology, euler_characteristic
from curvenet.surfacing.controlmesh import build_control_mesh, orient_loops


def _tri(cm):
    q = cm.quads
    return trimesh.Trimesh(cm.vertices, np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]]),
                           process=False)


def _net(name):
    s = shapes.SHAPES[name]()
    return s, [e.curve for e in s.network.edges]


@pytest.mark.parametrize("name", ["box", "l_prism", "house", "sphere", "ellipsoid",
                                  "capped_cylinder", "torus", "grid_box"])
def test_closed_shapes_give_closed_consistently_oriented_meshes(name):
    s, curves = _net(name)
    cm = build_control_mesh(curves, s.faces, 4)
    m = _tri(cm)
    assert m.is_watertight and m.is_winding_consistent and m.volume > 0
    assert euler_characteristic(cm.quads, len(cm.vertices)) == 2 - 2 * s.genus
    # no degenerate quad: four distinct vertices, non-zero area
    assert all(len(set(q)) == 4 for q in cm.quads.tolist())
    assert m.area_faces.min() > 0


def test_shared_samples_are_shared_vertices():
    s, curves = _net("box")
    cm = build_control_mesh(curves, s.faces, 4)
    # 8 junctions + 12 curves x 3 interior samples + 6 faces x 9 interior points
    assert len(cm.vertices) == 8 + 12 * 3 + 6 * 9
    for c, ids in enumerate(cm.curve_vids):
        np.testing.assert_allclose(cm.vertices[ids[[0, -1]]], curves[c][[0, -1]], atol=1e-12)


def test_inconsistent_loops_are_reoriented():
    s, curves = _net("box")
    loops = [list(lp) for lp in s.faces]
    loops[2] = [(c, not f) for c, f in reversed(loops[2])]
    fixed = orient_loops(loops, len(curves))
    assert fixed[2] == list(s.faces[2])
    cm = build_control_mesh(curves, loops, 4)
    assert _tri(cm).is_winding_consistent


def _seg(a, b):
    t = np.linspace(0, 1, 9)[:, None]
    return np.asarray(a, float) + t * (np.asarray(b, float) - a)


def test_t_junctions_on_opposite_sides_give_one_grid():
    # six curves, T-junctions at the middle of the bottom and the top: a 4-sided
    # patch with sides of 2, 1, 2, 1 curves -> one 8 x 4 grid
    curves = [_seg([0, 0, 0], [0.5, 0, 0]), _seg([0.5, 0, 0], [1, 0, 0]),
              _seg([1, 0, 0], [1, 1, 0]), _seg([1, 1, 0], [0.5, 1, 0]),
              _seg([0.5, 1, 0], [0, 1, 0]), _seg([0, 1, 0], [0, 0, 0])]
    cm = build_control_mesh(curves, [[(i, True) for i in range(6)]], 4)
    assert cm.patch_kind == ["grid"] and cm.quads.shape == (8 * 4, 4)
    assert np.abs(cm.vertices[:, 2]).max() < 1e-12


def test_five_curve_loop_is_four_sided():
    # one T-junction: with a curve's N segments each (adaptive=False), sides of 8, 4, 4, 4
    # segments cannot be one grid; the loop is still a 4-sided Coons patch, sampled
    # through a Tutte embedding in the square
    curves = [_seg([0, 0, 0], [0.5, 0, 0]), _seg([0.5, 0, 0], [1, 0, 0]),
              _seg([1, 0, 0], [1, 1, 0.5]), _seg([1, 1, 0.5], [0, 1, 0.5]),
              _seg([0, 1, 0.5], [0, 0, 0])]
    loops = [[(i, True) for i in range(5)]]
    cm = build_control_mesh(curves, loops, 4, adaptive=False)
    assert cm.patch_kind == ["split-coons4"]
    # the sides are straight, so the Coons patch is the ruled plane y = 2 z
    np.testing.assert_allclose(cm.vertices[:, 2], 0.5 * cm.vertices[:, 1], atol=1e-12)
    assert _tri(cm).area_faces.min() > 0
    # adaptive pieces balance the sides: the top takes two pieces, one grid of 8 x 4
    cm = build_control_mesh(curves, loops, 4)
    assert cm.patch_kind == ["grid"] and cm.quads.shape == (8 * 4, 4)
    assert [len(v) - 1 for v in cm.curve_vids] == [4, 4, 4, 8, 4]
    np.testing.assert_allclose(cm.vertices[:, 2], 0.5 * cm.vertices[:, 1], atol=1e-12)


def test_a_side_of_two_curves_balances_its_opposite_side():
    """Sides are balanced by their sums, the sparsest curve of the short side raised, and
    the raise carried along the quad strip of a neighbouring four-curve loop."""
    from curvenet.surfacing.pieces import equalise_pieces
    # loop 0: bottom = curves 0 (length 2) + 1 (length 1), right 2, top 3, left 4;
    # loop 1 shares the top (3) with a four-curve loop above: 3, 5, 6, 7 (6 opposite 3)
    loops = [[(0, True), (1, True), (2, True), (3, True), (4, True)],
             [(3, False), (5, True), (6, True), (7, True)]]
    sides = [[[0, 1], [2], [3], [4]], [[0], [1], [2], [3]]]
    jend = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 0], [3, 5], [5, 6], [6, 4]])
    lengths = np.array([2.0, 1.0, 1.0, 3.0, 1.0, 1.0, 3.0, 1.0])
    m = np.array([1, 1, 1, 3, 1, 1, 1, 1])
    out = equalise_pieces(m, loops, lengths, jend, m, sides=sides)
    assert out[0] + out[1] == out[3] == 3 and (out[0], out[1]) == (2, 1)
    assert out[6] == 3                                   # the strip above follows
    # the other way round: the single top curve takes the bottom's sum
    m = np.array([2, 2, 1, 1, 1, 1, 1, 1])
    out = equalise_pieces(m, loops, lengths, jend, m, sides=sides)
    assert out[3] == out[6] == 4 and out[2] == out[4] == 1
    # without the sides, nothing is balanced
    np.testing.assert_array_equal(equalise_pieces(m, loops, lengths, jend, m)[[0, 1, 3]],
                                  [2, 2, 1])


def test_three_sided_and_six_sided_loops_split_around_a_centre():
    s, curves = _net("sphere")
    cm = build_control_mesh(curves, s.faces, 4)
    tri_loops = [j for j, lp in enumerate(s.faces) if len(lp) == 3]
    assert all(cm.patch_kind[j] == "split" for j in tri_loops)
    # three sub-quads of 2 x 2 per triangle
    assert all((cm.face_patch == j).sum() == 12 for j in tri_loops)
    s, curves = _net("l_prism")
    cm = build_control_mesh(curves, s.faces, 4)
    assert sorted(cm.patch_kind).count("split") == 2


def test_two_sided_and_one_sided_loops_have_no_degenerate_faces():
    a = np.linspace(0, np.pi, 17)
    upper = np.stack([np.cos(a), np.sin(a), 0 * a], 1)
    lower = np.stack([np.cos(a), -np.sin(a), 0.2 * np.sin(a)], 1)[::-1]
    # lens: two curves between (1,0,0) and (-1,0,0)
    cm = build_control_mesh([upper, lower], [[(0, True), (1, True)]], 4, adaptive=False)
    assert cm.patch_kind == ["halves"]
    assert all(len(set(q)) == 4 for q in cm.quads.tolist())
    # closed stroke: one curve whose ends meet
    b = np.linspace(0, 2 * np.pi, 33)
    circle = np.stack([np.cos(b), np.sin(b), 0 * b], 1)
    cm = build_control_mesh([circle], [[(0, True)]], 4, adaptive=False)
    assert cm.patch_kind == ["halves"] and cm.quads.shape == (4, 4)     # 2N = 8 samples
    # adaptive: 360 degrees of turning -> 3 pieces of 4 -> a three-sided split
    cm = build_control_mesh([circle], [[(0, True)]], 4)
    assert cm.patch_kind == ["split"] and cm.quads.shape == (12, 4)
    assert all(len(set(q)) == 4 for q in cm.quads.tolist())
    assert _tri(cm).area_faces.min() > 0


def test_non_manifold_curve_is_shared_by_the_pieces():
    s, curves = _net("two_boxes")
    cm = build_control_mesh(curves, s.faces, 4)
    topo = edge_topology(cm.quads, len(cm.vertices))
    assert (topo.face_count == 3).any() and (topo.face_count <= 3).all()
    assert _tri(cm).is_winding_consistent


def test_adaptive_pieces_follow_quad_strips():
    from curvenet.surfacing.pieces import piece_counts
    t = np.linspace(0, 1, 33)[:, None]
    curves = [t * [3, 0, 0], [3, 0, 0] + t * [0, 1, 0], [3, 1, 0] - t * [3, 0, 0],
              [0, 1, 0] - t * [0, 1, 0]]
    # lengths 3, 1, 3, 1: median 2, so no curve exceeds 2 x median -> one piece each
    np.testing.assert_array_equal(piece_counts(curves, np.zeros(4, bool))[0], [1, 1, 1, 1])
    # a wavy bottom turns by more than 120 degrees in total -> more pieces; the
    # opposite curve follows so the loop stays one grid
    curves[0] = np.concatenate([3 * t, 0 * t, 0.1 * np.sin(6 * np.pi * t)], 1)
    m = piece_counts(curves, np.zeros(4, bool))[0]
    assert m[0] >= 2 and m[1] == m[2] == m[3] == 1
    cm = build_control_mesh(curves, [[(i, True) for i in range(4)]], 4)
    assert [len(v) - 1 for v in cm.curve_vids] == [4 * m[0], 4, 4 * m[0], 4]
    assert cm.patch_kind == ["grid"]


def _grid_of_four(lengths_up):
    """A 2 x 2 grid of quad loops on junctions ``(i, j)``, ``i, j`` in 0..2: horizontal
    curves ``h(i, j)`` to ``(i + 1, j)``, vertical ``v(i, j)`` to ``(i, j + 1)`` of the
    given heights per row ``j``. Returns (loops, jend, lengths, curve ids)."""
    ids, jend, lengths = {}, [], []
    for kind in "hv":
        for i in range(3 if kind == "v" else 2):
            for j in range(2 if kind == "v" else 3):
                ids[kind, i, j] = len(jend)
                a = 3 * i + j
                jend.append((a, a + 3) if kind == "h" else (a, a + 1))
                lengths.append(1.0 if kind == "h" else lengths_up[j])
    loops = [[(ids["h", i, j], True), (ids["v", i + 1, j], True),
              (ids["h", i, j + 1], False), (ids["v", i, j], False)]
             for i in range(2) for j in range(2)]
    return loops, np.array(jend), np.array(lengths), ids


def test_continuing_curves_keep_their_density():
    """A quad strip with twice the control points of the strip it continues into reads,
    to the umbrella fairness, as a jump of curvature: the continuing strip follows."""
    from curvenet.surfacing.pieces import continuations, equalise_pieces
    loops, jend, lengths, ids = _grid_of_four([1.0, 1.0])
    # only the centre junction is a crossing of four curves
    pairs = {tuple(sorted(p)) for p in continuations(loops, jend).tolist()}
    assert pairs == {tuple(sorted((ids["h", 0, 1], ids["h", 1, 1]))),
                     tuple(sorted((ids["v", 1, 0], ids["v", 1, 1])))}
    m = np.ones(len(jend), np.int64)
    m[ids["v", 1, 0]] = 2                    # one piece of the middle line turns more
    up = [ids["v", i, j] for i in range(3) for j in range(2)]
    strips = equalise_pieces(m, loops, lengths, jend, m)       # no curve may be raised
    assert sorted(strips[up]) == [1, 1, 1, 2, 2, 2]          # the lower strip alone
    out = equalise_pieces(m, loops, lengths, jend, np.full(len(jend), 3))
    assert (out[up] == 2).all()
    assert (out[[ids["h", i, j] for i in range(2) for j in range(3)]] == 1).all()
    # a curve whose own turning asks for one piece even at the lowered threshold (a
    # straight line continuing a winding one) keeps it
    most = np.full(len(jend), 3)
    most[ids["v", 1, 1]] = 1
    kept = equalise_pieces(m, loops, lengths, jend, most)
    assert kept[ids["v", 1, 1]] == 1 and kept[ids["v", 1, 0]] == 2


def test_a_short_curve_passes_on_no_more_pieces_than_it_has():
    """A curve of 1% of its continuation's length with two pieces: the continuation takes
    two, not the 134 its density would ask for."""
    from curvenet.surfacing.pieces import equalise_pieces
    loops, jend, lengths, ids = _grid_of_four([0.01, 1.0])
    m = np.ones(len(jend), np.int64)
    m[ids["v", 1, 0]] = 2
    out = equalise_pieces(m, loops, lengths, jend, np.full(len(jend), 200))
    assert out.max() == 2 and out[ids["v", 1, 1]] == 2



def test_a_curve_split_off_its_middle_keeps_the_grids_and_the_shape():
    """A meridian of a 3 x 2 torus split at a fifth of its length (where a closed stroke
    began): its short and long pieces sum to more pieces than the opposite meridian's.
    Balanced, both loops stay grids and the surface stays on the torus (unbalanced they
    fell to centre splits, 0.128 off the torus of minor radius 0.4)."""
    from curvenet.surfacing import surface_loops
    s = shapes.torus(1.0, 0.4, n_u=3, n_v=2)
    curves = [e.curve for e in s.network.edges]
    k = next(i for i, c in enumerate(curves) if np.ptp(c[:, 2]) > 0.1)     # a meridian
    c, cut, new = curves[k], len(curves[k]) // 5, len(curves)
    curves[k] = c[:cut + 1]
    curves.append(c[cut:])
    loops = [[x for ci, f in lp
              for x in ((([(ci, f), (new, f)] if f else [(new, f), (ci, f)])) if ci == k
                        else [(ci, f)])] for lp in s.faces]
    assert build_control_mesh(curves, loops, 4).patch_kind == ["grid"] * 6
    V = surface_loops(curves, loops).vertices
    off = np.abs(np.hypot(np.hypot(V[:, 0], V[:, 1]) - 1.0, V[:, 2]) - 0.4)
    assert off.max() < 0.02 and np.percentile(off, 90) < 0.005

def test_stroke_wobble_does_not_count_as_winding():
    # a quarter circle turns 90 degrees; a hand-drawn one wobbles (here a smooth offset
    # of 1% of its length, three periods: the scale of the re-drawn torus's strokes),
    # which adds up when summed over fine segments (136 degrees at 32). It stays one
    # piece, like the clean arc; a half circle (180 degrees) gets two either way.
    from curvenet.surfacing.pieces import piece_counts
    t = np.linspace(0, 1, 200)

    def arc(turn, wobble):
        r = 1 + wobble * turn * np.sin(6 * np.pi * t)
        return np.c_[np.cos(t * turn), np.sin(t * turn), 0 * t] * r[:, None]

    arcs = [arc(np.pi / 2, 0), arc(np.pi / 2, 0.01), arc(np.pi, 0), arc(np.pi, 0.01)]
    np.testing.assert_array_equal(piece_counts(arcs, np.zeros(4, bool))[0], [1, 1, 2, 2])
    # detail finer than one piece still counts: a straight curve with 12 waves turns by
    # ~1500 degrees (8 segments alias it to a few hundred); it gets the pieces that bring
    # its turning at their own scale under 120 degrees per piece
    wavy = np.c_[t, 0.05 * np.sin(24 * np.pi * t), 0 * t]
    m = piece_counts([wavy] * 4, np.zeros(4, bool))[0][0]
    fine = np.diff(wavy, axis=0)
    fine /= np.linalg.norm(fine, axis=1, keepdims=True)
    total = np.degrees(np.arccos(np.clip((fine[1:] * fine[:-1]).sum(1), -1, 1))).sum()
    assert total / 120 * 0.5 < m <= np.ceil(total / 120), (m, total)


@pytest.mark.parametrize("bad", [0, 1, -2, 2.5])
def test_resolution_validated(bad):
    s, curves = _net("box")
    with pytest.raises(ValueError, match="resolution"):
        build_control_mesh(curves, s.faces, bad)


def test_odd_resolution_rounds_up():
    s, curves = _net("box")
    cm = build_control_mesh(curves, s.faces, 3)
    assert all(len(v) == 5 for v in cm.curve_vids)


def test_empty_loops_rejected():
    s, curves = _net("box")
    with pytest.raises(ValueError, match="loops"):
        build_control_mesh(curves, [], 4)


def test_bad_loops_rejected():
    with pytest.raises(ValueError, match="out of range"):
        build_control_mesh([np.zeros((2, 3)) + [[0, 0, 0], [1, 0, 0]]], [[(3, True)]], 4)
    with pytest.raises(ValueError, match="curves\\[0\\]"):
        build_control_mesh([np.zeros((1, 3))], [[(0, True)]], 4)


def test_vectorised_turning_is_the_per_curve_loop_bit_for_bit():
    """Oracle: the one-curve :func:`_turning` and a loop over scales (issue 32)."""
    from curvenet.surfacing.pieces import (PIECE_ROUNDING, PIECE_TURN, TURN_SCALES,
                                                TURN_SEGMENTS, _scale_turnings, _turning,
                                                _turnings, _turns_pieces)
    rng = np.random.default_rng(3)
    curves = [e.curve for e in shapes.torus().network.edges]
    curves += [np.cumsum(rng.normal(size=(int(rng.integers(2, 80)), 3)), 0) for _ in range(200)]
    curves += [np.zeros((4, 3)), np.array([[0.0, 0, 0], [0, 0, 0], [1, 0, 0]])]  # degenerate
    for n in (8, 16, 24, 32):
        loop = np.array([_turning(c, n) for c in curves])
        assert np.array_equal(_turnings(curves, n), loop, equal_nan=True)

    def pieces(c):
        need = 1
        for s in range(1, TURN_SCALES + 1):
            t = _turning(c, TURN_SEGMENTS * s) / PIECE_TURN
            if t > s * (1 + PIECE_ROUNDING):
                need = max(need, int(np.ceil(t - PIECE_ROUNDING)))
        return need
    got = _turns_pieces(_scale_turnings(curves), PIECE_TURN)
    assert np.array_equal(got, [pieces(c) for c in curves])
    assert got.max() > 1                        # the random walks do ask for pieces
