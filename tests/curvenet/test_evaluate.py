"""Tests of curvenet.evaluate: analytic oracles and an independent KD-tree computation."""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from scipy.spatial import cKDTree

from curvenet.core.errors import InvalidParameterError, SketchFormatError
from curvenet.evaluate import (evaluate_mesh, format_report, load_mesh_arrays, sample_surface,
                               stroke_distance)


# ---------------------------------------------------------------------------
# helpers (also used by benchmarks/bench_eval.py)
# ---------------------------------------------------------------------------
def independent_metrics(mesh, reference, *, n=100_000, dense=1_000_000, r=0.01, seed=1):
    """The same metrics computed another way: trimesh sampling + scipy KD-tree.

    Each mesh's ``n`` samples are matched to the nearest of ``dense`` samples of the other
    surface (point-to-point, the paper's literal definition). The dense sampling biases
    each distance ``d`` upwards: by about ``E[rho^2] / (2 d) = 1 / (2 pi lambda d)`` where
    ``d`` is large, up to ``E[rho] = 1 / (2 sqrt(lambda))`` where ``d ~ 0`` (``lambda`` =
    samples per unit area; ~7e-4 for the normalised ellipsoid of area ~2 at 1e6 samples).
    On :func:`bumpy_pair` (Chamfer ~0.01) this over-estimates the Chamfer distance by
    ~0.6% at 1e6 samples and ~1.2% at 5e5 (an O(lambda^-1/2) floor),
    inside the 2% agreement asked for.
    """
    scale = 1.0 / reference.extents.max()
    centre = reference.bounds.mean(axis=0)
    m1 = trimesh.Trimesh((mesh.vertices - centre) * scale, mesh.faces, process=False)
    m2 = trimesh.Trimesh((reference.vertices - centre) * scale, reference.faces, process=False)

    def one_way(a, b, s):
        p, fa = trimesh.sample.sample_surface(a, n, seed=s)
        q, fb = trimesh.sample.sample_surface(b, dense, seed=s + 100)
        d, k = cKDTree(q).query(p)
        cos = np.abs(np.einsum("ij,ij->i", a.face_normals[fa], b.face_normals[fb[k]]))
        return d, np.degrees(np.arccos(np.clip(cos, 0, 1)))

    d12, a12 = one_way(m1, m2, seed)
    d21, a21 = one_way(m2, m1, seed + 1)
    p, rc = np.mean(d12 < r), np.mean(d21 < r)
    return {"chamfer": 0.5 * (d12.mean() + d21.mean()),
            "hausdorff": max(d12.max(), d21.max()),
            "normal_error_deg": 0.5 * (a12.mean() + a21.mean()),
            "fscore": 2 * p * rc / (p + rc) if p + rc else 0.0}


def bumpy_pair():
    """A coarse, bumpy ellipsoid (mesh) and a fine smooth one (reference).

    Bumps of amplitude 0.06 (0.03 after normalisation) spread the distances over
    0..0.025 (Chamfer ~0.01), so the F-score at 0.01 (~0.5) is far from 0 and 1 and
    tests something, and the KD-tree floor (~6e-5 at 1e6 dense samples) stays well
    under 2% of the Chamfer distance.
    """
    ref = trimesh.creation.icosphere(subdivisions=5)
    ref.vertices *= [1.0, 0.8, 0.6]
    mesh = trimesh.creation.icosphere(subdivisions=3)
    v = mesh.vertices
    bump = 1.0 + 0.06 * np.sin(3 * v[:, 0]) * np.cos(2 * v[:, 1] + 1.0)
    mesh.vertices = v * bump[:, None] * [1.0, 0.8, 0.6]
    return mesh, ref


def square(z=0.0, *, x1=1.0, n=4):
    """The rectangle [0, x1] x [0, 1] at height z, as an n x n grid of triangle pairs."""
    xs, ys = np.meshgrid(np.linspace(0, x1, n + 1), np.linspace(0, 1, n + 1), indexing="ij")
    v = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, z)])
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
    c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    f = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return v, f


