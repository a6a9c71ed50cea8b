"""Analytic oracles for II, principal directions, alignment and curl (Eq. 4, 12, 14-18)."""

import math

import pytest
import torch

from curvenet.neural.level_sets import (alignment_cos4, covariant_tv, curl,
                                        directional_derivative_II, principal_curvatures,
                                        second_fundamental_form, tangent_frame)
from curvenet.core.tolerances import NORM_EPS
from curvenet.neural.losses import alignment_loss, curl_loss, smoothness_loss
from curvenet.neural.siren import GradientSiren

D = torch.float64


def _sphere_field(p, r):
    """g = grad |x| and its Jacobian (P / |x|) and Hessian at points p."""
    rho = p.norm(dim=1, keepdim=True)
    n = p / rho
    eye = torch.eye(3, dtype=D)
    G = (eye - n[:, :, None] * n[:, None, :]) / rho[:, :, None]
    return n, G


def _cylinder_field(p):
    """g = grad sqrt(x^2 + y^2) (axis z) and its Jacobian."""
    q = p.clone()
    q[:, 2] = 0
    rho = q.norm(dim=1, keepdim=True)
    n = q / rho
    P2 = torch.diag(torch.tensor([1.0, 1.0, 0.0], dtype=D)) - n[:, :, None] * n[:, None, :]
    return n, P2 / rho[:, :, None]


def test_sphere_second_fundamental_form_is_identity_over_r():
    torch.manual_seed(0)
    r = 0.37
    p = torch.randn(200, 3, dtype=D)
    p = r * p / p.norm(dim=1, keepdim=True)
    g, G = _sphere_field(p, r)
    II = second_fundamental_form(0.5 * g, 0.5 * G)     # invariant to the scale of g
    n = g
    P = torch.eye(3, dtype=D) - n[:, :, None] * n[:, None, :]
    assert torch.allclose(II, P / r, atol=1e-12)
    k, _ = principal_curvatures(g, G)
    assert torch.allclose(k, torch.full_like(k, 1 / r), atol=1e-10)


def test_cylinder_principal_direction_along_axis_and_alignment_zero():
    torch.manual_seed(1)
    R = 0.6
    th = 2 * math.pi * torch.rand(100, dtype=D)
    z = torch.rand(100, dtype=D)
    p = torch.stack([R * torch.cos(th), R * torch.sin(th), z], 1)
    g, G = _cylinder_field(p)
    k, d = principal_curvatures(g, G)
    assert torch.allclose(k[:, 0], torch.full_like(k[:, 0], 1 / R), atol=1e-10)
    assert torch.allclose(k[:, 1], torch.zeros_like(k[:, 1]), atol=1e-10)
    assert torch.allclose(d[:, 1, 2].abs(), torch.ones(100, dtype=D), atol=1e-10)
    ruling = torch.tensor([0.0, 0.0, 1.0], dtype=D).expand(100, 3)
    circle = torch.stack([-torch.sin(th), torch.cos(th), 0 * th], 1)
    assert float(alignment_loss(g, G, ruling)) < 1e-20
    assert float(alignment_loss(g, G, circle)) < 1e-20
    # a 45-degree helix is the worst case: cos(4 * 45deg) = -1, loss 4
    helix = (ruling + circle) / math.sqrt(2)
    assert abs(float(alignment_loss(g, G, helix)) - 4.0) < 1e-10
    # 22.5 degrees: cos 4a = 0, loss 1
    a = math.pi / 8
    t = math.cos(a) * circle + math.sin(a) * ruling
    assert abs(float(alignment_loss(g, G, t)) - 1.0) < 1e-10
    # 11.25 degrees: (1 - cos 4a)^2 = (1 - 1/sqrt(2))^2
    a = math.pi / 16
    t = math.cos(a) * circle + math.sin(a) * ruling
    assert abs(float(alignment_loss(g, G, t)) - (1 - 1 / math.sqrt(2)) ** 2) < 1e-10


def test_alignment_is_frame_and_scale_invariant():
    torch.manual_seed(2)
    g = torch.randn(50, 3, dtype=D)
    G = torch.randn(50, 3, 3, dtype=D)
    t = torch.randn(50, 3, dtype=D)
    c1, v1 = alignment_cos4(g, G, t)
    c2, v2 = alignment_cos4(3.0 * g, 3.0 * G, -2.0 * t)
    assert torch.equal(v1, v2)
    assert torch.allclose(c1, c2, atol=1e-10)
    # eigenvector-based reference: angle to the first principal direction
    _, d = principal_curvatures(g, G)
    n = g / g.norm(dim=1, keepdim=True)
    tp = t - (t * n).sum(1, keepdim=True) * n
    cosa = (tp * d[:, 0]).sum(1) / tp.norm(dim=1)
    alpha = torch.acos(cosa.clamp(-1, 1))
    assert torch.allclose(c1[v1], torch.cos(4 * alpha)[v1], atol=1e-8)


