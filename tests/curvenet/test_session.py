"""Tests of curvenet.cycles.session: suggestions against the analytic shapes' true faces.

Oracles: the true faces of ``curvenet.datasets.shapes``, the cycle rank E - V + C and
galois ranks; the terminal loop is driven by piped answers (io.StringIO).
"""

from __future__ import annotations

import io

import pytest

from curvenet.datasets import shapes
from curvenet.cycles.gf2 import edge_mask, gf2_rank
from curvenet.cycles.find import find_patches
from curvenet.core.errors import InvalidParameterError, NetworkError
from curvenet.io.network import read_patches
from curvenet.model.patchset import PatchSet
from curvenet.cycles.session import PatchSession, Suggestion
from curvenet.review import run_interactive


def true_faces(shape):
    return {tuple(sorted(e for e, _ in f)) for f in shape.faces}


def edge_sets(patches):
    return {p.edges for p in patches}


@pytest.fixture(scope="module")
def box():
    return shapes.box()


@pytest.fixture(scope="module")
def two_boxes():
    return shapes.two_boxes()


@pytest.mark.parametrize("i", range(6))
def test_delete_box_face_suggests_it_back_first(box, i):
    session = PatchSession(find_patches(box.network))
    face = session.patches[i].edges
    sugg = session.delete(i)
    assert sugg and sugg[0].edges == face
    assert sugg[0].kind == "closing"          # the rank stayed full: the face closed the solid
    assert sugg[0].details["b"] == 4          # all four edges are open after the delete
    session.accept(sugg[0])
    assert edge_sets(session.patches) == true_faces(box)


def test_delete_from_solid_free_basis_offers_next_best(box):
    ps = find_patches(box.network, close="none")
    session = PatchSession(ps)
    missing = (true_faces(box) - edge_sets(ps.patches)).pop()
    deleted = session.patches[0].edges
    assert session.rank() == session.full_rank
    sugg = session.delete(0)
    assert session.rank() == session.full_rank - 1
    assert all(s.kind == "replacement" for s in sugg)
    assert deleted not in {s.edges for s in sugg}   # "next-best": the deleted cycle is excluded
    assert sugg[0].edges == missing and sugg[0].score == 4
    assert [s.score for s in sugg] == sorted(s.score for s in sugg)
    session.accept(sugg[0])
    assert session.rank() == session.full_rank


@pytest.mark.parametrize("backend", ["galois", "bitset"])
def test_two_boxes_both_closing_faces_on_top(two_boxes, backend):
    ps = find_patches(two_boxes.network, close="none")
    missing = true_faces(two_boxes) - edge_sets(ps.patches)
    assert len(missing) == 2
    session = PatchSession(ps, backend=backend)
    top = session.closing_suggestions()
    assert {s.edges for s in top[:2]} == missing
    # the suggestion names the solid it closes: it sums to zero with it over GF(2)
    for s in top:
        acc = edge_mask(s.edges)
        for j in s.details["solid"]:
            acc ^= edge_mask(session.patches[j].edges)
        assert acc == 0
    session.accept(top[0])
    nxt = session.closing_suggestions()
    assert nxt[0].edges in missing
    session.accept(nxt[0])
    assert edge_sets(session.patches) == true_faces(two_boxes)


def test_backends_agree(two_boxes):
    ps = find_patches(two_boxes.network, close="none")
    a = PatchSession(ps, backend="galois")
    b = PatchSession(ps, backend="bitset")
    assert [s.edges for s in a.closing_suggestions()] == [s.edges for s in b.closing_suggestions()]
    assert a.rank() == b.rank() == a.full_rank                  # a basis: no solid closed
    a.delete(3)
    b.delete(3)
    assert a.rank() == b.rank() == a.full_rank - 1
    assert [s.edges for s in a.replacement_suggestions()] \
        == [s.edges for s in b.replacement_suggestions()]


def test_replacements_restore_rank(two_boxes):
    session = PatchSession(find_patches(two_boxes.network, close="none"), backend="bitset")
    session.delete(0)
    n_edges = two_boxes.network.number_of_edges
    base = [edge_mask(p.edges) for p in session.patches]
    for s in session.replacement_suggestions(top=50):
        assert gf2_rank(base + [edge_mask(s.edges)], n_edges) == session.full_rank


def _shares_a_curve(a, b):
    return not set(a).isdisjoint(b)


@pytest.mark.parametrize("backend", ["galois", "bitset"])
def test_alternatives_to_a_basis_patch_are_the_next_cycles_through_its_curves(two_boxes,
                                                                            backend):
    session = PatchSession(find_patches(two_boxes.network, close="none"), backend=backend)
    n_edges = two_boxes.network.number_of_edges
    before = edge_sets(session.patches)
    face = session.patches[0].edges
    alts = session.alternatives_to(0, top=50)
    assert alts and all(s.kind == "replacement" for s in alts)
    assert edge_sets(session.patches) == before and not session.undo()  # nothing changed
    rest = [edge_mask(p.edges) for p in session.patches if p.edges != face]
    for s in alts:
        assert s.edges != face and s.edges not in before
        assert _shares_a_curve(s.edges, face)
        # the alternative takes the face's place: the rank is what it was
        assert gf2_rank(rest + [edge_mask(s.edges)], n_edges) == session.full_rank
    assert [s.score for s in alts] == sorted(s.score for s in alts)
    # the same as delete's suggestions kept to the face's curves (another API path)
    by_delete = [s.edges for s in session.delete(0, top=500) if _shares_a_curve(s.edges, face)]
    assert [s.edges for s in alts] == by_delete[:len(alts)]
    # once taken out, the face gets the same alternatives by its edges
    assert [s.edges for s in session.alternatives_to(face, top=50)] == [s.edges for s in alts]


