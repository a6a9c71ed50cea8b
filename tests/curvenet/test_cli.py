"""The curvenet command, invoked as a user would: real files in, files and exit codes out."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
import trimesh

from curvenet.datasets import shapes
from curvenet.cli import main
from curvenet.io.sketch import write_sketch


def run(*argv):
    """Run the CLI in a subprocess (the real entry point, real stdio)."""
    return subprocess.run([sys.executable, "-m", "curvenet.cli", *map(str, argv)],
                          capture_output=True, text=True, timeout=600)


@pytest.fixture
def box_obj(tmp_path):
    path = tmp_path / "box.obj"
    write_sketch(path, shapes.box().sketch())
    return path


def test_snap_patches_surface_eval_chain(tmp_path, box_obj):
    net = tmp_path / "net.json"
    r = run("snap", box_obj, "-o", net)
    assert r.returncode == 0, r.stderr
    data = json.loads(net.read_text())
    assert data["format"] == "curvenet.network" and len(data["edges"]) == 12

    pat = tmp_path / "patches.json"
    r = run("patches", net, "-o", pat)
    assert r.returncode == 0, r.stderr
    data = json.loads(pat.read_text())
    assert len(data["patches"]) == 6

    mesh_path = tmp_path / "box_out.ply"
    r = run("surface", box_obj, "--patches", pat, "-o", mesh_path, "--method", "classical",
            "--no-progress")
    assert r.returncode == 0, r.stderr
    mesh = trimesh.load(mesh_path, force="mesh")
    assert mesh.is_watertight
    np.testing.assert_allclose(mesh.bounds, [[0, 0, 0], [1, 1, 1]], atol=2e-3)

    ref = tmp_path / "ref.off"
    shapes.box().reference_mesh().export(ref)
    r = run("eval", mesh_path, ref, "--json", "--samples", "20000")
    assert r.returncode == 0, r.stderr
    metrics = json.loads(r.stdout)
    assert {"chamfer", "hausdorff", "normal_error_deg", "fscore"} <= set(metrics)
    assert metrics["fscore"] > 0.99
    # nothing half-written or temporary is left behind
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["box.obj", "net.json", "patches.json", "box_out.ply", "ref.off"])


@pytest.mark.parametrize("content, needle", [
    ("", "empty"),
    ("v 0 0 0\nv nan 1 0\nl 1 2\n", ":2"),
    ("v 0 0 0\nl 1\n", ""),
    ("v 0 0 0\nv 1 0 0\nl 1 7\n", ":3"),
])
def test_bad_sketch_gives_one_line_and_exit_2(tmp_path, content, needle):
    bad = tmp_path / "bad.obj"
    bad.write_text(content)
    out = tmp_path / "out.obj"
    r = run("surface", bad, "-o", out, "--no-progress")
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "bad.obj" in lines[0] and needle in lines[0]
    assert "Traceback" not in r.stderr
    assert not out.exists()


def test_missing_file_and_unknown_output_format(tmp_path, box_obj):
    r = run("patches", tmp_path / "nope.obj", "-o", tmp_path / "p.json")
    assert r.returncode == 2 and "nope.obj" in r.stderr
    r = run("surface", box_obj, "-o", tmp_path / "mesh.xyz")
    assert r.returncode == 2 and "mesh.xyz" in r.stderr
    r = run("snap", box_obj, "-o", tmp_path / "n.json", "--snap-tol", "7")
    assert r.returncode == 2 and "snap-tol" in r.stderr


def test_batch_reports_each_file_and_survives_a_bad_one(tmp_path, box_obj, capsys):
    bad = tmp_path / "broken.obj"
    bad.write_text("this is not a sketch\n")
    code = main(["surface", str(box_obj), str(bad), "--out-dir", str(tmp_path / "out"),
                 "--method", "classical", "--format", "ply"])
    out = capsys.readouterr().out
    assert code == 2
    assert "ok" in out and "FAILED" in out and "1 of 2 surfaced" in out
    assert (tmp_path / "out" / "box.ply").is_file()
    assert not (tmp_path / "out" / "broken.ply").exists()


def test_import_curvenet_and_patches_do_not_import_torch(box_obj, tmp_path):
    code = ("import sys, curvenet; from curvenet.cli import main; "
            f"main(['patches', {str(box_obj)!r}, '-o', {str(tmp_path / 'p.json')!r}]); "
            "sys.exit(3 if 'torch' in sys.modules else 0)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_outputs_get_ordinary_permissions(tmp_path, box_obj):
    import os
    import stat
    out = tmp_path / "net.json"
    assert main(["snap", str(box_obj), "-o", str(out)]) == 0
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(out.stat().st_mode) == 0o666 & ~mask


@pytest.mark.parametrize("flag,expected", [
    ((), None),
    (("--closed-box",), {"boundary": "dirichlet"}),
    (("--neural-set", "w_smooth=0.01", "--neural-set", "res=40", "--closed-box"),
     {"w_smooth": 0.01, "res": 40, "boundary": "dirichlet"}),
])
def test_neural_flags_reach_the_neural_fit(tmp_path, box_obj, monkeypatch, flag, expected):
    import curvenet.pipeline as pipeline
    seen = {}
    real = pipeline.surface

    def spy(*args, **kw):
        seen.update(kw)
        return real(*args, **{**kw, "method": "classical"})
    monkeypatch.setattr(pipeline, "surface", spy)
    out = tmp_path / "m.obj"
    assert main(["surface", str(box_obj), "-o", str(out), "--method", "neural",
                 "--no-progress", *flag]) == 0
    assert seen["method"] == "neural" and seen["neural_options"] == expected
    assert out.exists()


@pytest.mark.parametrize("value,match", [("w_smooth", "NAME=VALUE"), ("bogus=1", "unknown"),
                                         ("res=big", "int"), ("lr=fast", "float")])
def test_bad_neural_setting_is_one_clear_error(tmp_path, box_obj, capsys, value, match):
    with pytest.raises(SystemExit) as exc:
        main(["surface", str(box_obj), "-o", str(tmp_path / "m.obj"), "--neural-set", value])
    assert exc.value.code == 2
    assert match in capsys.readouterr().err
    assert not (tmp_path / "m.obj").exists()


def test_out_of_range_neural_setting_names_it(tmp_path, box_obj, capsys):
    rc = main(["surface", str(box_obj), "-o", str(tmp_path / "m.obj"), "--method", "neural",
               "--no-progress", "--neural-set", "res=2"])
    assert rc != 0 and "res" in capsys.readouterr().err


def test_snap_and_explain_print_the_snapping_line(tmp_path):
    """`snap` prints one line on what snapping did; `--snap-tol auto` is the default,
    a number overrides it; `surface --explain` shows the same line."""
    from curvenet.datasets.redraw import rough_sketch
    rough = tmp_path / "rough.obj"
    write_sketch(rough, rough_sketch(shapes.box().network, seed=0))
    r = run("snap", rough, "-o", tmp_path / "n.json")
    assert r.returncode == 0, r.stderr
    line = r.stdout.splitlines()[-1]
    assert line.startswith("snap: tolerance") and "auto" in line and "dangling ends" in line
    r = run("snap", rough, "-o", tmp_path / "m.json", "--snap-tol", "0.03")
    assert "tolerance 3.00% of the diagonal (given)" in r.stdout
    r = run("surface", rough, "-o", tmp_path / "s.obj", "--method", "classical", "--explain")
    assert r.returncode == 0, r.stderr
    assert any(x.startswith("snap: tolerance") for x in r.stdout.splitlines())
    # the fit auto kept, with the bending energy of each fit it tried
    fit = [x for x in r.stdout.splitlines() if x.startswith("fit: ")]
    assert len(fit) == 1 and "bending energy lsq " in fit[0] and "sweep " in fit[0]
    assert not any(x.startswith("smoothed: ") for x in r.stdout.splitlines())
    # and the surface's topology: the box's, one closed piece of genus 0
    assert "surface: 1 piece, closed, genus 0" in r.stdout.splitlines(), r.stdout
    # the same box drawn with per-sample jitter: its curves smoothed for the fit
    write_sketch(rough, rough_sketch(shapes.box().network, seed=0, jitter=0.002))
    r = run("surface", rough, "-o", tmp_path / "j.obj", "--method", "classical", "--explain")
    assert r.returncode == 0, r.stderr
    assert any(x.startswith("smoothed: ") and "per-sample noise" in x
               for x in r.stdout.splitlines()), r.stdout


def test_edge_length_sets_the_output_density(tmp_path, box_obj):
    """--edge-length F: output edges of about F of the diagonal, one file or a batch."""
    diag = np.sqrt(3.0)
    faces = {}
    for f in (0.05, 0.01):
        out = tmp_path / f"m{f}.obj"
        assert main(["surface", str(box_obj), "-o", str(out), "--method", "classical",
                     "--edge-length", str(f)]) == 0
        m = trimesh.load(out, force="mesh", process=False)
        assert 0.4 * f * diag < np.median(m.edges_unique_length) < 1.2 * f * diag
        faces[f] = len(m.faces)
    assert faces[0.01] > 10 * faces[0.05]
    assert main(["surface", str(box_obj), "--out-dir", str(tmp_path / "b"), "--method",
                 "classical", "--edge-length", "0.05", "--no-progress"]) == 0
    batch = trimesh.load(next((tmp_path / "b").glob("*.obj")), force="mesh", process=False)
    assert len(batch.faces) == faces[0.05]


@pytest.mark.parametrize("argv,match", [(["--edge-length", "0"], "(0, 1]"),
                                        (["--edge-length", "1.5"], "(0, 1]"),
                                        (["--edge-length", "fine"], "not a number"),
                                        (["--edge-length", "0.01", "--subdiv", "2"],
                                         "not allowed")])
def test_bad_edge_length_is_one_clear_error(tmp_path, box_obj, capsys, argv, match):
    with pytest.raises(SystemExit) as exc:
        main(["surface", str(box_obj), "-o", str(tmp_path / "m.obj"), *argv])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "--edge-length" in err and match in err
    assert not (tmp_path / "m.obj").exists()
