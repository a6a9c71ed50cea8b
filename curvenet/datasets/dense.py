"""A dense curved network of any size: the scaling benchmark's realistic input."""

from __future__ import annotations

import numpy as np

from ..model.sketch import Sketch
from .shapes import grid_box

__all__ = ["dense_blob"]


def dense_blob(n: int, *, seed: int = 0) -> Sketch:
    """A curved, unevenly drawn closed network with the layout of ``grid_box(n)``.

    Parameters
    ----------
    n : int, >= 1
        Grid lines per side of the box (``12 n^2`` strokes).
    seed : int
        Seed of the warp phases, point counts, spacings and wobble.

    Returns
    -------
    Sketch
        One stroke, ``(k, 3) float64`` with ``12 <= k <= 60``, per curve of
        ``grid_box(n)``, labelled ``boundary``, in that network's edge order.

    Notes
    -----

    The grid lines of the box are moved by a smooth monotone warp per axis (faces of
    unequal sizes), then every point is pushed out to a bumpy ellipsoid (radii
    1, 0.8, 0.6 times ``1 + 0.08 sin(3x) sin(2y) + 0.05 cos(4z)`` along the ray from
    the centre), so faces are curved quads; each curve is redrawn with 12 to 60
    unevenly spaced points (steps 0.2 to 1.8 times their mean) whose interior
    wobbles off by up to 0.2% of the grid spacing (ends exact, so they meet): curved
    quads of unequal sizes on a genus-0 surface. A dense "realistic" network for the
    scaling benchmark (issue 32).

    Examples
    --------
    >>> len(dense_blob(2).strokes)
    48
    """
    rng = np.random.default_rng(seed)
    phase = rng.uniform(0, 2 * np.pi, 3)

    def warp(p):                       # monotone per axis: slope 1 +- 0.6
        q = p - 0.5
        return q + 0.6 * np.sin(2 * np.pi * p + phase) / (2 * np.pi) \
            - 0.6 * np.sin(phase) / (2 * np.pi)

    def blob(p):
        d = warp(p)
        d = d / np.linalg.norm(d, axis=1, keepdims=True)
        bump = 1 + 0.08 * np.sin(3 * d[:, 0]) * np.sin(2 * d[:, 1]) + 0.05 * np.cos(4 * d[:, 2])
        r = bump / np.sqrt(((d / (1.0, 0.8, 0.6)) ** 2).sum(1))
        return d * r[:, None]

    spacing = 1.0 / n
    strokes = []
    for e in grid_box(n, samples=2).network.edges:
        a, b = e.curve[0], e.curve[-1]
        k = int(rng.integers(12, 61))
        t = (np.arange(k) + np.r_[0, rng.uniform(-0.4, 0.4, k - 2), 0]) / (k - 1)
        t = t[:, None]                              # steps 0.2 to 1.8 times the mean
        p = blob(a + t * (b - a))
        strokes.append(p + 0.002 * spacing * np.sin(np.pi * t) * rng.uniform(-1, 1, (1, 3)))
    return Sketch(strokes, ["boundary"] * len(strokes), {"shape": f"dense_blob({n})"})
