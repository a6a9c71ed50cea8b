"""Mesh-to-mesh metrics for the neural tests and benchmark (as `curvenet eval`).

Points are sampled uniformly by area on each mesh and their distances are taken
to the *surface* of the other mesh (libigl), after scaling so the reference's
longest bounding-box side is 1.
"""

import numpy as np

from curvenet.core.geometry import sample_surface


def fscore(V, F, Vr, Fr, *, threshold=0.01, n=20000, seed=0):
    """``(F-score, Chamfer)`` of mesh (V, F) against reference (Vr, Fr)."""
    import igl
    V, Vr = np.asarray(V, float), np.asarray(Vr, float)
    F, Fr = np.asarray(F, np.int64), np.asarray(Fr, np.int64)
    if len(F) == 0:
        return 0.0, float("inf")
    scale = 1.0 / np.max(Vr.max(0) - Vr.min(0))
    rng = np.random.default_rng(seed)
    pa, pb = sample_surface(V, F, n, rng)[0], sample_surface(Vr, Fr, n, rng)[0]
    da = np.sqrt(igl.point_mesh_squared_distance(pa, Vr, Fr)[0]) * scale
    db = np.sqrt(igl.point_mesh_squared_distance(pb, V, F)[0]) * scale
    prec, rec = (da < threshold).mean(), (db < threshold).mean()
    f = 0.0 if prec + rec == 0 else 2 * prec * rec / (prec + rec)
    return float(f), float((da.mean() + db.mean()) / 2)
