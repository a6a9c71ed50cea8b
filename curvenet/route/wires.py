"""Wires: the stretches of strokes a surface leaves out, kept as polylines beside it.

:func:`stroke_wires` keeps every stretch of a stroke farther from the surface than the
fidelity tolerance (the strokes of wire regions, overshoots trimmed by the snapping,
the second stroke of an overdrawn curve), with the stroke's own geometry.
"""

from __future__ import annotations

import numpy as np

from ..core.distance import point_surface_distance
from ..core.fidelity import FIDELITY_TOL_REL, STROKE_SPACING_REL, stroke_samples
from ..core.geometry import cumulative_length, interpolate_polyline

__all__ = ["MIN_WIRE_LENGTH", "stroke_wires"]

#: a stretch of stroke off the surface becomes a wire when it is at least this long,
#: as a fraction of the sketch's diagonal (shorter ones are the surface's wobble)
MIN_WIRE_LENGTH = 0.01


def stroke_wires(strokes, vertices, faces, *, tol_rel: float = FIDELITY_TOL_REL,
                 spacing_rel: float = STROKE_SPACING_REL,
                 min_length_rel: float = MIN_WIRE_LENGTH) -> list:
    """Stretches of the strokes that the surface does not pass through, as wires.

    Parameters
    ----------
    strokes : Sketch, CurveNetwork or list of (n, 3) array_like
        As in :func:`curvenet.evaluate.sketch_fidelity`; the diagonal of their points is
        the scale of the relative lengths below.
    vertices : (V, 3) float64
    faces : (F, 3) int64
        The surface.
    tol_rel : float
        A stroke sample farther than this from the surface is off it (the fidelity
        tolerance).
    spacing_rel : float
        Arc-length step of the stroke samples.
    min_length_rel : float
        Stretches shorter than this are left out.

    Returns
    -------
    list of (m, 3) float64
        One piece of one stroke each (m >= 2), in stroke order: the stroke's own points
        from the sample before its first sample off the surface to the sample after its
        last (so a wire starts and ends at the surface when it leaves it), the two ends
        interpolated on the stroke.

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box()
    >>> stroke = [[-0.5, -0.5, 0.5], [0.5, -0.5, 0.5], [1.5, -0.5, 0.5]]
    >>> [w.round(3).tolist() for w in stroke_wires([stroke], box.vertices, box.faces)]
    [[[0.518, -0.5, 0.5], [1.5, -0.5, 0.5]]]
    """
    lines, diag, pts, counts = stroke_samples(strokes, spacing_rel)
    off = point_surface_distance(pts, vertices, faces)[0] >= tol_rel * diag
    sid = np.repeat(np.arange(len(lines)), counts)
    first = np.r_[0, np.cumsum(counts)[:-1]]
    step = np.r_[0.0, np.linalg.norm(np.diff(pts, axis=0), axis=1)]
    step[first] = 0.0
    cum = np.cumsum(step) - np.cumsum(step)[first][sid]   # arc length along each stroke
    same = sid[1:] == sid[:-1]
    starts = np.flatnonzero(off & ~np.r_[False, off[:-1] & same])
    ends = np.flatnonzero(off & ~np.r_[off[1:] & same, False])
    last = first + counts - 1
    lo = np.maximum(starts - 1, first[sid[starts]])
    hi = np.minimum(ends + 1, last[sid[ends]])
    wires = []
    for a, b in zip(lo, hi):
        s0, s1, line = cum[a], cum[b], lines[sid[a]]
        if s1 - s0 < min_length_rel * diag:
            continue
        c = cumulative_length(line)
        eps = 1e-3 * spacing_rel * diag   # float noise of the two arc lengths
        inner = line[(c > s0 + eps) & (c < s1 - eps)]
        wires.append(np.concatenate([interpolate_polyline(line, [s0], cum=c), inner,
                                     interpolate_polyline(line, [s1], cum=c)]))
    return wires
