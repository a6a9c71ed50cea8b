"""FFT Poisson integration of a gradient field on the periodic padded box.

Zhang et al. 2025, Sec. 4.4.1 and 5.1: g is evaluated at stroke and surface
samples, splatted to the grid with trilinear weights, integrated by solving
``Laplace f = div g`` with the FFT on the box treated as a 3-torus (Eq. 8-10),
normalised by scale and shift (Eq. 11) and interpolated back trilinearly.

Conventions
-----------
* Points are unit-cube coordinates ``u in [0, 1]^3`` (the padded box mapped to
  the unit cube, one scale for all axes).
* Grid node ``(i, j, k)`` sits at the cell centre ``((i, j, k) + 0.5) h`` with
  ``h = 1 / res``; arrays are indexed ``[i, j, k]`` = ``[x, y, z]``.
* Trilinear stencils wrap around (periodic box), matching the FFT.

References
----------
Zhang, Wang, Bessmeltsev 2025, Eq. 8-11; Peng et al., "Shape As Points", 2021
(differentiable spectral Poisson solver, scale-and-shift normalisation).
"""

from __future__ import annotations

import math

import torch

from curvenet.core.tolerances import NORM_EPS, TINY_F32

__all__ = ["PoissonSolver", "splat", "stroke_strip", "normalize_splat", "interpolate",
           "normalize_scale_shift", "trilinear_stencil"]


def trilinear_stencil(points: torch.Tensor, res: int):
    """Flat node indices and weights of the 8-node periodic trilinear stencil.

    Parameters
    ----------
    points : (M, 3) tensor, unit-cube coordinates
    res : int

    Returns
    -------
    idx : (M, 8) int64, flat node indices ``(i * res + j) * res + k``
    w : (M, 8), weights summing to 1 (same dtype as ``points``)
    frac : (M, 3), fractional position inside the cell
    corners : (8, 3) int64, corner offsets in stencil order
    """
    s = points * res - 0.5                                        # node coordinates
    base = torch.floor(s)
    frac = s - base
    base = base.long()
    corners = torch.tensor([[(c >> 2) & 1, (c >> 1) & 1, c & 1] for c in range(8)],
                           device=points.device)                  # (8, 3)
    ijk = torch.remainder(base.unsqueeze(1) + corners, res)       # (M, 8, 3)
    idx = (ijk[..., 0] * res + ijk[..., 1]) * res + ijk[..., 2]
    cf = corners.to(points.dtype)
    w = torch.prod(cf * frac.unsqueeze(1) + (1 - cf) * (1 - frac.unsqueeze(1)), dim=-1)
    return idx, w, frac, corners


def splat(points: torch.Tensor, values: torch.Tensor, res: int, weights=None):
    """Rasterise point values onto the grid by trilinear weights (Sec. 5.1).

    Parameters
    ----------
    points : (M, 3) unit-cube coordinates (no gradient needed)
    values : (M, C), differentiable
    res : int
    weights : (M,) tensor, optional
        Mass of each point (default 1): its value and its trilinear weights are
        multiplied by it.

    Returns
    -------
    grid : (C, res, res, res), sum of weighted values per node
    weight : (res, res, res), sum of weights per node
    """
    idx, w, _, _ = trilinear_stencil(points.detach(), res)
    if weights is not None:
        w = w * weights.detach().to(w.dtype).unsqueeze(-1)
    w = w.to(values.dtype)
    flat = idx.reshape(-1)
    wsum = torch.zeros(res ** 3, dtype=values.dtype, device=values.device)
    wsum.index_add_(0, flat, w.reshape(-1))
    return _Splat.apply(values, w, flat, res), wsum.view(res, res, res)


