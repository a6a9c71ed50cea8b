"""Stroke labels and the one validator of a list of labelled strokes.

A stroke is an ``(n, 3) float64`` polyline with ``n >= 2`` finite points
(:func:`curvenet.core.geometry.as_polyline`). Labels are ``"boundary"`` (a curve
the surface passes through), ``"crease"`` (the same, with a sharp edge) and
``"construction"`` (ignored by surfacing).
"""

from __future__ import annotations

from .errors import InvalidParameterError

from .geometry import as_polyline

__all__ = ["LABELS", "check_labels", "check_strokes"]

#: Stroke labels, in the order the file formats and the documentation list them.
LABELS = ("boundary", "crease", "construction")


def check_labels(labels, n: int, *, default: str = "boundary") -> list:
    """Validate one label per stroke.

    Parameters
    ----------
    labels : sequence of str or None
        ``None`` gives every stroke ``default``.
    n : int
        Number of strokes.
    default : str
        One of :data:`LABELS`.

    Returns
    -------
    list of str

    Raises
    ------
    InvalidParameterError
        A count different from ``n`` or a label not in :data:`LABELS`.

    Examples
    --------
    >>> check_labels(None, 2, default="crease")
    ['crease', 'crease']
    """
    out = [default] * n if labels is None else [str(lab) for lab in labels]
    if len(out) != n:
        raise InvalidParameterError(f"labels: {len(out)} labels for {n} strokes")
    for i, lab in enumerate(out):
        if lab not in LABELS:
            raise InvalidParameterError(
                f"labels[{i}]: unknown label {lab!r}; use one of {LABELS}")
    return out


def check_strokes(strokes, labels=None, *, default_label: str = "boundary",
                  allow_empty: bool = True) -> tuple[list, list]:
    """Validate strokes and their labels.

    Parameters
    ----------
    strokes : iterable of (n_i, 3) array_like
        ``n_i >= 2`` finite points each.
    labels : sequence of str or None
        One of :data:`LABELS` per stroke; ``None`` labels every stroke ``default_label``.
    default_label : str
    allow_empty : bool
        Accept an empty stroke list.

    Returns
    -------
    strokes : list of (n_i, 3) float64 ndarray
        C-contiguous copies.
    labels : list of str

    Raises
    ------
    InvalidParameterError
        Naming the offending stroke (``strokes[i]``) or label (``labels[i]``).

    Examples
    --------
    >>> st, lab = check_strokes([[[0, 0, 0], [1, 0, 0]]], default_label="crease")
    >>> st[0].shape, lab
    ((2, 3), ['crease'])
    """
    if isinstance(strokes, (str, bytes)) or not hasattr(strokes, "__iter__"):
        raise InvalidParameterError(f"strokes: expected a list of (n, 3) arrays, "
                                    f"got {type(strokes).__name__}")
    strokes = list(strokes)
    if len(strokes) == 0 and not allow_empty:
        raise InvalidParameterError("strokes: expected at least one stroke, got none")
    out = [as_polyline(s, name=f"strokes[{i}]") for i, s in enumerate(strokes)]
    return out, check_labels(labels, len(out), default=default_label)
