"""Batch evaluation: score many results against references, as a table with its definitions.

A pair is ``(mesh, reference)``; the reference is a mesh (Chamfer, Hausdorff, normal
error, F-score: :func:`curvenet.evaluate.evaluate_mesh`) or the sketch the mesh was made
from (stroke distance: :func:`curvenet.evaluate.stroke_distance`). Pairs come from two
folders matched by file stem (:func:`pairs_from_dirs`) or from a CSV file with columns
``mesh,reference`` (:func:`pairs_from_csv`). :func:`metric_definitions` gives the header
lines that make the table reproducible: sample counts, normalisation, threshold, seed.
"""

from __future__ import annotations

import csv
import math
import time
from pathlib import Path

from ..io.common import require_file
from ..core.errors import CurvenetError, InvalidParameterError, SketchFormatError

__all__ = ["pairs_from_dirs", "pairs_from_csv", "evaluate_pairs", "metric_definitions",
           "is_mesh_file", "format_table", "summary_line"]

_MESH_SUFFIXES = (".obj", ".ply", ".stl", ".off", ".glb")

#: Columns of the printed table: key, heading, format.
_TABLE = (("fscore", "F-score", "{:.2%}"), ("chamfer", "Chamfer", "{:.3e}"),
          ("hausdorff", "Hausdorff", "{:.3e}"), ("normal_error_deg", "NE deg", "{:.2f}"),
          ("stroke_within_1pct", "strokes<1%", "{:.2%}"), ("stroke_p95", "stroke p95", "{:.3e}"))


