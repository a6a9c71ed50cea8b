"""Sketch and network file I/O: OBJ polylines, ``.curves`` blocks, plain text, JSON.

Formats
-------
``obj``
    Wavefront OBJ: ``v x y z`` vertices and ``l i1 i2 ... ik`` polylines (any
    number of indices, ``i/t`` index forms, negative indices counted back from
    the last vertex defined so far). Each ``l`` record with three or more
    indices is one stroke. Two-index records (one segment each, as exported by
    Houdini) are chained end to end into strokes; a chain is split at every
    vertex that is not shared by exactly two segments (a junction), so nothing
    is silently dropped or truncated. ``g`` / ``o`` names ``boundary``,
    ``crease`` or ``construction`` (also as a prefix such as ``crease_3``) label
    the strokes that follow; any other name keeps the label ``boundary``.
``curves``
    Blocks ``v n`` followed by ``n`` lines ``x y z`` (CASSIE export).
``txt``
    ``x y z`` per line, a blank line between strokes; ``CURVE i`` header lines
    also start a new stroke (Neveu et al. 2022 data).
``json``
    The project's own format::

        {"format": "curvenet.sketch", "version": 1,
         "strokes": [{"points": [[x, y, z], ...], "label": "boundary"}, ...],
         "metadata": {...}}

In ``curves`` and ``txt`` files a comment line ``# label: crease`` before a
stroke labels it (written by :func:`write_sketch` so labels survive a round
trip); ``#`` starts a comment in every text format.

Errors
------
Every bad input raises :class:`~curvenet.errors.SketchFormatError` naming the
file and, where there is one, the 1-based line: empty file, no strokes,
binary data or non-UTF-8 text, NaN/inf coordinates, an index out of range, an
unknown format, a file larger than ``max_bytes`` (default
:data:`MAX_FILE_BYTES`, 1 GiB). Strokes with fewer than two points are dropped
with a warning (kept in ``sketch.metadata["warnings"]``) when other strokes
remain, and are an error with ``strict=True`` or when nothing remains.

Parsing is vectorised with numpy (one pass of ``str.split`` per line, then a
single array conversion), so a 100 MB OBJ reads in a few seconds.
"""

from __future__ import annotations

import json
import re
import warnings
from pathlib import Path

import numpy as np

from ._atomic import atomic_write_text
from .core.geometry import as_polyline
from .core.strokes import LABELS
from .errors import InvalidParameterError, SketchFormatError
from .network import CurveNetwork, indexed_network
from .sketch import Sketch

__all__ = ["FORMATS", "MAX_FILE_BYTES", "read_sketch", "write_sketch", "write_network_obj",
           "read_network_obj", "detect_format"]

#: Supported format names.
FORMATS = ("obj", "curves", "txt", "json")

#: Largest file :func:`read_sketch` accepts by default (1 GiB); pass ``max_bytes`` to change.
MAX_FILE_BYTES = 1 << 30
_CHUNK_BYTES = 1 << 24

#: Largest coordinate magnitude accepted: squared distances of larger ones overflow float64.
MAX_ABS_COORDINATE = 1e150

_EXTENSIONS = {".obj": "obj", ".curves": "curves", ".txt": "txt", ".xyz": "txt",
               ".json": "json"}
_LABEL_RE = re.compile(r"#\s*label\s*:\s*(\w+)", re.IGNORECASE)


# --------------------------------------------------------------------------- helpers
def _load_text(path, max_bytes: int) -> str:
    """Read ``path`` as UTF-8 text, rejecting empty, huge, binary and non-UTF-8 files.

    The read itself is bounded (in chunks, at most ``max_bytes + 1`` bytes), so a
    device or a pipe (``/dev/zero``, whose ``stat`` size is 0) is refused too.
    """
    p = Path(path)
    if p.is_dir():
        raise SketchFormatError("is a directory, not a sketch file", path=path)
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
    if not data.strip():
        raise SketchFormatError("empty file", path=path)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        raise SketchFormatError("not UTF-8 text", path=path,
                                line=data.count(b"\n", 0, err.start) + 1) from None
    return text


