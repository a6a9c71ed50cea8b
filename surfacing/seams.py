"""Continuity report of B-spline pieces: G0 gap, G1 angle and deviation per seam.

Pieces sharing a border edge of the subdivided control mesh are matched sample by
sample (equal keys for equal points along the edge); gaps are distances of one
border to the other face, angles those between the two faces' normals.
"""

from __future__ import annotations

import numpy as np

from .levels import ControlNet, piece_grids
from .splines import EXACT_TOL, BSplinePiece, evaluate, project

__all__ = ["border_samples", "seam_report"]


def _nanmax(a: np.ndarray) -> float:
    return float(np.nanmax(a)) if np.isfinite(a).any() else 0.0


def border_samples(pid: int, G: np.ndarray, r: int, err: np.ndarray, n: int):
    """Keys, parameters, errors and piece-corner flags of a piece's border samples.

    A sample at fraction ``f / r`` of the level's border edge ``(a, b)`` has the key
    ``(min, max, f)`` (``f`` counted from ``min``), a sample at a vertex ``(a, a, 0)``:
    pieces sharing a border edge get equal keys for equal points.
    """
    M, N = G.shape[0] - 1, G.shape[1] - 1
    out = []
    along_u, along_v = np.arange(r * M + 1), np.arange(r * N + 1)
    for line, ii, jj in ((G[:, 0], along_u, 0), (G[:, N], along_u, r * N),
                       (G[0, :], 0, along_v), (G[M, :], r * M, along_v)):
        t = np.arange(r * (len(line) - 1) + 1)
        k, f = t // r, t % r
        a, b = line[k], line[np.minimum(k + 1, len(line) - 1)]
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        f = np.where(a == lo, f, r - f)
        vert = np.where(f == 0, lo, hi)
        key = np.where((f == 0) | (f == r), vert * (n * r + r) + vert * r,
                       lo * (n * r + r) + hi * r + f)
        ii, jj = np.broadcast_arrays(ii, jj)
        out.append((key, ii, jj))
    key, ii, jj = (np.concatenate(x) for x in zip(*out))
    key, first = np.unique(key, return_index=True)
    ii, jj = ii[first], jj[first]
    corner = ((ii == 0) | (ii == r * M)) & ((jj == 0) | (jj == r * N))
    return (np.full(len(key), pid), key, ii / r, jj / r, err[ii, jj], corner)


#: Normals where ``du`` and ``dv`` are closer than this (sine of their angle, about 3
#: degrees) are left out of G1: tangential patch corners, where ``du x dv`` is noise.
MIN_SINE = 0.05


def _normals(piece: BSplinePiece, u, v):
    """Points and unit normals; NaN normals where ``du x dv`` degenerates."""
    P, du, dv = evaluate(piece, u, v, derivatives=True)
    n = np.cross(du, dv)
    ln = np.linalg.norm(n, axis=1, keepdims=True)
    ok = ln > MIN_SINE * np.linalg.norm(du, axis=1, keepdims=True) * np.linalg.norm(
        dv, axis=1, keepdims=True)
    return P, np.where(ok, n / np.maximum(ln, 1e-300), np.nan)


