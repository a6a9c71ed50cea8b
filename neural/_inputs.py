"""Validation of the stroke arrays and labels that the neural entry points receive."""

from __future__ import annotations

import numpy as np

__all__ = ["LABELS", "check_strokes"]

LABELS = ("boundary", "crease", "construction")


def check_strokes(strokes, labels, *, allow_empty: bool = False):
    """Validate strokes and their labels.

    Parameters
    ----------
    strokes : sequence of (n_i, 3) array_like
        ``n_i >= 2`` finite points each.
    labels : sequence of str or None
        One of :data:`LABELS` per stroke; ``None`` labels every stroke ``"crease"``.
    allow_empty : bool
        Accept an empty stroke list.

    Returns
    -------
    strokes : list of (n_i, 3) float64 ndarray
    labels : list of str

    Raises
    ------
    ValueError
        Naming the offending stroke or label.
    """
    if not isinstance(strokes, (list, tuple)) or (len(strokes) == 0 and not allow_empty):
        raise ValueError("strokes must be a non-empty list of (n, 3) arrays")
    out = []
    for i, s in enumerate(strokes):
        a = np.asarray(s, dtype=np.float64)
        if a.ndim != 2 or a.shape[1] != 3 or len(a) < 2:
            raise ValueError(f"strokes[{i}] must have shape (n >= 2, 3), got {a.shape}")
        if not np.isfinite(a).all():
            raise ValueError(f"strokes[{i}] contains non-finite coordinates")
        out.append(a)
    lab = ["crease"] * len(out) if labels is None else list(labels)
    if len(lab) != len(out):
        raise ValueError(f"labels has {len(lab)} entries for {len(out)} strokes")
    for i, x in enumerate(lab):
        if x not in LABELS:
            raise ValueError(f"labels[{i}] must be 'boundary', 'crease' or 'construction', "
                             f"got {x!r}")
    return out, lab
