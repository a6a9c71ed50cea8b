"""Hostile but realistic uses of the CLI: nothing lost, nothing silently wrong (one test a case).

Each case gives one line naming the file (exit 2 for bad input, 1 for an internal
failure, 130 for an interrupted fit), writes nothing half-done and never touches
what the user gave.
"""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import textwrap
import types
import warnings

import numpy as np
import pytest
import trimesh

from curvenet.datasets import shapes
from curvenet.cli import _terminate, main
from curvenet.core.progress import PlainProgress, progress_bar
from curvenet.io.sketch import write_sketch


@pytest.fixture
def box_obj(tmp_path):
    path = tmp_path / "box.obj"
    write_sketch(path, shapes.box().sketch())
    return path


def one_error_line(capsys, *needles):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    for needle in needles:
        assert needle in err[0], err[0]
    return err[0]


def listing(folder):
    return sorted(p.name for p in folder.iterdir())


# ------------------------------------------------------------------ data loss
@pytest.mark.parametrize("command,name", [("surface", "box.obj"), ("snap", "box.obj"),
                                          ("snap", "box.json"), ("patches", "box.json")])
def test_output_that_is_the_input_is_refused(tmp_path, capsys, command, name):
    path = tmp_path / name
    write_sketch(path, shapes.box().sketch())
    before = path.read_bytes()
    assert main([command, str(path), "-o", str(path)]) == 2
    one_error_line(capsys, "is the input file")
    assert path.read_bytes() == before


def test_output_through_a_link_to_the_input_is_refused(tmp_path, box_obj, capsys):
    link = tmp_path / "link.obj"
    link.symlink_to(box_obj)
    before = box_obj.read_bytes()
    assert main(["surface", str(box_obj), "-o", str(link)]) == 2
    one_error_line(capsys, "is the input file")
    assert box_obj.read_bytes() == before


@pytest.mark.parametrize("command", ["surface", "patches", "snap"])
def test_a_symlink_loop_given_as_input_is_bad_input(tmp_path, capsys, command):
    a, b = tmp_path / "a.obj", tmp_path / "b.obj"
    a.symlink_to(b)
    b.symlink_to(a)
    assert main([command, str(a), "-o", str(tmp_path / "out.obj")]) == 2
    one_error_line(capsys, "symbolic link that leads nowhere")
    assert not (tmp_path / "out.obj").exists()


def test_patches_of_another_sketch_are_refused(tmp_path, box_obj, capsys):
    cyl = tmp_path / "cyl.obj"
    write_sketch(cyl, shapes.capped_cylinder().sketch())
    cyl_patches = tmp_path / "cyl_patches.json"
    assert main(["patches", str(cyl), "-o", str(cyl_patches)]) == 0
    capsys.readouterr()
    out = tmp_path / "out.obj"
    assert main(["surface", str(box_obj), "--patches", str(cyl_patches), "-o", str(out)]) == 2
    one_error_line(capsys, "does not match the sketch")
    assert not out.exists()
    # the box's own patches are accepted
    box_patches = tmp_path / "box_patches.json"
    assert main(["patches", str(box_obj), "-o", str(box_patches)]) == 0
    assert main(["surface", str(box_obj), "--patches", str(box_patches), "-o", str(out)]) == 0


def test_eval_refuses_nan_vertices(tmp_path, capsys):
    mesh = tmp_path / "nan.obj"
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nf 1 2 3\nf 1 2 4\n")
    ref = tmp_path / "ref.obj"
    trimesh.creation.icosphere().export(ref)
    assert main(["eval", str(mesh), str(ref)]) == 2
    one_error_line(capsys, str(mesh), "NaN")


def test_eval_warns_on_a_unit_mismatch(tmp_path, capsys):
    ref, big = tmp_path / "ref.obj", tmp_path / "big.obj"
    sphere = trimesh.creation.icosphere()
    sphere.export(ref)
    sphere.apply_scale(1000.0)
    sphere.export(big)
    assert main(["eval", str(big), str(ref), "--samples", "2000"]) == 0
    err = capsys.readouterr().err
    assert "warning" in err and "1e+03x" in err and "units" in err
    assert main(["eval", str(ref), str(ref), "--samples", "2000"]) == 0
    assert "warning" not in capsys.readouterr().err


