"""Crease curves and corner vertices for the Catmull-Clark control mesh.

A curve becomes a crease when it is labelled so, or when the two patches on it meet
at a dihedral angle above ``crease_angle``. The dihedral angle is estimated from the
curve network itself, at both ends of the curve: each patch's tangent plane there is
spanned by the curve's end tangent and the tangent of the next curve of the loop at
that junction (first-order geometry of the sketch, independent of the control mesh's
resolution). Where those two tangents are nearly parallel (a T-junction or a smooth
closed loop) the normal of the patch's control quads at the junction is used
instead; that normal also fixes the sign of the cross product.

Corners (vertices that subdivision keeps fixed) are junctions where three or more
sharp curves meet (crease, open boundary, or non-manifold), or where exactly two
sharp curves meet at a turn above the straight angle.

Notes
-----
Orbay & Kara 2011 keep surfaces smooth everywhere and leave creases to future work
(Sec. 5); this module adds the "conventional crease formulation" they name, with the
sharp rules of DeRose et al. 1998 in :mod:`.catmull_clark`.
"""

from __future__ import annotations

import numpy as np

from curvenet.core.tolerances import DIVISION_GUARD

from .controlmesh import ControlMesh
from .polyline import end_tangents

__all__ = ["DEFAULT_CREASE_ANGLE", "curve_uses", "dihedral_angles", "sharp_structure"]

#: Dihedral angle in degrees above which a curve shared by two patches becomes a crease.
DEFAULT_CREASE_ANGLE = 30.0


def curve_uses(loops: list, n_curves: int) -> np.ndarray:
    """Number of loop traversals of each curve, ``(C,) int64``."""
    cnt = np.zeros(n_curves, dtype=np.int64)
    for lp in loops:
        for ci, _ in lp:
            cnt[ci] += 1
    return cnt


def _patch_vertex_normals(cm: ControlMesh):
    """Area-weighted normal of each patch's quads at each of its vertices (keyed lookup)."""
    V, q = cm.vertices, cm.quads
    fn = np.cross(V[q[:, 2]] - V[q[:, 0]], V[q[:, 3]] - V[q[:, 1]])
    n = len(V)
    keys = (cm.face_patch[:, None] * n + q).ravel()
    vals = np.repeat(fn, 4, axis=0)
    uk, inv = np.unique(keys, return_inverse=True)
    acc = np.zeros((len(uk), 3))
    np.add.at(acc, inv, vals)
    acc /= np.maximum(np.linalg.norm(acc, axis=1, keepdims=True), DIVISION_GUARD)

    def lookup(patch: int, vertex: int) -> np.ndarray:
        k = patch * n + vertex
        i = np.searchsorted(uk, k)
        return acc[i] if i < len(uk) and uk[i] == k else np.zeros(3)
    return lookup