def _floats(rows, line_numbers, path, what="coordinates"):
    """Convert a list of token lists (each >= 3 numbers) into ``(n, 3) float64``.

    Raises with the line of the first malformed or non-finite row.
    """
    if not rows:
        return np.zeros((0, 3))
    lens = np.fromiter(map(len, rows), dtype=np.int64, count=len(rows))
    short = np.flatnonzero(lens < 3)
    if short.size:
        raise SketchFormatError(f"expected 3 {what}, got {lens[short[0]]}", path=path,
                                line=int(line_numbers[short[0]]))
    flat = [t for r in rows for t in r[:3]]
    try:
        arr = np.array(flat, dtype=np.float64).reshape(-1, 3)
    except ValueError:
        for r, ln in zip(rows, line_numbers):
            try:
                [float(t) for t in r[:3]]
            except ValueError:
                raise SketchFormatError(f"bad number in {' '.join(r[:3])!r}", path=path,
                                        line=int(ln)) from None
        raise  # pragma: no cover - unreachable: some row must have failed
    bad = np.flatnonzero(~np.isfinite(arr).all(axis=1))
    if bad.size:
        raise SketchFormatError("NaN or infinite coordinate", path=path,
                                line=int(line_numbers[bad[0]]))
    return arr


def _label_of(name_tokens) -> str | None:
    """Label named by a group/object line (``g crease``, ``o construction_2``), if any."""
    for tok in name_tokens:
        low = tok.lower()
        for lab in LABELS:
            if low == lab or (low.startswith(lab) and not low[len(lab)].isalpha()):
                return lab
    return None


def _finish(strokes, labels, lines, path, strict, metadata=None) -> Sketch:
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


def _split_lines(text):
    """Lines with their first token, skipping comments; returns (tokens, 1-based numbers)."""
    lines = text.splitlines()
    toks = [ln.split() for ln in lines]
    return lines, toks


# --------------------------------------------------------------------------- OBJ
def _parse_obj(text, path):
    """Parse OBJ text into vertices and polylines (fast path, slow path on any anomaly).

    The fast path handles the common layout (``v x y z`` and ``l i j ...`` records
    starting in column 0, integer or ``i/t`` indices) with two C-level
    ``numpy.fromstring`` calls; anything else (extra vertex columns, tabs, a bad
    token, index 0) falls back to :func:`_parse_obj_slow`, which also produces
    the error messages with line numbers.
    """
    lines = text.splitlines()
    v_idx, l_idx, g_idx = [], [], []
    for i, ln in enumerate(lines):
        c = ln[:2]
        if c == "v ":
            v_idx.append(i)
        elif c == "l ":
            l_idx.append(i)
        elif c in ("g ", "o ", "g", "o"):
            g_idx.append(i)
        elif ln and ln[0] not in "#vf" and ln.strip() and not ln.lstrip().startswith("#"):
            if ln.split()[0] in ("v", "l", "g", "o"):
                return _parse_obj_slow(text, path)
        elif c in ("v\t", "l\t"):
            return _parse_obj_slow(text, path)
    if not v_idx or not l_idx:
        return _parse_obj_slow(text, path)
    try:
        verts = np.fromstring("\n".join([lines[i][2:] for i in v_idx]), sep=" ")
        ltext = " 0 ".join([lines[i][2:] for i in l_idx]) + " 0"
        if "/" in ltext:
            ltext = re.sub(r"/\S*", "", ltext)
        flat = np.fromstring(ltext, sep=" ", dtype=np.int64)
    except ValueError:
        return _parse_obj_slow(text, path)
    if verts.size != 3 * len(v_idx) or not np.isfinite(verts).all():
        return _parse_obj_slow(text, path)
    zeros = np.flatnonzero(flat == 0)
    if len(zeros) != len(l_idx):
        return _parse_obj_slow(text, path)
    counts = np.diff(np.concatenate([[-1], zeros])) - 1
    if (counts < 1).any():
        return _parse_obj_slow(text, path)
    idx = flat[flat != 0]
    owner = np.repeat(np.arange(len(l_idx)), counts)
    nv_at = np.searchsorted(np.asarray(v_idx), np.asarray(l_idx))[owner]
    idx = np.where(idx < 0, nv_at + idx, idx - 1)
    if ((idx < 0) | (idx >= nv_at)).any():
        return _parse_obj_slow(text, path)
    labels_at = ["boundary"]
    for i in g_idx:
        lab = _label_of(lines[i].split()[1:])
        labels_at.append(lab if lab is not None else "boundary")
    which = np.searchsorted(np.asarray(g_idx, dtype=np.int64), np.asarray(l_idx))
    polys = np.split(idx, np.cumsum(counts)[:-1])
    return (verts.reshape(-1, 3), polys, [labels_at[w] for w in which.tolist()],
            [i + 1 for i in l_idx])


