"""Oracles for the FFT Poisson integration (Zhang et al. 2025, Eq. 8-11)."""

import math

import pytest
import torch

from curvenet.neural.poisson import (PoissonSolver, interpolate, normalize_scale_shift,
                                     normalize_splat, splat)


def _grid(n, dtype=torch.float64):
    c = (torch.arange(n, dtype=dtype) + 0.5) / n
    return torch.meshgrid(c, c, c, indexing="ij")


def _periodic_f(X, Y, Z):
    tp = 2 * math.pi
    f = torch.sin(tp * X) * torch.cos(2 * tp * Y) + 0.3 * torch.sin(tp * (Z + X)) \
        + 0.1 * torch.cos(3 * tp * Z)
    g = torch.stack([tp * torch.cos(tp * X) * torch.cos(2 * tp * Y)
                     + 0.3 * tp * torch.cos(tp * (Z + X)),
                     -2 * tp * torch.sin(tp * X) * torch.sin(2 * tp * Y),
                     0.3 * tp * torch.cos(tp * (Z + X)) - 0.3 * tp * torch.sin(3 * tp * Z)])
    return f, g


def _sine_mode(X, Y, Z):
    """f = sin(pi x) sin(2 pi y) sin(pi z), zero on the walls (mode k = (1, 2, 1)), and g."""
    p = math.pi
    f = torch.sin(p * X) * torch.sin(2 * p * Y) * torch.sin(p * Z)
    g = torch.stack([p * torch.cos(p * X) * torch.sin(2 * p * Y) * torch.sin(p * Z),
                     2 * p * torch.sin(p * X) * torch.cos(2 * p * Y) * torch.sin(p * Z),
                     p * torch.sin(p * X) * torch.sin(2 * p * Y) * torch.cos(p * Z)])
    return f, g


@pytest.mark.parametrize("dtype,tol", [(torch.float64, 1e-10), (torch.float32, 1e-4)])
def test_fft_poisson_recovers_periodic_function(dtype, tol):
    # band-limited periodic f: the spectral solve of Eq. 10 is exact up to round-off;
    # float32 round-off on 64^3 FFTs is ~1e-6 relative, so 1e-4 (the bound) has margin
    n = 64
    X, Y, Z = _grid(n)
    f, g = _periodic_f(X, Y, Z)
    fr = PoissonSolver(n, dtype=dtype).solve(g.to(dtype)).double()
    err = ((fr - fr.mean()) - (f - f.mean())).abs().max()
    assert err < tol


def test_odd_resolution_and_zero_mean():
    n = 33
    X, Y, Z = _grid(n)
    f, g = _periodic_f(X, Y, Z)
    fr = PoissonSolver(n, dtype=torch.float64).solve(g)
    assert abs(float(fr.mean())) < 1e-12
    assert ((fr - fr.mean()) - (f - f.mean())).abs().max() < 1e-10


@pytest.mark.parametrize("n", [24, 25])
def test_dirichlet_solve_recovers_function_zero_on_walls(n):
    # f = sin(pi x) sin(2 pi y) sin(pi z) vanishes on the walls but is not periodic
    # with period 1; the Dirichlet solve recovers it exactly (one sine mode)
    X, Y, Z = _grid(n)
    f, g = _sine_mode(X, Y, Z)
    fr = PoissonSolver(n, dtype=torch.float64, boundary="dirichlet").solve(g)
    assert (fr - f).abs().max() < 1e-10
    periodic = PoissonSolver(n, dtype=torch.float64).solve(g)
    assert ((periodic - periodic.mean()) - (f - f.mean())).abs().max() > 1e-2


