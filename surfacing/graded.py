"""Graded knots around irregular vertices: B-spline pieces that follow the limit into the corner.

Near an irregular vertex (extraordinary valence, a dart, a T-junction) the
Catmull-Clark limit is not a uniform bicubic spline. Subdividing the span at that
vertex gives four children; three of them have regular corners only, so over them
the limit *is* the uniform bicubic spline of the finer control grid, and only the
child at the vertex stays irregular. After ``grade`` such steps an irregular square
of side ``2^-grade`` span remains. Breakpoints at ``i +- 2^-k`` (``k = 1 .. grade``)
around the vertex make every regular child a polynomial piece of the B-spline: the
exact limit there lies in the spline space (a C2 piecewise bicubic on a tensor grid
minus one corner cell extends into that cell), so the poles acting on irregular
spans are fitted by least squares to exact limit points over the graded cells, and
what remains approximated is the corner cell, which shrinks geometrically with
``grade`` while each piece stays one B-spline surface.

The exact limit over the regular children comes from local subdivision (only the
one-ring of the current corner span is subdivided at each step, Catmull & Clark
1978), over the corner cell from limit points (Halstead, Kass & DeRose 1993).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from .levels import Level, extended_poles_many, local_samples, subdivide_grids, submesh
from .splines import (BSplinePiece, basis, clamp_uniform, evaluate, project, span_points,
                      uniform_knots)

__all__ = ["DEFAULT_GRADE", "MAX_GRADE", "CornerChains", "corner_chains", "graded_breaks",
           "fit_graded"]

#: Breakpoints ``i +- 2^-k`` for ``k = 1 .. DEFAULT_GRADE`` around each irregular vertex.
DEFAULT_GRADE = 5
#: Most grades a piece is refitted with when it misses its tolerance.
MAX_GRADE = 10


class CornerChains:
    """Exact limit over spans at irregular vertices, at any point outside the last corner cell.

    Attributes
    ----------
    rings : (grade, k, 5, 5, 3) float64
        Per step and span: uniform bicubic poles of the span refined once more (a
        2 x 2 grid of children), exact over the three children away from the
        irregular vertex.
    corner : (k, r + 1, r + 1, 3) float64
        Exact limit points on the ``r x r`` lattice of the last corner cell.
    """

    def __init__(self, rings: np.ndarray, corner: np.ndarray):
        self.rings, self.corner = rings, corner

    def limit(self, site: np.ndarray, dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
        """Exact limit points ``(n, 3)`` of spans ``site (n,)`` at offsets ``dx, dy (n,)``
        in ``[0, 1]`` from their irregular vertex (in span units).

        Points inside the last corner cell (side ``2^-grade``) must lie on its
        lattice.
        """
        grade, r = len(self.rings), self.corner.shape[1] - 1
        m = np.maximum(dx, dy)
        out = np.empty((len(site), 3))
        inner = m <= 2.0 ** -grade
        i = np.rint(dx[inner] * 2 ** grade * r).astype(np.int64)
        j = np.rint(dy[inner] * 2 ** grade * r).astype(np.int64)
        if not np.allclose(np.c_[i, j], np.c_[dx[inner], dy[inner]] * 2 ** grade * r,
                           atol=1e-9):
            raise ValueError("points in the corner cell must lie on its sample lattice")
        out[inner] = self.corner[site[inner], i, j]
        step = np.clip(np.floor(-np.log2(np.maximum(m, 1e-300))).astype(np.int64), 0,
                       max(grade - 1, 0))
        for k in np.unique(step[~inner]):
            sel = np.flatnonzero(~inner & (step == k))
            s, t = dx[sel] * 2.0 ** (k + 1), dy[sel] * 2.0 ** (k + 1)
            a = np.minimum(np.floor(s), 1).astype(np.int64)
            b = np.minimum(np.floor(t), 1).astype(np.int64)
            ia, ib = a[:, None] + np.arange(4), b[:, None] + np.arange(4)
            P = self.rings[k][site[sel][:, None, None], ia[:, :, None], ib[:, None, :]]
            out[sel] = span_points(P, s - a, t - b)
        return out


def corner_chains(lv: Level, spans: np.ndarray, grade: int, sample_levels: int) -> CornerChains:
    """Follow each span's irregular vertex ``grade`` subdivision steps down.

    Parameters
    ----------
    lv : Level
        The level the spans live on.
    spans : (k, 2, 2) int64
        Vertex ids of spans of ``lv`` with the irregular vertex at ``[0, 0]``.
    grade : int
    sample_levels : int
        The corner cell's lattice has ``2^sample_levels`` intervals per side.

    Returns
    -------
    CornerChains
    """
    grids = np.asarray(spans, np.int64)
    rings = []
    for _ in range(grade):
        V, Q, se, cr, grids = submesh(lv, grids)
        V, Q, se, cr, H = subdivide_grids(V, Q, se, cr, list(grids), 1)
        lv = Level(V, Q, se, cr)
        rings.append(extended_poles_many(lv, np.stack(H))[0])
        grids = np.stack([h[:2, :2] for h in H])
    rings = np.stack(rings) if rings else np.zeros((0, len(grids), 5, 5, 3))
    return CornerChains(rings, local_samples(lv, list(grids), sample_levels))


def graded_breaks(m: int, vertices, grade: int) -> np.ndarray:
    """Breakpoints ``0 .. m`` plus ``i +- 2^-k`` (``k = 1 .. grade``) around each ``i``.

    Returns
    -------
    (b,) float64, sorted, in ``[0, m]``
    """
    off = 2.0 ** -np.arange(1, grade + 1)
    v = np.asarray(vertices, np.float64)[:, None]
    b = np.unique(np.r_[np.arange(m + 1.0), (v + off).ravel(), (v - off).ravel()])
    return b[(b >= 0) & (b <= m)]


def _cell_samples(b: np.ndarray, r: int):
    """``r`` samples per cell of breakpoints ``b``: positions, index in the cell, and
    the lowest and highest cell each belongs to."""
    w = np.diff(b)
    k = len(w)
    x = np.r_[(b[:-1, None] + w[:, None] * np.arange(r) / r).ravel(), b[-1]]
    t = np.r_[np.tile(np.arange(r), k), r]
    hi = np.r_[np.repeat(np.arange(k), r), k - 1]
    return x, t, np.where(t == 0, np.maximum(hi - 1, 0), hi), hi


def fit_graded(E, off, centres, exact, *, grade: int, r: int, tol: float):
    """Graded-knot B-spline of a piece with irregular spans, fitted to the exact limit.

    Parameters
    ----------
    E : (M + 3, N + 3, 3) float64
        Uniform poles of the piece (exact on its regular spans).
    off : (M + 1, N + 1) bool
        Grid vertices where the uniform spline misses the limit; the spans around
        them are refitted.
    centres : (c, 2) int64
        The irregular grid vertices among them: knots are graded around these.
    exact : callable
        ``exact(u, v) -> (n, 3)`` exact limit points at piece parameters inside
        irregular spans (:meth:`CornerChains.limit` behind a lookup).
    grade : int
    r : int
        Samples per cell side for the measure; the fit uses every other one.
    tol : float
        Model units: errors above it are re-measured as distances to the surface.

    Returns
    -------
    poles : (a, b, 3) float64
    knots_u, knots_v : clamped knot vectors
    err : (r M + 1, r N + 1) float64
        Error at the uniform lattice of the spans (model units; zero where exact).
    deviation : float
        Largest error over all measured points (model units).
    """
    M, N = off.shape[0] - 1, off.shape[1] - 1
    bad = off[:-1, :-1] | off[1:, :-1] | off[:-1, 1:] | off[1:, 1:]
    bu = graded_breaks(M, centres[:, 0], grade)
    bv = graded_breaks(N, centres[:, 1], grade)
    P, tu = clamp_uniform(E, M, 0, bu)
    P, tv = clamp_uniform(P, N, 1, bv)
    bi, bj = np.nonzero(bad)                   # poles whose support meets an irregular span
    ou = (tu[:-4, None] < bi + 1) & (tu[4:, None] > bi)
    ov = (tv[:-4, None] < bj + 1) & (tv[4:, None] > bj)
    free = (ou.astype(np.int64) @ ov.T.astype(np.int64)) > 0
    ncu, ncv = len(bu) - 1, len(bv) - 1
    touched = np.zeros((ncu, ncv), bool)       # cells those poles act on (pole a: a-3 .. a)
    for du in range(4):
        for dv in range(4):
            touched |= free[du:du + ncu, dv:dv + ncv]
    xu, su, lu, hu = _cell_samples(bu, r)
    xv, sv, lov, hv = _cell_samples(bv, r)
    inc = (touched[lu][:, lov] | touched[lu][:, hv] | touched[hu][:, lov]
           | touched[hu][:, hv])
    iu, iv = np.nonzero(inc)
    u, v = xu[iu], xv[iv]
    si = np.clip(np.floor(u).astype(np.int64), 0, M - 1)
    sj = np.clip(np.floor(v).astype(np.int64), 0, N - 1)
    irr = bad[si, sj]
    S = np.empty((len(u), 3))
    uniform = BSplinePiece(E, uniform_knots(M), uniform_knots(N), -1, True, 0.0)
    S[~irr] = evaluate(uniform, u[~irr], v[~irr])
    S[irr] = exact(u[irr], v[irr])
    # least squares for the free poles on every other sample
    fit = (su[iu] % 2 == 0) & (sv[iv] % 2 == 0)
    cu, wu = basis(u[fit], tu, 0)
    cv, wv = basis(v[fit], tv, 0)
    nv = P.shape[1]
    cols = (cu[:, :, None] * nv + cv[:, None, :]).reshape(len(cu), 16)
    vals = (wu[:, :, None] * wv[:, None, :]).reshape(len(cu), 16)
    lut = np.full(free.size, -1, np.int64)
    lut[free.ravel()] = np.arange(int(free.sum()))
    fc = lut[cols]
    flat = P.reshape(-1, 3)
    rhs = S[fit] - np.einsum("nk,nkc->nc", np.where(fc < 0, vals, 0.0), flat[cols])
    rows = np.repeat(np.arange(len(cu)), 16).reshape(len(cu), 16)
    A = sp.csr_matrix((vals[fc >= 0], (rows[fc >= 0], fc[fc >= 0])),
                      shape=(len(cu), int(free.sum())))
    X = splu((A.T @ A).tocsc()).solve(np.asarray(A.T @ rhs))
    flat = flat.copy()
    flat[free.ravel()] = X
    P = flat.reshape(P.shape)
    pc = BSplinePiece(P, tu, tv, -1, False, 0.0)
    err = _distances(pc, S, u, v, tol)
    lattice = np.zeros((r * M + 1, r * N + 1))
    a, b = u * r, v * r
    on = (a == np.rint(a)) & (b == np.rint(b))
    lattice[a[on].astype(np.int64), b[on].astype(np.int64)] = err[on]
    return P, tu, tv, lattice, float(err.max(initial=0.0))


def _distances(pc, S: np.ndarray, u: np.ndarray, v: np.ndarray, tol: float) -> np.ndarray:
    """Errors of ``pc`` at ``(u, v)`` against ``S (n, 3)``: distances to the surface
    (Gauss-Newton projection) from the largest down, until the rest cannot exceed
    the largest distance; below that, the distance at equal parameters (an upper
    bound)."""
    err = np.linalg.norm(evaluate(pc, u, v) - S, axis=1)
    cand = np.flatnonzero(err > tol)
    cand = cand[np.argsort(-err[cand])]
    best, start, chunk = 0.0, 0, 64
    while start < len(cand) and err[cand[start]] > best:
        c = cand[start:start + chunk]
        err[c] = np.minimum(err[c], project(pc, S[c], u[c], v[c])[2])
        best = max(best, float(err[c].max()))
        start, chunk = start + chunk, chunk * 2
    return err
