"""Patch sides: group the curves of a loop into sides at its corners.

A loop of curves ``c_0 ... c_{n-1}`` (each oriented along the traversal) has a
junction before each curve. A junction is a *corner* when the traversal turns
by more than ``straight_angle`` there; consecutive curves meeting nearly straight
(a T-junction on the patch border) stay in one side, so a loop of five curves with
one T-junction is a four-sided patch.

The turn at a junction is measured between the chords to the points at the same arc
length on both sides, :data:`TANGENT_FRACTION` of the shorter curve's length: chords
of a tenth of each curve's own length read the sag of a long curve's chord as a turn
where a short curve meets it on a bend (where a closed stroke began on a tight bend,
a smooth curve came out cornered).

Notes
-----
Orbay & Kara 2011 (Sec. 4.2) surface four-sided loops only and take each curve as
a side; grouping at T-junctions is our extension (the issue asks for it). The
turning angle is measured between chords (see above), which ignores a hooked last
sample.
"""

from __future__ import annotations

import numpy as np

from curvenet.core.geometry import arc_length

from .polyline import end_tangents

__all__ = ["DEFAULT_STRAIGHT_ANGLE", "TANGENT_FRACTION", "junction_angles", "group_sides"]

#: Turning angle in degrees below which two curves count as one side.
DEFAULT_STRAIGHT_ANGLE = 30.0
#: Arc length of the chords that measure a junction's turn, fraction of the shorter of
#: the two curves meeting there.
TANGENT_FRACTION = 0.1


def junction_angles(loop_curves: list) -> np.ndarray:
    """Turning angle (degrees) of the traversal at the junction before each curve.

    Parameters
    ----------
    loop_curves : list of (m_i, 3) float64
        The loop's curves in traversal order, each running along the traversal
        (``loop_curves[i][-1]`` is the start of ``loop_curves[i + 1]``).

    Returns
    -------
    angles : (n,) float64 in [0, 180]
        ``angles[i]`` is the turn from the end of curve ``i - 1`` into curve ``i``
        (0: straight on; 180: doubling back).
    """
    n = len(loop_curves)
    lengths = np.array([arc_length(c) for c in loop_curves])
    scale = TANGENT_FRACTION * np.minimum(lengths, np.roll(lengths, 1))   # per junction
    t_start = np.empty((n, 3))
    t_end = np.empty((n, 3))
    for i, c in enumerate(loop_curves):
        t_start[i], t_end[i] = end_tangents(c, lengths=(scale[i], scale[(i + 1) % n]))
    d_in = -np.roll(t_end, 1, axis=0)          # travel direction arriving at junction i
    d_out = t_start                             # travel direction leaving junction i
    cos = np.clip(np.einsum("ij,ij->i", d_in, d_out), -1.0, 1.0)
    return np.degrees(np.arccos(cos))


def group_sides(loop_curves: list, straight_angle: float = DEFAULT_STRAIGHT_ANGLE) -> list:
    """Group a loop's curves into sides, split at corners.

    Parameters
    ----------
    loop_curves : list of (m_i, 3) float64
        As in :func:`junction_angles`.
    straight_angle : float
        Degrees; a junction that turns by more is a corner.

    Returns
    -------
    sides : list of list of int
        Curve positions in the loop, side by side, each side in traversal order,
        the first side starting at a corner. Empty when the loop has no corner
        (a smooth closed loop: the caller decides how to split it).

    Examples
    --------
    >>> import numpy as np
    >>> sq = [np.array([[0, 0, 0], [0.5, 0, 0.]]), np.array([[0.5, 0, 0], [1, 0, 0.]]),
    ...       np.array([[1, 0, 0], [1, 1, 0.]]), np.array([[1, 1, 0], [0, 1, 0.]]),
    ...       np.array([[0, 1, 0], [0, 0, 0.]])]
    >>> group_sides(sq)
    [[0, 1], [2], [3], [4]]
    """
    if not 0.0 <= straight_angle < 180.0:
        raise ValueError(f"straight_angle: expected degrees in [0, 180), got {straight_angle}")
    n = len(loop_curves)
    corner = junction_angles(loop_curves) > straight_angle
    if not corner.any():
        return []
    first = int(np.flatnonzero(corner)[0])
    sides: list = []
    for k in range(n):
        i = (first + k) % n
        if corner[i]:
            sides.append([i])
        else:
            sides[-1].append(i)
    return sides