def _parse_obj_slow(text, path):
    """Parse OBJ text into vertices and polylines, token by token.

    Returns
    -------
    verts : (V, 3) float64
    polys : list of (k,) int64 index arrays (0-based, validated)
    labels : list of str, one per polyline
    poly_lines : list of int, 1-based line of each polyline's ``l`` record
    """
    lines, toks = _split_lines(text)
    v_rows, v_lines, l_rows, l_lines, l_label, l_nverts = [], [], [], [], [], []
    label = "boundary"
    nv = 0
    for i, t in enumerate(toks):
        if not t:
            continue
        head = t[0]
        if head == "v":
            v_rows.append(t[1:])
            v_lines.append(i + 1)
            nv += 1
        elif head == "l":
            l_rows.append(t[1:])
            l_lines.append(i + 1)
            l_label.append(label)
            l_nverts.append(nv)
        elif head in ("g", "o"):
            lab = _label_of(t[1:])
            label = lab if lab is not None else "boundary"
    verts = _floats(v_rows, v_lines, path, "vertex coordinates")
    if not l_rows:
        raise SketchFormatError("no 'l' polyline records" if len(verts) else
                                "no 'v' or 'l' records: not an OBJ polyline file", path=path)
    counts = np.fromiter(map(len, l_rows), dtype=np.int64, count=len(l_rows))
    short = np.flatnonzero(counts < 1)
    if short.size:
        raise SketchFormatError("'l' record without indices", path=path,
                                line=l_lines[short[0]])
    flat = " ".join(" ".join(r) for r in l_rows)
    if "/" in flat:
        flat = re.sub(r"/\S*", "", flat)
    try:
        idx = np.array(flat.split(), dtype=np.int64)
    except ValueError:
        for r, ln in zip(l_rows, l_lines):
            try:
                [int(x.split("/")[0]) for x in r]
            except ValueError:
                raise SketchFormatError(f"bad index in 'l {' '.join(r)}'", path=path,
                                        line=ln) from None
        raise  # pragma: no cover
    owner = np.repeat(np.arange(len(l_rows)), counts)
    nv_at = np.asarray(l_nverts, dtype=np.int64)[owner]
    idx = np.where(idx < 0, nv_at + idx, idx - 1)
    bad = np.flatnonzero((idx < 0) | (idx >= nv_at) | (idx >= len(verts)))
    if bad.size:
        j = owner[bad[0]]
        raise SketchFormatError(f"vertex index out of range (only {nv_at[bad[0]]} vertices "
                                "defined before this line)", path=path, line=l_lines[j])
    polys = np.split(idx, np.cumsum(counts)[:-1])
    return verts, polys, l_label, l_lines


