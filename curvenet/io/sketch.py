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
``abc``
    ABC dataset feature curves (``*_features_*.yml``): each curve evaluated at its
    ``vert_parameters``; see :mod:`curvenet.io.abc`.
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
Every bad input raises :class:`~curvenet.core.errors.SketchFormatError` naming the
file and, where there is one, the 1-based line: empty file, no strokes,
binary data or non-UTF-8 text, NaN/inf coordinates, an index out of range, an
unknown format, a file larger than ``max_bytes`` (default
:data:`MAX_FILE_BYTES`, 1 GiB). Strokes with fewer than two points are dropped
with a warning (kept in ``sketch.metadata["warnings"]``) when other strokes
remain, and are an error with ``strict=True`` or when nothing remains.

Parsing is vectorised with numpy: OBJ with one pass of ``str.split`` per line,
then a single array conversion, so a 100 MB OBJ reads in a few seconds;
``curves`` and ``txt`` in pieces of whole lines whose coordinate lines go
through one ``numpy.loadtxt`` call each, so the memory a read holds is a few
copies of the file and of its coordinates (figures in ``benchmarks/README.md``).

Layout
------
This module holds the public functions and the writers; the readers live
beside it, one module per format: :mod:`curvenet.io.obj` (OBJ),
:mod:`curvenet.io.text` (``curves``, ``txt``, JSON), and their shared file
loading and checks in :mod:`curvenet.io.common`.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..core.atomic import atomic_write_text
from .abc import looks_like_abc, read_abc_features
from .common import MAX_ABS_COORDINATE, finish_sketch, load_text
from .obj import chain_segments, parse_obj, read_obj
from .text import read_blocks, read_json
from ..core.errors import SketchFormatError
from ..model.network import CurveNetwork, indexed_network
from ..model.sketch import Sketch

__all__ = ["FORMATS", "WRITE_FORMATS", "MAX_FILE_BYTES", "read_sketch", "write_sketch",
           "write_network_obj", "read_network_obj", "detect_format", "MAX_ABS_COORDINATE"]

#: Formats :func:`write_sketch` writes; :data:`FORMATS` adds the read-only ``abc``.
WRITE_FORMATS = ("obj", "curves", "txt", "json")
#: Supported format names.
FORMATS = WRITE_FORMATS + ("abc",)

#: Largest file :func:`read_sketch` accepts by default (1 GiB); pass ``max_bytes`` to change.
MAX_FILE_BYTES = 1 << 30

_EXTENSIONS = {".obj": "obj", ".curves": "curves", ".txt": "txt", ".xyz": "txt",
               ".json": "json", ".yml": "abc", ".yaml": "abc"}


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
        text = load_text(path, MAX_FILE_BYTES)
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
    if looks_like_abc(text):
        return "abc"
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
    format : {'obj', 'curves', 'txt', 'json', 'abc'}, optional
        Defaults to the extension (``.obj``, ``.curves``, ``.txt``/``.xyz``,
        ``.json``, ``.yml``/``.yaml``); other extensions are recognised by content.
    strict : bool
        Raise on a stroke with fewer than two points instead of dropping it.
    max_bytes : int
        Refuse larger files (default :data:`MAX_FILE_BYTES`, 1 GiB).
    points : {"auto", True, False}
        Blocks of unordered point samples (consecutive points far apart):
        ``auto`` detects them block by block and recovers the curves they
        sample, ``True`` reads every block so, ``False`` never (see
        :func:`curvenet.io.points.read_point_blocks`).

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
    text = load_text(path, max_bytes)
    fmt = format or detect_format(path, text)
    if fmt == "obj":
        sketch = read_obj(text, path, strict)
    elif fmt == "json":
        sketch = read_json(text, path, strict)
    elif fmt == "abc":
        strokes, labels, meta = read_abc_features(text, path)
        sketch = finish_sketch(strokes, labels, [None] * len(strokes), path, strict, meta)
    else:
        sketch = read_blocks(text, path, strict, fmt)
    del text  # the strokes are parsed: free the file's text before the point-block pass
    from .points import read_point_blocks
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
    """Write a sketch atomically in one of :data:`WRITE_FORMATS`.

    Parameters
    ----------
    path : str or os.PathLike
    sketch : Sketch
    format : {'obj', 'curves', 'txt', 'json'}, optional
        Defaults to the extension; ``obj`` when the extension is unknown (``abc``
        is read-only).

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
    if fmt not in WRITE_FORMATS:
        what = "read-only format" if fmt in FORMATS else "unknown format"
        raise SketchFormatError(f"{what} {fmt!r}; use one of {WRITE_FORMATS}", path=path)
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
    text = load_text(path, max_bytes)
    verts, polys, labels, lines = parse_obj(text, path)
    polys, labels, lines = chain_segments(polys, labels, lines, len(verts))
    polys = [p for p in polys if len(p) >= 2]
    if not polys:
        raise SketchFormatError("no polylines with two or more points", path=path)
    net = indexed_network(verts, polys, labels, range(len(polys)))
    net.report = {"polylines": len(polys), "source": str(path)}
    return net
