"""Bicubically blended Coons patches (Orbay & Kara 2011, Sec. 4.2; Coons 1967).

Corner and side numbering used throughout (``u`` to the right, ``v`` up)::

    P01 ----- top c2(u) ----> P11
     ^                         ^
     |                         |
    left c3(v)            right c1(v)
     |                         |
    P00 --- bottom c0(u) ---> P10

The patch

    S(u, v) = (1 - h(v)) c0(u) + h(v) c2(u) + (1 - h(u)) c3(v) + h(u) c1(v)
              - [1 - h(u), h(u)] [[P00, P01], [P10, P11]] [1 - h(v), h(v)]^T

with the cubic Hermite blend ``h(t) = 3 t^2 - 2 t^3`` interpolates all four
boundary curves exactly (``h(0) = 0``, ``h(1) = 1``), and ``h'(0) = h'(1) = 0``
so the blend adds no cross-boundary slope of its own.
"""

from __future__ import annotations

import numpy as np

from curvenet.core.geometry import sample_at

__all__ = ["hermite_blend", "coons_grid", "coons_eval"]


def hermite_blend(t: np.ndarray) -> np.ndarray:
    """Cubic Hermite blending function ``h(t) = 3 t^2 - 2 t^3`` (elementwise)."""
    t = np.asarray(t, dtype=np.float64)
    return t * t * (3.0 - 2.0 * t)


def _check_sides(bottom, right, top, left):
    out = []
    for name, c in (("bottom", bottom), ("right", right), ("top", top), ("left", left)):
        c = np.asarray(c, dtype=np.float64)
        if c.ndim != 2 or c.shape[1] != 3 or len(c) < 2:
            raise ValueError(f"{name}: expected an (m, 3) array with m >= 2, got shape {c.shape}")
        out.append(c)
    b, r, t, lf = out
    if len(b) != len(t) or len(lf) != len(r):
        raise ValueError(f"opposite sides need equal sample counts: bottom {len(b)} / top "
                         f"{len(t)}, left {len(lf)} / right {len(r)}")
    return b, r, t, lf


def coons_grid(bottom, right, top, left) -> np.ndarray:
    """Sample a bicubically blended Coons patch on the grid of its boundary samples.

    Parameters
    ----------
    bottom, top : (p + 1, 3) float64
        ``c0`` from P00 to P10 and ``c2`` from P01 to P11, sampled at ``u_i = i / p``.
    right, left : (q + 1, 3) float64
        ``c1`` from P10 to P11 and ``c3`` from P00 to P01, sampled at ``v_j = j / q``.

    Returns
    -------
    grid : (p + 1, q + 1, 3) float64
        ``grid[i, j] = S(i / p, j / q)``; its border rows and columns equal the given
        curves exactly (bottom and top win at the corners if the curves disagree).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.linspace(0, 1, 5)[:, None]
    >>> b, tp = t * [1, 0, 0], t * [1, 0, 0] + [0, 1, 0]
    >>> lf, r = t * [0, 1, 0], t * [0, 1, 0] + [1, 0, 0]
    >>> g = coons_grid(b, r, tp, lf)
    >>> bool(np.allclose(g[..., 2], 0))
    True

    References
    ----------
    Orbay & Kara 2011, Sec. 4.2 (Fig. 6): control mesh sampled from a Coons patch.
    """
    b, r, t, lf = _check_sides(bottom, right, top, left)
    p, q = len(b) - 1, len(lf) - 1
    hu = hermite_blend(np.linspace(0.0, 1.0, p + 1))[:, None, None]   # (p+1, 1, 1)
    hv = hermite_blend(np.linspace(0.0, 1.0, q + 1))[None, :, None]   # (1, q+1, 1)
    p00, p10, p01, p11 = b[0], b[-1], t[0], t[-1]
    ruled_v = (1 - hv) * b[:, None] + hv * t[:, None]
    ruled_u = (1 - hu) * lf[None] + hu * r[None]
    corner = ((1 - hu) * (1 - hv) * p00 + hu * (1 - hv) * p10
              + (1 - hu) * hv * p01 + hu * hv * p11)
    g = ruled_v + ruled_u - corner
    g[:, 0], g[:, -1] = b, t                      # exact boundaries (no round-off)
    g[0, 1:-1], g[-1, 1:-1] = lf[1:-1], r[1:-1]
    return g


def coons_eval(bottom, right, top, left, uv: np.ndarray) -> np.ndarray:
    """Evaluate a bicubically blended Coons patch at arbitrary parameters.

    Parameters
    ----------
    bottom, right, top, left : (m_k, 3) float64
        Boundary polylines as in :func:`coons_grid` (any sample counts; each is
        parametrised by normalised arc length).
    uv : (k, 2) float64 in [0, 1]^2

    Returns
    -------
    (k, 3) float64
    """
    curves = [np.asarray(c, dtype=np.float64) for c in (bottom, right, top, left)]
    uv = np.asarray(uv, dtype=np.float64)
    u, v = uv[:, 0], uv[:, 1]
    c0, c1, c2, c3 = (sample_at(curves[0], u), sample_at(curves[1], v),
                      sample_at(curves[2], u), sample_at(curves[3], v))
    hu, hv = hermite_blend(u)[:, None], hermite_blend(v)[:, None]
    p00, p10, p01, p11 = curves[0][0], curves[0][-1], curves[2][0], curves[2][-1]
    corner = ((1 - hu) * (1 - hv) * p00 + hu * (1 - hv) * p10
              + (1 - hu) * hv * p01 + hu * hv * p11)
    return (1 - hv) * c0 + hv * c2 + (1 - hu) * c3 + hu * c1 - corner