def test_interrupted_neural_fit_writes_the_partial_surface_and_exits_130(
        tmp_path, box_obj, capsys, monkeypatch):
    from curvenet.neural import flow
    ref = shapes.box().reference_mesh()

    def interrupted_fit(strokes, **kw):
        return types.SimpleNamespace(vertices=np.asarray(ref.vertices),
                                     faces=np.asarray(ref.faces),
                                     report={"interrupted": True})
    monkeypatch.setattr(flow, "fit_flow_surface", interrupted_fit)
    out = tmp_path / "out.obj"
    assert main(["surface", str(box_obj), "-o", str(out), "--method", "neural",
                 "--no-progress"]) == 130
    assert "partial" in capsys.readouterr().out
    assert len(trimesh.load(out, force="mesh").faces) == len(ref.faces)


# ------------------------------------------------------------------ bad input is exit 2
@pytest.mark.parametrize("content,needle", [
    ("[" * 100_000, "nested too deeply"),
    ('{"format": "curvenet.sketch", "strokes": [[[1' + "0" * 400 + ', 0, 0], [0, 0, 0]]]}',
     "too large"),
])
def test_hostile_json_is_bad_input(tmp_path, capsys, content, needle):
    path = tmp_path / "hostile.json"
    path.write_text(content)
    assert main(["snap", str(path), "-o", str(tmp_path / "n.json")]) == 2
    one_error_line(capsys, str(path), needle)


def test_unreadable_input_is_bad_input(tmp_path, box_obj, capsys, monkeypatch):
    import curvenet.io.common as cio  # the module that opens sketch files

    def denied(path, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(path))
    monkeypatch.setattr(cio, "open", denied, raising=False)
    assert main(["snap", str(box_obj), "-o", str(tmp_path / "n.json")]) == 2
    one_error_line(capsys, str(box_obj), "Permission denied")


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero")
def test_endless_device_is_refused_with_a_bounded_read(tmp_path, capsys):
    assert main(["snap", "/dev/zero", "-o", str(tmp_path / "n.json")]) == 2
    one_error_line(capsys, "/dev/zero", "binary data")


def test_unwritable_folder_names_the_requested_file(tmp_path, box_obj, capsys, monkeypatch):
    import curvenet.core.atomic as atomic

    def denied(*args, **kwargs):
        raise PermissionError(13, "Permission denied")
    monkeypatch.setattr(atomic.tempfile, "mkstemp", denied)
    out = tmp_path / "out.obj"
    assert main(["surface", str(box_obj), "-o", str(out)]) == 2
    line = one_error_line(capsys, str(out), "Permission denied")
    assert ".out.obj." not in line   # not the hidden temporary file


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_read_only_folder_is_refused_before_work(tmp_path, box_obj, capsys):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    assert main(["surface", str(box_obj), "-o", str(ro / "out.obj")]) == 2
    one_error_line(capsys, "not writable")


def test_out_dir_that_is_a_file(tmp_path, box_obj, capsys):
    not_dir = tmp_path / "file"
    not_dir.write_text("x")
    assert main(["surface", str(box_obj), str(box_obj), "--out-dir", str(not_dir)]) == 2
    one_error_line(capsys, "is a file")


def test_preview_in_a_missing_folder_is_refused_before_the_mesh(tmp_path, box_obj, capsys):
    out = tmp_path / "out.obj"
    assert main(["surface", str(box_obj), "-o", str(out), "--preview",
                 str(tmp_path / "no" / "such" / "p.png")]) == 2
    one_error_line(capsys, "--preview", "does not exist")
    assert not out.exists() and not (tmp_path / "no").exists()


def test_disk_full_is_one_line_naming_the_output(tmp_path, box_obj, capsys, monkeypatch):
    def full(self, *args, **kwargs):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(trimesh.Trimesh, "export", full)
    out = tmp_path / "out.obj"
    assert main(["surface", str(box_obj), "-o", str(out)]) == 2
    one_error_line(capsys, str(out), "No space left on device")
    assert listing(tmp_path) == ["box.obj"]


# ------------------------------------------------------------------ absurd sizes
@pytest.mark.parametrize("flags,needle", [
    (["--subdiv", "100"], "the limit is"),
    (["--resolution", "100000"], "the limit is"),
    (["--method", "neural", "--neural-set", "res=100000"], "res <= "),
])
def test_absurd_sizes_are_refused_up_front(tmp_path, box_obj, capsys, flags, needle):
    out = tmp_path / "out.obj"
    assert main(["surface", str(box_obj), "-o", str(out), "--no-progress", *flags]) == 2
    one_error_line(capsys, needle)
    assert not out.exists()


