"""Anchors of the flow fit: oriented points the surface must pass through (hybrid fills)."""

import numpy as np
import pytest
import torch

from curvenet.core.distance import point_surface_distance
from curvenet.neural.flow import fit_flow_surface
from curvenet.neural.losses import normal_loss

SMALL = dict(res=32, width=32, hidden_layers=1, n_stroke=300, n_surface=200, n_volume=200,
             init_steps=10, steps=30, geometric_init_steps=20)


def test_normal_loss_is_one_minus_cos_squared_whatever_the_sign_and_length():
    n = torch.tensor([[0.0, 0.0, 1.0]] * 4, dtype=torch.float64)
    g = torch.tensor([[0.0, 0.0, 2.0], [0.0, 0.0, -0.3], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0]],
                     dtype=torch.float64)
    per_sample = [0.0, 0.0, 1.0, 0.5]   # parallel, antiparallel, tangent, 45 degrees
    for k, want in enumerate(per_sample):
        assert float(normal_loss(g[k:k + 1], n[k:k + 1])) == pytest.approx(want)
    assert float(normal_loss(g, n)) == pytest.approx(np.mean(per_sample))
    # a zero g has no direction: it costs 1, and its gradient is finite
    g0 = torch.zeros(1, 3, dtype=torch.float64, requires_grad=True)
    loss = normal_loss(g0, n[:1])
    loss.backward()
    assert loss.item() == pytest.approx(1.0) and torch.isfinite(g0.grad).all()
    gr = torch.randn(8, 3, dtype=torch.float64, requires_grad=True)
    nr = torch.nn.functional.normalize(torch.randn(8, 3, dtype=torch.float64), dim=-1)
    assert torch.autograd.gradcheck(lambda x: normal_loss(x, nr), (gr,))


def _cap(n=800, seed=0):
    """Points of the unit sphere above z = 0.3 with their radial normals."""
    v = np.random.default_rng(seed).normal(size=(6 * n, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    return v[v[:, 2] > 0.3][:n]


def test_anchors_pull_the_surface_onto_a_cap_with_its_normals():
    """One equator stroke bounds many surfaces; anchors on a spherical cap choose the sphere."""
    t = np.linspace(0, 2 * np.pi, 64)
    equator = [np.c_[np.cos(t), np.sin(t), 0 * t]]
    cap = _cap()
    free = fit_flow_surface(equator, progress=False, **SMALL)
    h = free.spacing
    assert np.median(point_surface_distance(cap, free.vertices, free.faces)[0]) > h
    assert np.isnan(free.history["full"]["normal"]).all()
    for normals in (cap, -cap):   # the sign of the normals does not matter
        fit = fit_flow_surface(equator, anchors=(cap, 3.0 * normals), progress=False, **SMALL)
        d, face = point_surface_distance(cap, fit.vertices, fit.faces)
        assert np.median(d) < 0.2 * h and np.percentile(d, 95) < 0.5 * h
        fn = np.cross(*(fit.vertices[fit.faces[:, k]] - fit.vertices[fit.faces[:, 0]]
                        for k in (1, 2)))
        fn /= np.linalg.norm(fn, axis=1, keepdims=True)
        assert np.median(np.abs((fn[face] * cap).sum(1))) > 0.98
        assert fit.history["full"]["normal"][-1] < 0.1


@pytest.mark.parametrize("anchors, match", [
    ((np.zeros((4, 3)), np.zeros((4, 3))), "non-zero normals"),
    ((np.zeros((4, 3)), np.ones((3, 3))), "shapes"),
    ((np.zeros((0, 3)), np.zeros((0, 3))), "m >= 1"),
    ((np.full((2, 3), np.nan), np.ones((2, 3))), "finite"),
    (np.zeros((4, 3)), "pair"),
])
def test_bad_anchors(anchors, match):
    t = np.linspace(0, 2 * np.pi, 16)
    with pytest.raises(ValueError, match=match):
        fit_flow_surface([np.c_[np.cos(t), np.sin(t), 0 * t]], anchors=anchors, progress=False,
                         **SMALL)