# ---------------------------------------------------------------------------
# analytic oracles
# ---------------------------------------------------------------------------
def test_mesh_against_itself_is_zero():
    m = trimesh.creation.icosphere(subdivisions=4)
    r = evaluate_mesh(m, m, n_samples=20_000)
    # samples lie on the triangles up to round-off (~1e-16); no sampling floor
    assert r["chamfer"] < 1e-12 and r["hausdorff"] < 1e-12
    assert r["normal_error_deg"] < 1e-3
    assert r["fscore"] == 1.0 and r["precision"] == 1.0 and r["recall"] == 1.0


def test_concentric_spheres():
    """Unit icosphere vs the same scaled by 1.01: every distance is 0.01 * h, h in [h_min, 1].

    The copy's faces are parallel to the reference's at offset 0.01 * h_f (h_f = distance of
    face f's plane from the centre, h_f >= 1 - (circumradius^2)/2 ~ 0.9997 at 5
    subdivisions) and its vertices are exactly 0.01 from the reference's. The reference's
    longest side is 2, so normalised: Chamfer = Hausdorff = 0.005 within 3e-4 relative.
    """
    ref = trimesh.creation.icosphere(subdivisions=5)
    big = ref.copy()
    big.vertices *= 1.01
    r = evaluate_mesh(big, ref, n_samples=50_000)
    assert r["scale"] == pytest.approx(0.5)
    assert r["chamfer"] == pytest.approx(0.005, rel=3e-4)
    assert r["hausdorff"] == pytest.approx(0.005, rel=3e-4)
    assert r["hausdorff"] <= 0.005 * (1 + 1e-9)
    # parallel faces; only points whose closest point is on a shared edge (a band of
    # width <= 0.01 * circumradius, a few % of the area) may see a neighbour's normal,
    # tilted by the dihedral angle (~2.2 deg): mean well under 0.2 deg
    assert r["normal_error_deg"] < 0.2
    assert r["fscore"] == 1.0
    # radius 1.03: normalised distance 0.015 > 0.01, nothing matches
    far = ref.copy()
    far.vertices *= 1.03
    r = evaluate_mesh(far, ref, n_samples=10_000)
    assert r["chamfer"] == pytest.approx(0.015, rel=3e-4)
    assert r["fscore"] == 0.0 and r["precision"] == 0.0 and r["recall"] == 0.0


@pytest.mark.parametrize("offset", [0.003, 0.02])
def test_offset_plane_exact(offset):
    """Same footprint, offset along the normal: every distance equals the offset exactly."""
    ref = square(0.0)
    mesh = square(offset, n=3)  # a different triangulation of the parallel square
    r = evaluate_mesh(mesh, ref, n_samples=5_000)
    assert r["scale"] == 1.0
    assert r["chamfer"] == pytest.approx(offset, rel=1e-12)
    assert r["hausdorff"] == pytest.approx(offset, rel=1e-12)
    assert r["normal_error_deg"] < 1e-5
    assert r["fscore"] == (1.0 if offset < 0.01 else 0.0)


def test_partial_overlap_precision_recall():
    """Mesh = left half of the reference square: precision 1, recall = P(x < 0.51) = 0.51.

    Reference samples with x > 0.5 are at distance x - 0.5: mean over the reference is
    0.5 * 0.25 = 0.125 (std of one distance 0.161, so std of the mean at n = 40000 is
    8e-4); Chamfer = (0 + 0.125) / 2. Binomial std of the recall: sqrt(.51*.49/n) = 2.5e-3.
    Tolerances are 4 standard deviations.
    """
    n = 40_000
    r = evaluate_mesh(square(0.0, x1=0.5), square(0.0), n_samples=n)
    assert r["precision"] == 1.0
    assert r["recall"] == pytest.approx(0.51, abs=4 * 2.5e-3)
    assert r["fscore"] == pytest.approx(2 * 0.51 / 1.51, abs=0.01)
    assert r["mean_mesh_to_reference"] < 1e-12
    assert r["mean_reference_to_mesh"] == pytest.approx(0.125, abs=4 * 8e-4)
    assert r["chamfer"] == pytest.approx(0.0625, abs=2 * 8e-4)
    # the farthest reference points (x near 1) are 0.5 away; P(no sample in x > 0.999)
    # = 0.999^n ~ e^-40
    assert r["hausdorff"] == pytest.approx(0.5, abs=1e-3)