def test_alternatives_to_a_closing_patch_close_the_solid(box):
    # a box's face has no alternative: every other cycle through its curves folds onto a face
    boxed = PatchSession(find_patches(box.network))
    assert all(boxed.alternatives_to(i) == [] for i in range(6))
    session = PatchSession(find_patches(shapes.latlong_sphere().network))  # a closed solid
    face = session.patches[12].edges
    alts = session.alternatives_to(face)
    assert alts and all(s.kind == "closing" for s in alts)
    for s in alts:
        assert _shares_a_curve(s.edges, face) and s.edges != face
        acc = edge_mask(s.edges)
        for j in s.details["solid"]:                 # indexes session.patches, never the face
            assert session.patches[j].edges != face
            acc ^= edge_mask(session.patches[j].edges)
        assert acc == 0
    session.reject(alts[0])
    assert alts[0].edges not in {s.edges for s in session.alternatives_to(face)}
    with pytest.raises(InvalidParameterError):
        session.alternatives_to(99)


def test_reject_and_undo(box):
    session = PatchSession(find_patches(box.network, close="none"))
    first = session.closing_suggestions()[0]
    session.reject(first)
    assert first.edges not in {s.edges for s in session.closing_suggestions()}
    assert session.undo()
    assert session.closing_suggestions()[0].edges == first.edges
    n = len(session.patches)
    session.accept(first)
    assert session.patches[-1].source == "closing"
    assert session.undo() and len(session.patches) == n
    session.delete(0)
    assert session.undo() and len(session.patches) == n
    assert not session.undo()


def test_invalid_actions(box):
    session = PatchSession(find_patches(box.network))
    with pytest.raises(InvalidParameterError):
        session.delete(99)
    with pytest.raises(InvalidParameterError):
        session.delete([0, 1, 2])                 # not a current patch
    with pytest.raises(NetworkError):
        session.accept([0, 1])                    # not a closed loop
    with pytest.raises(InvalidParameterError):
        session.accept(session.patches[0].edges)  # already there
    with pytest.raises(InvalidParameterError):
        PatchSession(find_patches(box.network), backend="magic")
    with pytest.raises(InvalidParameterError):
        PatchSession("patches")


def test_save_roundtrip(tmp_path, box):
    session = PatchSession(find_patches(box.network, close="none"))
    session.accept(session.closing_suggestions()[0])
    path = tmp_path / "p.json"
    session.save(path)
    back = read_patches(path)
    assert edge_sets(back.patches) == true_faces(box)
    assert [p.source for p in back.patches].count("closing") == 1


def test_suggestion_describe():
    s = Suggestion((1, 2, 3), "closing", 104.0, 3, {"a": 5.0, "b": 4, "solid": (0, 1)})
    text = s.describe()
    assert "3 edges" in text and "Ws = 104.0" in text and "[1, 2, 3]" in text


# --------------------------------------------------------------------------- terminal loop
def test_interactive_piped_closing(box):
    out = io.StringIO()
    ps = run_interactive(find_patches(box.network, close="none"),
                         input=io.StringIO("c\na\nq\n"), output=out, backend="bitset")
    assert isinstance(ps, PatchSet)
    assert edge_sets(ps.patches) == true_faces(box)
    assert "closing patch: 4 edges" in out.getvalue()


def test_interactive_delete_reject_then_accept_and_save(tmp_path, two_boxes):
    path = tmp_path / "out.json"
    ps0 = find_patches(two_boxes.network, close="none")
    answers = "d 0\nr\na\nl\nu\nu\ns {}\nq\n".format(path)
    out = io.StringIO()
    ps = run_interactive(ps0, input=io.StringIO(answers), output=out, backend="bitset")
    text = out.getvalue()
    assert "rejected" in text and "accepted" in text and "undone" in text
    # two undos: back to the start (accept and reject undone, the delete kept)
    assert len(ps.patches) == len(ps0.patches) - 1
    assert read_patches(path).patches == ps.patches


def test_interactive_end_of_input_and_bad_commands(box):
    out = io.StringIO()
    ps = run_interactive(find_patches(box.network), input=io.StringIO("x\nd 42\nd\n"),
                         output=out, backend="bitset")
    assert "commands:" in out.getvalue() and "cannot delete" in out.getvalue()
    assert len(ps.patches) == 6


def test_interactive_preview_png(tmp_path, box):
    pytest.importorskip("matplotlib")
    png = tmp_path / "s.png"
    run_interactive(find_patches(box.network, close="none"), input=io.StringIO("c\nn\nq\nq\n"),
                    output=io.StringIO(), preview=png, backend="bitset")
    assert png.is_file() and png.read_bytes()[:4] == b"\x89PNG"


def test_interactive_offers_the_cycles_through_a_rejected_patch(two_boxes):
    # a wrong patch taken out: the first offered are the cycles through its curves that
    # could take its place; a rejected offer is followed by the cycles through its own
    ps0 = find_patches(two_boxes.network, close="none")
    expected = PatchSession(ps0, backend="bitset").alternatives_to(0)
    out = io.StringIO()
    ps = run_interactive(ps0, input=io.StringIO("d 0\nr\na\nq\n"), output=out,
                         backend="bitset")
    text = out.getvalue()
    assert f"#1 {expected[0].describe()}" in text
    first, second = [line for line in text.splitlines() if line.lstrip().startswith("#")][:2]
    rejected = set(expected[0].edges)
    assert "alternatives through its curves next" in text
    accepted = ps.patches[-1].edges
    assert accepted != expected[0].edges and not rejected.isdisjoint(accepted)
    assert str(list(accepted)) in second
