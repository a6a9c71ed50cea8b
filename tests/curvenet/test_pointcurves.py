"""Unordered point samples of curves: detection, recovery of the network, surfaces, CLI."""

import numpy as np
import networkx as nx
import pytest

import curvenet
from curvenet.datasets import shapes
from curvenet.cli import main
from curvenet.core.errors import SketchFormatError
from curvenet.evaluate import evaluate_mesh
from curvenet.io.sketch import read_sketch
from curvenet.io.points import JUMP_RATIO, NotCurvesError, jump_ratio, recover_curves
from curvenet.datasets.shapes import sample_curves
from curvenet.model.sketch import Sketch
from curvenet.snap.graph import snap

# (spacing, rms noise, density ratio) as fractions of the diagonal
CASES = {"uniform": (0.002, 0.0, 1.0), "uneven": (0.004, 0.0025, 3.0),
         "noisy": (0.002, 0.005, 1.0), "noisy-uneven": (0.003, 0.005, 3.0)}


def samples(shape, case, seed):
    net = shape.network
    sp, noise, uneven = CASES[case]
    d = net.diagonal
    return sample_curves([e.curve for e in net.edges], sp * d, noise=noise * d,
                         uneven=uneven, rng=seed)


def recovered_network(points):
    return snap(Sketch(recover_curves(points).strokes))


def same_graph(net, truth) -> bool:
    return nx.is_isomorphic(net.graph(), truth.graph())


def write_xyz(path, pts):
    np.savetxt(path, pts, fmt="%.9g")
    return path


def test_jump_ratio_tells_polylines_from_shuffled_points():
    t = np.linspace(0, 2 * np.pi, 300)
    line = np.column_stack([np.cos(t), np.sin(t), t / 5])
    assert jump_ratio(line) < 1.5
    assert jump_ratio(np.random.default_rng(0).permutation(line)) > 5 * JUMP_RATIO


def test_jump_ratios_of_many_strokes_are_each_strokes_own(monkeypatch):
    """The batched ratios equal the one-by-one ones, bit for bit, across runs of strokes
    (a run of 2,000 points here), with repeated points, coincident strokes, shuffled
    blocks and strokes of one or two points."""
    import curvenet.io.points as pc
    monkeypatch.setattr(pc, "_RUN_POINTS", 2_000)
    rng = np.random.default_rng(3)
    strokes = []
    for k in range(400):
        s = np.cumsum(rng.normal(size=(int(rng.integers(1, 60)), 3)), axis=0) * rng.uniform(
            1e-3, 10) + rng.uniform(-100, 100, 3)
        if k % 7 == 0 and len(s) > 3:
            s[2] = s[1]
        if k % 11 == 0:
            s = rng.permutation(s)
        if k % 13 == 0:
            s[:] = s[0]
        strokes.append(s)
    want = [jump_ratio(s) for s in strokes]
    assert pc.jump_ratios(strokes).tolist() == want
    assert max(want) > 3.0 and min(want) == 1.0         # shuffled blocks; tiny strokes


def test_shuffled_circle_comes_back_closed_and_ordered():
    t = np.linspace(0, 2 * np.pi, 600) + np.random.default_rng(1).uniform(0, 0.01, 600)
    pts = np.column_stack([np.cos(t), np.sin(t), 0 * t])
    rc = recover_curves(pts)
    assert len(rc.strokes) == 1 and rc.report["loops"] == 1
    s = rc.strokes[0]
    assert np.array_equal(s[0], s[-1])
    assert np.abs(np.linalg.norm(s[:, :2], axis=1) - 1).max() < 0.01
    ang = np.unwrap(np.arctan2(s[:, 1], s[:, 0]))
    steps = np.diff(ang)
    assert (np.sign(steps) == np.sign(steps.sum())).all()  # monotone: ordered along the loop
    assert abs(abs(ang[-1] - ang[0]) - 2 * np.pi) < 0.05


@pytest.mark.parametrize("name", sorted(shapes.SHAPES))
def test_network_recovered_from_unordered_samples(name):
    # one trial per sampling case; the rate over many seeds is the slow test below
    shape = shapes.SHAPES[name]()
    ok = [same_graph(recovered_network(samples(shape, case, seed)), shape.network)
          for seed, case in enumerate(CASES)]
    assert all(ok), dict(zip(CASES, ok))


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(shapes.SHAPES))
def test_network_recovery_rate(name):
    shape = shapes.SHAPES[name]()
    trials = [(case, seed) for case in CASES for seed in range(10)]
    ok = sum(same_graph(recovered_network(samples(shape, c, s)), shape.network)
             for c, s in trials)
    assert ok >= 0.95 * len(trials), f"{ok}/{len(trials)}"


@pytest.mark.parametrize("case, seed", [("noisy", 0), ("noisy-uneven", 0), ("noisy-uneven", 1)])
def test_noise_links_near_a_pole_are_dropped(case, seed):
    # six meridians converge at each pole; under 0.5% noise neighbouring ones get linked
    # near it (a loop back to the pole, a bridge closing a small triangle with it)
    shape = shapes.ellipsoid()
    rc = recover_curves(samples(shape, case, seed))
    assert len(rc.strokes) == len(shape.network.edges)
    assert same_graph(snap(Sketch(rc.strokes)), shape.network)
    truth = np.array([p for _, p in shape.network.graph().nodes(data="pos")])
    off = np.linalg.norm(rc.junctions[:, None] - truth[None], axis=2).min(axis=1)
    assert off.max() < 2 * rc.cell


