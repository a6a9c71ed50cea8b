"""Reading the text formats: ``curves`` blocks, plain ``txt`` points, and the project's JSON.

See :mod:`curvenet.io` for the formats (``# label:`` comments, JSON schema) and errors.
"""

from __future__ import annotations

import io
import json
import re

import numpy as np

from .common import finish_sketch, nonfinite_error, parse_rows
from ..core.geometry import as_polyline
from ..core.strokes import LABELS
from ..core.errors import InvalidParameterError, SketchFormatError

__all__ = ["read_blocks", "read_json"]

#: A comment line ``# label: crease`` labels the stroke that follows it.
_LABEL_RE = re.compile(r"#\s*label\s*:\s*(\w+)", re.IGNORECASE)


def read_blocks(text, path, strict, fmt):
    """Shared reader for ``curves`` (``v n`` headers) and ``txt`` (blank line / CURVE).

    The text is read in pieces of whole lines (about :data:`_PIECE_CHARS` characters).
    In a piece of plain ASCII, the lines of coordinates are found with numpy on its
    bytes and parsed in one ``numpy.loadtxt`` call; only the other lines (comments,
    headers, blank lines that end a block) are looked at one by one. A piece the
    vectorised reading does not cover exactly (a bad number, a short row, other
    line breaks or non-ASCII text) is read token by token. Either way the temporary
    memory is bounded by the piece, and the errors are those of a token-by-token
    reading of the whole file (:func:`curvenet.io.common.parse_rows`).
    """
    blocks = _Blocks(path, fmt)
    for piece in _pieces(text, _PIECE_CHARS):
        if not blocks.fast_piece(piece):
            blocks.slow_piece(piece)
    return blocks.finish(strict)


#: Characters per piece of :func:`read_blocks` (whole lines; bounds its temporary memory).
_PIECE_CHARS = 1 << 18
#: Bytes the vectorised reading treats as blanks inside a line.
_BLANK = np.zeros(256, dtype=bool)
_BLANK[[ord(" "), ord("\t"), ord("\r")]] = True
#: First bytes of a line of coordinates.
_NUMBER = np.zeros(256, dtype=bool)
_NUMBER[list(b"0123456789+-.")] = True
#: Bytes that ``str.split``/``str.splitlines`` treat as blanks or line breaks and the
#: vectorised reading does not (pieces with them are read token by token).
_ODD = np.zeros(256, dtype=bool)
_ODD[[0x0B, 0x0C, 0x1C, 0x1D, 0x1E, 0x1F]] = True


def _pieces(text, size):
    """Consecutive slices of ``text`` of at least ``size`` characters, ending at a newline."""
    pos = 0
    while pos < len(text):
        end = text.find("\n", pos + size)
        end = len(text) if end < 0 else end + 1
        yield text[pos:end]
        pos = end


