"""Closed-form Green's-function feature functions against quadrature and their regularity."""

from __future__ import annotations

import math

import numpy as np
import pytest
import torch
from scipy import integrate

from curvenet.neural.feature import (
    feature_function,
    mollified_feature_function,
    mollifier,
    segment_integral,
    triangle_integral,
)

D = torch.float64
A2 = torch.tensor([0.2, -0.1], dtype=D)
B2 = torch.tensor([1.1, 0.4], dtype=D)
TRI = torch.tensor([[0.0, 0.0, 0.0], [1.0, 0.2, 0.1], [0.3, 0.9, -0.2]], dtype=D)


def _quad_segment(x, a, b):
    length = float(np.linalg.norm(b - a))
    t = (b - a) / length
    return integrate.quad(lambda u: math.log(np.linalg.norm(x - (a + u * t))) / (2 * math.pi),
                          0.0, length, epsabs=1e-13, epsrel=1e-13)[0]


def _quad_triangle(x, v0, v1, v2):
    e1, e2 = v1 - v0, v2 - v0
    area2 = np.linalg.norm(np.cross(e1, e2))
    f = lambda v, u: -area2 / (4 * math.pi * np.linalg.norm(x - (v0 + u * e1 + v * e2)))  # noqa: E731
    return integrate.dblquad(f, 0.0, 1.0, 0.0, lambda u: 1.0 - u, epsabs=1e-12, epsrel=1e-12)[0]


@pytest.mark.parametrize("x", [[0.5, 0.9], [-1.0, 0.3], [3.0, 2.0], [0.6, 0.15], [1.5, 0.62]])
def test_segment_matches_quadrature(x):
    # quad reaches ~1e-13 on this smooth integrand; 1e-9 leaves room for rounding in logs
    x = np.asarray(x)
    val = segment_integral(torch.tensor(x, dtype=D), A2, B2).item()
    assert abs(val - _quad_segment(x, A2.numpy(), B2.numpy())) < 1e-9


@pytest.mark.parametrize("x", [[0.3, 0.3, 0.5], [2.0, 1.0, -1.0], [-0.5, -0.5, 0.01],
                               [0.5, 0.1, -0.3], [1.2, 1.2, 0.05]])
def test_triangle_matches_quadrature(x):
    x = np.asarray(x)
    val = triangle_integral(torch.tensor(x, dtype=D), *TRI).item()
    assert abs(val - _quad_triangle(x, *TRI.numpy())) < 1e-9


def test_finite_on_M_and_at_vertices():
    pts2 = torch.stack([A2, B2, 0.5 * (A2 + B2), 0.3 * A2 + 0.7 * B2]).requires_grad_(True)
    v2 = segment_integral(pts2, A2, B2)
    (g2,) = torch.autograd.grad(v2.sum(), pts2)
    tri_pts = torch.stack([TRI[0], TRI[1], 0.5 * (TRI[0] + TRI[2]), TRI.mean(0),
                           2 * TRI[1] - TRI[0]]).requires_grad_(True)
    v3 = triangle_integral(tri_pts, *TRI)
    (g3,) = torch.autograd.grad(v3.sum(), tri_pts)
    for t in (v2, g2, v3, g3):
        assert torch.isfinite(t).all()
    # continuity at a point of M: the limit from off-M points equals the value on M
    c = TRI.mean(0)
    n = torch.linalg.cross(TRI[1] - TRI[0], TRI[2] - TRI[0])
    n = n / n.norm()
    for eps in (1e-4, 1e-6):
        near = triangle_integral(c + eps * n, *TRI)
        assert abs((near - triangle_integral(c, *TRI)).item()) < 2 * eps


def _one_sided_normal_derivatives(fun, p, n, eps=1e-7):
    out = []
    for s in (1.0, -1.0):
        q = (p + s * eps * n).clone().requires_grad_(True)
        (g,) = torch.autograd.grad(fun(q).sum(), q)
        out.append((g * n).sum().item())
    return out


def test_normal_derivative_jumps_by_one():
    # Eq. 2 with g = 1: d f / d n+ - d f / d n- = 1 on M (the sign convention: n+ from the
    # side the normal points to, where f grows away from M)
    t = (B2 - A2) / (B2 - A2).norm()
    n2 = torch.stack([-t[1], t[0]])
    p2 = 0.4 * A2 + 0.6 * B2
    up, dn = _one_sided_normal_derivatives(lambda q: segment_integral(q, A2, B2), p2, n2)
    assert abs((up - dn) - 1.0) < 1e-5
    n3 = torch.linalg.cross(TRI[1] - TRI[0], TRI[2] - TRI[0])
    n3 = n3 / n3.norm()
    p3 = TRI.T @ torch.tensor([0.2, 0.5, 0.3], dtype=D)
    up, dn = _one_sided_normal_derivatives(lambda q: triangle_integral(q, *TRI), p3, n3)
    assert abs((up - dn) - 1.0) < 1e-5
    # tangential derivative has no jump
    tang = (TRI[1] - TRI[0]) / (TRI[1] - TRI[0]).norm()
    g = []
    for s in (1.0, -1.0):
        q = (p3 + s * 1e-7 * n3).clone().requires_grad_(True)
        g.append(torch.autograd.grad(triangle_integral(q, *TRI), q)[0] @ tang)
    assert abs((g[0] - g[1]).item()) < 1e-5


