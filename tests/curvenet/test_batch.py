"""Batch surfacing (curvenet.batch, `surface --out-dir`) and batch evaluation (`eval --pairs`)."""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import trimesh

from curvenet.datasets import shapes
from curvenet.batch.run import MANIFEST_NAME, BatchOptions, plan_outputs, read_manifest, run_batch
from curvenet.cli import main
from curvenet.core.errors import InvalidParameterError
from curvenet.core.fidelity import stroke_fidelity
from curvenet.io.sketch import write_sketch


# batch mechanics, not surface density, are tested here: a coarse output keeps files quick
COARSE = ["--edge-length", "0.03"]


def _opts(**kw):
    return BatchOptions(method="classical", edge_length=0.03, **kw)


@pytest.fixture(autouse=True)
def scratch(tmp_path, monkeypatch):
    """The temporary folder of this test and of the processes it starts: the working
    folders of the batches and workers killed on purpose here stay out of /tmp."""
    folder = tmp_path / "tmp"
    folder.mkdir()
    monkeypatch.setenv("TMPDIR", str(folder))
    monkeypatch.setattr(tempfile, "tempdir", str(folder))
    return folder


def _boxes(folder, n):
    """``n`` distinct small box sketches (heights 1, 1.1, ...), named s00, s01, ..."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for k in range(n):
        p = folder / f"s{k:02d}.obj"
        write_sketch(p, shapes.box(size=(1.0, 1.0 + 0.1 * k, 1.0), samples=9).sketch())
        paths.append(p)
    return paths


def _shapes(folder):
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for name in ("box", "house", "l_prism", "capped_cylinder"):
        p = folder / f"{name}.obj"
        write_sketch(p, getattr(shapes, name)().sketch())
        out.append(p)
    return out


# --------------------------------------------------------------------------- issue 20 items
def test_same_stem_inputs_are_refused_before_any_work(tmp_path, capsys):
    a, b = tmp_path / "a" / "shape.obj", tmp_path / "b" / "shape.obj"
    for p in (a, b):
        p.parent.mkdir()
        write_sketch(p, shapes.box().sketch())
    out = tmp_path / "out"
    code = main(["surface", str(a), str(b), "--out-dir", str(out), "--method", "classical",
                 *COARSE])
    err = capsys.readouterr().err
    assert code == 2
    assert str(a) in err and str(b) in err and err.count("\n") == 1
    assert not out.exists() or not any(out.iterdir())
    with pytest.raises(InvalidParameterError):  # the same file twice clashes too
        plan_outputs([str(a), str(a)], out, "obj")


def test_an_internal_error_in_one_file_does_not_stop_the_batch(tmp_path, capsys, monkeypatch):
    import curvenet.pipeline
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000)  # bad input: one error row, not an internal failure
    box, house = _shapes(tmp_path / "in")[:2]
    broken = tmp_path / "broken.obj"
    broken.write_bytes(box.read_bytes())
    real = curvenet.pipeline.surface

    def surface(source, **kw):  # an internal bug that shows for one file only
        if str(source).endswith("broken.obj"):
            raise RecursionError("maximum recursion depth exceeded")
        return real(source, **kw)
    monkeypatch.setattr(curvenet.pipeline, "surface", surface)
    report = tmp_path / "r.json"
    code = main(["surface", str(deep), str(broken), str(box), str(house), "--out-dir",
                 str(tmp_path / "o"), "--method", "classical", *COARSE, "--report", str(report)])
    out = capsys.readouterr().out
    assert code == 1  # documented: an internal failure in any file -> 1, after the batch
    assert (tmp_path / "o" / "box.obj").is_file() and (tmp_path / "o" / "house.obj").is_file()
    rows = {os.path.basename(r["input"]): r for r in json.loads(report.read_text())["rows"]}
    assert rows["deep.json"]["status"] == "error"
    assert "nested too deeply" in rows["deep.json"]["error"]
    assert rows["broken.obj"]["status"] == "internal"
    assert "RecursionError" in rows["broken.obj"]["error"]
    assert rows["box.obj"]["status"] == rows["house.obj"]["status"] == "ok"
    assert "2 of 4 surfaced" in out and "1 internal failures" in out


def test_report_and_preview_paths_are_checked_before_any_work(tmp_path, capsys):
    box = _shapes(tmp_path / "in")[0]
    out = tmp_path / "out"
    base = ["surface", str(box), "--out-dir", str(out), "--method", "classical", *COARSE]
    assert main(base + ["--report", str(tmp_path / "nope" / "r.csv")]) == 2
    assert main(base + ["--report", str(tmp_path / "r.txt")]) == 2
    afile = tmp_path / "afile"
    afile.write_text("x")
    assert main(base + ["--preview-dir", str(afile)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 3 and "nope" in err[0] and "r.txt" in err[1] and "afile" in err[2]
    assert not (out / "box.obj").exists()
    assert main(base + ["--report", str(out / "r.csv")]) == 0  # inside the new out-dir
    assert (out / "r.csv").is_file() and (out / "box.obj").is_file()


# --------------------------------------------------------------------------- report
def test_stroke_fidelity_is_the_share_of_stroke_length_on_the_surface():
    box = trimesh.creation.box()  # [-0.5, 0.5]^3, diagonal sqrt(3)
    on = np.array([[-0.5, -0.5, 0.5], [0.5, -0.5, 0.5]])  # an edge: length 1, distance 0
    off = np.array([[0.0, 0.0, 0.6], [0.0, 3.0, 0.6]])  # 0.1 above the top, length 3
    fid = stroke_fidelity(box, [on, off])
    assert fid["fidelity"] == pytest.approx(1 / 4, abs=0.01)
    assert fid["diagonal"] == pytest.approx(np.sqrt(3))
    # the off stroke is 0.1 away over x in [0, 0.5] then farther: p95 well above 1%
    assert fid["p95"] > 0.01 and fid["median"] > 0.1 / np.sqrt(3) - 1e-9


def test_report_rows_and_contact_sheet(tmp_path):
    inputs = _shapes(tmp_path / "in")
    bad = tmp_path / "in" / "bad.obj"
    bad.write_text("v 0 0\n")
    res = run_batch(inputs + [bad], tmp_path / "out", _opts(),
                    preview_dir=tmp_path / "prev")
    assert res.counts == {"ok": 4, "skipped": 0, "error": 1, "internal": 0}
    assert res.exit_code == 2
    for row in res.rows[:4]:
        assert row["route"] == "classical" and row["coverage"] == pytest.approx(1.0)
        # classical patches interpolate their boundary curves
        assert row["fidelity"] == pytest.approx(1.0) and row["patches"] >= 6
        assert {"t_snap", "t_patches", "t_classical", "t_fidelity", "t_total"} <= set(row)
        # four closed solids of genus 0: one closed piece each, no walls
        assert (row["pieces"], row["closed"], row["boundary_loops"], row["genus"],
                row["nonmanifold_edges"]) == (1, 1, 0, 0, 0)
        assert len(row["input_sha256"]) == 64 and os.path.isfile(row["output"])
    assert res.rows[4]["status"] == "error" and "bad.obj:1" in res.rows[4]["error"]
    from matplotlib.image import imread

    from curvenet.view.colours import FAILED_COLOUR, ROUTE_COLOURS
    img = imread(tmp_path / "prev" / "contact_sheet.png")[..., :3]
    for key, rgb in (("classical", ROUTE_COLOURS["classical"]), ("failed", FAILED_COLOUR)):
        assert np.sum(np.all(np.abs(img - rgb) < 0.02, axis=-1)) > 500, key  # frames
    assert sorted(p.name for p in (tmp_path / "prev").iterdir()) == [
        "box.png", "capped_cylinder.png", "contact_sheet.png", "house.png", "l_prism.png"]


def _crashing_file(local, options, tmp, **kw):
    """``_surface_file``, but the process dies (as in a native crash) on house.obj, in
    the middle of its task, with its working folder made and a file in it."""
    if local.endswith("house.obj"):
        Path(tmp, "partial.obj").write_text("v 0 0 0\n")
        os._exit(3)
    return _REAL_FILE(local, options, tmp, **kw)


_REAL_FILE = __import__("curvenet.batch.run").batch.run._surface_file


@pytest.mark.skipif(__import__("multiprocessing").get_start_method() != "fork",
                    reason="the crash is injected into forked pool processes")
def test_a_pool_process_that_dies_costs_only_its_own_file(tmp_path, monkeypatch, scratch):
    import curvenet.batch.run
    from curvenet.batch.run import LocalExecutor
    inputs = _shapes(tmp_path / "in") + _boxes(tmp_path / "in", 2)
    monkeypatch.setattr(curvenet.batch.run, "_surface_file", _crashing_file)
    res = run_batch(inputs, tmp_path / "out", _opts(),
                    executor=LocalExecutor(2))
    status = {os.path.basename(r["input"]): r["status"] for r in res.rows}
    assert status.pop("house.obj") == "internal"
    assert set(status.values()) == {"ok"} and res.exit_code == 1
    assert list(scratch.iterdir()) == []   # the dead worker's folder went with the batch's


# --------------------------------------------------------------------------- resuming
def test_an_interrupted_batch_of_20_restarts_where_it_stopped(tmp_path):
    inputs = _boxes(tmp_path / "in", 20)
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "curvenet.cli", "surface", *map(str, inputs),
           "--out-dir", str(out), "--method", "classical", *COARSE]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    manifest = out / MANIFEST_NAME
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and proc.poll() is None:
        if manifest.is_file() and manifest.read_text().count("\n") >= 5:
            break
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    done = {k for k, e in read_manifest(out).items() if e["status"] == "ok"}
    assert 5 <= len(done) < 20
    stamps = {p: os.stat(p).st_mtime_ns for p in done}

    report = tmp_path / "r.csv"
    code = main(cmd[3:] + ["--skip-existing", "--report", str(report)])
    assert code == 0
    with open(report) as fh:
        rows = list(csv.DictReader(line for line in fh if not line.startswith("#")))
    assert len(rows) == 20
    assert {r["output"] for r in rows if r["status"] == "skipped"} == done
    assert {r["output"] for r in rows if r["status"] == "ok"} == {
        str(out / f"s{k:02d}.obj") for k in range(20)} - done
    assert all(os.stat(p).st_mtime_ns == stamps[p] for p in done)  # not rewritten


def test_skip_existing_reruns_changed_inputs_settings_and_outputs(tmp_path):
    inputs = _boxes(tmp_path / "in", 3)
    out = tmp_path / "out"
    opts = _opts()
    assert run_batch(inputs, out, opts).counts["ok"] == 3
    write_sketch(inputs[0], shapes.house().sketch())  # a new input under the same name
    (out / "s01.obj").write_text("tampered\n")  # an output changed since
    res = run_batch(inputs, out, opts, skip_existing=True)
    assert [r["status"] for r in res.rows] == ["ok", "ok", "skipped"]
    res = run_batch(inputs, out, BatchOptions(method="classical", subdiv=1), skip_existing=True)
    assert [r["status"] for r in res.rows] == ["ok", "ok", "ok"]  # new settings


# --------------------------------------------------------------------------- dask
def test_dask_cluster_with_a_bad_file_and_a_killed_worker_matches_jobs_2(tmp_path, capsys):
    distributed = pytest.importorskip("distributed")
    inputs = _shapes(tmp_path / "in") + _boxes(tmp_path / "in", 4)
    bad = tmp_path / "in" / "bad.obj"
    bad.write_text("l 1 2\n")
    args = ["surface", *map(str, inputs + [bad]), "--method", "classical", "--format", "ply",
            *COARSE]
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        pids = client.run(os.getpid)
        victim = next(iter(pids.values()))
        manifest = tmp_path / "dask" / MANIFEST_NAME
        killed = threading.Event()

        def kill_after_first_result():
            deadline = time.monotonic() + 120
            while time.monotonic() < deadline:
                if manifest.is_file() and manifest.read_text().count("\n") >= 1:
                    os.kill(victim, signal.SIGKILL)
                    killed.set()
                    return
                time.sleep(0.01)

        killer = threading.Thread(target=kill_after_first_result)
        killer.start()
        code = main(args + ["--out-dir", str(tmp_path / "dask"), "--scheduler",
                            cluster.scheduler_address, "--report", str(tmp_path / "r.json")])
        killer.join()
    assert killed.is_set()
    assert code == 2  # documented: bad input in some file, no internal failure
    rows = json.loads((tmp_path / "r.json").read_text())["rows"]
    assert [r["status"] for r in rows] == ["ok"] * len(inputs) + ["error"]
    assert "bad.obj" in rows[-1]["error"]
    assert all(r["worker"].startswith("tcp://") for r in rows)  # ran on the cluster
    assert main(args + ["--out-dir", str(tmp_path / "local"), "--jobs", "2"]) == 2
    capsys.readouterr()
    for p in inputs:
        a = (tmp_path / "dask" / f"{p.stem}.ply").read_bytes()
        assert a == (tmp_path / "local" / f"{p.stem}.ply").read_bytes(), p.name
    assert not (tmp_path / "dask" / "bad.ply").exists()


def test_a_task_whose_worker_dies_for_good_is_reported_and_the_rest_goes_on(tmp_path):
    distributed = pytest.importorskip("distributed")
    import dask
    inputs = _shapes(tmp_path / "in") + _boxes(tmp_path / "in", 2)
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), \
            distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                     dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        from curvenet.batch.run import DaskExecutor
        victim = next(iter(client.run(os.getpid).values()))
        killed = []

        def on_row(row, done, total):  # the worker is on the next file by now: kill it
            if not killed:
                os.kill(victim, signal.SIGKILL)
                killed.append(done)

        res = run_batch(inputs, tmp_path / "out", _opts(),
                        executor=DaskExecutor(client), on_row=on_row)
    # the tasks on the dead worker (running or queued there) are lost; the others run
    lost = [r for r in res.rows if r["status"] == "internal"]
    assert 1 <= len(lost) <= len(inputs) - 2 and res.exit_code == 1
    assert all("KilledWorker" in r["error"] for r in lost)
    assert res.counts["ok"] == len(inputs) - len(lost)
    assert all(os.path.isfile(r["output"]) for r in res.rows if r["status"] == "ok")


# --------------------------------------------------------------------------- eval --pairs
def test_eval_pairs_scores_a_folder_against_references(tmp_path, capsys):
    out, ref = tmp_path / "out", tmp_path / "ref"
    ref.mkdir()
    run_batch(_shapes(tmp_path / "in")[:3], out, _opts())
    for name in ("box", "house"):
        getattr(shapes, name)().reference_mesh().export(ref / f"{name}.ply")
    # l_prism is scored against its sketch; a box grown 1.5x about its centre is 0.25 away
    write_sketch(ref / "l_prism.obj", shapes.l_prism().sketch())
    grown = trimesh.creation.box(extents=(1.5, 1.5, 1.5))
    grown.apply_translation((0.5, 0.5, 0.5))
    grown.export(out / "zz.ply")
    shapes.box().reference_mesh().export(ref / "zz.ply")
    report = tmp_path / "e.csv"
    code = main(["eval", "--pairs", str(out), str(ref), "--samples", "2000",
                 "--report", str(report)])
    text = capsys.readouterr().out
    assert code == 0
    assert "2000 area-uniform points" in text and "closer than 0.01" in text
    lines = report.read_text().splitlines()
    assert lines[0].startswith("# curvenet eval") and lines[-1].startswith("# 4 pairs")
    rows = {os.path.basename(r["mesh"]): r
            for r in csv.DictReader(x for x in lines if not x.startswith("#"))}
    assert float(rows["box.obj"]["fscore"]) == pytest.approx(1.0)
    assert float(rows["house.obj"]["fscore"]) == pytest.approx(1.0)
    assert float(rows["l_prism.obj"]["stroke_within_1pct"]) == pytest.approx(1.0)
    assert float(rows["zz.ply"]["fscore"]) == 0.0
    assert float(rows["zz.ply"]["chamfer"]) == pytest.approx(0.25, rel=0.05)

    pairs = tmp_path / "pairs.csv"
    pairs.write_text("mesh,reference\nout/box.obj,ref/box.ply\nout/box.obj,ref/nothere.ply\n")
    assert main(["eval", "--pairs", str(pairs), "--samples", "500", "--json"]) == 2
    data = json.loads(capsys.readouterr().out)
    assert [r["status"] for r in data["rows"]] == ["ok", "error"]
    assert "nothere.ply" in data["rows"][1]["error"]


# --------------------------------------------------------------------------- issue 32
_PARENT = r"""
import os, sys, time
import curvenet.batch.run as br