class _Splat(torch.autograd.Function):
    """The splat's sums, written channel by channel into one contiguous (C, res^3) grid.

    Autograd's own splat (an out-of-place ``index_add`` into a (res^3, C) grid) copies
    the grid once more, and hands the FFT a grid whose channels are strided by C, which
    torch's CPU transform copies again. Here the grid is made channel-major in place,
    and the backward gathers each channel's gradient, then weighs and sums the eight
    corners of each point in the order autograd's backward does, so the gradient is the
    same bit for bit. Twice differentiable (the backward is made of torch operations).
    """

    @staticmethod
    def forward(ctx, values, w, flat, res):
        C, n3 = values.shape[1], res ** 3
        src = (w.unsqueeze(-1) * values.unsqueeze(1)).permute(2, 0, 1).reshape(-1)
        chan = flat + n3 * torch.arange(C, device=flat.device).unsqueeze(1)   # (C, M*8)
        grid = torch.zeros(C * n3, dtype=values.dtype, device=values.device)
        grid.index_add_(0, chan.reshape(-1), src)
        ctx.save_for_backward(w, flat)
        return grid.view(C, res, res, res)

    @staticmethod
    def backward(ctx, grad):
        w, flat = ctx.saved_tensors
        C = grad.shape[0]
        g = grad.reshape(C, -1).index_select(1, flat).t().contiguous().view(-1, 8, C)
        return (g * w.unsqueeze(-1)).sum(1), None, None, None


def stroke_strip(x_s, x_u, width: float):
    """Surface samples off the strokes' strip, and the mass the stroke samples take over.

    The strokes lie on the surface, so splatting stroke samples beside the surface
    samples counts the surface along the strokes twice. That extra density is a
    curved line of normals; its potential at the stroke itself, where Eq. 11 sets the
    zero level, differs from its potential elsewhere on the surface, so the zero set
    between strokes moves towards the concave side (a rough sphere shrinks between
    its strokes). Dropping the surface samples closer than ``width`` to a stroke
    sample and giving the stroke samples their mass keeps one density along the
    whole surface. Where the surface folds at a stroke (the rim of an open
    surface) the extra density is also what holds it on the stroke, so the fits
    train without it and use it only in their guarded polish (:mod:`neural.presets`).

    Parameters
    ----------
    x_s : (n_s, 3) tensor, stroke samples
    x_u : (n_u, 3) tensor, surface samples (same device and dtype)
    width : float
        Strip half-width, unit-cube units.

    Returns
    -------
    keep : (n_u,) bool tensor, the surface samples outside the strip
    mass : (n_s + kept,) tensor, the masses of the stroke samples, ``k / n_s`` each for
        the ``k`` surface samples dropped (1 when none is), then of the kept ones (1)
    """
    from scipy.spatial import cKDTree
    d, _ = cKDTree(x_s.detach().cpu().double().numpy()).query(
        x_u.detach().cpu().double().numpy(), distance_upper_bound=width)
    near = torch.as_tensor(d < width, device=x_u.device)
    k = int(near.sum())
    mass = x_s.new_ones(len(x_s) + len(x_u) - k)
    mass[: len(x_s)] = k / len(x_s) if k else 1.0
    return ~near, mass


def normalize_splat(grid: torch.Tensor, weight: torch.Tensor) -> torch.Tensor:
    """Per-node normalisation of a splatted field ("once stabilised", Sec. 5.1).

    Each node's sum is divided by ``max(weight, mean positive weight)``: the density bias of
    the samples goes, and sparsely hit nodes are not inflated.

    Parameters
    ----------
    grid : (C, res, res, res), weight : (res, res, res), as returned by :func:`splat`

    Returns
    -------
    (C, res, res, res)
    """
    wref = weight.sum() / (weight > 0).sum().clamp(min=1)
    return grid / torch.maximum(weight, wref)