def test_dirichlet_solve_high_modes_and_gradcheck():
    # a sum of sine modes up to k = n - 1 (the highest with a cosine derivative)
    n = 12
    X, Y, Z = _grid(n)
    p = math.pi
    f, g = 0.0, 0.0
    for kx, ky, kz, c in [(1, 1, 1, 1.0), (n - 1, 2, 3, 0.3), (4, n - 1, n - 1, -0.2)]:
        sx, sy, sz = (torch.sin(k * p * t) for k, t in ((kx, X), (ky, Y), (kz, Z)))
        cx, cy, cz = (torch.cos(k * p * t) for k, t in ((kx, X), (ky, Y), (kz, Z)))
        f = f + c * sx * sy * sz
        g = g + c * p * torch.stack([kx * cx * sy * sz, ky * sx * cy * sz, kz * sx * sy * cz])
    solver = PoissonSolver(n, dtype=torch.float64, boundary="dirichlet")
    assert (solver.solve(g) - f).abs().max() < 1e-10
    small = PoissonSolver(4, dtype=torch.float64, boundary="dirichlet")
    gg = torch.randn(3, 4, 4, 4, dtype=torch.float64, requires_grad=True)
    assert torch.autograd.gradcheck(lambda t: small.solve(t).sum(-1), (gg,))


def test_lowpass_is_a_gaussian_filter_of_the_solution():
    # the low-passed solve of an exact gradient is f blurred by a Gaussian of that many
    # cells: periodic, against scipy's spatial filter with wrapped edges; Dirichlet, a
    # single sine mode scaled by the Gaussian's gain at its frequency
    from scipy.ndimage import gaussian_filter
    n, cells = 32, 1.5
    X, Y, Z = _grid(n)
    f, g = _periodic_f(X, Y, Z)
    fr = PoissonSolver(n, dtype=torch.float64, lowpass=cells).solve(g).numpy()
    blurred = gaussian_filter((f - f.mean()).numpy(), cells, mode="wrap", truncate=6.0)
    assert abs(fr - blurred).max() < 2e-3 * abs(blurred).max()
    assert abs(fr - (f - f.mean()).numpy()).max() > 0.1 * abs(blurred).max()
    f, g = _sine_mode(X, Y, Z)
    fr = PoissonSolver(n, dtype=torch.float64, boundary="dirichlet", lowpass=cells).solve(g)
    gain = math.exp(-0.5 * (math.pi * cells / n) ** 2 * 6)      # mode k = (1, 2, 1)
    assert (fr - gain * f).abs().max() < 1e-10
    with pytest.raises(ValueError, match="lowpass"):
        PoissonSolver(8, lowpass=-1.0)


def test_solver_rejects_bad_shape():
    with pytest.raises(ValueError, match="g_grid"):
        PoissonSolver(8).solve(torch.zeros(3, 8, 8, 9))
    with pytest.raises(ValueError, match="boundary"):
        PoissonSolver(8, boundary="neumann")


def test_splat_then_interpolate_partition_of_unity():
    torch.manual_seed(0)
    p = torch.rand(200, 3, dtype=torch.float64)
    vals = torch.ones(200, 1, dtype=torch.float64)
    grid, w = splat(p, vals, 16)
    # trilinear weights sum to one per point: total mass is conserved
    assert torch.isclose(grid.sum(), torch.tensor(200.0, dtype=torch.float64))
    assert torch.allclose(grid[0], w)


def test_splat_matches_autograds_scatter_and_is_twice_differentiable():
    """The channel-major splat and its hand-written backward give the sums and the
    gradient of a plain autograd scatter into a (res^3, C) grid, bit for bit."""
    from curvenet.neural.poisson import trilinear_stencil
    torch.manual_seed(3)
    res, M = 7, 300
    p, mass = torch.rand(M, 3), torch.rand(M)
    vals = torch.randn(M, 3, requires_grad=True)
    idx, w, _, _ = trilinear_stencil(p, res)
    w = w * mass.unsqueeze(-1)
    src = (w.unsqueeze(-1) * vals.unsqueeze(1)).reshape(-1, 3)
    ref = torch.zeros(res ** 3, 3).index_add(0, idx.reshape(-1), src).t().reshape(3, res, res, res)
    grid, wsum = splat(p, vals, res, mass)
    assert torch.equal(grid, ref)
    assert torch.equal(wsum.reshape(-1), torch.zeros(res ** 3).index_add(0, idx.reshape(-1),
                                                                         w.reshape(-1)))
    probe = torch.randn(3, res, res, res)
    g_ref, = torch.autograd.grad((ref * probe).sum(), vals)
    g_new, = torch.autograd.grad((grid * probe).sum(), vals)
    assert torch.equal(g_new, g_ref)
    p64, v64 = p.double(), vals.detach().double().requires_grad_(True)
    assert torch.autograd.gradgradcheck(lambda v: splat(p64, v, 4, mass.double())[0], (v64,))


