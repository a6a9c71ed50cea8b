"""Reading the text formats: ``curves`` blocks, plain ``txt`` points, and the project's JSON.

See :mod:`curvenet.io` for the formats (``# label:`` comments, JSON schema) and errors.
"""

from __future__ import annotations

import json
import re

import numpy as np

from ._io_common import finish_sketch, split_lines, xyz_rows
from .core.geometry import as_polyline
from .core.strokes import LABELS
from .errors import InvalidParameterError, SketchFormatError

__all__ = ["read_blocks", "read_json"]

#: A comment line ``# label: crease`` labels the stroke that follows it.
_LABEL_RE = re.compile(r"#\s*label\s*:\s*(\w+)", re.IGNORECASE)


def read_blocks(text, path, strict, fmt):
    """Shared reader for ``curves`` (``v n`` headers) and ``txt`` (blank line / CURVE)."""
    lines, toks = split_lines(text)
    rows, row_lines, row_stroke = [], [], []
    starts, labels = [], []  # per stroke: first line, label
    pending_label = None
    expect = None  # curves: points still expected in the current block
    open_block = False
    for i, t in enumerate(toks):
        ln = i + 1
        if not t:
            if fmt == "txt":
                open_block = False
            continue
        if t[0].startswith("#"):
            m = _LABEL_RE.match(lines[i].strip())
            if m:
                lab = m.group(1).lower()
                if lab not in LABELS:
                    raise SketchFormatError(f"unknown label {lab!r}", path=path, line=ln)
                pending_label = lab
            continue
        if fmt == "curves":
            if t[0] == "v":
                if expect:
                    raise SketchFormatError(f"block ended {expect} point(s) early", path=path,
                                            line=ln)
                try:
                    expect = int(t[1])
                except (IndexError, ValueError):
                    raise SketchFormatError("expected 'v <count>'", path=path,
                                            line=ln) from None
                if expect < 0:
                    raise SketchFormatError(f"negative point count {expect}", path=path, line=ln)
                starts.append(ln)
                labels.append(pending_label or "boundary")
                pending_label = None
                continue
            if not expect:
                raise SketchFormatError("point outside a 'v <count>' block", path=path,
                                        line=ln)
            expect -= 1
        else:
            if t[0].upper() == "CURVE":
                open_block = False
                continue
            if not open_block:
                starts.append(ln)
                labels.append(pending_label or "boundary")
                pending_label = None
                open_block = True
        rows.append(t)
        row_lines.append(ln)
        row_stroke.append(len(starts) - 1)
    if fmt == "curves" and expect:
        raise SketchFormatError(f"file ends {expect} point(s) short of the last block",
                                path=path, line=len(lines))
    if not starts:
        raise SketchFormatError("no strokes", path=path)
    pts = xyz_rows(rows, row_lines, path)
    sid = np.asarray(row_stroke, dtype=np.int64)
    counts = np.bincount(sid, minlength=len(starts))
    strokes = np.split(pts, np.cumsum(counts)[:-1])
    return finish_sketch(strokes, labels, starts, path, strict)


def read_json(text, path, strict):
    """Read the project's ``curvenet.sketch`` JSON (see :mod:`curvenet.io`)."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as err:
        raise SketchFormatError(f"invalid JSON: {err.msg}", path=path, line=err.lineno) from None
    except RecursionError:
        raise SketchFormatError("invalid JSON: nested too deeply", path=path) from None
    except ValueError as err:  # e.g. an integer literal longer than Python's digit limit
        raise SketchFormatError(f"invalid JSON: {err}", path=path) from None
    if not isinstance(data, dict) or data.get("format") != "curvenet.sketch":
        raise SketchFormatError("not a curvenet.sketch JSON file (missing "
                                "\"format\": \"curvenet.sketch\")", path=path)
    if data.get("version", 1) != 1:
        raise SketchFormatError(f"unsupported version {data.get('version')!r}", path=path)
    raw = data.get("strokes")
    if not isinstance(raw, list):
        raise SketchFormatError("\"strokes\" must be a list", path=path)
    strokes, labels, where = [], [], []
    for i, s in enumerate(raw):
        pts = s.get("points") if isinstance(s, dict) else s
        lab = s.get("label", "boundary") if isinstance(s, dict) else "boundary"
        if lab not in LABELS:
            raise SketchFormatError(f"strokes[{i}]: unknown label {lab!r}", path=path)
        try:  # short strokes are dropped (or rejected) by finish_sketch, naming the file
            arr = as_polyline(pts, name=f"strokes[{i}]", min_points=0)
        except InvalidParameterError as err:
            raise SketchFormatError(str(err), path=path) from None
        strokes.append(arr)
        labels.append(lab)
        where.append(None)
    meta = data.get("metadata", {})
    if not isinstance(meta, dict):
        raise SketchFormatError("\"metadata\" must be an object", path=path)
    return finish_sketch(strokes, labels, where, path, strict, meta)
