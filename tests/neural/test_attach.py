"""The stroke-constrained fairing of the extracted mesh (neural.attach): on a shrunken,
bumpy sphere with great-circle strokes of the true one it removes the bumps and brings the
surface back onto the strokes."""

import numpy as np
import trimesh

from curvenet.core.fidelity import stroke_fidelity
from curvenet.evaluate import roughness
from curvenet.neural.attach import attach_to_strokes


def test_attach_takes_bumps_out_and_the_surface_onto_the_strokes():
    s = trimesh.creation.icosphere(5)
    n = s.vertices / np.linalg.norm(s.vertices, axis=1)[:, None]
    bumps = 0.01 * (np.sin(40 * n[:, 0]) * np.sin(40 * n[:, 1]))[:, None] * n
    V = 0.96 * n + bumps                                   # shrunk 4% and bumpy
    t = np.linspace(0, 2 * np.pi, 400)
    strokes = [np.c_[np.cos(t), np.sin(t), 0 * t], np.c_[np.cos(t), 0 * t, np.sin(t)],
               np.c_[0 * t, np.cos(t), np.sin(t)]]
    h = 0.05                                               # a grid cell of the extraction
    X, rep = attach_to_strokes(V, s.faces, strokes, h, cutoff=6.0, weight=100.0)
    assert rep["pulled"] == rep["samples"] > 0             # every sample within 3 cells
    before, after = (stroke_fidelity((P, s.faces), strokes)["fidelity"] for P in (V, X))
    assert before < 0.1 and after > 0.95
    assert roughness((X, s.faces))["median"] < 0.5 * roughness((V, s.faces))["median"]
    # nearer the true sphere next to the strokes, and no farther elsewhere (between
    # the strokes the fairing keeps the extracted shape: it pulls, it does not inflate)
    near = np.min(np.abs(n), axis=1) < 2 * h                # within 2 cells of a circle
    err = [np.abs(np.linalg.norm(P, axis=1) - 1.0) for P in (V, X)]
    assert err[1][near].mean() < 0.4 * err[0][near].mean()
    assert err[1][~near].mean() < err[0][~near].mean()
    # far strokes are left out, and a zero pull is the low-pass alone
    far = [np.c_[3 + np.cos(t), np.sin(t), 0 * t]]
    Y, rep = attach_to_strokes(V, s.faces, far, h, cutoff=6.0, weight=100.0)
    assert rep["pulled"] == 0
    Z, _ = attach_to_strokes(V, s.faces, strokes, h, cutoff=6.0, weight=0.0)
    np.testing.assert_allclose(Y, Z, atol=1e-9)
