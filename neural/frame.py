"""The padded box of a flow fit: world coordinates <-> the unit cube the grid lives in.

The box is a cube (the sketch's longest side plus ``padding`` of it on every side,
Zhang et al. 2025 Sec. 4.4.1: 20 %) so that the Poisson grid is isotropic.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Frame", "stroke_nodes"]


@dataclass
class Frame:
    """World <-> unit-cube map of the padded box.

    Attributes
    ----------
    box_min : (3,) float64, world corner of the padded cube
    side : float, world side length of the cube
    """

    box_min: np.ndarray
    side: float

    @classmethod
    def from_points(cls, points: np.ndarray, padding: float) -> "Frame":
        """The cube around ``points (n, 3)`` padded by ``padding`` of its longest side.

        Raises
        ------
        ValueError
            If the points span no volume along every axis (a single point).
        """
        lo, hi = points.min(0), points.max(0)
        ext = float((hi - lo).max())
        if not ext > 0:
            raise ValueError("strokes have a zero-size bounding box")
        side = ext * (1.0 + 2.0 * padding)
        return cls((lo + hi) / 2.0 - side / 2.0, side)

    def to_unit(self, x):
        """World points ``(..., 3)`` -> unit-cube coordinates ``(..., 3)`` float64."""
        return (np.asarray(x, float) - self.box_min) / self.side

    def to_world(self, u):
        """Unit-cube coordinates ``(..., 3)`` -> world points ``(..., 3)`` float64."""
        return np.asarray(u, float) * self.side + self.box_min


def stroke_nodes(strokes, origin, h: float, shape) -> np.ndarray:
    """The grid nodes (``shape`` bool) nearest to the samples of ``strokes`` (list of (k, 3)
    polylines) taken half a cell apart: node ``(i, j, k)`` lies at ``origin + (i, j, k) *
    h`` (clipped to the grid)."""
    from curvenet.core.geometry import densify_polylines
    nodes = np.zeros(shape, bool)
    if len(strokes):
        ijk = np.rint((densify_polylines(strokes, h / 2.0)[0] - origin) / h).astype(np.int64)
        nodes[tuple(np.clip(ijk, 0, np.asarray(shape) - 1).T)] = True
    return nodes