def is_mesh_file(path) -> bool:
    """Whether ``path`` is a mesh (by extension; an OBJ only when it has ``f`` lines).

    An OBJ with only ``v``/``l`` lines is a sketch or network, not a mesh.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in _MESH_SUFFIXES:
        return False
    if suffix != ".obj":
        return True
    if not path.is_file():
        return False
    with open(path, "rb") as fh:
        return any(raw.startswith(b"f ") for raw in fh)


def pairs_from_dirs(out_dir, ref_dir) -> list:
    """Pairs ``(mesh, reference)`` matched by stem: every mesh in ``out_dir`` (sorted).

    A mesh without a reference of the same stem is paired with None (reported as an
    error row); a stem with several references is refused.

    Raises
    ------
    InvalidParameterError
        A folder that does not exist, no mesh in ``out_dir``, or an ambiguous reference.
    """
    out_dir, ref_dir = Path(out_dir), Path(ref_dir)
    for d in (out_dir, ref_dir):
        if not d.is_dir():
            raise InvalidParameterError(f"--pairs: {d} is not a folder")
    refs: dict = {}
    for p in sorted(ref_dir.iterdir()):
        if p.is_file() and not p.name.startswith("."):
            refs.setdefault(p.stem, []).append(p)
    pairs = []
    for mesh in sorted(p for p in out_dir.iterdir() if p.is_file() and is_mesh_file(p)):
        cands = refs.get(mesh.stem, [])
        if len(cands) > 1:
            raise InvalidParameterError(
                f"--pairs: {mesh.name} matches several references: "
                f"{', '.join(c.name for c in cands)}; use a CSV of pairs")
        pairs.append((str(mesh), str(cands[0]) if cands else None))
    if not pairs:
        raise InvalidParameterError(f"--pairs: no mesh files in {out_dir}")
    return pairs


def pairs_from_csv(path) -> list:
    """Pairs from a CSV with a header row ``mesh,reference``; relative paths are taken
    relative to the CSV's folder.

    Raises
    ------
    SketchFormatError
        No such file, no ``mesh``/``reference`` columns, or an empty cell (names the line).
    """
    path = require_file(path)
    with open(path, newline="", encoding="utf-8", errors="replace") as fh:
        reader = csv.DictReader(fh)
        if not {"mesh", "reference"} <= set(reader.fieldnames or ()):
            raise SketchFormatError("the header must name the columns mesh,reference",
                                    path=path, line=1)
        pairs = []
        for row in reader:
            mesh, ref = (row.get("mesh") or "").strip(), (row.get("reference") or "").strip()
            if not mesh or not ref:
                raise SketchFormatError("empty mesh or reference", path=path,
                                        line=reader.line_num)
            pairs.append(tuple(str(path.parent / p) for p in (mesh, ref)))
    if not pairs:
        raise SketchFormatError("no pairs", path=path)
    return pairs


def metric_definitions(n_samples: int, threshold: float, seed: int) -> list:
    """Header lines stating how every number in the table was measured."""
    return [
        "curvenet eval: mesh vs reference mesh (SharpNet metrics, Niu et al. 2025, Sec. 5) "
        "or vs the sketch (stroke distance)",
        f"sampling: {n_samples} area-uniform points on each mesh, seed {seed}; distances "
        "from samples to the other mesh's triangles (not to its samples)",
        "normalisation: both meshes scaled about the reference's bbox centre so that the "
        "reference's longest bbox side is 1",
        "chamfer: mean of the two mean point-to-surface distances (not squared); hausdorff: "
        "max of both; NE: mean angle between sample and closest-triangle normals (deg, "
        "orientation-agnostic)",
        f"fscore: 2PR/(P+R), P and R the shares of samples closer than {threshold:g} "
        "(strict) to the other surface",
        "sketch references: strokes resampled every 1e-3 of the sketch's bbox diagonal; "
        "distances divided by that diagonal; strokes<1%: share of samples closer than 0.01",
    ]


def _score(mesh, ref, n_samples, threshold, seed) -> dict:
    from .metrics import evaluate_mesh, stroke_distance
    if is_mesh_file(ref):
        return {"kind": "mesh", **evaluate_mesh(mesh, ref, n_samples=n_samples,
                                                threshold=threshold, seed=seed)}
    require_file(ref)
    from ..io.sketch import read_sketch
    return {"kind": "sketch", **stroke_distance(mesh, read_sketch(ref))}


def evaluate_pairs(pairs, *, n_samples: int = 100_000, threshold: float = 0.01,
                   seed: int = 0, on_row=None) -> list:
    """Score each pair; a pair that fails is a row with ``status`` and ``error``.

    Parameters
    ----------
    pairs : list of (str, str or None)
    n_samples, threshold, seed
        As in :func:`curvenet.evaluate.evaluate_mesh`.
    on_row : callable, optional
        ``on_row(row, n_done, n_total)`` after each pair.

    Returns
    -------
    list of dict
        ``mesh``, ``reference``, ``status`` (``ok``, ``error`` for bad input, ``internal``),
        ``kind`` (``mesh`` / ``sketch``), the metrics, ``seconds``.
    """
    rows = []
    for k, (mesh, ref) in enumerate(pairs):
        t0 = time.perf_counter()
        row = {"mesh": mesh, "reference": ref}
        try:
            if ref is None:
                raise InvalidParameterError(f"{mesh}: no reference of the same name")
            row.update(_score(mesh, ref, n_samples, threshold, seed), status="ok")
        except CurvenetError as err:
            row.update(status="error", error=str(err))
        except Exception as err:  # one pair's failure; the table goes on
            row.update(status="internal", error=f"{type(err).__name__}: {err}")
        row["seconds"] = time.perf_counter() - t0
        rows.append(row)
        if on_row:
            on_row(row, k + 1, len(pairs))
    return rows


def _means(rows) -> dict:
    ok = [r for r in rows if r["status"] == "ok"]
    out = {}
    for key, _head, _fmt in _TABLE:
        vals = [r[key] for r in ok if isinstance(r.get(key), (int, float))]
        if vals:
            out[key] = math.fsum(vals) / len(vals)
    return out


def format_table(rows) -> str:
    """A text table, one line per pair and a ``mean`` line over the pairs scored ok."""
    keys = [c for c in _TABLE if any(c[0] in r for r in rows)]
    names = [Path(r["mesh"]).name for r in rows] + ["mean"]
    width = max(len(n) for n in names)
    lines = [f"{'mesh':<{width}}  " + "  ".join(f"{h:>11}" for _k, h, _f in keys)]
    for name, row in zip(names, rows + [_means(rows)]):
        if row.get("status", "ok") != "ok":
            lines.append(f"{name:<{width}}  FAILED: {row.get('error', '')}")
            continue
        cells = [f.format(row[k]) if k in row else "-" for k, _h, f in keys]
        lines.append(f"{name:<{width}}  " + "  ".join(f"{c:>11}" for c in cells))
    return "\n".join(lines)


def summary_line(rows) -> str:
    """``N pairs: k scored, m failed; mean F-score ...``."""
    ok = sum(r["status"] == "ok" for r in rows)
    means = _means(rows)
    parts = [f"{len(rows)} pairs: {ok} scored, {len(rows) - ok} failed"]
    if "fscore" in means:
        parts.append(f"mean F-score {means['fscore']:.2%}, mean Chamfer {means['chamfer']:.3e}")
    if "stroke_within_1pct" in means:
        parts.append(f"mean strokes<1% {means['stroke_within_1pct']:.2%}")
    return "; ".join(parts)