def test_tangent_frame_orthonormal():
    n = torch.randn(100, 3, dtype=D)
    n = n / n.norm(dim=1, keepdim=True)
    t1, t2 = tangent_frame(n)
    M = torch.stack([t1, t2, n], 1)
    assert torch.allclose(M @ M.transpose(1, 2), torch.eye(3, dtype=D).expand(100, 3, 3),
                          atol=1e-12)


def test_curl_zero_for_gradient_field_and_nonzero_for_rotation():
    torch.manual_seed(3)
    p = torch.randn(64, 3, dtype=D)
    _, G = _sphere_field(p, 1.0)
    assert float(curl_loss(G)) < 1e-24
    rot = torch.tensor([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]], dtype=D)
    c = curl(rot.expand(5, 3, 3))
    assert torch.allclose(c, torch.tensor([0.0, 0.0, 2.0], dtype=D).expand(5, 3))


def test_sphere_and_cylinder_are_covariantly_constant():
    # II = P / r on a sphere and the cylinder's II are parallel tensors: nabla_S II = 0
    torch.manual_seed(4)
    p = torch.randn(30, 3, dtype=D)
    p = 0.5 * p / p.norm(dim=1, keepdim=True)
    x = p.clone().requires_grad_(True)
    g, G = _sphere_field(x, 0.5)
    H = torch.stack([torch.stack([torch.autograd.grad(G[:, i, a].sum(), x, retain_graph=True)[0]
                                  for a in range(3)], 1) for i in range(3)], 1)
    tv = covariant_tv(g.detach(), G.detach(), H.detach())
    assert float(tv.max()) < 1e-5          # sqrt(eps) floor = 1e-6


def test_directional_derivative_matches_finite_difference():
    torch.manual_seed(5)
    net = GradientSiren(width=16, hidden_layers=1, omega_0=5.0).double()
    x = torch.rand(10, 3, dtype=D)
    d = torch.randn(10, 3, dtype=D)
    g, G, H = net.jet(x, order=2)
    dII = directional_derivative_II(g, G, H, d)
    h = 1e-6
    gp, Gp = net.jet(x + h * d, order=1)
    gm, Gm = net.jet(x - h * d, order=1)
    fd = (second_fundamental_form(gp, Gp) - second_fundamental_form(gm, Gm)) / (2 * h)
    assert torch.allclose(dII, fd, atol=1e-5 * (1 + float(fd.detach().abs().max())))


def _smoothness_autograd(net, x, eps=NORM_EPS):
    """Eq. 5 by double backward instead of the closed-form jet (the oracle).

    ``II`` is built from ``net.jet(x, order=1)`` and differentiated with respect to
    ``x`` by autograd (6 distinct components, ``create_graph``), then projected as in
    :func:`neural.level_sets.covariant_tv`.
    """
    x = x.detach().requires_grad_(True)
    g, G = net.jet(x, order=1)
    II = second_fundamental_form(g, G)
    grads = {}
    for i in range(3):
        for j in range(i, 3):
            grads[i, j] = torch.autograd.grad(II[:, i, j].sum(), x, create_graph=True)[0]
    Dx = torch.stack([torch.stack([grads[min(i, j), max(i, j)] for j in range(3)], 1)
                      for i in range(3)], 1)                      # (N, 3, 3, 3): d II_ij / d x_k
    n = g / g.norm(dim=-1, keepdim=True).clamp(min=eps)
    P = torch.eye(3, dtype=g.dtype, device=g.device) - n.unsqueeze(-1) * n.unsqueeze(-2)
    t1, t2 = tangent_frame(n)
    total = 0.0
    for t in (t1, t2):
        Dt = P @ torch.einsum("nijk,nk->nij", Dx, t) @ P
        total = total + (Dt * Dt).sum((-1, -2))
    return torch.sqrt(total + eps).mean()


def test_smoothness_jet_equals_autograd():
    torch.manual_seed(6)
    net = GradientSiren(width=16, hidden_layers=1, omega_0=5.0).double()
    x = torch.rand(20, 3, dtype=D)
    g, G, H = net.jet(x, order=2)
    a = smoothness_loss(g, G, H)
    b = _smoothness_autograd(net, x)
    assert torch.allclose(a, b, rtol=1e-9)


@pytest.mark.parametrize("fn", ["align", "smooth"])
def test_gradcheck_losses(fn):
    torch.manual_seed(7)
    g = torch.randn(4, 3, dtype=D, requires_grad=True)
    G = torch.randn(4, 3, 3, dtype=D, requires_grad=True)
    if fn == "align":
        t = torch.randn(4, 3, dtype=D)
        assert torch.autograd.gradcheck(lambda a, b: alignment_loss(a, b, t), (g, G))
    else:
        H = torch.randn(4, 3, 3, 3, dtype=D)
        H = (H + H.transpose(-1, -2)).requires_grad_(True)
        assert torch.autograd.gradcheck(smoothness_loss, (g, G, H))
