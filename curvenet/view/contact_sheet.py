"""A contact sheet of a batch: one tile per file, its name, route and stroke fidelity.

The tiles are the small pictures :func:`curvenet.batch.run_batch` writes into the preview
folder (rendered by :func:`curvenet.view.preview.render_preview` on the workers). Each tile's
frame and caption are coloured by the route the file took, so a mixed batch shows at
a glance which files went classical, neural or hybrid; inside a tile the faces are
coloured by the route that made them and the wires drawn (the same colours,
:data:`curvenet.view.colours.ROUTE_COLOURS`). Failed files get a red, empty tile with
the error's first words.
"""

from __future__ import annotations

import math
from pathlib import Path

from ..core.atomic import atomic_path
from ..core.errors import InvalidParameterError
from .colours import FAILED_COLOUR, ROUTE_COLOURS

__all__ = ["contact_sheet"]

#: Tile width and height in inches at 100 dpi, and the number of columns at most.
TILE_INCHES, MAX_COLUMNS = (2.4, 2.3), 6


def _route_key(row: dict) -> str:
    """The row's route (its surfacer's label without a ``+refine``), or ``"failed"``."""
    if row.get("status") not in ("ok", "skipped"):
        return "failed"
    return str(row.get("route") or "classical").removesuffix("+refine")


def _colour(key: str):
    return FAILED_COLOUR if key == "failed" else ROUTE_COLOURS.get(key, (0.0, 0.0, 0.0))


def _caption(row: dict) -> str:
    name = Path(row.get("output") or row["input"]).stem
    if _route_key(row) == "failed":
        return f"{name}\nFAILED: {str(row.get('error', ''))[:40]}"
    fid = row.get("fidelity")
    fid = "" if fid is None else f", fidelity {fid:.0%}"
    return f"{name}\n{row.get('route')}{fid}"


def contact_sheet(path, rows, tiles_dir, *, title: str | None = None) -> Path:
    """Write one PNG with a tile per report row.

    Parameters
    ----------
    path : str or os.PathLike
        The PNG (written atomically).
    rows : list of dict
        Batch report rows (:class:`curvenet.batch.BatchResult`): ``input``, ``output``,
        ``status``, ``route``, ``fidelity``, ``error``.
    tiles_dir : str or os.PathLike
        Folder holding ``STEM.png`` per output stem; a missing tile is drawn empty.
    title : str, optional
        Figure title (default: counts per route).

    Returns
    -------
    pathlib.Path
    """
    if not rows:
        raise InvalidParameterError("contact_sheet: no rows")
    fig = _sheet(rows, tiles_dir, title)
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=100, facecolor="white")
    return path


def _sheet(rows, tiles_dir, title):
    """The contact sheet's Figure (Agg canvas).

    Laid out by matplotlib's constrained layout, which measures the title and every
    caption: the title sits above the first row's captions, each caption above its
    tile, whatever their number of lines.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.image import imread

    cols = min(MAX_COLUMNS, len(rows))
    nrows = math.ceil(len(rows) / cols)
    fig = Figure(figsize=(TILE_INCHES[0] * cols, TILE_INCHES[1] * nrows + 0.5), dpi=100,
                 layout="constrained")
    fig.get_layout_engine().set(w_pad=0.02, h_pad=0.04, wspace=0.02, hspace=0.04)
    FigureCanvasAgg(fig)
    counts: dict = {}
    for k, row in enumerate(rows):
        key = _route_key(row)
        counts[key] = counts.get(key, 0) + 1
        ax = fig.add_subplot(nrows, cols, k + 1)
        tile = Path(tiles_dir) / f"{Path(row.get('output') or row['input']).stem}.png"
        if key != "failed" and tile.is_file():
            ax.imshow(imread(tile))
        ax.set_xticks([])
        ax.set_yticks([])
        for spine in ax.spines.values():
            spine.set_edgecolor(_colour(key))
            spine.set_linewidth(3)
        ax.set_title(_caption(row), fontsize=7, color=_colour(key))
    fig.suptitle(title or ", ".join(f"{v} {k}" for k, v in sorted(counts.items())),
                 fontsize=10)
    return fig
