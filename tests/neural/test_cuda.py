"""The CUDA path of the neural backend: the same answers as the CPU, and the same quality.

Skipped where torch sees no CUDA device (the CI machine); run on a GPU machine with
``python -m pytest tests/neural/test_cuda.py``. Float64 comparisons are tight (1e-9):
every operation has a deterministic CPU counterpart, only the summation order differs.
"""

import numpy as np
import pytest
import torch

from curvenet.neural.feature import feature_function, mollified_feature_function
from curvenet.neural.poisson import PoissonSolver, interpolate, splat
from curvenet.neural.siren import GradientSiren

from .test_flow import _fit_and_score

pytestmark = pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device")

CUDA = torch.device("cuda")


@pytest.mark.parametrize("boundary", ["periodic", "dirichlet"])
@pytest.mark.parametrize("n", [32, 33])
def test_poisson_cuda_matches_cpu(boundary, n):
    g = torch.randn(3, n, n, n, dtype=torch.float64, generator=torch.Generator().manual_seed(n))
    cpu = PoissonSolver(n, dtype=torch.float64, boundary=boundary).solve(g)
    gpu = PoissonSolver(n, device=CUDA, dtype=torch.float64, boundary=boundary).solve(g.to(CUDA))
    assert gpu.device.type == "cuda"
    assert (gpu.cpu() - cpu).abs().max() < 1e-9 * cpu.abs().max()


def test_splat_and_interpolate_cuda_match_cpu():
    gen = torch.Generator().manual_seed(1)
    p = torch.rand(5000, 3, dtype=torch.float64, generator=gen)
    v = torch.randn(5000, 3, dtype=torch.float64, generator=gen)
    grid, w = splat(p, v, 24)
    grid_g, w_g = splat(p.to(CUDA), v.to(CUDA), 24)
    assert torch.allclose(grid_g.cpu(), grid, atol=1e-12) and torch.allclose(w_g.cpu(), w)
    f = grid[0]
    assert torch.allclose(interpolate(f.to(CUDA), p.to(CUDA)).cpu(), interpolate(f, p), atol=1e-12)


def test_siren_jet_cuda_matches_cpu():
    torch.manual_seed(0)
    net = GradientSiren(64, 2, 30.0).double()
    x = torch.rand(500, 3, dtype=torch.float64)
    ref = net.jet(x, order=2)
    out = net.to(CUDA).jet(x.to(CUDA), order=2)
    for a, b in zip(out, ref):
        assert (a.cpu() - b).abs().max() < 1e-9 * (1 + b.abs().max())


def test_feature_functions_cuda_match_cpu():
    gen = torch.Generator().manual_seed(2)
    verts = torch.rand(40, 3, dtype=torch.float64, generator=gen)
    tris = torch.randint(40, (60, 3), generator=gen)
    tris = tris[(tris != tris[:, [1, 2, 0]]).all(1)]  # no degenerate triangles
    x = torch.rand(2000, 3, dtype=torch.float64, generator=gen) * 1.4 - 0.2
    for fn, kw in ((feature_function, {}), (mollified_feature_function, {"radius": 0.4})):
        ref = fn(x, verts, tris, **kw)
        out = fn(x.to(CUDA), verts.to(CUDA), tris.to(CUDA), **kw)
        assert out.device.type == "cuda"
        assert (out.cpu() - ref).abs().max() < 1e-9 * (1 + ref.abs().max())


def test_rough_sphere_draft_on_cuda():
    r, f, cd = _fit_and_score("sphere", device="cuda")
    assert r.report["device"].startswith("cuda")
    assert f >= 0.90, (f, cd)


def test_rough_torus_default_on_cuda_has_genus_one():
    # default, not draft: draft's small samples make the torus seed-dependent (F 0.81 with
    # CUDA's random stream at seed 0, 0.95-0.98 with the CPU's at seeds 0-2); a few s on a GPU
    import trimesh
    r, f, cd = _fit_and_score("torus", quality="default", device="cuda")
    m = trimesh.Trimesh(r.vertices, r.faces)
    assert f >= 0.90 and m.is_watertight and m.euler_number == 0, (f, cd, m.euler_number)


def test_crease_refine_on_cuda():
    from curvenet.neural.crease_refit import crease_refine

    from .test_crease_refit import _box_edges, _box_mesh
    v, f = _box_mesh()
    strokes = _box_edges()
    r = crease_refine(v, f, strokes, ["crease"] * 12, steps=30, res=32, progress=False,
                      device="cuda")
    assert r.report["n_channels"] >= 3 and np.isfinite(r.report["final_loss"])
    assert len(r.faces) > 0
    # the refit stays on the unit box: every vertex within a few cells of its surface
    d = np.minimum(np.abs(r.vertices), np.abs(r.vertices - 1)).min(1)
    assert np.quantile(d, 0.95) < 0.1
