"""A subdivided unit box and its 12 edges as strokes, for the crease tests."""

import numpy as np
import trimesh


def box_mesh():
    """Unit box [0, 1]^3, subdivided so that faces near an edge exist on both sides:
    ``(vertices (V, 3) float64, faces (F, 3) int64)``."""
    m = trimesh.creation.box(extents=(1, 1, 1))
    m.apply_translation((0.5, 0.5, 0.5))
    m = m.subdivide().subdivide().subdivide()
    return np.asarray(m.vertices), np.asarray(m.faces)


BOX_CORNERS = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)


def box_edges():
    """The 12 edges of the unit box as straight 20-point strokes."""
    c = BOX_CORNERS
    edges = [(a, b) for a in range(8) for b in range(a + 1, 8) if bin(a ^ b).count("1") == 1]
    return [c[a] + np.linspace(0, 1, 20)[:, None] * (c[b] - c[a]) for a, b in edges]