def test_normal_error_orientation_agnostic_and_tilt():
    ref = square(0.0)
    v, f = ref
    flipped = (v, f[:, ::-1])
    r = evaluate_mesh(flipped, ref, n_samples=2_000)
    assert r["normal_error_deg"] < 1e-5  # |n_p . n_q| as in the paper
    # the square tilted by 10 degrees about its mid-line y = 0.5: every pair of normals
    # (one triangle plane each side) is 10 degrees apart
    t = np.radians(10.0)
    vt = v.copy()
    y = v[:, 1] - 0.5
    vt[:, 1], vt[:, 2] = 0.5 + y * np.cos(t), y * np.sin(t)
    r = evaluate_mesh((vt, f), ref, n_samples=2_000)
    assert r["normal_error_deg"] == pytest.approx(10.0, abs=1e-9)


def test_scale_invariance_and_seed():
    mesh, ref = bumpy_pair()
    a = evaluate_mesh(mesh, ref, n_samples=5_000, seed=3)
    big_mesh = trimesh.Trimesh(mesh.vertices * 7.0 + 3.0, mesh.faces, process=False)
    big_ref = trimesh.Trimesh(ref.vertices * 7.0 + 3.0, ref.faces, process=False)
    b = evaluate_mesh(big_mesh, big_ref, n_samples=5_000, seed=3)
    for key in ("chamfer", "hausdorff", "fscore"):
        assert b[key] == pytest.approx(a[key], rel=1e-9, abs=1e-12)
    # round-off may pick the other triangle at a tie (closest point on a shared edge)
    assert b["normal_error_deg"] == pytest.approx(a["normal_error_deg"], rel=1e-3)
    assert b["scale"] == pytest.approx(a["scale"] / 7.0)
    assert evaluate_mesh(mesh, ref, n_samples=5_000, seed=3) == a
    assert evaluate_mesh(mesh, ref, n_samples=5_000, seed=4) != a


# ---------------------------------------------------------------------------
# independent computation
# ---------------------------------------------------------------------------
def test_agrees_with_kdtree_computation_within_2_percent():
    mesh, ref = bumpy_pair()
    ours = evaluate_mesh(mesh, ref)
    theirs = independent_metrics(mesh, ref)
    assert 0.2 < ours["fscore"] < 0.95  # a non-trivial case
    for key in ("chamfer", "hausdorff", "normal_error_deg", "fscore"):
        assert ours[key] == pytest.approx(theirs[key], rel=0.02), key


def test_sampler_is_area_weighted():
    """Two triangles of areas 1/2 and 3/2: 1/4 of the samples on the first (4 sigma)."""
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [3, 0, 0], [0, 1, 5]], float)
    f = np.array([[0, 1, 2], [1, 3, 4]])
    areas = 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]),
                                 axis=1)
    n = 40_000
    p, fi = sample_surface(v, f, n, np.random.default_rng(0))
    share = areas[0] / areas.sum()
    assert np.mean(fi == 0) == pytest.approx(share, abs=4 * np.sqrt(share * (1 - share) / n))
    # points lie in their triangles' planes
    nrm = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])[fi]
    assert np.abs(np.einsum("ij,ij->i", p - v[f[fi, 0]], nrm)).max() < 1e-12


# ---------------------------------------------------------------------------
# strokes
# ---------------------------------------------------------------------------
def test_stroke_distance_oracles():
    ref = square(0.0)
    strokes = [np.array([[0.0, 0, 0.003], [1, 0, 0.003]]),
               np.array([[0.2, 0.2, 0.003], [0.2, 0.9, 0.003], [0.8, 0.9, 0.003]])]
    diag = np.linalg.norm([1.0, 0.9, 0.0])
    d = stroke_distance(ref, strokes)
    assert d["diagonal"] == pytest.approx(diag)
    for key in ("stroke_mean", "stroke_max", "stroke_p95"):
        assert d[key] == pytest.approx(0.003 / diag, rel=1e-9)
    assert d["stroke_within_1pct"] == 1.0
    # a stroke leaving the surface linearly: distance grows 0 -> 0.2 along its length,
    # uniform in arc length, so mean = 0.1 and p95 = 0.19 (relative to its diagonal)
    s = np.array([[0.0, 0.5, 0.0], [1.0, 0.5, 0.0], [1.0, 0.5, 0.2]])
    d = stroke_distance(ref, [s], spacing=1e-4)
    diag = np.linalg.norm([1.0, 0.0, 0.2])
    assert d["stroke_max"] == pytest.approx(0.2 / diag, rel=1e-9)
    # arc length: 1.0 on the surface, 0.2 rising; mean = (0.2 * 0.1) / 1.2
    assert d["stroke_mean"] == pytest.approx(0.02 / 1.2 / diag, rel=2e-3)


