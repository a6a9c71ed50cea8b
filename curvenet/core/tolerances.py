"""Named tolerances shared by the graph code and both backends.

Every geometric test that needs a small number takes it from here, so one name
says what a threshold guards and one place says how large it is (trimesh's
``constants.py`` is the model). Relative tolerances (``*_REL``) are fractions of
a length the caller names: the sketch's bounding-box diagonal, a polyline's
length, or the squared diagonal for areas, so millimetre and metre inputs behave
the same. The two absolute floors (:data:`DIVISION_GUARD`, :data:`TINY_F32`)
only keep a division by an exact zero finite; they never change a
non-degenerate result.

Examples
--------
>>> import numpy as np
>>> from curvenet.core.tolerances import DIVISION_GUARD
>>> seg = np.array([2.0, 0.0])
>>> (np.array([1.0, 0.0]) / np.maximum(seg, DIVISION_GUARD)).tolist()
[0.5, 0.0]
"""

from __future__ import annotations

import math
import numbers

from .errors import InvalidParameterError

__all__ = [
    "DIVISION_GUARD",
    "TINY_F32",
    "NORM_EPS",
    "ZERO_LENGTH",
    "COINCIDENT_REL",
    "DUPLICATE_POINT_REL",
    "DEFAULT_SNAP_TOL",
    "DEGENERATE_AREA_REL",
    "SNAP_TOL_RANGE",
    "check_snap_tol",
]

#: Floor of a denominator in float64 numpy code, ``x / max(d, DIVISION_GUARD)``: keeps a
#: division by an exact zero (a repeated point, a zero-length segment or curve, a zero
#: area) finite where the numerator is zero too. Far below any real length, so it never
#: changes a non-degenerate result.
DIVISION_GUARD = 1e-300

#: Floor of a squared length, a norm or a denominator in torch code that may run in
#: float32, where :data:`DIVISION_GUARD` underflows to 0. It shifts a norm by at most
#: ``sqrt(1e-30) = 1e-15`` and keeps the gradient of ``sqrt`` finite at 0.
TINY_F32 = 1e-30

#: Floor of a vector norm (or squared norm) before dividing by it, in unit-cube or
#: normalised coordinates, numpy or torch (gradients of an implicit field, Newton steps,
#: tangents, chords): a smaller vector yields a small vector instead of NaN.
NORM_EPS = 1e-12

#: Length (input units) at or under which a whole polyline counts as zero-length: its
#: arc-length parameters are then uniform in the point index.
ZERO_LENGTH = 1e-12

#: Two points closer than this fraction of the bounding-box diagonal are the same point
#: (coincidence in exact snapping, welding of shared curve samples, smallest grid cell).
COINCIDENT_REL = 1e-9

#: Consecutive samples of one polyline closer than this fraction of a reference length
#: (the sketch's diagonal, the polyline's own length) are repeats and are dropped.
DUPLICATE_POINT_REL = 1e-12

#: A triangle with area under this fraction of the squared bounding-box diagonal is
#: degenerate: it has no normal and no area to sample.
DEGENERATE_AREA_REL = 1e-14

#: Admissible snapping tolerance, as a fraction of the bounding-box diagonal: open at
#: 0 (no tolerance is no snapping), closed at 0.5 (beyond it every point is near every
#: other). Used by :class:`curvenet.snap.SnapOptions` and the CLI's ``--snap-tol``.
SNAP_TOL_RANGE = (0.0, 0.5)


def check_snap_tol(value) -> float:
    """Validate a snapping tolerance against :data:`SNAP_TOL_RANGE`.

    Parameters
    ----------
    value : float
        Fraction of the bounding-box diagonal (a real number, not a string).

    Returns
    -------
    float

    Raises
    ------
    InvalidParameterError
        Not a real number, not finite, or outside ``(0, 0.5]``.

    Examples
    --------
    >>> check_snap_tol(0.01)
    0.01
    """
    lo, hi = SNAP_TOL_RANGE
    real = isinstance(value, numbers.Real) and not isinstance(value, bool)
    x = float(value) if real else math.nan
    if not (math.isfinite(x) and lo < x <= hi):
        raise InvalidParameterError(f"snap_tol must be in ({lo:g}, {hi:g}] (a fraction of the "
                                    f"bounding-box diagonal), got {value!r}")
    return x

#: Default snapping tolerance, a fraction of the bounding-box diagonal. Chosen so
#: that rough redraws (0.3% wobble, ends off by up to 1.5%, 1% gaps) snap
#: reliably: two ends that both stop 1.5% short of a right-angle corner are
#: 2.1% apart. Measured: 100/100 seeded redraws recovered for each of box,
#: L-prism, lat-long sphere and saddle grid (tests/curvenet/test_snap.py, slow).
#: Curves drawn closer together than this are taken as one curve: use a smaller
#: value for dense curve grids (e.g. 0.005 for the Neveu et al. gridshells).
#: Re-exported by :mod:`curvenet.snap`.
DEFAULT_SNAP_TOL = 0.025
