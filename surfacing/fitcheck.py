"""Checks that judge the candidate fits of one control net (``fit="auto"`` of
:func:`surfacing.surface_loops`): whether the drawn sections imply the swept shape more
firmly than the fairness energy, and whether a fit has left its loops' curves.

A direct fit interpolates the curve samples exactly and measures its fairness over the
whole net. Where a loop's boundary is a zig-zag (a small patch between close
crossings, drawn with a per-sample jitter as large as the patch), the fairness of a
fine net leaves it a near-free direction, and the exact interpolation of the zig-zag
drives the inside out along it: a petal several times the model's size, every curve
sample still on it. Such a fit is not a surface of that loop, whatever its bending
energy (a bent petal and a bent sphere have the same energy at any size).
"""

from __future__ import annotations

import numpy as np

__all__ = ["ESCAPE", "escape", "sweep_check"]

#: A fit has left a loop where the limit point of one of the loop's control vertices
#: lies outside the box of the loop's curve samples by more than ``ESCAPE`` times that
#: box's diagonal. A surface spanning a loop bulges out of the loop's box by a fraction
#: of its size (a hemisphere over a circle by a third of the box's diagonal); leaving it
#: by twice the diagonal is no span. (The figures of the public inputs and of the petals
#: are in benchmarks/README.md, "fits that leave their loops".)
ESCAPE = 2.0


def escape(P, quads, face_patch, on_curve, target) -> np.ndarray:
    """Per loop, how far its vertices ``P`` leave the box of its curve samples.

    Parameters
    ----------
    P : (n, 3) float64
        Limit points of one fit's control vertices (or the control points themselves).
    quads : (f, 4) int64
        Control quads; ``face_patch (f,) int64`` their loops.
    on_curve : (n,) bool
        Control vertices that interpolate a curve sample, ``target (n, 3) float64``.

    Returns
    -------
    (loops,) float64
        The largest distance of a loop's vertices outside the box of its on-curve
        targets, as a fraction of the box's diagonal (0 inside); a loop with
        no on-curve vertex gets 0.

    Examples
    --------
    >>> q = np.array([[0, 1, 2, 3]])
    >>> on = np.ones(4, bool)
    >>> T = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    >>> float(escape(T, q, np.array([0]), on, T)[0])
    0.0
    >>> P = T.copy(); P[2, 2] = 2.828
    >>> round(float(escape(P, q, np.array([0]), on, T)[0]), 3)
    2.0
    """
    face_patch = np.asarray(face_patch, dtype=np.int64)
    loop = np.repeat(face_patch, quads.shape[1])
    v = np.asarray(quads).ravel()
    n_loops = int(face_patch.max()) + 1 if len(face_patch) else 0
    lo = np.full((n_loops, 3), np.inf)
    hi = np.full((n_loops, 3), -np.inf)
    on = on_curve[v]
    np.minimum.at(lo, loop[on], target[v[on]])
    np.maximum.at(hi, loop[on], target[v[on]])
    keep = np.isfinite(lo[:, 0])[loop]           # vertices of loops that have a box
    lv, vv = loop[keep], v[keep]
    out = np.linalg.norm(np.maximum(lo[lv] - P[vv], 0.0) + np.maximum(P[vv] - hi[lv], 0.0),
                         axis=1)
    size = np.linalg.norm(hi[lv] - lo[lv], axis=1)
    ratio = np.zeros(n_loops)
    np.maximum.at(ratio, lv, out / np.maximum(size, np.finfo(float).tiny))
    return ratio


def sweep_check(spread, P_lsq, P_sweep, diag: float) -> dict:
    """Whether the drawn sections imply their swept shape more firmly than the fairness
    energy does another: ``{"spread": s, "departure": d}``, fractions of ``diag``.

    ``spread`` (n,) float64 is :attr:`ControlMesh.spread`, NaN outside the swept loops;
    ``P_lsq``, ``P_sweep`` (n, 3) float64 the two fits. ``s``: its RMS over the control
    vertices inside the swept loops, i.e. how much the swept shape is left open by its
    sides (the sweep along ``u`` against the one along ``v``). ``d``: the RMS distance there
    between the least-squares fit and the swept fit. Where the departure is the
    larger, the least-squares fit moved the surface off a shape that the sections
    predict, two ways, more alike than that move (a tall elliptic tube drawn as three
    meridians: the two sweeps agree to the curves' sampling, the least-squares fit
    rounds the tube between them); the sweep is kept although it bends more.
    """
    inside = np.isfinite(spread)
    if not inside.any():
        return {"spread": 0.0, "departure": 0.0}
    dev = np.linalg.norm(P_lsq[inside] - P_sweep[inside], axis=1)
    return {"spread": float(np.sqrt(np.mean(spread[inside] ** 2))) / diag,
            "departure": float(np.sqrt(np.mean(dev ** 2))) / diag}