class _Blocks:
    """The state of reading ``curves``/``txt`` blocks: strokes so far and the open block."""

    def __init__(self, path, fmt):
        self.path, self.fmt = path, fmt
        self.starts, self.labels, self.counts = [], [], []  # per stroke
        self.pending_label = None
        self.expect = None  # curves: points still expected in the current block
        self.open_block = False
        self.arrays = []  # coordinates, in file order
        self.error = None  # the coordinate error to raise: smallest (rank, line, error)
        self.lines = 0  # lines read so far

    def kind(self, toks):
        """'blank', 'comment', 'header' or 'row' for a line's tokens."""
        if not toks:
            return "blank"
        if toks[0].startswith("#"):
            return "comment"
        head = toks[0] if self.fmt == "curves" else toks[0].upper()
        return "header" if head == ("v" if self.fmt == "curves" else "CURVE") else "row"

    def rows(self, lines):
        """Give the coordinate rows on ``lines`` (1-based, increasing) to the open block."""
        if self.fmt == "curves":
            if not self.expect or len(lines) > self.expect:
                raise SketchFormatError("point outside a 'v <count>' block", path=self.path,
                                        line=int(lines[self.expect or 0]))
            self.expect -= len(lines)
        elif not self.open_block:
            self._start(int(lines[0]))
            self.open_block = True
        self.counts[-1] += len(lines)

    def _start(self, ln):
        self.starts.append(ln)
        self.labels.append(self.pending_label or "boundary")
        self.pending_label = None
        self.counts.append(0)

    def line(self, ln, line, toks):
        """Read one line; returns whether it is a coordinate row (its values are not read)."""
        kind = self.kind(toks)
        if kind == "blank":
            if self.fmt == "txt":
                self.open_block = False
        elif kind == "comment":
            m = _LABEL_RE.match(line.strip())
            if m:
                lab = m.group(1).lower()
                if lab not in LABELS:
                    raise SketchFormatError(f"unknown label {lab!r}", path=self.path, line=ln)
                self.pending_label = lab
        elif kind == "header" and self.fmt == "txt":
            self.open_block = False
        elif kind == "header":
            if self.expect:
                raise SketchFormatError(f"block ended {self.expect} point(s) early",
                                        path=self.path, line=ln)
            try:
                self.expect = int(toks[1])
            except (IndexError, ValueError):
                raise SketchFormatError("expected 'v <count>'", path=self.path,
                                        line=ln) from None
            if self.expect < 0:
                raise SketchFormatError(f"negative point count {self.expect}", path=self.path,
                                        line=ln)
            self._start(ln)
        else:
            self.rows([ln])
        return kind == "row"

    def _values(self, arr, err):
        if err is not None and (self.error is None or err[:2] < self.error[:2]):
            self.error = err
        if self.error is None:
            self.arrays.append(arr)

    def slow_piece(self, piece):
        """Read a piece line by line, its coordinates token by token."""
        rows, row_lines = [], []
        lines = piece.splitlines()
        for i, line in enumerate(lines):
            toks = line.split()
            if self.line(self.lines + i + 1, line, toks):
                rows.append(toks)
                row_lines.append(self.lines + i + 1)
        self.lines += len(lines)
        self._values(*parse_rows(rows, row_lines, self.path))

    def fast_piece(self, piece):
        """Read a piece with vectorised coordinate lines; False (nothing read) if it has
        lines that only the token-by-token reading reads exactly."""
        if not piece.isascii():
            return False
        raw = piece.encode("ascii") + (b"" if piece.endswith("\n") else b"\n")
        b = np.frombuffer(raw, dtype=np.uint8)
        cr = np.flatnonzero(b == 13)
        if _ODD[b].any() or (b[cr + 1] != 10).any():  # \r only in \r\n
            return False
        ends = np.flatnonzero(b == 10)
        starts = np.concatenate([[0], ends[:-1] + 1])
        ink = np.flatnonzero(~_BLANK[b])  # includes the newlines
        head = b[ink[np.searchsorted(ink, starts)]]  # first non-blank byte of each line
        num = _NUMBER[head]
        other = np.flatnonzero(~num & ((head != 10) | (self.fmt == "txt")))
        texts = [raw[starts[i]:ends[i]].decode("ascii") for i in other.tolist()]
        toks = [t.split() for t in texts]
        if any(self.kind(t) == "row" for t in toks):
            return False
        vals = np.zeros((0, 3))
        if num.any():
            keep = np.repeat(num, ends - starts + 1)
            try:
                vals = np.loadtxt(io.BytesIO(b[keep].tobytes()), dtype=np.float64,
                                  comments=None, usecols=(0, 1, 2), ndmin=2)
            except ValueError:
                return False
        rows = np.flatnonzero(num) + self.lines + 1  # 1-based lines of the coordinates
        if len(vals) != len(rows):
            return False
        cut = np.searchsorted(rows, other + self.lines + 1)
        prev = 0
        for i, c, text, t in zip(other.tolist(), cut.tolist(), texts, toks):
            if c > prev:
                self.rows(rows[prev:c])
            prev = c
            self.line(self.lines + i + 1, text, t)
        if prev < len(rows):
            self.rows(rows[prev:])
        self.lines += len(ends)
        self._values(vals, nonfinite_error(vals, rows, self.path))
        return True

    def finish(self, strict):
        """The sketch, or the first error a token-by-token reading would raise."""
        if self.fmt == "curves" and self.expect:
            raise SketchFormatError(f"file ends {self.expect} point(s) short of the last block",
                                    path=self.path, line=self.lines)
        if not self.starts:
            raise SketchFormatError("no strokes", path=self.path)
        if self.error is not None:
            raise self.error[2]
        pts = np.concatenate(self.arrays) if len(self.arrays) != 1 else self.arrays[0]
        self.arrays = []  # the one copy left is pts
        strokes = np.split(pts, np.cumsum(self.counts)[:-1])
        return finish_sketch(strokes, self.labels, self.starts, self.path, strict)


def read_json(text, path, strict):
    """Read the project's ``curvenet.model.sketch`` JSON (see :mod:`curvenet.io`)."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as err:
        raise SketchFormatError(f"invalid JSON: {err.msg}", path=path, line=err.lineno) from None
    except RecursionError:
        raise SketchFormatError("invalid JSON: nested too deeply", path=path) from None
    except ValueError as err:  # e.g. an integer literal longer than Python's digit limit
        raise SketchFormatError(f"invalid JSON: {err}", path=path) from None
    if not isinstance(data, dict) or data.get("format") != "curvenet.sketch":
        raise SketchFormatError("not a curvenet.model.sketch JSON file (missing "
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