def seam_report(pieces: list, border: list, net: ControlNet) -> list:
    """Continuity report of every pair of pieces sharing at least one border segment."""
    pid, vid, u, v, err, corner = (np.concatenate(x) for x in zip(*border))
    P = np.empty((len(pid), 3))
    Nrm = np.empty((len(pid), 3))
    by = np.argsort(pid, kind="stable")
    at = np.searchsorted(pid[by], np.arange(len(pieces) + 1))
    for k, piece in enumerate(pieces):
        m = by[at[k]:at[k + 1]]
        P[m], Nrm[m] = _normals(piece, u[m], v[m])
    order = np.lexsort((pid, vid))
    pid, vid, P, Nrm, err = pid[order], vid[order], P[order], Nrm[order], err[order]
    corner = corner[order]
    u, v = u[order], v[order]
    starts = np.flatnonzero(np.r_[True, vid[1:] != vid[:-1]])
    counts = np.diff(np.r_[starts, len(vid)])
    pairs = []                                           # (entry i, entry j)
    for c in np.unique(counts[counts > 1]):
        s = starts[counts == c]
        for x in range(c):
            for y in range(x + 1, c):
                pairs.append(np.stack([s + x, s + y], 1))
    if not pairs:
        return []
    pr = np.concatenate(pairs)
    pr = pr[pid[pr[:, 0]] != pid[pr[:, 1]]]
    gap = np.linalg.norm(P[pr[:, 0]] - P[pr[:, 1]], axis=1)
    far = np.flatnonzero(gap > EXACT_TOL * net.diagonal)   # geometric gap: onto the other
    for k in np.unique(pid[pr[far, 1]]):
        f = far[pid[pr[far, 1]] == k]
        j = pr[f, 1]
        gap[f] = np.minimum(gap[f], project(pieces[k], P[pr[f, 0]], u[j], v[j])[2])
    gap /= max(net.diagonal, 1e-300)
    cos = np.einsum("ij,ij->i", Nrm[pr[:, 0]], Nrm[pr[:, 1]])
    ang = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))     # NaN where degenerate
    at_corner = corner[pr[:, 0]] | corner[pr[:, 1]]
    dev = np.maximum(err[pr[:, 0]], err[pr[:, 1]])
    key = np.sort(np.stack([pid[pr[:, 0]], pid[pr[:, 1]]], 1), axis=1)
    uk, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    inv = inv.ravel()
    curves, sharp = _piece_curves(net)
    n_sides: dict = {}                                 # pieces bordering each level-0 edge
    for c in curves:
        for e in c:
            n_sides[e] = n_sides.get(e, 0) + 1
    out = []
    by = np.argsort(inv, kind="stable")                  # each pair's samples, in a slice
    at = np.r_[0, np.cumsum(cnt)]
    for g in np.flatnonzero(cnt > 1):                  # a shared point is not a seam
        m = by[at[g]:at[g + 1]]
        a, b = (int(x) for x in uk[g])
        shared = curves[a].keys() & curves[b].keys()
        flipped = bool(np.nanmean(cos[m]) < 0) if np.isfinite(cos[m]).any() else False
        a_m = 180.0 - ang[m] if flipped else ang[m]
        ends = at_corner[m]
        out.append({"pieces": [a, b], "patches": [pieces[a].patch, pieces[b].patch],
                    "curves": sorted({curves[a][e] for e in shared} - {-1}),
                    "crease": bool(shared) and all(e in sharp or n_sides[e] > 2 for e in shared),
                    "manifold": all(n_sides[e] == 2 for e in shared), "flipped": flipped,
                    "gap": float(gap[m].max()),
                    "angle": _nanmax(a_m[~ends]), "corner_angle": _nanmax(a_m[ends]),
                    "deviation": float(dev[m].max())})
    return out


def _piece_curves(net: ControlNet):
    """Per piece: {level-0 border edge key: curve index or -1}; and the sharp keys."""
    n = len(net.vertices)
    edge_curve = {}
    for c, ids in enumerate(net.curve_vids):
        ids = np.asarray(ids, np.int64)
        for k in (np.minimum(ids[:-1], ids[1:]) * n + np.maximum(ids[:-1], ids[1:])).tolist():
            edge_curve[k] = c
    se = np.asarray(net.sharp_edges, np.int64).reshape(-1, 2)
    sharp = set((se.min(1) * n + se.max(1)).tolist())
    out = []
    for _, G in piece_grids(net.quads, net.face_patch):
        ring = np.r_[G[:, 0], G[-1, 1:], G[-2::-1, -1], G[0, -2::-1]]
        a, b = ring[:-1], ring[1:]
        keys = (np.minimum(a, b) * n + np.maximum(a, b)).tolist()
        out.append({k: edge_curve.get(k, -1) for k in keys})
    return out, sharp
