"""SharpNet feature functions: the Laplace Green's function integrated over a feature set M.

The feature function of Niu et al. 2025 (Eq. 5) is

    f(x) = int_M G(x, y) dS_y,    G = ln r / (2 pi) in 2D,   G = -1 / (4 pi r) in 3D,

the single-layer potential of M with unit density. It is continuous everywhere, harmonic (so
C-infinity) off M, and its normal derivative jumps by exactly 1 across M (Eq. 2 with g = 1).
M is a polyline (2D: segments) or a triangle mesh (3D: triangles); the integral over one
element has a closed form and f is the sum over elements.

The mollified, local version (Eq. 6) multiplies each element's contribution by a smooth,
compactly supported bump phi_i(x) = phi(|x - c_i|^2 / rho^2) around the element centre c_i, so
only elements within ``radius`` of a query point contribute; the neighbour pairs come from a
``scipy.spatial.cKDTree`` and the cost is about O(n k) for k neighbours instead of O(n m).

Everything is torch, vectorised over query points and elements, differentiable (to any order,
including double backward for Eikonal losses) with respect to the query points and to M's
vertices, and finite on M (the gradient is finite on M too: there torch's ``abs`` picks the mean
of the two one-sided normal derivatives).

References
----------
Niu et al. 2025, "SharpNet", Sec. 3.2 (Eqs. 1-6).
Closed form on a triangle: D. R. Wilton, S. M. Rao, A. W. Glisson et al., "Potential integrals
for uniform and linear source distributions on polygonal and polyhedral domains", IEEE TAP
32(3), 1984 (the 1/R integral, Eq. 9 there).
"""

from __future__ import annotations

import math

import numpy as np
import torch
from scipy.spatial import cKDTree

from curvenet.core.tolerances import DIVISION_GUARD, TINY_F32

__all__ = [
    "segment_integral",
    "triangle_integral",
    "mollifier",
    "feature_function",
    "mollified_feature_function",
    "element_centres",
]

#: Guard below which squared lengths are treated as zero (query point on a vertex / edge line).
_TINY2 = TINY_F32
#: ``I_n`` of the mollifier (Sec. 3.2.3: "set to 1/e"), so that phi(0) = 1.
MOLLIFIER_I_N = 1.0 / math.e
#: Default bound on (query points x elements) pairs evaluated at once by the global version.
DEFAULT_MAX_PAIRS = 1 << 21


def _safe_norm(v: torch.Tensor) -> torch.Tensor:
    # sqrt with a finite gradient at 0 (the guard shifts |v| by at most 1e-15)
    return torch.sqrt((v * v).sum(-1).clamp_min(_TINY2))


