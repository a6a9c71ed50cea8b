"""Shared pieces of the sketch readers: guarded file loading, coordinate rows, labels.

Used by the per-format readers (:mod:`curvenet.io.obj`, :mod:`curvenet.io.text`)
and by :mod:`curvenet.io`, which documents the formats and their errors.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..core.strokes import LABELS
from ..core.errors import SketchFormatError
from ..model.sketch import Sketch

__all__ = ["load_text", "require_file", "xyz_rows", "parse_rows", "nonfinite_error",
           "label_of", "finish_sketch", "split_lines", "MAX_ABS_COORDINATE"]

#: Files are read in chunks of this many bytes (the read stops past ``max_bytes``).
_CHUNK_BYTES = 1 << 20
#: Largest coordinate magnitude accepted: squared distances of larger ones overflow float64.
MAX_ABS_COORDINATE = 1e150


def require_file(path) -> Path:
    """``path`` as a ``Path`` when it is a file; else one line saying what it is instead.

    Raises
    ------
    SketchFormatError
        No such file, a folder, or a symbolic link that leads nowhere (a loop of links,
        or a missing target).
    """
    p = Path(path)
    if p.is_file():
        return p
    if p.is_dir():
        raise SketchFormatError("is a directory, not a file", path=path)
    if p.is_symlink():
        raise SketchFormatError("a symbolic link that leads nowhere (a loop of links, or "
                                "its target is missing)", path=path)
    raise SketchFormatError("no such file", path=path)


def load_text(path, max_bytes: int) -> str:
    """Read ``path`` as UTF-8 text, rejecting empty, huge, binary and non-UTF-8 files.

    The read itself is bounded (in chunks, at most ``max_bytes + 1`` bytes), so a
    device or a pipe (``/dev/zero``, whose ``stat`` size is 0) is refused too.
    """
    p = Path(path)
    if p.is_dir():
        raise SketchFormatError("is a directory, not a sketch file", path=path)
    if p.is_symlink() and not p.exists():
        require_file(p)
    chunks, total = [], 0
    try:
        with open(p, "rb") as fh:
            while total <= max_bytes:
                chunk = fh.read(min(_CHUNK_BYTES, max_bytes + 1 - total))
                if not chunk:
                    break
                nul = chunk.find(b"\x00")
                if nul >= 0:
                    line = sum(c.count(b"\n") for c in chunks) + chunk.count(b"\n", 0, nul) + 1
                    raise SketchFormatError("binary data (NUL byte), not a text sketch",
                                            path=path, line=line)
                chunks.append(chunk)
                total += len(chunk)
    except OSError as err:
        raise SketchFormatError(f"cannot read file: {err.strerror or err}", path=path) from None
    if total > max_bytes:
        raise SketchFormatError(f"file is larger than the limit of {max_bytes} bytes "
                                "(pass max_bytes= to raise it)", path=path)
    data = b"".join(chunks)
    del chunks  # the joined copy replaces them: at most two copies of the file at once
    if not data or data.isspace():  # (bytes.strip() would copy the whole file)
        raise SketchFormatError("empty file", path=path)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise SketchFormatError("not UTF-8 text", path=path,
                                line=data.count(b"\n", 0, err.start) + 1) from None


def xyz_rows(rows, line_numbers, path, what="coordinates"):
    """Convert a list of token lists (each >= 3 numbers) into ``(n, 3) float64``.

    Raises with the line of the first malformed or non-finite row (see :func:`parse_rows`).
    """
    arr, err = parse_rows(rows, line_numbers, path, what)
    if err is not None:
        raise err[2]
    return arr


def parse_rows(rows, line_numbers, path, what="coordinates"):
    """Convert token lists (the first three of each are used) into ``(n, 3) float64``.

    Returns
    -------
    (arr, None) or (None, (rank, line, SketchFormatError))
        The error is the first row with fewer than three tokens (rank 0), else the
        first with a token that is not a number (rank 1), else the first with a NaN
        or infinite value (rank 2); a reader that parses in pieces keeps the error
        of the smallest ``(rank, line)``, which is the one a single pass would give.
    """
    if not rows:
        return np.zeros((0, 3)), None
    lens = np.fromiter(map(len, rows), dtype=np.int64, count=len(rows))
    short = np.flatnonzero(lens < 3)
    if short.size:
        ln = int(line_numbers[short[0]])
        return None, (0, ln, SketchFormatError(f"expected 3 {what}, got {lens[short[0]]}",
                                               path=path, line=ln))
    flat = [t for r in rows for t in r[:3]]
    try:
        arr = np.array(flat, dtype=np.float64).reshape(-1, 3)
    except ValueError:
        for r, ln in zip(rows, line_numbers):
            try:
                [float(t) for t in r[:3]]
            except ValueError:
                return None, (1, int(ln), SketchFormatError(
                    f"bad number in {' '.join(r[:3])!r}", path=path, line=int(ln)))
        raise  # pragma: no cover - unreachable: some row must have failed
    err = nonfinite_error(arr, line_numbers, path)
    return (arr, None) if err is None else (None, err)


def nonfinite_error(arr, line_numbers, path):
    """``(2, line, SketchFormatError)`` for the first row of ``arr`` with a NaN or inf, or None."""
    bad = np.flatnonzero(~np.isfinite(arr).all(axis=1))
    if not bad.size:
        return None
    ln = int(line_numbers[bad[0]])
    return 2, ln, SketchFormatError("NaN or infinite coordinate", path=path, line=ln)


def label_of(name_tokens) -> str | None:
    """Label named by a group/object line (``g crease``, ``o construction_2``), if any."""
    for tok in name_tokens:
        low = tok.lower()
        for lab in LABELS:
            if low == lab or (low.startswith(lab) and not low[len(lab)].isalpha()):
                return lab
    return None


def finish_sketch(strokes, labels, lines, path, strict, metadata=None) -> Sketch:
    """Drop (or reject) strokes with fewer than two points and build the Sketch."""
    keep_s, keep_l, warns = [], [], []
    for i, (s, lab, ln) in enumerate(zip(strokes, labels, lines)):
        if len(s) < 2:
            where = f"strokes[{i}]" if ln is None else f"stroke starting at line {ln}"
            msg = f"{where} has {len(s)} point(s); a stroke needs 2"
            if strict:
                raise SketchFormatError(msg, path=path, line=ln)
            warns.append(msg)
            continue
        keep_s.append(s)
        keep_l.append(lab)
    if not keep_s:
        raise SketchFormatError("no strokes with at least two points" if warns else
                                "no strokes", path=path)
    big = max(float(np.abs(s).max()) for s in keep_s)
    if big > MAX_ABS_COORDINATE:
        raise SketchFormatError(f"coordinates up to {big:.3g} in size: lengths would overflow "
                                f"(the limit is {MAX_ABS_COORDINATE:.0e}; rescale the sketch)",
                                path=path)
    if warns:
        more = f" and {len(warns) - 1} more" if len(warns) > 1 else ""
        warnings.warn(f"{path}: {warns[0]}{more} (dropped)", stacklevel=3)
    meta = dict(metadata or {})
    if warns:
        meta.setdefault("warnings", []).extend(warns)
    return Sketch(keep_s, keep_l, meta, None if path is None else str(path))


def split_lines(text):
    """The text's lines and the tokens of each (``str.split``), comments included."""
    lines = text.splitlines()
    toks = [ln.split() for ln in lines]
    return lines, toks