def _chain_segments(polys, labels, lines, nverts):
    """Join chains of two-index segments end to end; keep longer polylines as they are.

    A vertex where exactly two segment ends meet (and that no longer polyline
    uses) is a chain point; every other vertex ends a chain (junction, free
    end, or a point of a longer polyline). Closed chains come back closed (first
    index repeated at the end). Returns (polys, labels, lines), chains in the
    order of their first segment in the file.
    """
    seg_ids = [i for i, p in enumerate(polys) if len(p) == 2 and p[0] != p[1]]
    if len(seg_ids) < 2:
        return polys, labels, lines
    seg = np.array([polys[i] for i in seg_ids], dtype=np.int64)  # (S, 2)
    deg = np.bincount(seg.ravel(), minlength=nverts)
    other = [p for i, p in enumerate(polys) if not (len(p) == 2 and p[0] != p[1])]
    used_elsewhere = np.zeros(nverts, dtype=bool)
    if other:
        used_elsewhere[np.concatenate(other)] = True
    # adjacency: for each vertex the (up to two) incident segments
    order = np.argsort(seg.ravel(), kind="stable")
    ends_v = seg.ravel()[order]
    ends_s = order // 2
    start = np.searchsorted(ends_v, np.arange(nverts))
    through = (deg == 2) & ~used_elsewhere
    label_of_seg = [labels[i] for i in seg_ids]
    line_of_seg = [lines[i] for i in seg_ids]
    visited = np.zeros(len(seg), dtype=bool)
    chains = []  # (first segment id, index list, label, line)

    def other_seg(v, s):
        a, b = ends_s[start[v]], ends_s[start[v] + 1]
        return b if a == s else a

    def walk(s, v):
        """Extend from segment s beyond its end vertex v while v is a chain point."""
        out = []
        while through[v]:
            s = other_seg(v, s)
            if visited[s] or label_of_seg[s] != cur_label:
                break
            visited[s] = True
            v = seg[s, 1] if seg[s, 0] == v else seg[s, 0]
            out.append(v)
        return out

    for s0 in range(len(seg)):
        if visited[s0]:
            continue
        visited[s0] = True
        cur_label = label_of_seg[s0]
        a, b = seg[s0]
        fwd = walk(s0, b)
        back = walk(s0, a)
        chain = back[::-1] + [a, b] + fwd
        chains.append((seg_ids[s0], np.asarray(chain, dtype=np.int64), cur_label,
                       line_of_seg[s0]))
    keep = [(i, p, labels[i], lines[i]) for i, p in enumerate(polys)
            if not (len(p) == 2 and p[0] != p[1])]
    allp = sorted(keep + chains, key=lambda t: t[0])
    return [t[1] for t in allp], [t[2] for t in allp], [t[3] for t in allp]


def _read_obj(text, path, strict):
    verts, polys, labels, lines = _parse_obj(text, path)
    polys, labels, lines = _chain_segments(polys, labels, lines, len(verts))
    return _finish([verts[p] for p in polys], labels, lines, path, strict)


# --------------------------------------------------------------------------- curves / txt
def _read_blocks(text, path, strict, fmt):
    """Shared reader for ``curves`` (``v n`` headers) and ``txt`` (blank line / CURVE)."""
    lines, toks = _split_lines(text)
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
    pts = _floats(rows, row_lines, path)
    sid = np.asarray(row_stroke, dtype=np.int64)
    counts = np.bincount(sid, minlength=len(starts))
    strokes = np.split(pts, np.cumsum(counts)[:-1])
    return _finish(strokes, labels, starts, path, strict)


# --------------------------------------------------------------------------- JSON
def _read_json(text, path, strict):
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
        try:  # short strokes are dropped (or rejected) by _finish, naming the file
            arr = as_polyline(pts, name=f"strokes[{i}]", min_points=0)
        except InvalidParameterError as err:
            raise SketchFormatError(str(err), path=path) from None
        strokes.append(arr)
        labels.append(lab)
        where.append(None)
    meta = data.get("metadata", {})
    if not isinstance(meta, dict):
        raise SketchFormatError("\"metadata\" must be an object", path=path)
    return _finish(strokes, labels, where, path, strict, meta)


# --------------------------------------------------------------------------- public
def detect_format(path, text: str | None = None) -> str:
    """Format name for ``path``: by extension, else by sniffing the content.

    Raises
    ------
    SketchFormatError
        The content matches none of :data:`FORMATS`.
    """
    ext = Path(path).suffix.lower()
    if ext in _EXTENSIONS:
        return _EXTENSIONS[ext]
    if text is None:
        text = _load_text(path, MAX_FILE_BYTES)
    first = None
    heads = set()
    for ln in text.splitlines()[:2000]:
        t = ln.split()
        if not t or t[0].startswith("#"):
            continue
        if first is None:
            first = t
        heads.add(t[0])
    if first is None:
        raise SketchFormatError("no content to recognise", path=path)
    if first[0].startswith("{"):
        return "json"
    if "l" in heads and "v" in heads:
        return "obj"
    if first[0] == "v" and len(first) == 2:
        return "curves"
    if first[0].upper() == "CURVE":
        return "txt"
    if len(first) >= 3:
        try:
            [float(x) for x in first[:3]]
            return "txt"
        except ValueError:
            pass
    raise SketchFormatError(f"unknown sketch format (extension {ext or 'none'!r}); use one of "
                            f"{', '.join(FORMATS)} or pass format=", path=path)