def _cross2(u: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def segment_integral(x: torch.Tensor, a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """Integral of ``G = ln|x - y| / (2 pi)`` over the segment ``[a, b]`` (closed form).

    Parameters
    ----------
    x, a, b : (..., 2) tensors
        Query points and segment end points; broadcast against each other.

    Returns
    -------
    (...) tensor
        ``int_a^b ln|x - y| / (2 pi) ds_y``.

    Notes
    -----
    With ``s`` the coordinate of ``x`` along the segment (from ``a``), ``h`` its distance from
    the segment's line and ``w = u - s``,
    ``int ln(w^2 + h^2) / 2 dw = w ln(w^2 + h^2) / 2 - w + |h| atan2(w, |h|)``, evaluated
    between ``w0 = -s`` and ``w1 = L - s``. On the segment (h = 0) the last term vanishes and
    its derivative in h jumps by ``2 pi``: the normal derivative of the result jumps by 1.
    """
    d = b - a
    length = _safe_norm(d)
    t = d / length.unsqueeze(-1)
    ax = x - a
    s = (ax * t).sum(-1)
    ah = _cross2(t, ax).abs()

    def prim(w: torch.Tensor) -> torch.Tensor:
        r2 = w * w + ah * ah
        ok = r2 > _TINY2
        r2s = torch.where(ok, r2, torch.ones_like(r2))
        ahs = torch.where(ok, ah, torch.ones_like(ah))
        lg = torch.where(ok, 0.5 * w * torch.log(r2s), torch.zeros_like(r2))
        at = torch.where(ok, ah * torch.atan2(w, ahs), torch.zeros_like(r2))
        return lg - w + at

    return (prim(length - s) - prim(-s)) / (2.0 * math.pi)


def triangle_integral(x: torch.Tensor, v0: torch.Tensor, v1: torch.Tensor,
                      v2: torch.Tensor) -> torch.Tensor:
    """Integral of ``G = -1 / (4 pi |x - y|)`` over the triangle ``(v0, v1, v2)`` (closed form).

    Parameters
    ----------
    x, v0, v1, v2 : (..., 3) tensors
        Query points and triangle corners; broadcast against each other.

    Returns
    -------
    (...) tensor
        ``-1/(4 pi) int_T dA_y / |x - y|``; finite everywhere, including on the triangle.

    Notes
    -----
    Wilton et al. 1984: with ``h`` the height of ``x`` over the triangle's plane and, per edge
    ``i`` (unit tangent ``t``, outward in-plane normal ``m``), ``t0`` the signed in-plane
    distance to the edge line, ``l-/l+`` the end-point coordinates along ``t`` and ``R-/R+`` the
    end-point distances,
    ``int dA / R = sum_i t0 ln((R+ + l+)/(R- + l-)) - |h| [atan(t0 l+ / (R0^2 + |h| R+))
    - atan(t0 l- / (R0^2 + |h| R-))]``, ``R0^2 = t0^2 + h^2``. The log ratio is evaluated in the
    form ``(R- - l-)/(R+ - l+)`` when ``l- + l+ < 0`` (the same value, as
    ``(R + l)(R - l) = R0^2``) to avoid cancellation. Degenerate triangles contribute 0.
    """
    e1 = v1 - v0
    e2 = v2 - v0
    nrm = torch.cross(e1, e2, dim=-1)
    n = nrm / _safe_norm(nrm).unsqueeze(-1)
    h = ((x - v0) * n).sum(-1)
    ah = h.abs()
    corners = (v0, v1, v2)
    total = torch.zeros(torch.broadcast_shapes(x.shape, v0.shape)[:-1],
                        dtype=x.dtype, device=x.device)
    for i in range(3):
        a = corners[i]
        b = corners[(i + 1) % 3]
        d = b - a
        t = d / _safe_norm(d).unsqueeze(-1)
        m = torch.cross(t, n, dim=-1)
        ax = a - x
        bx = b - x
        t0 = (ax * m).sum(-1)
        lm = (ax * t).sum(-1)
        lp = (bx * t).sum(-1)
        rm = _safe_norm(ax)
        rp = _safe_norm(bx)
        pos = (lp + lm) >= 0
        num = torch.where(pos, rp + lp, rm - lm)
        den = torch.where(pos, rm + lm, rp - lp)
        ok = (num > DIVISION_GUARD) & (den > DIVISION_GUARD)
        one = torch.ones_like(num)
        logt = torch.where(ok, torch.log(torch.where(ok, num, one))
                           - torch.log(torch.where(ok, den, one)), torch.zeros_like(num))
        total = total + t0 * logt
        r0sq = t0 * t0 + h * h
        for r, ll, sign in ((rp, lp, 1.0), (rm, lm, -1.0)):
            xx = r0sq + ah * r
            good = xx > _TINY2
            ang = torch.atan2(torch.where(good, t0 * ll, torch.zeros_like(xx)),
                              torch.where(good, xx, one))
            total = total - sign * ah * ang
    return -total / (4.0 * math.pi)


def _kernel(dim: int):
    return segment_integral if dim == 2 else triangle_integral


def _check_inputs(x: torch.Tensor, vertices: torch.Tensor, elements: torch.Tensor):
    if not isinstance(x, torch.Tensor) or x.ndim != 2 or x.shape[1] not in (2, 3):
        raise ValueError(f"x must be an (n, 2) or (n, 3) tensor, got shape "
                         f"{getattr(x, 'shape', None)}")
    dim = x.shape[1]
    if vertices.ndim != 2 or vertices.shape[1] != dim:
        raise ValueError(f"vertices must be (k, {dim}) to match x, got {tuple(vertices.shape)}")
    if elements.ndim != 2 or elements.shape[1] != dim:
        raise ValueError(f"elements must be (m, {dim}) ({'segments' if dim == 2 else 'triangles'}"
                         f") for {dim}D points, got {tuple(elements.shape)}")
    if elements.numel() and (int(elements.min()) < 0 or int(elements.max()) >= len(vertices)):
        raise ValueError("elements index outside vertices")
    return dim


def _channel_setup(m: int, channels, n_channels, device):
    if channels is None:
        return torch.zeros(m, dtype=torch.long, device=device), 1, True
    ch = torch.as_tensor(channels, dtype=torch.long, device=device)
    if ch.shape != (m,):
        raise ValueError(f"channels must have one entry per element ({m}), got {tuple(ch.shape)}")
    c = int(n_channels) if n_channels is not None else (int(ch.max()) + 1 if m else 1)
    if m and (int(ch.min()) < 0 or int(ch.max()) >= c):
        raise ValueError(f"channels must lie in [0, n_channels={c})")
    return ch, c, False


def element_centres(vertices: torch.Tensor, elements: torch.Tensor) -> torch.Tensor:
    """Centres ``c(M_i)``: mean of each element's 2 (segment) or 3 (triangle) vertices.

    Returns an ``(m, d)`` tensor (Sec. 3.2.3).
    """
    return vertices[elements].mean(dim=1)


def feature_function(x: torch.Tensor, vertices: torch.Tensor, elements, *, channels=None,
                     n_channels: int | None = None,
                     max_pairs: int = DEFAULT_MAX_PAIRS) -> torch.Tensor:
    """Global feature function (Eq. 5): sum of the closed-form element integrals.

    Parameters
    ----------
    x : (n, d) tensor, d in {2, 3}
        Query points.
    vertices : (k, d) tensor
        Vertices of M (may require grad: learnable feature vertices).
    elements : (m, d) integer array or tensor
        Segments (2D) or triangles (3D) of M, indices into ``vertices``.
    channels : (m,) integer array, optional
        Channel of each element (feature splitting, Sec. 3.3); ``None`` is one channel.
    n_channels : int, optional
        Number of output channels (default ``max(channels) + 1``).
    max_pairs : int
        Bound on query x element pairs evaluated at once (memory; chunking over queries).

    Returns
    -------
    (n,) tensor when ``channels`` is None, else (n, n_channels) tensor
        ``f(x)`` (per channel: the integral over that channel's elements only).

    Notes
    -----
    Cost and memory O(n m); the chunks bound the forward memory only (autograd keeps each
    chunk's graph). Use :func:`mollified_feature_function` for large n and m.
    """
    elements = torch.as_tensor(elements, dtype=torch.long, device=vertices.device)
    dim = _check_inputs(x, vertices, elements)
    m = elements.shape[0]
    ch, c, single = _channel_setup(m, channels, n_channels, vertices.device)
    kern = _kernel(dim)
    ev = vertices[elements]  # (m, d, d): element corners
    corners = [ev[None, :, j, :] for j in range(dim)]  # each (1, m, d)
    onehot = torch.nn.functional.one_hot(ch, c).to(x.dtype)  # (m, c)
    step = max(1, int(max_pairs) // max(m, 1))
    outs = []
    for s in range(0, x.shape[0], step):
        xc = x[s:s + step, None, :]  # (B, 1, d)
        vals = kern(xc, *corners)  # (B, m)
        outs.append(vals @ onehot)  # (B, c)
    out = torch.cat(outs, 0) if outs else x.new_zeros((0, c))
    return out[:, 0] if single else out


def mollifier(r: torch.Tensor, i_n: float = MOLLIFIER_I_N) -> torch.Tensor:
    """Mollifier ``phi(r) = exp(-1 / (1 - r^2)) / I_n`` for ``|r| < 1``, else 0 (Sec. 3.2.3).

    C-infinity in r; with the default ``I_n = 1/e`` it equals 1 at ``r = 0``. Gradients are
    exactly 0 outside the support (no NaN from the masked branch).
    """
    inside = r.abs() < 1.0
    rs = torch.where(inside, r, torch.zeros_like(r))
    val = torch.exp(-1.0 / (1.0 - rs * rs)) / i_n
    return torch.where(inside, val, torch.zeros_like(val))


def _pairs_within(xq: np.ndarray, centres: np.ndarray, radius: float):
    """(query index, element index) pairs with ``|x - c| < radius`` (cKDTree; O(n log m + k))."""
    if len(xq) == 0 or len(centres) == 0:
        z = np.zeros(0, dtype=np.int64)
        return z, z
    tc = cKDTree(centres)
    lists = tc.query_ball_point(xq, radius, return_sorted=False)
    counts = np.fromiter((len(li) for li in lists), dtype=np.int64, count=len(lists))
    qi = np.repeat(np.arange(len(xq), dtype=np.int64), counts)
    ej = (np.concatenate([np.asarray(li, dtype=np.int64) for li in lists])
          if counts.sum() else np.zeros(0, dtype=np.int64))
    return qi, ej


def mollified_feature_function(x: torch.Tensor, vertices: torch.Tensor, elements, *,
                               radius: float, channels=None, n_channels: int | None = None,
                               i_n: float = MOLLIFIER_I_N,
                               max_pairs: int = DEFAULT_MAX_PAIRS) -> torch.Tensor:
    """Local feature function (Eq. 6): ``sum_i phi(|x - c_i|^2 / radius^2) int_{M_i} G``.

    Parameters
    ----------
    x : (n, d) tensor
        Query points.
    vertices : (k, d) tensor
        Vertices of M (may require grad).
    elements : (m, d) integer array or tensor
        Segments (2D) or triangles (3D).
    radius : float
        Support radius rho of each element's mollifier (same units as x): element i contributes
        only where ``|x - c_i| < radius``.
    channels, n_channels : see :func:`feature_function`.
    i_n : float
        Mollifier normalisation ``I_n`` (paper: 1/e).
    max_pairs : int
        Neighbour pairs evaluated per chunk.

    Returns
    -------
    (n,) or (n, n_channels) tensor

    Notes
    -----
    C0 on M and C-infinity elsewhere (Sec. 3.2.3): the normal-derivative jump at a point of
    element i is ``phi_i(x)`` instead of 1. Neighbour pairs are found on detached coordinates
    (cKDTree over element centres); pairs just outside the support contribute exactly 0 with
    zero gradient, so moving vertices only needs the pairs recomputed per call. The argument of
    phi is the squared distance over ``radius^2``, as in the paper (``r = d(x, M_i)``).
    """
    if not (isinstance(radius, (int, float)) and math.isfinite(radius) and radius > 0):
        raise ValueError(f"radius must be a positive finite number, got {radius!r}")
    elements = torch.as_tensor(elements, dtype=torch.long, device=vertices.device)
    dim = _check_inputs(x, vertices, elements)
    m = elements.shape[0]
    ch, c, single = _channel_setup(m, channels, n_channels, vertices.device)
    kern = _kernel(dim)
    centres = element_centres(vertices, elements)  # (m, d)
    qi, ej = _pairs_within(x.detach().cpu().numpy().astype(np.float64),
                           centres.detach().cpu().numpy().astype(np.float64), float(radius))
    qi = torch.from_numpy(qi).to(x.device)
    ej = torch.from_numpy(ej).to(x.device)
    ev = vertices[elements]  # (m, d, d)
    out = x.new_zeros(x.shape[0] * c)
    step = max(1, int(max_pairs))
    inv_r2 = 1.0 / (float(radius) ** 2)
    for s in range(0, qi.shape[0], step):
        q = qi[s:s + step]
        e = ej[s:s + step]
        xq = x[q]  # (P, d)
        cor = ev[e]  # (P, d, d)
        vals = kern(xq, *[cor[:, j, :] for j in range(dim)])  # (P,)
        dc = xq - centres[e]
        phi = mollifier((dc * dc).sum(-1) * inv_r2, i_n)
        out = out.index_add(0, q * c + ch[e], vals * phi)
    out = out.view(x.shape[0], c)
    return out[:, 0] if single else out