def sleepy(path, data, options, **render):
    with open(path + ".tmp", "w") as f:
        f.write(str(os.getpid()))
    os.replace(path + ".tmp", path)
    time.sleep(120)
    return {}

br.surface_task = sleepy
if sys.argv[2] == "poll":
    br._set_death_signal = lambda: False     # the fallback alone: getppid() polling
folder = sys.argv[1]
for _ in br.LocalExecutor(2).run([f"{folder}/a.pid", f"{folder}/b.pid"], None, {}):
    pass
"""


def _gone(pid: int) -> bool:
    """No such process, or a zombie (dead, waiting to be reaped by its new parent)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] in ("Z", "X")
    except FileNotFoundError:
        return True


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("watch", ["signal", "poll"])
def test_pool_workers_exit_within_5_s_of_their_parent_being_killed(tmp_path, watch):
    parent = subprocess.Popen([sys.executable, "-c", _PARENT, str(tmp_path), watch])
    pids = [tmp_path / "a.pid", tmp_path / "b.pid"]
    try:
        deadline = time.monotonic() + 60
        while not all(p.exists() for p in pids):
            assert parent.poll() is None and time.monotonic() < deadline, "workers never started"
            time.sleep(0.05)
        workers = [int(p.read_text()) for p in pids]
        assert not any(_gone(w) for w in workers)
        parent.send_signal(signal.SIGKILL)
        parent.wait()
        killed = time.monotonic()
        while not all(_gone(w) for w in workers) and time.monotonic() - killed < 5:
            time.sleep(0.05)
        alive = [w for w in workers if not _gone(w)]
        assert not alive, f"workers {alive} outlived their killed parent by 5 s"
    finally:
        if parent.poll() is None:
            parent.kill()
        for p in pids:
            if p.exists() and not _gone(int(p.read_text())):
                os.kill(int(p.read_text()), signal.SIGKILL)
