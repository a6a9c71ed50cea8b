"""Reading Wavefront OBJ polylines: a vectorised parser, its token-by-token fallback,
and the chaining of two-index segments into strokes.

See :mod:`curvenet.io` for the format (``v``, ``l``, ``g``/``o`` labels) and errors.
"""

from __future__ import annotations

import re

import numpy as np

from .common import finish_sketch, label_of, split_lines, xyz_rows
from ..core.errors import SketchFormatError

__all__ = ["parse_obj", "parse_obj_slow", "chain_segments", "read_obj"]


#: Characters that :meth:`str.splitlines` breaks lines at, besides ``\n`` and ``\r\n``
#: (ASCII ones; a text with any of them, or with non-ASCII characters, takes the
#: token-by-token parser).
_OTHER_BREAKS = "\r\x0b\x0c\x1c\x1d\x1e"


def _line_kinds(text):
    """The text's bytes, each line ended by ``\n``, and per line its start offset, its
    length with the ``\n`` and its first two characters, for an ASCII text whose only line
    break is ``\n``: ``(b, start, span, c0, c1)``, uint8 bytes and codes (0 past a line's
    end), int64 offsets, one per :meth:`str.splitlines` line."""
    b = np.frombuffer((text if text.endswith("\n") or not text else text + "\n")
                      .encode("ascii"), np.uint8)
    nl = np.flatnonzero(b == 10)
    start = np.concatenate([[0], nl[:-1] + 1]).astype(np.int64)
    span = nl + 1 - start
    c0 = np.where(span > 1, b[start], 0)                 # every line ends in b: in range
    c1 = np.where(span > 2, b[np.minimum(start + 1, len(b) - 1)], 0)
    return b, start, span, c0, c1


def _bodies(b, start, span, lines, sep):
    """The text of ``lines`` (line numbers) after their first two characters, each followed
    by ``sep``."""
    chosen = np.zeros(len(start), bool)
    chosen[lines] = True
    keep = np.repeat(chosen, span)
    keep[start[lines]] = keep[start[lines] + 1] = False
    return b[keep].tobytes().decode("ascii").replace("\n", sep)


def parse_obj(text, path):
    """Parse OBJ text into vertices and polylines (fast path, slow path on any anomaly).

    The fast path handles the common layout (ASCII, ``\n`` or ``\r\n`` line ends,
    ``v x y z`` and ``l i j ...`` records starting in column 0, integer or ``i/t``
    indices): the lines are told apart from their first two bytes, all at once, and
    read with two C-level ``numpy.fromstring`` calls; anything else (extra vertex
    columns, tabs, an indented record, a bad token, index 0) falls back to
    :func:`parse_obj_slow`, which also produces the error messages with line numbers.
    """
    if "\r" in text:
        text = text.replace("\r\n", "\n")
    if not text.strip() or not text.isascii() or any(c in text for c in _OTHER_BREAKS):
        return parse_obj_slow(text, path)
    b, start, span, c0, c1 = _line_kinds(text)
    sp, tab = ord(" "), ord("\t")
    first = np.frombuffer(b"vlgo", np.uint8)
    if ((c0 == sp) | (c0 == tab)).any() or (np.isin(c0, first) & (c1 == tab)).any():
        return parse_obj_slow(text, path)             # an indented record or a tab after one
    v_idx = np.flatnonzero((c0 == ord("v")) & (c1 == sp))
    l_idx = np.flatnonzero((c0 == ord("l")) & (c1 == sp))
    g_idx = np.flatnonzero(np.isin(c0, first[2:]) & ((c1 == sp) | (c1 == 0)))
    if not len(v_idx) or not len(l_idx):
        return parse_obj_slow(text, path)
    try:
        verts = np.fromstring(_bodies(b, start, span, v_idx, "\n"), sep=" ")
        ltext = _bodies(b, start, span, l_idx, " 0 ")
        if "/" in ltext:
            ltext = re.sub(r"/\S*", "", ltext)
        flat = np.fromstring(ltext, sep=" ", dtype=np.int64)
    except ValueError:
        return parse_obj_slow(text, path)
    if verts.size != 3 * len(v_idx) or not np.isfinite(verts).all():
        return parse_obj_slow(text, path)
    zeros = np.flatnonzero(flat == 0)
    if len(zeros) != len(l_idx):
        return parse_obj_slow(text, path)
    counts = np.diff(np.concatenate([[-1], zeros])) - 1
    if (counts < 1).any():
        return parse_obj_slow(text, path)
    idx = flat[flat != 0]
    owner = np.repeat(np.arange(len(l_idx)), counts)
    nv_at = np.searchsorted(v_idx, l_idx)[owner]
    idx = np.where(idx < 0, nv_at + idx, idx - 1)
    if ((idx < 0) | (idx >= nv_at)).any():
        return parse_obj_slow(text, path)
    labels_at = ["boundary"]
    for a, n in zip(start[g_idx].tolist(), span[g_idx].tolist()):
        lab = label_of(text[a:a + n].split()[1:])
        labels_at.append(lab if lab is not None else "boundary")
    which = np.searchsorted(g_idx, l_idx)
    polys = np.split(idx, np.cumsum(counts)[:-1])
    return (verts.reshape(-1, 3), polys, [labels_at[w] for w in which.tolist()],
            (l_idx + 1).tolist())


def parse_obj_slow(text, path):
    """Parse OBJ text into vertices and polylines, token by token.

    Returns
    -------
    verts : (V, 3) float64
    polys : list of (k,) int64 index arrays (0-based, validated)
    labels : list of str, one per polyline
    poly_lines : list of int, 1-based line of each polyline's ``l`` record
    """
    lines, toks = split_lines(text)
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
            lab = label_of(t[1:])
            label = lab if lab is not None else "boundary"
    verts = xyz_rows(v_rows, v_lines, path, "vertex coordinates")
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


def chain_segments(polys, labels, lines, nverts):
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


def read_obj(text, path, strict):
    """Read OBJ polylines as strokes, two-index segments chained (see :mod:`curvenet.io`)."""
    verts, polys, labels, lines = parse_obj(text, path)
    polys, labels, lines = chain_segments(polys, labels, lines, len(verts))
    return finish_sketch([verts[p] for p in polys], labels, lines, path, strict)