def _fd_laplacian(fun, x, h=1e-3):
    lap = torch.zeros(x.shape[0], dtype=D)
    f0 = fun(x)
    for k in range(x.shape[1]):
        e = torch.zeros(x.shape[1], dtype=D)
        e[k] = h
        lap += (fun(x + e) - 2 * f0 + fun(x - e)) / h**2
    return lap


def test_harmonic_and_smooth_off_M():
    # off M the feature function is harmonic (Eq. 1, h = 0): the 5-/7-point Laplacian is
    # O(h^2 f'''') ~ 1e-6 at distance >= 0.1; autograd gradients match central differences
    rng = np.random.default_rng(0)
    verts = torch.tensor(rng.normal(size=(6, 3)), dtype=D)
    faces = torch.tensor([[0, 1, 2], [1, 3, 2], [3, 4, 5]])
    x = torch.tensor(rng.normal(size=(40, 3)) * 2.0, dtype=D)
    fun = lambda q: feature_function(q, verts, faces)  # noqa: E731
    from curvenet.neural.feature import element_centres
    dist = torch.cdist(x, element_centres(verts, faces)).min(1).values
    keep = dist > 0.3
    lap = _fd_laplacian(fun, x[keep])
    assert lap.abs().max().item() < 1e-4
    xg = x[keep].clone().requires_grad_(True)
    (g,) = torch.autograd.grad(fun(xg).sum(), xg)
    h = 1e-5
    fd = torch.stack([(fun(x[keep] + h * e) - fun(x[keep] - h * e)) / (2 * h)
                      for e in torch.eye(3, dtype=D)], 1)
    assert (g - fd).abs().max().item() < 1e-8


def test_gradient_wrt_vertices_gradcheck():
    segs = torch.tensor([[0, 1], [1, 2]])
    v2 = torch.tensor([[0.0, 0.0], [0.7, 0.2], [1.3, -0.4]], dtype=D, requires_grad=True)
    x2 = torch.tensor([[0.3, 0.5], [1.0, -0.8], [2.0, 0.1]], dtype=D, requires_grad=True)
    assert torch.autograd.gradcheck(lambda v, q: feature_function(q, v, segs), (v2, x2))
    faces = torch.tensor([[0, 1, 2]])
    v3 = TRI.clone().requires_grad_(True)
    x3 = torch.tensor([[0.3, 0.3, 0.5], [1.0, -0.5, 0.2]], dtype=D, requires_grad=True)
    assert torch.autograd.gradcheck(lambda v, q: feature_function(q, v, faces), (v3, x3))
    # second order (Eikonal losses need double backward)
    assert torch.autograd.gradgradcheck(lambda v, q: feature_function(q, v, faces), (v3, x3))


def test_channels_sum_to_single_and_chunking():
    rng = np.random.default_rng(1)
    verts = torch.tensor(rng.normal(size=(10, 3)), dtype=D)
    faces = torch.tensor(rng.integers(0, 10, size=(8, 3)))
    faces = faces[[len(set(f.tolist())) == 3 for f in faces]]
    x = torch.tensor(rng.normal(size=(50, 3)), dtype=D)
    ch = torch.arange(len(faces)) % 3
    multi = feature_function(x, verts, faces, channels=ch, n_channels=4)
    assert multi.shape == (50, 4) and torch.all(multi[:, 3] == 0)
    single = feature_function(x, verts, faces, max_pairs=7)  # several chunks
    assert torch.allclose(multi.sum(1), single, atol=1e-14)


def test_mollifier_values_and_support():
    r = torch.tensor([0.0, 0.5, 0.999, 1.0, 1.5, -0.5], dtype=D)
    phi = mollifier(r)
    assert phi[0].item() == pytest.approx(1.0)
    assert phi[1].item() == pytest.approx(math.exp(1 - 1 / 0.75))
    assert phi[3].item() == 0.0 and phi[4].item() == 0.0 and phi[5] == phi[1]
    rr = r.clone().requires_grad_(True)
    (g,) = torch.autograd.grad(mollifier(rr).sum(), rr)
    assert torch.isfinite(g).all() and g[3] == 0 and g[4] == 0