def test_stroke_distance_on_analytic_shape():
    from curvenet.datasets.shapes import box

    shape = box()
    d = stroke_distance(shape.reference_mesh(), shape.sketch())
    # the curves lie on the box's edges, which are edges of its reference mesh
    assert d["stroke_max"] < 1e-9
    net = stroke_distance(shape.reference_mesh(), shape.network)
    assert net["stroke_max"] < 1e-9


def test_geodesic_sketch_lies_on_its_mesh(data_dir):
    """NeuralSketch2Surf's geodesic curves were traced on original_meshes/1.obj.

    Coordinates are stored with 6 decimals: rounding moves a point by at most
    0.5e-6 * sqrt(3) ~ 9e-7, i.e. ~4.5e-7 of the ~1.95 diagonal; 1e-5 leaves margin.
    """
    root = data_dir / "surfaces" / "neuralsketch2surf"
    sketch = root / "sketch_dataset_112" / "geo" / "1_geo_N10_L100.obj"
    d = stroke_distance(root / "original_meshes" / "1.obj", sketch)  # both as paths
    assert d["stroke_max"] < 1e-5 and d["stroke_within_1pct"] == 1.0
    assert d["n_stroke_samples"] > 1000


# ---------------------------------------------------------------------------
# inputs and errors
# ---------------------------------------------------------------------------
def test_paths_and_pairs(tmp_path):
    mesh, ref = bumpy_pair()
    p1, p2 = tmp_path / "mesh.obj", tmp_path / "ref.ply"
    mesh.export(p1)
    ref.export(p2)
    a = evaluate_mesh(str(p1), p2, n_samples=3_000)
    b = evaluate_mesh((mesh.vertices, mesh.faces), ref, n_samples=3_000)
    for key in ("chamfer", "hausdorff", "fscore"):
        assert a[key] == pytest.approx(b[key], rel=1e-6)
    json.dumps(a)  # JSON-ready: plain Python numbers


@pytest.mark.parametrize("content", ["", "garbage\n", "v 0 0 0\nv 1 0 0\nl 1 2\n"])
def test_bad_files_name_the_file(tmp_path, content):
    bad = tmp_path / "bad.obj"
    bad.write_text(content)
    good = trimesh.creation.box()
    with pytest.raises(SketchFormatError, match="bad.obj"):
        evaluate_mesh(bad, good)
    with pytest.raises(SketchFormatError, match="missing.stl"):
        evaluate_mesh(good, tmp_path / "missing.stl")


def test_bad_arrays_and_options():
    box = trimesh.creation.box()
    with pytest.raises(InvalidParameterError, match="reference"):
        load_mesh_arrays((np.zeros((3, 2)), [[0, 1, 2]]), name="reference")
    with pytest.raises(InvalidParameterError, match="out of range"):
        evaluate_mesh((box.vertices, box.faces + 100), box)
    with pytest.raises(InvalidParameterError, match="NaN"):
        evaluate_mesh((box.vertices * np.nan, box.faces), box)
    with pytest.raises(InvalidParameterError, match="zero extent"):
        evaluate_mesh(box, (np.zeros((3, 3)), [[0, 1, 2]]))
    with pytest.raises(InvalidParameterError, match="n_samples"):
        evaluate_mesh(box, box, n_samples=0)
    with pytest.raises(InvalidParameterError, match="threshold"):
        evaluate_mesh(box, box, threshold=-1)
    with pytest.raises(InvalidParameterError, match="strokes"):
        stroke_distance(box, [])


def test_format_report():
    r = evaluate_mesh(trimesh.creation.box(), trimesh.creation.box(), n_samples=1_000)
    text = format_report({**r, "stroke_mean": 0.001})
    lines = text.splitlines()
    assert lines[0].startswith("Chamfer distance")
    assert "F-score @ 0.01" in text and "100.00%" in text and "stroke distance mean" in text
    assert len({line.rfind(" ") for line in lines}) == 1  # values form one column
    assert format_report({}) == "(no metrics)"