def test_short_triangle_bridge_dropped_long_one_kept():
    from curvenet.io.pointjunctions import bridges
    # junction 0 (many curves); junctions 1 and 2 of degree 3, joined by chain 2
    chains = [np.array([0, 10, 1]), np.array([0, 11, 2]), np.array([1, 12, 2]),
              np.array([1, 13, 3]), np.array([2, 14, 4]), np.array([0, 15, 5]),
              np.array([0, 16, 6]), np.array([3, 17, 5]), np.array([4, 18, 6])]
    cluster = np.arange(20)
    keep = np.ones(len(chains), bool)
    for scale, dropped in ((1.0, [2]), (3.0, [])):
        lengths = scale * np.array([5.0, 6.0, 5.0, 30, 30, 40, 40, 30, 30])
        assert np.flatnonzero(bridges(chains, lengths, cluster, keep, 1.0)).tolist() == dropped
    loop = chains + [np.array([0, 19, 0])]
    lengths = np.array([20.0] * 9 + [3.0])
    assert np.flatnonzero(bridges(loop, lengths, cluster, np.ones(10, bool), 1.0)).tolist() == [9]


@pytest.mark.parametrize("name, case", [("box", "noisy"), ("torus", "uneven"),
                                        ("torus", "noisy"), ("sphere", "uneven")])
def test_surface_from_points_scores_as_the_true_curves(name, case):
    # within 1 F-score point of the classical surface of the true curves
    shape = shapes.SHAPES[name]()
    ref = shape.reference_mesh(4)
    truth = curvenet.surface(shape.sketch(), method="classical", subdiv=2)
    pts = samples(shape, case, 3)
    res = curvenet.surface(Sketch([pts]), method="classical", subdiv=2, points=True)
    assert res.diagnostics["reading"].startswith("point samples (forced")
    f_true = evaluate_mesh(truth.mesh, ref, n_samples=20_000)["fscore"]
    f_pts = evaluate_mesh(res.mesh, ref, n_samples=20_000)["fscore"]
    assert f_pts >= f_true - 0.01, (f_pts, f_true)


def test_mixed_file_is_read_block_by_block(tmp_path):
    box = shapes.box()
    edges = box.network.edges
    ordered, rest = edges[:5], edges[5:]
    pts = sample_curves([e.curve for e in rest], 0.004 * box.network.diagonal, rng=2)
    blocks = ["\n".join(" ".join(f"{v:.9g}" for v in row) for row in e.curve) for e in ordered]
    blocks.append("\n".join(" ".join(f"{v:.9g}" for v in row) for row in pts))
    path = tmp_path / "mixed.txt"
    path.write_text("\n\n".join(blocks) + "\n")
    sk = read_sketch(path)
    assert sk.metadata["point_blocks"][0]["stroke"] == 5
    assert "stroke 6" in sk.metadata["reading"] and "5 stroke(s) read as polylines" in \
        sk.metadata["reading"]
    for i, e in enumerate(ordered):  # ordered strokes are kept as they are
        assert np.array_equal(sk.strokes[i], e.curve)
    assert same_graph(snap(sk), box.network)
    assert read_sketch(path, points=False).strokes[5].shape == pts.shape


def test_scatter_is_refused_in_one_line(tmp_path, capsys):
    rng = np.random.default_rng(0)
    scatter = np.column_stack([rng.uniform(size=(4000, 2)), np.zeros(4000)])
    path = write_xyz(tmp_path / "scan.xyz", scatter)
    with pytest.raises(NotCurvesError, match="not curve samples"):
        read_sketch(path)
    assert issubclass(NotCurvesError, SketchFormatError)
    assert main(["surface", str(path), "-o", str(tmp_path / "o.obj")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "scan.xyz" in err[0] and "not curve samples" in err[0]
    assert not (tmp_path / "o.obj").exists()


def test_polylines_are_not_read_as_points(tmp_path):
    sk = shapes.grid_sheet().sketch()
    assert read_sketch_roundtrip(sk, tmp_path).strokes[0].shape == sk.strokes[0].shape


def read_sketch_roundtrip(sk, tmp_path):
    from curvenet.io.sketch import write_sketch
    write_sketch(tmp_path / "s.txt", sk)
    back = read_sketch(tmp_path / "s.txt")
    assert "reading" not in back.metadata and len(back) == len(sk)
    return back


def test_cli_points_flag(tmp_path, capsys):
    torus = shapes.torus()
    pts = samples(torus, "uneven", 4)
    path = write_xyz(tmp_path / "torus.xyz", pts)
    assert main(["snap", str(path), "-o", str(tmp_path / "n.json"), "--points"]) == 0
    out = capsys.readouterr().out
    assert "24 vertices, 48 curves" in out and "reading: point samples (forced" in out
    # forced on an ordered polyline, the point reading gives the same curve
    t = np.linspace(0, 2 * np.pi, 400)
    ring = write_xyz(tmp_path / "ring.xyz", np.column_stack([np.cos(t), np.sin(t), 0 * t]))
    assert main(["surface", str(ring), "-o", str(tmp_path / "r.obj"), "--points", "--explain",
                 "--method", "classical", "--subdiv", "1", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "reading: point samples (forced by points=True): stroke 1 (400 points" in out
    assert (tmp_path / "r.obj").exists()
