"""The sketch: a list of 3D strokes with per-stroke labels.

A stroke is an ``(n, 3) float64`` array with ``n >= 2`` finite points. Labels are
``"boundary"`` (default: a curve the surface passes through), ``"crease"`` (a
curve the surface passes through with a sharp edge) and ``"construction"``
(ignored by surfacing).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.strokes import LABELS, check_strokes

__all__ = ["LABELS", "Sketch", "label_counts"]


def label_counts(labels) -> dict:
    """``{label: count}`` in :data:`LABELS` order, labels that occur only.

    Examples
    --------
    >>> label_counts(["crease", "boundary", "crease"])
    {'boundary': 1, 'crease': 2}
    """
    labels = list(labels)
    return {lab: labels.count(lab) for lab in LABELS if lab in labels}


@dataclass
class Sketch:
    """Strokes plus labels.

    Attributes
    ----------
    strokes : list of (n_i, 3) float64 ndarray
    labels : list of str
        One of :data:`LABELS` per stroke.
    metadata : dict
        Free-form (units, author, source file ...); kept by the JSON format.
    source : str or None
        The file it was read from, if any.

    Examples
    --------
    >>> s = Sketch([[[0, 0, 0], [1, 0, 0]], [[0, 0, 0], [0, 1, 0]]])
    >>> len(s), s.labels
    (2, ['boundary', 'boundary'])
    >>> round(s.diagonal, 6)
    1.414214
    """

    strokes: list
    labels: list | None = None
    metadata: dict = field(default_factory=dict)
    source: str | None = None

    def __post_init__(self):
        self.strokes, self.labels = check_strokes(self.strokes, self.labels)

    def __len__(self) -> int:
        return len(self.strokes)

    def __repr__(self) -> str:
        n = sum(len(s) for s in self.strokes)
        return (f"<Sketch(strokes={len(self.strokes)}, points={n}, "
                f"labels={label_counts(self.labels)}, bounds={np.round(self.bounds, 4).tolist()})>")

    @property
    def points(self) -> np.ndarray:
        """All stroke points stacked, ``(N, 3) float64``."""
        if not self.strokes:
            return np.zeros((0, 3))
        return np.concatenate(self.strokes, axis=0)

    @property
    def bounds(self) -> np.ndarray:
        """Axis-aligned bounding box ``(2, 3)``: min row, max row."""
        pts = self.points
        if len(pts) == 0:
            return np.zeros((2, 3))
        return np.stack([pts.min(axis=0), pts.max(axis=0)])

    @property
    def diagonal(self) -> float:
        """Length of the bounding-box diagonal (the unit of every relative tolerance)."""
        b = self.bounds
        return float(np.linalg.norm(b[1] - b[0]))

    def select(self, labels=("boundary", "crease")) -> "Sketch":
        """The sub-sketch of strokes whose label is in ``labels``."""
        keep = [i for i, lab in enumerate(self.labels) if lab in labels]
        return Sketch([self.strokes[i] for i in keep], [self.labels[i] for i in keep],
                      dict(self.metadata), self.source)