def read_sketch(path, *, format: str | None = None, strict: bool = False,
                max_bytes: int = MAX_FILE_BYTES, points="auto") -> Sketch:
    """Read a sketch file.

    Parameters
    ----------
    path : str or os.PathLike
    format : {'obj', 'curves', 'txt', 'json'}, optional
        Defaults to the extension (``.obj``, ``.curves``, ``.txt``/``.xyz``,
        ``.json``); other extensions are recognised by content.
    strict : bool
        Raise on a stroke with fewer than two points instead of dropping it.
    max_bytes : int
        Refuse larger files (default :data:`MAX_FILE_BYTES`, 1 GiB).
    points : {"auto", True, False}
        Blocks of unordered point samples (consecutive points far apart):
        ``auto`` detects them block by block and recovers the curves they
        sample, ``True`` reads every block so, ``False`` never (see
        :func:`curvenet.pointcurves.read_point_blocks`).

    Returns
    -------
    Sketch
        Strokes ``(n_i, 3) float64`` in file order, labels, ``source = str(path)``;
        where blocks were read as point samples, ``metadata["reading"]`` says so and why.

    Raises
    ------
    SketchFormatError
        Any malformed input; the message names the file and line.

    Notes
    -----
    See the module docstring for each format. OBJ strokes come in the order of
    their ``l`` records (a chain of segments at the position of its first
    segment).

    Examples
    --------
    >>> import tempfile, os
    >>> p = os.path.join(tempfile.mkdtemp(), "s.obj")
    >>> _ = open(p, "w").write("v 0 0 0\\nv 1 0 0\\nv 1 1 0\\ng crease\\nl 1 2\\nl 2 3\\n")
    >>> sk = read_sketch(p)
    >>> len(sk), sk.labels, sk.strokes[0].shape
    (1, ['crease'], (3, 3))
    """
    if format is not None and format not in FORMATS:
        raise SketchFormatError(f"unknown format {format!r}; use one of {FORMATS}", path=path)
    text = _load_text(path, max_bytes)
    fmt = format or detect_format(path, text)
    if fmt == "obj":
        sketch = _read_obj(text, path, strict)
    elif fmt == "json":
        sketch = _read_json(text, path, strict)
    else:
        sketch = _read_blocks(text, path, strict, fmt)
    from .pointcurves import read_point_blocks
    return read_point_blocks(sketch, points)


def _fmt_points(arr) -> list:
    """Rows ``'x y z'`` with 17 significant digits (exact float64 round trip)."""
    return [" ".join(map(repr, row)) for row in np.asarray(arr, dtype=np.float64).tolist()]


def _sketch_text(sketch: Sketch, fmt: str) -> str:
    out = []
    if fmt == "json":
        data = {"format": "curvenet.sketch", "version": 1,
                "strokes": [{"points": s.tolist(), "label": lab}
                            for s, lab in zip(sketch.strokes, sketch.labels)],
                "metadata": sketch.metadata}
        return json.dumps(data) + "\n"
    if fmt == "obj":
        out.append("# curvenet sketch: one 'l' polyline per stroke, groups name labels")
        offset = 1
        body = []
        current = None
        for s, lab in zip(sketch.strokes, sketch.labels):
            out.extend("v " + r for r in _fmt_points(s))
            if lab != current:
                body.append(f"g {lab}")
                current = lab
            body.append("l " + " ".join(map(str, range(offset, offset + len(s)))))
            offset += len(s)
        out.extend(body)
    elif fmt == "curves":
        for s, lab in zip(sketch.strokes, sketch.labels):
            out.append(f"# label: {lab}")
            out.append(f"v {len(s)}")
            out.extend(_fmt_points(s))
    else:  # txt
        for i, (s, lab) in enumerate(zip(sketch.strokes, sketch.labels)):
            if i:
                out.append("")
            out.append(f"# label: {lab}")
            out.extend(_fmt_points(s))
    return "\n".join(out) + "\n"


