"""Tests of curvenet.view.contact_sheet: the title, captions and tiles are laid out apart."""

from __future__ import annotations

import pytest

from curvenet.core.errors import InvalidParameterError
from curvenet.view.contact_sheet import _sheet, contact_sheet


def _rows(n):
    rows = [dict(input=f"f{i}.obj", output=f"f{i}.obj", status="ok",
                 route=("classical", "hybrid", "neural")[i % 3], fidelity=0.9)
            for i in range(n)]
    rows[min(2, n - 1)] = dict(input="bad.obj", output="bad.obj", status="error",
                               error="no strokes at all in this file")
    return rows


def _overlap(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


@pytest.mark.parametrize("n, title", [(1, None), (5, None), (9, "a title\nof two lines"),
                                      (14, None)])
def test_title_and_captions_do_not_overlap(tmp_path, n, title):
    fig = _sheet(_rows(n), tmp_path, title)         # no tiles on disk: empty frames
    renderer = fig.canvas.get_renderer()
    fig.draw(renderer)
    head = fig._suptitle.get_window_extent(renderer)
    caps = [ax.title.get_window_extent(renderer) for ax in fig.axes]
    frames = [ax.get_window_extent(renderer) for ax in fig.axes]
    for cap, frame in zip(caps, frames):
        assert not _overlap(head, cap) and not _overlap(head, frame)
        assert cap.y0 >= frame.y1 - 1                # each caption above its own tile
    for i, a in enumerate(caps + frames):            # and nothing over anything else
        for j, b in enumerate(caps + frames):
            if i < j and (i, j) not in [(k, k + len(caps)) for k in range(len(caps))]:
                assert not _overlap(a, b)
    assert head.y1 <= fig.bbox.y1                   # inside the picture


def test_contact_sheet_writes_a_png(tmp_path):
    out = contact_sheet(tmp_path / "sheet.png", _rows(3), tmp_path)
    assert out.read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(InvalidParameterError):
        contact_sheet(tmp_path / "none.png", [], tmp_path)