# ------------------------------------------------------------------ smaller ones
def test_huge_coordinates_name_the_file_without_numpy_warnings(tmp_path, capsys):
    path = tmp_path / "huge.obj"
    path.write_text("v 1e308 0 0\nv -1e308 1e308 0\nv 0 0 1e308\nl 1 2 3\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(["snap", str(path), "-o", str(tmp_path / "n.json")]) == 2
    one_error_line(capsys, str(path), "overflow")


def test_sigterm_while_writing_leaves_no_temporary_file(tmp_path, box_obj):
    out = tmp_path / "out.obj"
    code = textwrap.dedent(f"""
        import os, signal, sys, trimesh
        from curvenet.cli import main
        def export(self, path, **kw):
            open(path, "w").write("half a mesh")
            os.kill(os.getpid(), signal.SIGTERM)
        trimesh.Trimesh.export = export
        sys.exit(main(["surface", {str(box_obj)!r}, "-o", {str(out)!r}]))
    """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 128 + 15, r.stderr
    assert listing(tmp_path) == ["box.obj"]


def test_terminate_handler_unwinds_atomic_writes(tmp_path):
    from curvenet.core.atomic import atomic_path
    with pytest.raises(SystemExit):
        with atomic_path(tmp_path / "x.obj") as tmp:
            tmp.write_text("half")
            _terminate(15, None)
    assert listing(tmp_path) == []


def test_later_stage_errors_name_the_file(tmp_path, capsys):
    path = tmp_path / "dots.obj"
    path.write_text("v 0 0 0\nv 0 0 0\nl 1 2\nv 1 1 1\nv 1 1 1\nl 3 4\n")
    assert main(["surface", str(path), "-o", str(tmp_path / "o.obj")]) == 2
    one_error_line(capsys, str(path))


def test_huge_seed_names_the_flag(tmp_path, box_obj, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["surface", str(box_obj), "-o", str(tmp_path / "o.obj"), "--seed", str(10**23)])
    assert exc.value.code == 2
    one_error_line(capsys, "--seed")


def test_option_error_is_one_line_with_a_hint(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["surface", "x.obj", "--no-such-flag"])
    assert exc.value.code == 2
    one_error_line(capsys, "--no-such-flag", "--help")


def test_garbage_stl_says_what_is_wrong(tmp_path, capsys):
    garbage = tmp_path / "garbage.stl"
    garbage.write_bytes(bytes(np.random.default_rng(0).integers(1, 256, 300, dtype=np.uint8)))
    ref = tmp_path / "ref.obj"
    trimesh.creation.icosphere().export(ref)
    assert main(["eval", str(garbage), str(ref)]) == 2
    line = one_error_line(capsys, str(garbage), "STL")
    assert "module" not in line


def test_strokes_that_collapse_are_an_error_not_an_empty_network(tmp_path, capsys):
    path = tmp_path / "points.json"
    strokes = [[[float(i), 0.0, 0.0], [float(i), 0.0, 0.0]] for i in range(2000)]
    path.write_text(json.dumps({"format": "curvenet.sketch", "strokes": strokes}))
    out = tmp_path / "n.json"
    assert main(["snap", str(path), "-o", str(out)]) == 2
    one_error_line(capsys, str(path))
    assert not out.exists()


def test_dropped_one_point_strokes_give_one_warning(tmp_path):
    from curvenet.io.sketch import read_sketch
    path = tmp_path / "ones.json"
    strokes = [[[0, 0, 0], [1, 0, 0]]] + [[[i, 1.0, 0]] for i in range(1000)]
    path.write_text(json.dumps({"format": "curvenet.sketch", "strokes": strokes}))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        read_sketch(path)
    assert len(caught) == 1 and "999 more" in str(caught[0].message)


def test_missing_folders_are_never_created(tmp_path, box_obj, capsys):
    out = tmp_path / "new" / "deep" / "out.obj"
    assert main(["surface", str(box_obj), "-o", str(out)]) == 2
    one_error_line(capsys, "does not exist")
    assert not (tmp_path / "new").exists()


def test_interactive_save_into_a_missing_folder(tmp_path, box_obj, monkeypatch, capsys):
    target = tmp_path / "new" / "p.json"
    monkeypatch.setattr(sys, "stdin", io.StringIO(f"s {target}\nq\n"))
    assert main(["patches", str(box_obj), "-o", str(tmp_path / "p.json"),
                 "--interactive"]) == 0
    assert "cannot save" in capsys.readouterr().out
    assert not (tmp_path / "new").exists()


def test_progress_off_a_terminal_is_a_few_plain_lines():
    out = io.StringIO()
    bar = progress_bar(1000, desc="neural", unit="step", file=out)
    assert isinstance(bar, PlainProgress)
    for _ in range(1000):
        bar.update(1)
        bar.set_postfix({"loss": "0.1"})
    bar.close()
    lines = out.getvalue().splitlines()
    assert 2 <= len(lines) <= 6 and "\r" not in out.getvalue()
    assert lines[-1].startswith("neural: 1000/1000 step")
