"""End-to-end checks of the flow-aligned neural surfacing driver (Zhang et al. 2025).

The small tests use a tiny configuration (seconds); the analytic-shape F-score
checks of the issue run the real ``draft`` preset and are heavy: all are
marked ``slow`` (the CI keeps the tiny end-to-end runs).
"""

import numpy as np
import pytest

from curvenet.neural import flow, flowfit
from curvenet.neural.flow import fit_flow_surface
from curvenet.neural.flowfit import FlowFit
from curvenet.neural.frame import Frame
from curvenet.neural.poisson import stroke_strip
from curvenet.neural.presets import get_config
from curvenet.neural.sampling import StrokeSampler, sample_surface_cells

from ._metrics import fscore

TINY = dict(res=32, width=32, hidden_layers=1, n_stroke=300, n_surface=200, n_volume=200,
            init_steps=3, steps=4, geometric_init_steps=5)


def _circles(n=64, r=1.0):
    t = np.linspace(0, 2 * np.pi, n)
    z = 0 * t
    return [np.c_[r * np.cos(t), r * np.sin(t), z], np.c_[r * np.cos(t), z, r * np.sin(t)],
            np.c_[z, r * np.cos(t), r * np.sin(t)]]


def test_result_fields_and_world_coordinates():
    strokes = [s * 10.0 + 5.0 for s in _circles()]
    r = fit_flow_surface(strokes, progress=False, **TINY)
    assert r.report["steps"] == {"init": 3, "full": 4}
    assert r.report["interrupted"] is False
    assert r.f_grid.shape == (32, 32, 32) and r.f_grid[0, 0, 0] == pytest.approx(1.0)
    assert set(r.history) == {"init", "full"}
    assert len(r.history["full"]["data"]) == 4
    assert {"init", "full", "extract", "total"} <= set(r.timings)
    if len(r.faces):
        lo, hi = r.vertices.min(0), r.vertices.max(0)
        # the surface lies inside the padded box of the strokes (world units)
        assert (lo > 5.0 - 10 * 1.5).all() and (hi < 5.0 + 10 * 1.5).all()
    # f interpolated at a box corner node (outside) is +1
    assert r.f(r.origin[None])[0] == pytest.approx(1.0, abs=1e-5)


def test_deterministic_on_cpu():
    a = fit_flow_surface(_circles(), progress=False, seed=3, **TINY)
    b = fit_flow_surface(_circles(), progress=False, seed=3, **TINY)
    assert np.array_equal(a.f_grid, b.f_grid)
    assert a.history == b.history or all(
        np.allclose(a.history[s][t], b.history[s][t], equal_nan=True)
        for s in a.history for t in a.history[s])


