"""Small surface-comparison helper for the surfacing tests and benchmark.

Chamfer distance (mean of the two mean point-to-surface distances) and F-score at a
threshold, after scaling so the reference's longest bounding-box side is 1; points
are sampled uniformly on each mesh and measured to the *other mesh's surface*
(igl.point_mesh_squared_distance), so the sampling density sets no floor.
"""

from __future__ import annotations

import numpy as np

from curvenet.core.geometry import sample_surface


def _dist(points, V, F):
    import igl
    d2, _, _ = igl.point_mesh_squared_distance(points, V, F.astype(np.int64))
    return np.sqrt(np.maximum(d2, 0.0))


def compare(V, F, Vref, Fref, *, n=20000, threshold=0.01, seed=0):
    """Return dict(chamfer, fscore, precision, recall, hausdorff) in reference-scaled units."""
    V, Vref = np.asarray(V, float), np.asarray(Vref, float)
    F, Fref = np.asarray(F, np.int64), np.asarray(Fref, np.int64)
    lo = Vref.min(0)
    scale = 1.0 / (Vref.max(0) - lo).max()
    V, Vref = (V - lo) * scale, (Vref - lo) * scale
    rng = np.random.default_rng(seed)
    d_pr = _dist(sample_surface(V, F, n, rng)[0], Vref, Fref)     # ours -> reference (precision)
    d_rc = _dist(sample_surface(Vref, Fref, n, rng)[0], V, F)      # reference -> ours (recall)
    p, r = (d_pr < threshold).mean(), (d_rc < threshold).mean()
    f = 2 * p * r / (p + r) if p + r > 0 else 0.0
    return {"chamfer": 0.5 * (d_pr.mean() + d_rc.mean()), "fscore": f, "precision": p,
            "recall": r, "hausdorff": max(d_pr.max(), d_rc.max())}