def interpolate(grid: torch.Tensor, points: torch.Tensor, *, with_gradient: bool = False):
    """Periodic trilinear interpolation of a scalar grid at points.

    Parameters
    ----------
    grid : (res, res, res), differentiable
    points : (M, 3) unit-cube coordinates
    with_gradient : bool
        Also return the spatial gradient of the interpolant (unit-cube units).

    Returns
    -------
    values : (M,)
    gradient : (M, 3), only when ``with_gradient``
    """
    res = grid.shape[0]
    idx, w, frac, corners = trilinear_stencil(points.detach(), res)
    vals = grid.reshape(-1)[idx]                                  # (M, 8)
    out = (w.to(vals.dtype) * vals).sum(-1)
    if not with_gradient:
        return out
    cf = corners.to(frac.dtype)
    lin = cf * frac.unsqueeze(1) + (1 - cf) * (1 - frac.unsqueeze(1))   # (M, 8, 3)
    dlin = 2 * cf - 1                                                   # (8, 3)
    grads = []
    for a in range(3):
        others = [b for b in range(3) if b != a]
        wa = dlin[:, a] * lin[..., others[0]] * lin[..., others[1]]     # (M, 8)
        grads.append((wa.to(vals.dtype) * vals).sum(-1) * res)
    return out, torch.stack(grads, -1)


def normalize_scale_shift(f_grid: torch.Tensor, f_strokes: torch.Tensor, *,
                         eps: float = NORM_EPS):
    """Scale-and-shift normalisation of Eq. 11.

    ``f <- (f - mean_strokes f) / |f(corner) - mean_strokes f|``: the stroke
    samples average to 0 and the box corner (node ``[0, 0, 0]``) becomes +-1.

    Parameters
    ----------
    f_grid : (res, res, res)
    f_strokes : (M,), f interpolated at the stroke samples

    Returns
    -------
    f_grid, f_strokes : normalised, same shapes

    Notes
    -----
    Eq. 11 divides by ``|f(0)|`` of the unshifted f; we divide by the corner
    value *after* the shift, so that the corner is exactly +-1 whatever the
    (arbitrary) mean of the FFT solution. The divisor is clamped at ``eps``.
    """
    shift = f_strokes.mean()
    scale = (f_grid[0, 0, 0] - shift).abs().clamp(min=eps)
    return (f_grid - shift) / scale, (f_strokes - shift) / scale


def _along(M: torch.Tensor, x: torch.Tensor, axis: int) -> torch.Tensor:
    """Apply the matrix ``M`` (m, n) along ``axis`` of the 3D tensor ``x`` (size n there)."""
    return torch.movedim(torch.tensordot(M, torch.movedim(x, axis, 0), dims=1), 0, axis)


