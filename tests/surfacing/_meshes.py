"""Small quad meshes for the surfacing tests."""

import numpy as np


def cube():
    """Unit cube, 8 vertices (index 4x + 2y + z), 6 outward quads."""
    V = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)

    def i(x, y, z):
        return 4 * x + 2 * y + z

    Q = np.array([[i(0, 0, 0), i(0, 1, 0), i(1, 1, 0), i(1, 0, 0)],
                  [i(0, 0, 1), i(1, 0, 1), i(1, 1, 1), i(0, 1, 1)],
                  [i(0, 0, 0), i(1, 0, 0), i(1, 0, 1), i(0, 0, 1)],
                  [i(0, 1, 0), i(0, 1, 1), i(1, 1, 1), i(1, 1, 0)],
                  [i(0, 0, 0), i(0, 0, 1), i(0, 1, 1), i(0, 1, 0)],
                  [i(1, 0, 0), i(1, 1, 0), i(1, 1, 1), i(1, 0, 1)]])
    return V, Q


def grid(n=4, m=4, f=None):
    """Open (n x m)-quad grid over [0, 1]^2, z = f(x, y)."""
    x, y = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, m + 1), indexing="ij")
    z = np.zeros_like(x) if f is None else f(x, y)
    V = np.stack([x.ravel(), y.ravel(), z.ravel()], 1)
    idx = np.arange((n + 1) * (m + 1)).reshape(n + 1, m + 1)
    Q = np.stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(),
                  idx[:-1, 1:].ravel()], 1)
    return V, Q, idx
