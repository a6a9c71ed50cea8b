"""Rims on the strokes' bounding box: the zero set closed flat where it leaves through one.

Not in the paper. Eq. 5's flow alignment prefers a surface that continues past an open
rim tangentially: a capped cylinder drawn by its two rim circles and a few rulings, and
nothing on its caps, comes out as a tube that runs on past both rims and closes through
the walls of the periodic box (``FlowConfig.boundary``); a portafilter's basket, drawn by
its rim, is domed over; a dress bulges in lobes past its hem. Where the strokes end at a
rim, nothing was drawn beyond it.

:func:`close_rims` reads that off the strokes' bounding box (the whole sketch's, when its
parts are fitted apart). Each of its six sides is a plane no stroke lies beyond. The zero
set of f crosses the plane along a set of curves; where most of them (``share`` of the
crossing points, at least) lie within :data:`RIM_REACH` grid cells of a stroke, the
surface leaves the sketch through a drawn rim, and f is clipped at that plane: the
implicit intersection ``max(f, s)`` with ``s`` the distance beyond the plane (scaled to
f's step per cell at its zero set, and no larger than f at the box's corner), whose zero
set is the surface up to the plane and a flat cap on it.

Where the surface crosses the plane along a curve that no stroke follows (a sphere drawn
by great circles none of which passes through the point where it meets the plane), the
side is left open: that surface beyond the strokes is part of the shape they imply.
Where it only bulges past a stroke that touches the plane, the crossing is a small loop
around the stroke, within the reach of the stroke, and the clip takes off a dome a cell
or two high that the stroke's extreme says is not there either.

A pair of sides closer together than twice that reach is left open: a flat sketch (a
circle, strokes in one plane) has no inside between them, and closing both would leave
no surface. Only rims on the sides of the axis-aligned box are found: a rim tilted to the axes (a
cylinder drawn at a slant) or one below the top of the sketch (a mug's, under a handle
that rises above it) runs on as before.

:func:`clamp_to` puts back onto the clipped planes the vertices that the fairing
(:mod:`neural.attach`) moved past them: a low-pass rounds the cap's edge and domes it.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from curvenet.core.geometry import densify_polylines

__all__ = ["RIM_REACH", "close_rims", "clamp_to", "strokes_box"]

#: A crossing point of a side's plane lies on a rim when a stroke is within this many
#: grid cells of it (the fairing's reach at ``default``, ``FlowConfig.attach_reach``,
#: is 6; the zero set lies within a cell or two of smooth strokes).
RIM_REACH = 3.0


def strokes_box(strokes) -> tuple[np.ndarray, np.ndarray]:
    """Lowest and highest corner, (3,) float64 each, of the points of ``strokes`` (list of
    (k_i, 3) float64): the box whose sides :func:`close_rims` looks at."""
    points = np.vstack(strokes)
    return points.min(axis=0), points.max(axis=0)


def close_rims(f: np.ndarray, origin: np.ndarray, h: float, box, strokes,
               share: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Clip f at each side of ``box`` that its zero set leaves through a rim (module notes).

    Parameters
    ----------
    f : (n, n, n) float32
        Node grid, node ``[i, j, k]`` at ``origin + (i, j, k) * h``, positive outside.
    origin : (3,) float64
    h : float
        Node spacing (world units).
    box : ((3,), (3,)) float64, or None
        Lowest and highest corner of the strokes' bounding box (world units); None
        closes none.
    strokes : list of (k_i, 3) float64
    share : float
        Least share of the crossing points within :data:`RIM_REACH` cells of a stroke
        for a side to be closed; 0 closes none.

    Returns
    -------
    f : (n, n, n) float32
        Clipped at the closed sides (the input when none is closed).
    lo, hi : (3,) float64
        The closed sides' planes; ``-inf`` / ``inf`` where a side is left open.

    Examples
    --------
    >>> n, h = 24, 0.1
    >>> x = -1.15 + h * np.arange(n)
    >>> X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    >>> tube = (np.hypot(X, Y) - 0.5).astype(np.float32)     # endless along z
    >>> t = np.linspace(0, 2 * np.pi, 60)
    >>> rims = [np.c_[0.5 * np.cos(t), 0.5 * np.sin(t), np.full(60, z)] for z in (-0.5, 0.5)]
    >>> box = (np.array([-0.5, -0.5, -0.5]), np.array([0.5, 0.5, 0.5]))
    >>> g, lo, hi = close_rims(tube, np.full(3, -1.15), h, box, rims, 0.5)
    >>> lo.tolist(), hi.tolist()                                   # the ends, not the sides
    ([-inf, -inf, -0.5], [inf, inf, 0.5])
    >>> bool(g[12, 12, 0] > 0), bool(g[12, 12, 12] < 0)            # closed beyond the rims
    (True, True)
    """
    lo, hi = np.full(3, -np.inf), np.full(3, np.inf)
    if share <= 0 or box is None or not len(strokes):
        return f, lo, hi
    n = f.shape[0]
    tree = cKDTree(densify_polylines(strokes, 0.5 * h)[0])
    clip = None
    for axis in range(3):
        if box[1][axis] - box[0][axis] < 2.0 * RIM_REACH * h:
            continue                    # flat along the axis: no inside between its sides
        for side, plane in ((-1, box[0][axis]), (1, box[1][axis])):
            u = (plane - origin[axis]) / h                     # the plane in node units
            i = int(np.clip(np.floor(u), 0, n - 2))
            points = _crossings(f, axis, i, u - i, origin, h, plane)
            if not len(points) or np.mean(tree.query(points)[0] < RIM_REACH * h) < share:
                continue
            (lo if side < 0 else hi)[axis] = plane
            shape = [1, 1, 1]
            shape[axis] = n
            beyond = (side * ((origin[axis] + h * np.arange(n)) - plane) / h).reshape(shape)
            clip = beyond if clip is None else np.maximum(clip, beyond)
    if clip is None:
        return f, lo, hi
    # saturated at the box corner's value, so f away from the surface keeps its scale
    return np.maximum(f, np.minimum(_step(f) * clip, f[0, 0, 0]).astype(np.float32)), lo, hi


