"""Tests of curvenet.review.web and ``curvenet review``, without a browser.

The page's actions are called as the browser's clicks call them; the CLI is run as a
subprocess on real files (a malformed sketch, Ctrl-C). The browser itself is driven
in test_review_browser.py. Skipped where the ``[view]`` extra (viser) is missing,
except the test that a missing extra is named.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
import urllib.request

import pytest
import trimesh

from curvenet.core.errors import (InvalidParameterError, MissingDependencyError,
                                  NetworkError, OutputError)
from curvenet.cycles.find import find_patches
from curvenet.cycles.gf2 import edge_mask, gf2_rank
from curvenet.datasets import shapes
from curvenet.io.network import read_patches
from curvenet.review.web import require_viser


def test_missing_viser_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "viser", None)      # import viser -> ImportError
    with pytest.raises(MissingDependencyError, match=r"curvenet\[view\]"):
        require_viser()


def test_graph_commands_do_not_import_viser():
    code = ("import sys, curvenet, curvenet.cli, curvenet.review; "
            "curvenet.cli.build_parser(); sys.exit('viser' in sys.modules)")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


viser = pytest.importorskip("viser")
from curvenet.review.web import ReviewPage  # noqa: E402


@pytest.fixture
def page_of(tmp_path):
    pages = []

    def make(ps, **kw):
        kw.setdefault("output", tmp_path / "out.json")
        page = ReviewPage(ps, port=0, **kw)
        pages.append(page)
        return page

    yield make
    for page in pages:
        page.close()


def test_page_is_local_offline_and_lists_the_patches_in_order(page_of):
    ps = find_patches(shapes.l_prism().network)
    page = page_of(ps)
    assert page.server.get_host() == "127.0.0.1"
    assert page.labels == [f"patch {i + 1}" for i in range(len(ps.patches))]
    assert page.accepted() == [True] * len(ps.patches) and not page.unsaved
    html = urllib.request.urlopen(page.url, timeout=10).read().decode()
    assert '<div id="root">' in html
    # one self-contained file: no script, style or font fetched from anywhere else
    assert "src=\"http" not in html and "href=\"http" not in html and "@import" not in html


def test_untick_save_undo(page_of, tmp_path):
    ps = find_patches(shapes.box().network, close="none")          # five faces, a basis
    page = page_of(ps)
    page.set_accepted(0, False)
    assert page.accepted() == [False] + [True] * 4 and page.unsaved
    assert page.selected == 0                                      # unticking selects it
    assert page.session.rank() == page.session.full_rank - 1
    assert page.save() == tmp_path / "out.json" and not page.unsaved
    back = read_patches(tmp_path / "out.json")
    assert [p.edges for p in back.patches] == [p.edges for p in ps.patches[1:]]
    assert [p.source for p in back.patches] == [p.source for p in ps.patches[1:]]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.json"]   # no temp file left
    assert page.undo() and page.accepted() == [True] * 5 and page.unsaved
    assert not page.undo()
    page.set_accepted(1, True)                                     # already ticked: nothing
    assert not page.undo()
    with pytest.raises(InvalidParameterError, match="row"):
        page.set_accepted(5, False)


def test_alternatives_of_a_selected_patch_and_using_one(page_of):
    shape = shapes.two_boxes()
    ps = find_patches(shape.network, close="none")
    page = page_of(ps)
    n = len(ps.patches)
    page.select(0)
    alts = page.alternatives
    assert alts and [a.edges for a in alts] == [a.edges for a in page.session.alternatives_to(0)]
    assert "alternative 1 of" in page._selection_text.content
    page.next_alternative()
    assert page.shown == (1 % len(alts))
    used = alts[page.shown]
    page.use_alternative()
    assert page.labels[-1] == f"patch {n + 1}" and page.accepted() == [False] + [True] * n
    assert page.patchset.patches[-1].edges == used.edges
    assert page.patchset.patches[-1].source == "user"
    masks = [edge_mask(p.edges) for p in page.patchset.patches]
    assert gf2_rank(masks, shape.network.number_of_edges) == page.session.full_rank
    assert page.selected == n                                      # the new row is selected
    assert page.undo()                                             # one step: both undone
    assert page.accepted() == [True] * n + [False]
    page.select(None)
    assert page.selected is None and page.alternatives == []


def test_surface_button_shows_the_surface_or_says_why_not(page_of):
    calls = []

    def surface(patchset):
        calls.append(len(patchset.patches))
        return trimesh.creation.box()

    ps = find_patches(shapes.box().network)
    page = page_of(ps, surface=surface)
    page.set_accepted(2, False)
    page.show_surface()
    assert calls == [5] and "12 triangles" in page.status
    assert page._layer_boxes["show surface"].value and not page._layer_boxes["show patches"].value

    def broken(patchset):
        raise NetworkError("no loops")

    page2 = page_of(ps, surface=broken)
    page2.show_surface()
    assert "no surface: no loops" in page2.status
    page3 = page_of(ps)
    assert page3._buttons["Surface"].disabled


def test_bad_arguments(page_of, tmp_path):
    ps = find_patches(shapes.box().network)
    given = tmp_path / "given.json"
    given.write_text("{}")
    with pytest.raises(OutputError, match="input"):
        page_of(ps, output=given, inputs=[given])
    with pytest.raises(OutputError, match="does not exist"):
        page_of(ps, output=tmp_path / "no" / "out.json")
    with pytest.raises(InvalidParameterError, match="port"):
        ReviewPage(ps, output=tmp_path / "o.json", port=70000)
    with pytest.raises(InvalidParameterError, match="PatchSet"):
        ReviewPage("patches", output=tmp_path / "o.json")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["given.json"]


# --------------------------------------------------------------------------- the command
def _review(args, cwd, **kw):
    return subprocess.Popen([sys.executable, "-m", "curvenet.cli", "review", *args,
                             "--no-browser", "--port", "0"], cwd=cwd, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, **kw)


def test_malformed_sketch_is_refused_before_the_server_starts(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 nan 0\nl 1 2\n")
    proc = _review([str(bad)], tmp_path)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 2
    assert err.count("\n") == 1 and "bad.obj" in err and "Traceback" not in err
    assert "review:" not in out and "http" not in out
    proc = _review([str(bad), "-o", str(bad)], tmp_path)          # -o over the input
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 2 and "refusing to overwrite" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.obj"]


def test_ctrl_c_stops_cleanly_and_nothing_is_written(tmp_path):
    from curvenet.io.sketch import write_sketch

    write_sketch(tmp_path / "box.obj", shapes.box().sketch())
    proc = _review(["box.obj"], tmp_path)
    line = ""
    deadline = time.monotonic() + 60
    while "review: http" not in line and time.monotonic() < deadline:
        line = proc.stdout.readline()
    assert "review: http://127.0.0.1:" in line and "box.patches.json" in line
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 0, err
    assert "review: stopped" in out and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["box.obj"]   # Save never pressed


def test_review_reads_a_saved_patch_set_as_saved(tmp_path):
    ps = find_patches(shapes.box().network)
    from curvenet.io.network import write_patches

    write_patches(tmp_path / "p.json", type(ps)(ps.network, ps.patches[:4], ps.report))
    proc = _review(["p.json", "-o", "q.json"], tmp_path)
    line = proc.stdout.readline()
    while "review:" not in line:
        line = proc.stdout.readline()
    assert "(4 patches;" in line
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=30)
    assert proc.returncode == 0
    assert json.loads((tmp_path / "p.json").read_text())["format"] == "curvenet.patches"