def test_keyboard_interrupt_returns_surface_so_far(monkeypatch):
    calls = {"n": 0}
    real = flowfit.sample_surface_cells

    def interrupting(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(flowfit, "sample_surface_cells", interrupting)
    r = fit_flow_surface(_circles(), progress=False, **TINY)
    assert r.report["interrupted"] is True
    assert r.report["steps"]["full"] == 2
    assert r.f_grid.shape == (32, 32, 32)


def test_poisson_every_runs():
    r = fit_flow_surface(_circles(), progress=False, poisson_every=2, **TINY)
    assert len(r.history["full"]["total"]) == 4
    assert np.isfinite(r.history["full"]["total"]).all()


def test_init_res_solves_the_initialisation_stage_on_its_own_grid(monkeypatch):
    """The initialisation stage integrates f on the ``init_res`` grid, the full stage and the
    result on ``res``; the full stage's first surface samples come from the coarse f."""
    grids = []
    real = FlowFit.solve

    def spy(self, *args, **kwargs):
        out = real(self, *args, **kwargs)
        grids.append(out[0].shape)
        return out

    monkeypatch.setattr(FlowFit, "solve", spy)
    r = fit_flow_surface(_circles(), progress=False, **dict(TINY, init_res=16))
    assert grids == [(16,) * 3] * 3 + [(32,) * 3] * 4
    assert r.f_grid.shape == (32,) * 3 and len(r.faces)
    assert np.isfinite(r.history["full"]["total"]).all()
    grids.clear()
    fit_flow_surface(_circles(), progress=False, **dict(TINY, init_res=64))
    assert set(grids) == {(32,) * 3}        # never finer than res


def _alignment_with_f(fit, n=400):
    """Mean ``|cos|`` between g and the gradient of ``fit.f`` at samples of its zero set."""
    import torch

    from curvenet.neural.poisson import interpolate
    x = sample_surface_cells(fit.f, n, torch.Generator().manual_seed(1))
    _, grad = interpolate(fit.f, x, with_gradient=True)
    with torch.no_grad():
        g = fit.net(x)
    return float(torch.nn.functional.cosine_similarity(g, grad, dim=-1).abs().mean())


def test_the_bridge_turns_g_along_the_initialisation_surface():
    """``bridge_steps``: between the stages g is fitted to sigma times the unit gradient of
    the initialisation's f. Off the strokes the initialisation never trained g; after the
    bridge g points along f's gradient on its zero set, and the stage is reported."""
    import torch

    from curvenet.neural.training import train
    cfg = get_config("draft", **dict(TINY, init_steps=6, bridge_steps=40))
    fit = FlowFit(_circles(), cfg, torch.device("cpu"), 0, None)
    init, bridge, full = fit.stages()
    assert (bridge.name, full.name) == ("bridge", "full")
    train(fit.net.parameters(), [fit.geometric_stage()], lr=1e-3)
    train(fit.net.parameters(), [init], lr=cfg.lr)
    before = _alignment_with_f(fit)
    train(fit.net.parameters(), [bridge], lr=cfg.lr)
    assert _alignment_with_f(fit) > max(0.9, before + 0.05)
    losses = fit.history["bridge"]["total"]
    assert len(losses) == 40 and losses[-1] < 0.5 * losses[0]

    r = fit_flow_surface(_circles(), progress=False, **dict(TINY, bridge_steps=2))
    assert r.report["steps"] == {"init": 3, "bridge": 2, "full": 4}
    assert set(r.history) == {"init", "bridge", "full"}
    r = fit_flow_surface(_circles(), progress=False, **dict(TINY, init_steps=0, bridge_steps=2))
    assert r.report["steps"]["bridge"] == 2 and len(r.faces)   # f from the strokes alone

    # an f that does not cross zero has no zero set to sample: the bridge fits g at the strokes
    fit = FlowFit(_circles(), cfg, torch.device("cpu"), 0, None)
    fit._surface_samples = lambda n: None
    train(fit.net.parameters(), [fit.stages()[1]], lr=cfg.lr)
    losses = fit.history["bridge"]["total"]
    assert np.isfinite(losses).all() and losses[-1] < 0.5 * losses[0]


def test_smooth_near_weights_the_smoothness_term_down_next_to_the_strokes():
    """With ``smooth_near`` each surface sample's smoothness term is scaled by its weight
    relative to ``w_smooth`` (at most 1, the paper's 0.01 / 0.1 next to a stroke): in the
    first full step of the same fit the recorded term is smaller and the others equal."""
    a = fit_flow_surface(_circles(), progress=False, w_smooth=0.1, **TINY)
    b = fit_flow_surface(_circles(), progress=False, w_smooth=0.1, smooth_near=3.0, **TINY)
    first = {t: (a.history["full"][t][0], b.history["full"][t][0]) for t in ("smooth", "align")}
    assert 0.1 * first["smooth"][0] < first["smooth"][1] < first["smooth"][0]
    assert first["align"][0] == first["align"][1]


def test_refine_from_init_mesh():
    import trimesh
    m = trimesh.creation.icosphere(2, radius=1.0)
    r = fit_flow_surface(_circles(), progress=False, init_mesh=(m.vertices, m.faces),
                         **{**TINY, "prefit_steps": 5})
    assert r.report["steps"] == {"prefit": 5, "full": 4}


def test_refine_prefit_reproduces_the_init_mesh():
    # the prefit regresses g on sigma * grad SDF of the mesh (|target|^2 = 0.25); it must fit
    # it, and the bootstrapped surface (no full step) must be the mesh's sphere. A curl
    # penalty in the prefit once collapsed g to a constant (MSE stuck at 0.25, F ~0.3)
    import trimesh
    m = trimesh.creation.icosphere(3, radius=1.0)
    r = fit_flow_surface(_circles(), progress=False, init_mesh=(m.vertices, m.faces),
                         quality="draft", res=48, prefit_steps=150, steps=0)
    assert r.history["prefit"]["total"][-1] < 0.05
    f, _ = fscore(r.vertices, r.faces, m.vertices, m.faces, threshold=0.02)
    assert f >= 0.9, f


def test_polish_keeps_the_surface_of_the_field():
    # g prefitted to sigma * grad SDF of the unit sphere, no flow step: f re-integrated from
    # 16 times the samples of a step (strokes and f's zero set) must still be that sphere,
    # the one the stroke circles lie on
    import trimesh
    m = trimesh.creation.icosphere(3, radius=1.0)
    r = fit_flow_surface(_circles(), progress=False, init_mesh=(m.vertices, m.faces),
                         quality="draft", res=48, prefit_steps=150, steps=0, polish=16)
    radius = np.linalg.norm(r.vertices, axis=1)
    assert abs(radius.mean() - 1.0) < 0.02 and radius.std() < 0.01, (radius.mean(), radius.std())


def test_average_from_averages_the_last_steps_and_leaves_training_alone():
    # the running mean starts at step int(average_from * steps) of the full stage; the
    # steps themselves (losses, f) are those of a fit without it
    from curvenet.neural.training import torch_device, train
    runs, fields = {}, []
    for average_from in (0.5, 1.0):
        cfg = get_config("draft", **TINY, polish=2, average_from=average_from)
        fit = FlowFit(_circles(), cfg, torch_device("cpu"), 0, None)
        record = fit._record

        def keep_f(stage, k, row, fit=fit, record=record):
            record(stage, k, row)
            if stage == "full" and fit.averaged is not None:
                fields.append(fit.f * fit.f[0, 0, 0].sign())

        fit._record = keep_f
        run = train(fit.net.parameters(), fit.stages(), lr=cfg.lr)
        runs[average_from] = (fit, run)
    (fit, run), (plain, plain_run) = runs[0.5], runs[1.0]
    assert plain.averaged is None and plain.f_mean is None
    assert int(fit.averaged.n_averaged) == 2 and len(fields) == 2
    # the field's running mean is the mean of the same two steps' f, signed so that the
    # box corner (outside) is +1
    assert float((fit.f_mean - (fields[0] + fields[1]) / 2).abs().max()) < 1e-6
    for stage, terms in plain.history.items():
        for term, values in terms.items():        # NaN where a term is not computed
            np.testing.assert_array_equal(fit.history[stage][term], values)
    assert bool((run.best == plain_run.best).all())
    averaged = list(fit.averaged.module.parameters())
    assert any(not bool((a == p).all()) for a, p in zip(averaged, fit.net.parameters()))


def _averaged_sphere_fit():
    """A fit whose g is prefitted to the unit sphere, averaged once with f = that sphere."""
    import torch
    import trimesh

    from curvenet.neural.training import train
    m = trimesh.creation.icosphere(3, radius=1.0)
    cfg = get_config("draft", res=48, prefit_steps=150, polish=16)
    fit = FlowFit(_circles(), cfg, torch.device("cpu"), 0, (m.vertices, m.faces))
    train(fit.net.parameters(), fit.stages()[:1], lr=cfg.lr)
    fit.f = _sphere_f(fit.frame, 48, 1.0)
    fit._average()
    return fit


def _assert_polish_is_unit_sphere(fit, f):
    V = flow._extract(fit.polish(f), fit.frame, _circles(), ["crease"] * 3, True)[0]
    r = np.linalg.norm(V, axis=1)
    assert len(r) and abs(r.mean() - 1.0) < 0.02 and r.std() < 0.01, (r.mean(), r.std())


def test_polish_integrates_the_averaged_network():
    # the averaged copy holds g prefitted to the unit sphere and the net itself is zeroed
    # afterwards: the polish must integrate the copy (the sphere), not the zero field
    import torch
    fit = _averaged_sphere_fit()
    with torch.no_grad():
        for p in fit.net.parameters():
            p.zero_()
    _assert_polish_is_unit_sphere(fit, _sphere_f(fit.frame, 48, 1.0))


def test_polish_starts_from_the_averaged_field():
    # the averaged f is the unit sphere and the last step's f a sphere of radius 0.6: a
    # round moves a surface only part of the way, so the polish returns the unit sphere
    # only if its first samples lie on the averaged f's zero set
    fit = _averaged_sphere_fit()
    _assert_polish_is_unit_sphere(fit, _sphere_f(fit.frame, 48, 0.6))


def _sphere_f(frame, res, radius):
    """Unit-cube node grid (res^3, float32 tensor) of |x| - radius in ``frame``'s world."""
    import torch
    u = (np.arange(res) + 0.5) / res
    world = frame.to_world(np.stack(np.meshgrid(u, u, u, indexing="ij"), -1).reshape(-1, 3))
    return torch.as_tensor((np.linalg.norm(world, axis=1) - radius).reshape(res, res, res),
                           dtype=torch.float32)


class _PolishFit:
    """A stand-in fit whose polish returns the sphere of radius ``polished``."""
    frame = Frame.from_points(np.vstack(_circles()), 0.2)

    def __init__(self, polished):
        self.polished = polished

    def polish(self, f):
        return _sphere_f(self.frame, 48, self.polished)


@pytest.mark.parametrize("last, polished, kept", [(1.0, 0.8, False), (0.8, 1.0, True),
                                                   (1.0, 1.0, True)])
def test_polish_is_kept_only_when_it_holds_the_strokes(last, polished, kept):
    # the strokes lie on the unit sphere: a polished f whose zero set is the sphere of
    # radius 0.8 is off them and the last step's surface is returned; the other way round
    # (and on a tie) the polished one
    fit, strokes, labels = _PolishFit(polished), _circles(), ["crease"] * 3
    cfg = get_config("draft", attach=0.0)
    mesh = flow._extract(_sphere_f(fit.frame, 48, last), fit.frame, strokes, labels, True)
    ((V, _F, *_), attach, _), info = flow._polished(fit, None, mesh, strokes, labels, True,
                                                    cfg)
    assert attach is None
    assert info["kept"] is kept
    on, off = (0, 1) if last == 1.0 else (1, 0)
    assert info["fidelity"][on] == 1.0
    assert info["fidelity"][off] == 1.0 if last == polished else info["fidelity"][off] < 0.01
    r = np.linalg.norm(V, axis=1)
    assert abs(r.mean() - (polished if kept else last)) < 0.01


@pytest.mark.parametrize("polished, kept", [(0.94, True), (0.8, False)])
def test_polish_is_judged_after_the_fairing(polished, kept):
    # a polished sphere of radius 0.94 lies off the unit circles by more than the
    # fidelity's tolerance and within the fairing's reach: as extracted it holds none of
    # them, faired it holds them all as the last step's surface does, and it is kept,
    # the last step's surface not even faired; at radius 0.8, out of the fairing's
    # reach, it is neither faired nor kept
    fit, strokes, labels = _PolishFit(polished), _circles(), ["crease"] * 3
    cfg = get_config("draft")
    raw = flow._extract(fit.polish(None), fit.frame, strokes, labels, True)
    assert flow._fidelity(raw[0], raw[1], strokes) < 0.05
    mesh = flow._extract(_sphere_f(fit.frame, 48, 1.0), fit.frame, strokes, labels, True)
    (out, attach, _), info = flow._polished(fit, None, mesh, strokes, labels, True, cfg)
    assert info == {"fidelity": [1.0, 1.0 if kept else 0.0], "kept": kept,
                    "faired": [not kept, kept]}
    assert (out[2] is mesh[2]) is not kept                 # whose f's grid
    radius = np.linalg.norm(out[0], axis=1)
    assert attach["kept"]
    if kept:                            # pulled from 0.94 onto the circles
        assert attach["fidelity"][0] < 0.05 and (np.abs(radius - 1.0) < 0.02).mean() > 0.3
    else:
        assert np.abs(radius - 1.0).max() < 0.01


@pytest.mark.parametrize("polished, kept", [(0.995, True), (0.985, False)])
def test_polish_may_hold_a_little_less_of_the_strokes(monkeypatch, polished, kept):
    # faired, the polished surface is returned while it holds no less than the last
    # step's (1.0 here) by more than POLISH_SLACK; the last step's surface is faired only
    # when the polished one falls short of all it could hold
    last = ("last", np.array([[0, 1, 2]]), None, None, 0.1)
    mesh = ("polished",) + last[1:]
    monkeypatch.setattr(flow, "_extract", lambda *a: mesh)
    monkeypatch.setattr(flow, "_fidelity_and_ceiling", lambda *a: (1.0, 1.0))   # all in reach
    monkeypatch.setattr(flow, "_faired", lambda m, *a: (m, None, polished if m is mesh
                                                        else 1.0))
    chosen, info = flow._polished(_PolishFit(1.0), None, last, [], [], True,
                                  get_config("default"))
    assert flow.POLISH_SLACK == 0.01
    assert info == {"fidelity": [1.0, polished], "kept": kept, "faired": [not kept, True]}
    assert chosen[0] is (mesh if kept else last)


def test_dirichlet_boundary_keeps_walls_outside():
    r = fit_flow_surface(_circles(), progress=False, boundary="dirichlet", **TINY)
    f = r.f_grid
    walls = np.concatenate([f[0].ravel(), f[-1].ravel(), f[:, 0].ravel(), f[:, -1].ravel(),
                            f[:, :, 0].ravel(), f[:, :, -1].ravel()])
    assert (walls > 0).all()


@pytest.mark.slow
def test_dirichlet_boundary_closes_capped_cylinder():
    # periodic: the capless cylinder leaves through the box walls (not watertight);
    # dirichlet: it closes inside the box (genus 0), though not at the rims
    import trimesh
    _, sk = _rough_shape_sketch("capped_cylinder")
    r = fit_flow_surface(sk.strokes, labels=sk.labels, quality="draft", progress=False,
                         boundary="dirichlet")
    m = trimesh.Trimesh(r.vertices, r.faces)
    assert m.is_watertight and m.euler_number == 2


@pytest.mark.parametrize("kw,match", [
    (dict(strokes=[]), "strokes"),
    (dict(strokes=[np.zeros((1, 3))]), r"strokes\[0\]"),
    (dict(strokes=[np.full((3, 3), np.nan)]), "NaN"),
    (dict(strokes=[np.zeros((3, 3))]), "zero"),
    (dict(labels=["flow", "crease", "crease"]), r"labels\[0\]"),
    (dict(labels=["crease"]), "labels"),
    (dict(quality="fast"), "quality"),
    (dict(device="tpu"), "device"),
])
def test_bad_input(kw, match):
    args = dict(strokes=_circles(), progress=False)
    args.update(kw)
    with pytest.raises(ValueError, match=match):
        fit_flow_surface(args.pop("strokes"), **args)


def _rough_shape_sketch(name, seed=0):
    shapes = pytest.importorskip("curvenet.datasets.shapes")
    redraw = pytest.importorskip("curvenet.datasets.redraw")
    shape = shapes.SHAPES[name]()
    sk = redraw.rough_sketch(shape.network, seed=seed)
    return shape, sk


def _fit_and_score(name, quality="draft", **kw):
    shape, sk = _rough_shape_sketch(name)
    r = fit_flow_surface(sk.strokes, labels=sk.labels, quality=quality, progress=False, **kw)
    ref = shape.reference_mesh(4)
    f, cd = fscore(r.vertices, r.faces, ref.vertices, ref.faces)
    return r, f, cd


def test_rough_sphere_draft():
    # the one end-to-end quality check in CI: about 10-15 s on 2 idle cores
    r, f, cd = _fit_and_score("sphere")
    assert f >= 0.90, (f, cd)


@pytest.mark.slow
@pytest.mark.parametrize("name", [
    "sphere", "ellipsoid", "torus",
    pytest.param("capped_cylinder", marks=pytest.mark.xfail(
        strict=True, reason="known limit: caps without strokes open into a tube (F 0.64); the "
        "paper's energy prefers a capsule (F 0.58), see benchmarks/bench_flow_limits.py")),
])
def test_rough_analytic_shapes_draft_fscore(name):
    r, f, cd = _fit_and_score(name)
    assert f >= 0.90, (name, f, cd)
    if name == "torus":
        import trimesh
        m = trimesh.Trimesh(r.vertices, r.faces)
        assert m.is_watertight and m.euler_number == 0      # genus 1


@pytest.mark.slow
def test_lowpass_keeps_the_hole_of_a_sparse_torus_wireframe():
    # four meridians and two rings, exact: without the solve's low-pass the noise of a
    # step's splat decides the sign of f in the hole, and default's last step walls it
    import trimesh

    from curvenet.datasets import shapes
    torus = shapes.torus(1.0, 0.25, n_u=4, n_v=2)
    r = fit_flow_surface([e.curve for e in torus.network.edges], quality="default",
                         lowpass=2.0)
    ref = torus.reference_mesh(5)
    f, cd = fscore(r.vertices, r.faces, ref.vertices, ref.faces)
    assert f >= 0.95, (f, cd)
    assert trimesh.Trimesh(r.vertices, r.faces).euler_number == 0


@pytest.mark.slow
def test_the_bridge_keeps_a_sparse_torus_tube_round_between_its_meridians():
    # three meridians and two rings, exact: without the bridge the full stage's first
    # surface samples splat the untrained g of the tube's top and dent it between two
    # meridians, to a third of its radius (F 0.66 at this seed)
    import trimesh

    from curvenet.datasets import shapes
    torus = shapes.torus(1.0, 0.4, n_u=3, n_v=2)
    r = fit_flow_surface([e.curve for e in torus.network.edges], quality="default",
                         progress=False)
    ref = torus.reference_mesh(5)
    f, cd = fscore(r.vertices, r.faces, ref.vertices, ref.faces)
    assert f >= 0.85, (f, cd)
    V = r.vertices
    q = np.hypot(V[:, 0], V[:, 1]) - 1.0
    top = np.abs(V[:, 2]) > 0.8 * np.abs(q)           # the tube's top and bottom
    phi = np.arctan2(V[:, 1], V[:, 0]) % (2 * np.pi / 3)
    between = top & (np.abs(phi - np.pi / 3) < np.pi / 9)
    assert np.percentile(np.hypot(q, V[:, 2])[between], 5) > 0.3
    assert trimesh.Trimesh(r.vertices, r.faces).euler_number == 0


def test_stroke_strip_hands_the_surface_along_the_strokes_to_them():
    # surface samples on the plane z = 0.5, stroke samples on the line y = 0.5 in it
    import torch
    gen = torch.Generator().manual_seed(0)
    x_u = torch.rand(4000, 3, generator=gen, dtype=torch.float64)
    x_u[:, 2] = 0.5
    x_s = torch.rand(500, 3, generator=gen, dtype=torch.float64)
    x_s[:, 1:] = 0.5
    width = 0.05
    keep, mass = stroke_strip(x_s, x_u, width)
    d = torch.cdist(x_u, x_s).amin(1)
    assert bool((d[keep] >= width).all()) and bool((d[~keep] < width).all())
    k = int((~keep).sum())
    assert 0.08 < k / len(x_u) < 0.12                       # the strip's share of the plane
    assert len(mass) == len(x_s) + len(x_u) - k and bool((mass[len(x_s):] == 1).all())
    assert float(mass[: len(x_s)].sum()) == pytest.approx(k)  # the splat's total mass is kept
    keep, mass = stroke_strip(x_s + torch.tensor([0.0, 0.3, 0.3], dtype=torch.float64),
                              x_u, width)
    assert bool(keep.all()) and bool((mass == 1).all())


def _integrate_radial_field(strip, res=64, iters=12, n=1500, seed=0):
    """Mean radial offset (cells) of the zero set after ``iters`` rounds of splat, Poisson
    solve and surface resampling with the exact g = sigma * grad |x - c| of a sphere drawn
    as 3 great circles: the fit's integration loop with a perfect network."""
    import torch

    from curvenet.neural.poisson import PoissonSolver, interpolate, normalize_scale_shift, splat
    R, c = 0.3, 0.5
    strokes = [c + R * s for s in _circles(200)]
    gen = torch.Generator().manual_seed(seed)
    sampler = StrokeSampler(strokes, "cpu", torch.float64)
    solver = PoissonSolver(res, dtype=torch.float64)
    x = (torch.arange(res, dtype=torch.float64) + 0.5) / res
    f = (torch.stack(torch.meshgrid(x, x, x, indexing="ij"), -1) - c).norm(dim=-1) - R
    for _ in range(iters):
        x_s, _ = sampler.sample(n, gen)
        x_u = sample_surface_cells(f, n, gen)
        mass = None
        if strip:
            keep, mass = stroke_strip(x_s, x_u, 1.0 / res)
            x_u = x_u[keep]
        p = torch.cat([x_s, x_u])
        grid, _ = splat(p, 0.5 * (p - c) / (p - c).norm(dim=-1, keepdim=True), res, mass)
        f = solver.solve(grid)
        f, _ = normalize_scale_shift(f, interpolate(f, x_s))
        f = f if f[0, 0, 0] > 0 else -f
    s = sample_surface_cells(f, 20000, gen)
    return float(((s - c).norm(dim=-1) - R).mean()) * res


def test_stroke_strip_keeps_a_sphere_between_its_strokes():
    # with the stroke samples splatted on top of the surface samples the zero set shrinks
    # between the strokes (about a sixth of a cell here); with the strip it stays put
    assert _integrate_radial_field(strip=False) < -0.1
    assert abs(_integrate_radial_field(strip=True)) < 0.06


def test_polish_with_the_stroke_strip_keeps_the_sphere():
    # g prefitted to the unit sphere, two normalised flow steps and the polish with the strip:
    # the surface stays the sphere the stroke circles lie on
    import trimesh
    m = trimesh.creation.icosphere(3, radius=1.0)
    r = fit_flow_surface(_circles(), progress=False, init_mesh=(m.vertices, m.faces),
                         quality="draft", res=48, prefit_steps=150, steps=2, normalize_from=0.0,
                         polish=8, polish_strip=1.0)
    radius = np.linalg.norm(r.vertices, axis=1)
    assert abs(radius.mean() - 1.0) < 0.02 and radius.std() < 0.015, (radius.mean(), radius.std())


def test_surface_samples_come_from_exactly_the_sign_change_cells():
    """The cells sampled are those whose 8 corners hold both signs (the 2^3 max and
    min pooling they replace), every sample on the zero set within a fraction of a
    cell."""
    import torch
    import torch.nn.functional as F

    from curvenet.neural.poisson import interpolate
    from curvenet.neural.sampling import _in_some_cell
    torch.manual_seed(0)
    n = 24
    c = (torch.arange(n, dtype=torch.float32) + 0.5) / n
    X, Y, Z = torch.meshgrid(c, c, c, indexing="ij")
    f = ((X - 0.5) ** 2 + (Y - 0.5) ** 2 + (Z - 0.5) ** 2).sqrt() - 0.3
    f = f + 0.01 * torch.randn_like(f)
    f[3, 4, 5] = 0.0                                   # a zero corner is neither sign
    f5 = f[None, None]
    cmin, cmax = -F.max_pool3d(-f5, 2, stride=1)[0, 0], F.max_pool3d(f5, 2, stride=1)[0, 0]
    want = (cmin < 0) & (cmax > 0)
    assert torch.equal(_in_some_cell(f > 0) & _in_some_cell(f < 0), want)
    p = sample_surface_cells(f, 500, torch.Generator().manual_seed(1))
    assert p.shape == (500, 3) and float(interpolate(f, p).abs().max()) < 0.5 / n


def test_subdivide_curves_the_final_mesh_of_the_same_fit():
    import trimesh
    strokes = _circles()
    flat = fit_flow_surface(strokes, progress=False, seed=0, **TINY, subdivide=0)
    curved = fit_flow_surface(strokes, progress=False, seed=0, **TINY, subdivide=1)
    assert len(flat.faces) and len(curved.faces) == 4 * len(flat.faces)
    np.testing.assert_allclose(curved.vertices[:len(flat.vertices)], flat.vertices)
    a = trimesh.Trimesh(flat.vertices, flat.faces, process=False)
    b = trimesh.Trimesh(curved.vertices, curved.faces, process=False)
    assert b.euler_number == a.euler_number and b.is_watertight == a.is_watertight
    # the new vertices bulge out of the flat facets of a round surface: a larger volume
    assert abs(b.volume) > abs(a.volume)
    assert curved.report["n_faces"] == len(curved.faces)