def test_interpolate_reproduces_linear_function_and_gradient():
    n = 16
    X, Y, Z = _grid(n)
    f = 0.3 * X - 0.7 * Y + 0.2 * Z
    torch.manual_seed(1)
    # stay away from the periodic seam, where the interpolant wraps
    p = 0.1 + 0.8 * torch.rand(100, 3, dtype=torch.float64)
    v, gr = interpolate(f, p, with_gradient=True)
    exact = 0.3 * p[:, 0] - 0.7 * p[:, 1] + 0.2 * p[:, 2]
    assert torch.allclose(v, exact, atol=1e-12)
    assert torch.allclose(gr, torch.tensor([0.3, -0.7, 0.2], dtype=torch.float64).expand(100, 3),
                          atol=1e-10)


def test_normalize_splat_averages_dense_nodes_and_keeps_sparse_ones_small():
    # 10 equal values at one node centre (weight 10) and one value at another (weight 1):
    # mean positive weight 5.5, so the dense node becomes the average and the sparse one is
    # divided by 5.5, not inflated to the full value
    res = 8
    dense, sparse = (torch.tensor([2, 3, 4]) + 0.5) / res, (torch.tensor([6, 6, 6]) + 0.5) / res
    pts = torch.cat([dense.expand(10, 3), sparse[None]]).double()
    vals = torch.full((11, 1), 3.0, dtype=torch.float64)
    grid, w = splat(pts, vals, res)
    out = normalize_splat(grid, w)
    assert out[0, 2, 3, 4].item() == pytest.approx(3.0)
    assert out[0, 6, 6, 6].item() == pytest.approx(3.0 / 5.5)
    assert (out[0][w == 0] == 0).all()


def test_scale_shift_normalisation():
    f = torch.randn(8, 8, 8, dtype=torch.float64)
    fs = torch.randn(50, dtype=torch.float64)
    g, gs = normalize_scale_shift(2.5 * f + 4.0, 2.5 * fs + 4.0)
    assert abs(float(gs.mean())) < 1e-12
    assert abs(abs(float(g[0, 0, 0])) - 1.0) < 1e-12
    g2, gs2 = normalize_scale_shift(f, fs)     # invariant to scale and shift of f
    assert torch.allclose(g, g2) and torch.allclose(gs, gs2)


def test_gradcheck_splat_solve_interpolate():
    torch.manual_seed(2)
    n = 6
    p = torch.rand(5, 3, dtype=torch.float64)
    q = torch.rand(4, 3, dtype=torch.float64)
    solver = PoissonSolver(n, dtype=torch.float64)

    def fn(values):
        grid, _ = splat(p, values, n)
        f = solver.solve(grid)
        return normalize_scale_shift(f, interpolate(f, q))[1]

    vals = torch.randn(5, 3, dtype=torch.float64, requires_grad=True)
    assert torch.autograd.gradcheck(fn, (vals,))


@pytest.mark.parametrize("n", [5, 6])
def test_periodic_solve_backward_is_its_adjoint(n):
    """The periodic solve's backward is the adjoint spectral multiplier, not autograd's
    transform of a zero-filled spectrum: <solve(g), w> = <g, solve^T(w)> for any g, w,
    gradients and second derivatives match finite differences, odd and even n (the
    Nyquist modes)."""
    from curvenet.neural.poisson import _spectral_adjoint
    torch.manual_seed(n)
    solver = PoissonSolver(n, dtype=torch.float64)
    g = torch.randn(3, n, n, n, dtype=torch.float64)
    w = torch.randn(n, n, n, dtype=torch.float64)
    lhs = (solver.solve(g) * w).sum()
    rhs = (g * _spectral_adjoint(w, solver._op)).sum()
    assert abs(float(lhs - rhs)) < 1e-10 * float(lhs.abs() + 1)
    g.requires_grad_(True)
    assert torch.autograd.gradcheck(solver.solve, (g,))
    assert torch.autograd.gradgradcheck(solver.solve, (g,))