class PoissonSolver:
    """Spectral solver of ``Laplace f = div g`` on the periodic unit cube (Eq. 8-10).

    The frequency grids are built once per (res, device, dtype) and reused.

    Parameters
    ----------
    res : int
        Nodes per axis.
    device : str or torch.device
    dtype : torch.dtype
        Real dtype of the fields.
    boundary : {"periodic", "dirichlet"}
        ``"periodic"``: the unit cube is a 3-torus (Eq. 8-10). ``"dirichlet"``:
        f = 0 on the cube's walls: f in sines, exact projections by dense
        per-axis transforms (:meth:`_solve_sine`).
    lowpass : float
        Standard deviation, in grid cells, of a Gaussian low-pass applied to f in
        the same spectral solve (each mode scaled by ``exp(-omega^2 s^2 / 2)``,
        ``omega`` its angular frequency, ``s = lowpass / res``); 0: none. Not in
        the paper; the solver of Shape As Points (Peng et al. 2021) has one.

    Notes
    -----
    ``f_hat = i (u . g_hat) / (-2 pi |u|^2)`` with ``u`` the frequencies in
    cycles per unit length (``torch.fft.fftfreq``), Eq. 10; the mean
    (``u = 0``) is set to 0. Nyquist frequencies are zeroed in the derivative
    (an odd operator has no real Nyquist mode). Uses ``torch.fft.rfftn``: the
    half spectrum of a real field.

    Examples
    --------
    >>> solver = PoissonSolver(16)
    >>> f = solver.solve(torch.zeros(3, 16, 16, 16))
    >>> float(f.abs().max())
    0.0
    """

    def __init__(self, res: int, *, device="cpu", dtype=torch.float32, boundary: str = "periodic",
                 lowpass: float = 0.0):
        if boundary not in ("periodic", "dirichlet"):
            raise ValueError(f"boundary must be 'periodic' or 'dirichlet', got {boundary!r}")
        if not lowpass >= 0:
            raise ValueError(f"lowpass must be >= 0 cells, got {lowpass!r}")
        self.res, self.boundary, self.lowpass = int(res), boundary, float(lowpass)
        self.device, self.dtype = device, dtype
        if boundary == "dirichlet":
            self._init_sine()
            return
        n = self.res
        u = torch.fft.fftfreq(n, d=1.0 / n, dtype=torch.float64)
        ur = torch.fft.rfftfreq(n, d=1.0 / n, dtype=torch.float64)
        if n % 2 == 0:                       # no real Nyquist mode for a derivative
            u[n // 2] = 0.0
            ur[-1] = 0.0
        ux, uy, uz = u.view(n, 1, 1), u.view(1, n, 1), ur.view(1, 1, -1)
        uu = (torch.fft.fftfreq(n, d=1.0 / n, dtype=torch.float64) ** 2).view(n, 1, 1) \
            + (torch.fft.fftfreq(n, d=1.0 / n, dtype=torch.float64) ** 2).view(1, n, 1) \
            + (torch.fft.rfftfreq(n, d=1.0 / n, dtype=torch.float64) ** 2).view(1, 1, -1)
        inv = torch.where(uu > 0, 1.0 / (-2.0 * math.pi * uu.clamp(min=TINY_F32)),
                          torch.zeros_like(uu)) * self._gain(4.0 * uu)
        # i u / (-2 pi |u|^2) per axis: (3, n, n, n//2+1), complex, stored so (a real
        # operator would be converted to complex on every multiply)
        op = torch.stack([(ux * inv).expand(n, n, -1), (uy * inv).expand(n, n, -1),
                          (uz * inv).expand(n, n, -1)]).to(device=device, dtype=dtype)
        self._op = torch.complex(torch.zeros_like(op), op).contiguous()

    def _init_sine(self) -> None:
        """Bases of the Dirichlet solve: f = sum_k a_k prod_axes sin(pi k x), k = 1..n.

        Nodes sit at ``x_i = (i + 1/2) / n``, where the sine modes ``k = 1..n``
        (DST-II) and the cosine modes ``k = 0..n-1`` (DCT-II) are discretely
        orthogonal, so projections are exact. ``d/dx`` maps sine mode k to k pi
        times cosine mode k; cosine mode n does not exist (its row is zero).
        """
        n = self.res
        i = torch.arange(n, dtype=torch.float64) + 0.5
        k = torch.arange(1, n + 1, dtype=torch.float64)
        S = torch.sin(math.pi * k[:, None] * i[None] / n)                 # (n modes, n nodes)
        C = torch.cos(math.pi * k[:-1, None] * i[None] / n)               # modes 1..n-1
        Cp = torch.cat([C / (C * C).sum(1, keepdim=True), torch.zeros(1, n, dtype=torch.float64)])
        kk = k.view(n, 1, 1) ** 2 + k.view(1, n, 1) ** 2 + k.view(1, 1, n) ** 2
        inv = self._gain(kk) / (math.pi * kk)

        def put(t):
            return t.to(device=self.device, dtype=self.dtype).contiguous()
        self._synth, self._sin_proj = put(S.T), put(S / (S * S).sum(1, keepdim=True))
        self._cos_proj, self._k, self._inv = put(Cp), put(k), put(inv)

    def _gain(self, kk: torch.Tensor) -> torch.Tensor:
        """The low-pass's gain of the modes ``sin / cos(pi k x)`` with ``kk = |k|^2``
        (a periodic mode of ``u`` cycles per unit has ``k = 2 u``)."""
        s = self.lowpass / self.res
        return torch.exp(-0.5 * (math.pi * s) ** 2 * kk)

    def solve(self, g_grid: torch.Tensor) -> torch.Tensor:
        """Integrate a gradient grid.

        Parameters
        ----------
        g_grid : (3, res, res, res), gradient in unit-cube units

        Returns
        -------
        f : (res, res, res), zero mean
        """
        n = self.res
        if tuple(g_grid.shape) != (3, n, n, n):
            raise ValueError(f"g_grid must have shape (3, {n}, {n}, {n}), "
                             f"got {tuple(g_grid.shape)}")
        if self.boundary == "dirichlet":
            return self._solve_sine(g_grid)
        return self._spectral(g_grid)

    def _solve_sine(self, g_grid: torch.Tensor) -> torch.Tensor:
        """``Laplace f = div g`` with f = 0 on the walls, in the sine basis.

        g's component a is projected on cosines along axis a and sines along the
        others; then ``a_k = sum_a k_a G_a(k) / (pi |k|^2)`` and f is synthesised
        from the sines. Dense (n, n) transforms per axis: O(n^4), exact, on any
        device, with autograd.
        """
        n = self.res
        acc = 0.0
        for a in range(3):
            G = g_grid[a]
            for ax in range(3):
                G = _along(self._cos_proj if ax == a else self._sin_proj, G, ax)
            acc = acc + self._k.view([n if d == a else 1 for d in range(3)]) * G
        f = acc * self._inv
        for ax in range(3):
            f = _along(self._synth, f, ax)
        return f

    def _spectral(self, g_grid: torch.Tensor) -> torch.Tensor:
        return _Spectral.apply(g_grid, self._op)


def _spectral_forward(g_grid: torch.Tensor, op: torch.Tensor) -> torch.Tensor:
    """(n, n, n): ``irfftn(sum_a op_a rfftn(g_a))`` of a (3, n, n, n) gradient grid;
    ``op`` (3, n, n, n//2+1) complex, ``i u_a / (-2 pi |u|^2)``."""
    n = g_grid.shape[-1]
    gh = torch.fft.rfftn(g_grid, dim=(-3, -2, -1))               # (3, n, n, n//2+1)
    return torch.fft.irfftn(torch.einsum("a...,a...->...", op, gh), s=(n, n, n),
                            dim=(-3, -2, -1))


def _spectral_adjoint(f_grad: torch.Tensor, op: torch.Tensor) -> torch.Tensor:
    """(3, n, n, n): the adjoint of :func:`_spectral_forward` applied to an (n, n, n)
    grid: ``irfftn(conj(op_a) rfftn(f_grad))``. The solve is a periodic convolution of
    each component with a real kernel; its multiplier ``op_a`` is Hermitian (``i``
    times a real function odd in the frequency), so the adjoint's multiplier is its
    conjugate, ``-op_a``. One inverse transform per component: torch's CPU inverse of
    the three at once first copies its input at a poor stride."""
    n = f_grad.shape[-1]
    fh = -torch.fft.rfftn(f_grad, dim=(-3, -2, -1))
    out = f_grad.new_empty((3, n, n, n))
    for a in range(3):
        out[a] = torch.fft.irfftn(op[a] * fh, s=(n, n, n), dim=(-3, -2, -1))
    return out


class _Spectral(torch.autograd.Function):
    """The periodic solve with its adjoint as the backward: autograd's backward of
    ``rfftn`` is a full complex transform of a zero-filled spectrum, several times the
    cost of the forward on a CPU; the adjoint takes one real transform and three
    inverse ones. Twice differentiable (the backward is made of torch operations)."""

    @staticmethod
    def forward(ctx, g_grid, op):
        ctx.save_for_backward(op)
        return _spectral_forward(g_grid, op)

    @staticmethod
    def backward(ctx, f_grad):
        (op,) = ctx.saved_tensors
        return _spectral_adjoint(f_grad, op), None