def clamp_to(V: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``V`` (m, 3) float64 with each coordinate clipped to ``[lo, hi]`` (:func:`close_rims`'s
    planes; the input itself when every side is open)."""
    if np.isinf(lo).all() and np.isinf(hi).all():
        return V
    return np.clip(V, lo, hi)


def _step(f: np.ndarray) -> float:
    """Median change of f (n, n, n) between neighbouring nodes across its zero set (1.0
    when f does not cross zero): the scale of a distance in cells in units of f."""
    steps = [np.abs(np.diff(f, axis=a))[np.diff(np.signbit(f), axis=a)] for a in range(3)]
    steps = np.concatenate(steps)
    return float(np.median(steps)) if len(steps) else 1.0


def _crossings(f, axis: int, i: int, t: float, origin, h: float, plane: float) -> np.ndarray:
    """World points (p, 3) where the zero set of f, interpolated linearly to the plane
    ``t`` of the way from node layer ``i`` to ``i + 1`` along ``axis``, crosses the edges
    of that plane's node grid."""
    s = (1.0 - t) * np.take(f, i, axis=axis) + t * np.take(f, i + 1, axis=axis)
    others = [a for a in range(3) if a != axis]
    out = []
    for k in range(2):                           # edges along each in-plane axis
        a, b = s[:-1] if k == 0 else s[:, :-1], s[1:] if k == 0 else s[:, 1:]
        r, c = np.nonzero(np.signbit(a) != np.signbit(b))
        w = a[r, c] / (a[r, c] - b[r, c])                   # fraction of the edge
        uv = np.c_[r + (w if k == 0 else 0.0), c + (w if k == 1 else 0.0)]
        p = np.empty((len(r), 3))
        p[:, others] = origin[others] + h * uv
        p[:, axis] = plane
        out.append(p)
    return np.concatenate(out)