def write_sketch(path, sketch: Sketch, *, format: str | None = None) -> None:
    """Write a sketch atomically in one of :data:`FORMATS`.

    Parameters
    ----------
    path : str or os.PathLike
    sketch : Sketch
    format : {'obj', 'curves', 'txt', 'json'}, optional
        Defaults to the extension; ``obj`` when the extension is unknown.

    Notes
    -----
    Coordinates are written with 17 significant digits, so reading the file
    back gives bit-identical strokes and the same labels (``curves`` and
    ``txt`` carry labels in ``# label: ...`` comment lines). OBJ strokes are
    one ``l`` record each (never two-index segments, so no chaining applies
    on reading back, except for two-point strokes, which stay separate unless
    they share vertex indices, and they never do: every stroke has its own
    vertices).
    """
    fmt = format or _EXTENSIONS.get(Path(path).suffix.lower(), "obj")
    if fmt not in FORMATS:
        raise SketchFormatError(f"unknown format {fmt!r}; use one of {FORMATS}", path=path)
    atomic_write_text(path, _sketch_text(sketch, fmt))


def write_network_obj(path, network: CurveNetwork) -> None:
    """Write a curve network as OBJ polylines sharing junction vertices (atomic).

    The first ``V`` OBJ vertices are the network's vertices (in order), followed
    by the interior points of each curve; each edge is one ``l`` record from its
    ``u`` to its ``v`` index (a loop edge starts and ends at the same index).
    Edges are grouped ``g boundary`` / ``g crease``. :func:`read_network_obj`
    gives back the same graph (isolated vertices aside).
    """
    out = ["# curvenet network: first V vertices are junctions, one 'l' per edge"]
    out.extend("v " + r for r in _fmt_points(network.positions))
    nxt = network.number_of_vertices + 1
    body = []
    current = None
    for e in network.edges:
        inner = e.curve[1:-1]
        out.extend("v " + r for r in _fmt_points(inner))
        ids = [e.u + 1, *range(nxt, nxt + len(inner)), e.v + 1]
        nxt += len(inner)
        if e.label != current:
            body.append(f"g {e.label}")
            current = e.label
        body.append("l " + " ".join(map(str, ids)))
    out.extend(body)
    atomic_write_text(path, "\n".join(out) + "\n")


def read_network_obj(path, *, max_bytes: int = MAX_FILE_BYTES) -> CurveNetwork:
    """Read a clean curve network from OBJ polylines that share junction vertices.

    Parameters
    ----------
    path : str or os.PathLike
    max_bytes : int

    Returns
    -------
    CurveNetwork
        Vertices: every OBJ vertex that ends a polyline, is used by two or more
        polylines (or twice by one), or where three or more segments meet;
        numbered in order of OBJ index (the vertex of a loop with no
        other vertex on it is appended after those). Edges: the polyline pieces between
        consecutive vertices, in file order; a closed polyline with no other
        vertex on it becomes a loop edge (``u == v``). ``edge.strokes`` holds
        the index of the source polyline (after chaining two-index segments as
        :func:`read_sketch` does); ``report`` has ``{"polylines": n}``.

    Notes
    -----
    This is the exact graph of the file, with no tolerance: it is the oracle
    :func:`curvenet.snap.snap` is checked against on clean networks.
    """
    text = _load_text(path, max_bytes)
    verts, polys, labels, lines = _parse_obj(text, path)
    polys, labels, lines = _chain_segments(polys, labels, lines, len(verts))
    polys = [p for p in polys if len(p) >= 2]
    if not polys:
        raise SketchFormatError("no polylines with two or more points", path=path)
    net = indexed_network(verts, polys, labels, range(len(polys)))
    net.report = {"polylines": len(polys), "source": str(path)}
    return net
