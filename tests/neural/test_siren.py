"""The closed-form SIREN jet against autograd, and the SIREN initialisation."""

import pytest
import torch

from curvenet.neural.siren import GradientSiren


def _autograd_derivatives(net, x):
    x = x.detach().requires_grad_(True)
    g = net(x)
    G = torch.stack([torch.autograd.grad(g[:, i].sum(), x, create_graph=True)[0]
                     for i in range(3)], 1)
    H = torch.stack([torch.stack([torch.autograd.grad(G[:, i, a].sum(), x, retain_graph=True)[0]
                                  for a in range(3)], 1) for i in range(3)], 1)
    return g, G, H


@pytest.mark.parametrize("hidden", [0, 2])
def test_jet_matches_double_backward(hidden):
    torch.manual_seed(0)
    net = GradientSiren(width=16, hidden_layers=hidden).double()
    x = torch.rand(9, 3, dtype=torch.float64)
    g, G, H = net.jet(x, order=2)
    g0, G0, H0 = _autograd_derivatives(net, x)
    # identical maths, different summation order: float64 round-off only (values ~1e2)
    assert torch.allclose(g, g0, atol=1e-12)
    assert torch.allclose(G, G0, atol=1e-10)
    assert torch.allclose(H, H0, atol=1e-8)
    g1, G1 = net.jet(x, order=1)
    assert torch.allclose(g1, g) and torch.allclose(G1, G)
    assert torch.allclose(net.jet(x, order=0), g)


def test_jet_gradcheck_parameters():
    torch.manual_seed(1)
    net = GradientSiren(width=3, hidden_layers=1, omega_0=3.0).double()
    x = torch.rand(2, 3, dtype=torch.float64)

    class _Jet(torch.nn.Module):
        def __init__(self, inner):
            super().__init__()
            self.inner = inner

        def forward(self, pts):
            return self.inner.jet(pts, order=2)[2]

    wrapped = _Jet(net)

    def fn(weight, pts):
        return torch.func.functional_call(wrapped, {"inner.layers.1.weight": weight}, (pts,))

    w = net.layers[1].weight.detach().clone().requires_grad_(True)
    assert torch.autograd.gradcheck(fn, (w, x.clone().requires_grad_(True)))


def test_siren_init_bounds():
    net = GradientSiren(width=32, hidden_layers=2, omega_0=30.0)
    assert net.layers[0].weight.abs().max() <= 1.0 / 3
    assert net.layers[1].weight.abs().max() <= (6 / 32) ** 0.5 / 30 + 1e-7


def test_jet_rejects_bad_order():
    with pytest.raises(ValueError, match="order"):
        GradientSiren(8, 0).jet(torch.rand(2, 3), order=3)