def dihedral_angles(cm: ControlMesh, curves: list,
                    straight_angle: float = 30.0) -> np.ndarray:
    """Dihedral angle (degrees) between the two patches on each curve.

    Parameters
    ----------
    cm : ControlMesh
    curves : list of (m_i, 3) float64
        The dense network curves (for end tangents).
    straight_angle : float
        Degrees; tangents closer to parallel than this use the control-quad normal.

    Returns
    -------
    (C,) float64
        Smaller of the angles between the patch normals at the two ends (a crease
        must look sharp at both ends, which discounts a rough tangent at one junction);
        NaN for curves not used by exactly two loop traversals.
    """
    C = len(curves)
    tang = np.array([np.stack(end_tangents(c)) for c in curves])      # (C, 2, 3)
    normal_of = _patch_vertex_normals(cm)
    sin_min = np.sin(np.radians(straight_angle))
    rec: dict = {}
    for j, lp in enumerate(cm.loops):
        n = len(lp)
        for i, (ci, fwd) in enumerate(lp):
            for at_start in (True, False):
                other_ci, other_fwd = lp[(i - 1) % n] if at_start else lp[(i + 1) % n]
                end = (0 if fwd else 1) if at_start else (1 if fwd else 0)
                t_c = tang[ci, end]
                # the neighbour's tangent pointing away from the shared junction
                o_end = (1 if other_fwd else 0) if at_start else (0 if other_fwd else 1)
                t_o = tang[other_ci, o_end]
                nrm = np.cross(t_c, t_o) if at_start else np.cross(t_o, t_c)
                m = normal_of(j, int(cm.junction_of_end[ci, end]))
                ln = np.linalg.norm(nrm)
                if ln < sin_min:
                    nrm = m
                else:
                    nrm = nrm / ln
                    if np.dot(nrm, m) < 0:
                        nrm = -nrm
                rec.setdefault((ci, end), []).append(nrm)
    out = np.full(C, np.nan)
    for ci in range(C):
        a = [rec.get((ci, e), []) for e in (0, 1)]
        if len(a[0]) == 2 and len(a[1]) == 2:
            ang = [np.degrees(np.arccos(np.clip(np.dot(x[0], x[1]), -1, 1))) for x in a]
            out[ci] = float(np.min(ang))
    return out


def sharp_structure(cm: ControlMesh, curves: list, crease_curves=(), *,
                    crease_angle: float | None = DEFAULT_CREASE_ANGLE,
                    straight_angle: float = 30.0):
    """Crease curves, sharp control edges and corner vertices.

    Parameters
    ----------
    cm : ControlMesh
    curves : list of (m_i, 3) float64
    crease_curves : iterable of int
        Curves labelled crease.
    crease_angle : float or None
        Degrees; None turns dihedral detection off.
    straight_angle : float
        Degrees; two sharp curves turning more at a junction make it a corner.

    Returns
    -------
    crease : (C,) bool
        Labelled or detected crease curves.
    detected : list of int
        Curves made creases by the dihedral test (not labelled).
    sharp_edges : (s, 2) int64
        Control edges along crease curves.
    corners : (n,) bool
        Corner control vertices.
    dihedral : (C,) float64
    """
    C = len(curves)
    crease = np.zeros(C, bool)
    for ci in crease_curves:
        ci = int(ci)
        if not 0 <= ci < C:
            raise ValueError(f"crease_curves: index {ci} out of range [0, {C})")
        crease[ci] = True
    uses = curve_uses(cm.loops, C)
    dih = dihedral_angles(cm, curves, straight_angle)
    detected: list = []
    if crease_angle is not None:
        if not 0.0 <= crease_angle <= 180.0:
            raise ValueError(f"crease_angle: expected degrees in [0, 180], got {crease_angle}")
        hit = np.nan_to_num(dih, nan=0.0) > crease_angle
        detected = [int(i) for i in np.flatnonzero(hit & ~crease & (uses > 0))]
        crease |= hit
    crease &= uses > 0
    sharp_c = crease | ((uses != 2) & (uses > 0))
    se = [np.stack([cm.curve_vids[c][:-1], cm.curve_vids[c][1:]], 1)
          for c in np.flatnonzero(crease)]
    sharp_edges = np.concatenate(se) if se else np.zeros((0, 2), np.int64)
    # corners at junctions
    corners = np.zeros(len(cm.vertices), bool)
    inc: dict = {}
    for c in np.flatnonzero(sharp_c):
        t0, t1 = end_tangents(curves[c])
        inc.setdefault(int(cm.junction_of_end[c, 0]), []).append(t0)
        inc.setdefault(int(cm.junction_of_end[c, 1]), []).append(t1)
    cos_straight = np.cos(np.radians(straight_angle))
    for v, ts in inc.items():
        if len(ts) >= 3:
            corners[v] = True
        elif len(ts) == 2 and np.dot(ts[0], -ts[1]) < cos_straight:
            corners[v] = True
    return crease, detected, sharp_edges, corners, dih