def _strip(n=12, length=1.0, width=0.1):
    s = np.linspace(0, length, n + 1)
    verts = np.concatenate([np.stack([s, np.full_like(s, -width), np.zeros_like(s)], 1),
                            np.stack([s, np.full_like(s, width), np.zeros_like(s)], 1)])
    k = n + 1
    faces = [[i, i + 1, k + i] for i in range(n)] + [[i + 1, k + i + 1, k + i] for i in range(n)]
    return torch.tensor(verts, dtype=D), torch.tensor(faces)


def test_mollified_matches_global_in_the_limit_and_at_centre():
    verts, faces = _strip()
    rng = np.random.default_rng(2)
    x = torch.tensor(rng.uniform(-0.3, 1.3, size=(200, 3)), dtype=D)
    glob = feature_function(x, verts, faces)
    # phi = 1 - O((d / radius)^4): with radius 100x the extent the two agree to ~1e-8
    moll = mollified_feature_function(x, verts, faces, radius=100.0)
    assert (moll - glob).abs().max().item() < 1e-6
    # where the mollifier of the only element equals 1 (its centre) they agree exactly
    one = faces[:1]
    c = verts[one[0]].mean(0, keepdim=True)
    assert torch.allclose(mollified_feature_function(c, verts, one, radius=0.05),
                          feature_function(c, verts, one), atol=1e-15)
    # 2D, a polyline
    v2 = torch.tensor([[0.0, 0.0], [0.5, 0.1], [1.0, 0.0]], dtype=D)
    s2 = torch.tensor([[0, 1], [1, 2]])
    x2 = torch.tensor(rng.uniform(-1, 2, size=(50, 2)), dtype=D)
    assert (mollified_feature_function(x2, v2, s2, radius=100.0)
            - feature_function(x2, v2, s2)).abs().max().item() < 1e-6


def test_mollified_jump_and_smoothness():
    verts, faces = _strip(n=12)
    radius = 0.25
    fun = lambda q: mollified_feature_function(q.reshape(-1, 3), verts, faces,  # noqa: E731
                                               radius=radius)
    # on M the normal-derivative jump is sum_i phi_i(p) jump_i = phi_k(p) for the element k
    # that contains p (the others are smooth there)
    p = torch.tensor([0.52, -0.03, 0.0], dtype=D)
    n = torch.tensor([0.0, 0.0, 1.0], dtype=D)
    up, dn = _one_sided_normal_derivatives(fun, p, n)
    from curvenet.neural.feature import element_centres
    cen = element_centres(verts, faces)
    inside = [k for k, f in enumerate(faces.tolist())
              if _in_triangle(p[:2].numpy(), verts[f, :2].numpy())]
    assert len(inside) == 1
    phik = mollifier(((p - cen[inside[0]]) ** 2).sum() / radius**2)
    assert abs((up - dn) - phik.item()) < 1e-5
    # C-infinity off M, also across the support boundaries |x - c_i| = radius (the sum is
    # no longer harmonic there): along a line above M, crossing many support boundaries and the
    # fade-out past the strip's end, the autograd second derivative matches central differences
    # of the autograd first derivative to O(step^2) (a kink in f' would leave an O(1) mismatch)
    s = torch.linspace(-0.4, 1.4, 1801, dtype=D)
    line = torch.stack([s, torch.full_like(s, 0.05), torch.full_like(s, 0.15)], 1)
    line.requires_grad_(True)
    val = fun(line)
    (g,) = torch.autograd.grad(val.sum(), line, create_graph=True)
    (gg,) = torch.autograd.grad(g[:, 0].sum(), line)
    d2 = gg[:, 0].detach()
    step = (s[1] - s[0]).item()
    fd2 = (g[2:, 0] - g[:-2, 0]).detach() / (2 * step)
    assert (fd2 - d2[1:-1]).abs().max().item() < 1e-2 * d2.abs().max().item()
    assert torch.isfinite(d2).all()


def _in_triangle(p, tri):
    a, b, c = tri
    m = np.array([b - a, c - a]).T
    u, v = np.linalg.solve(m, p - a)
    return u > 0 and v > 0 and u + v < 1


def test_invalid_inputs():
    v = torch.zeros(3, 3, dtype=D)
    with pytest.raises(ValueError, match="radius"):
        mollified_feature_function(torch.zeros(2, 3, dtype=D), v, [[0, 1, 2]], radius=-1.0)
    with pytest.raises(ValueError, match="elements"):
        feature_function(torch.zeros(2, 3, dtype=D), v, [[0, 1]])
    with pytest.raises(ValueError, match="index"):
        feature_function(torch.zeros(2, 3, dtype=D), v, [[0, 1, 5]])
