"""Report tables of batch runs, as CSV or JSON (chosen by the file's extension).

Both formats carry the same things: header lines (the settings and metric definitions a
reader needs to reproduce the numbers), one row per file, and a summary line. In CSV the
header and summary are ``#`` comment lines (``pandas.read_csv(path, comment="#")`` reads
the rows); in JSON they are the ``header`` list and the ``summary`` string.
"""

from __future__ import annotations

import csv
import io
import json
import os
from pathlib import Path

from ..core.atomic import atomic_write_text, check_output_path
from ..core.errors import InvalidParameterError

__all__ = ["write_table", "table_columns", "check_report_path", "REPORT_FORMATS"]

REPORT_FORMATS = (".csv", ".json")


def check_report_path(path, *, inputs=(), out_dir=None) -> Path:
    """The report path, checked before any work (:func:`curvenet.core.atomic.check_output_path`).

    Refused: an extension other than .csv / .json, a folder, a missing or read-only
    folder (except ``out_dir``, which the batch creates), one of ``inputs``.
    """
    path = Path(path)
    if path.suffix.lower() not in REPORT_FORMATS:
        raise InvalidParameterError(f"--report {path}: use a .csv or .json file name")
    if path.is_dir():
        raise InvalidParameterError(f"--report {path}: is a folder")
    if out_dir is None or os.path.abspath(path.parent) != os.path.abspath(out_dir):
        check_output_path(path, inputs=inputs, what="--report")
    return path


def table_columns(rows, first=()) -> list:
    """Column names: ``first`` (those present), then every other key in order of appearance."""
    seen = {}
    for row in rows:
        for key in row:
            seen.setdefault(key, None)
    present = [c for c in first if c in seen]
    return present + [c for c in seen if c not in present]


def write_table(path, rows, *, header=(), summary: str = "", first=()) -> Path:
    """Write ``rows`` (list of dict) to a .csv or .json report, atomically.

    Parameters
    ----------
    path : str or os.PathLike
        ``.csv`` or ``.json``.
    rows : list of dict
        One per file; missing keys are empty cells (CSV) or absent (JSON).
    header : sequence of str
        Lines before the table (settings, metric definitions).
    summary : str
        One line after the table.
    first : sequence of str
        Columns to put first, in this order.

    Returns
    -------
    pathlib.Path
    """
    path = check_report_path(path)
    if path.suffix.lower() == ".json":
        text = json.dumps({"header": list(header), "rows": list(rows), "summary": summary},
                          indent=1, default=str) + "\n"
    else:
        buf = io.StringIO()
        for line in header:
            buf.write(f"# {line}\n")
        writer = csv.DictWriter(buf, fieldnames=table_columns(rows, first), restval="",
                                lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
        if summary:
            buf.write(f"# {summary}\n")
        text = buf.getvalue()
    atomic_write_text(path, text)
    return path
