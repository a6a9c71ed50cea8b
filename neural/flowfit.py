"""One flow fit: the network, the samplers, the Poisson solver, the current f and the steps.

:class:`FlowFit` holds the state of one fit of :func:`neural.flow.fit_flow_surface`
and builds the step functions of its stages (Zhang et al. 2025, Sec. 5.2: an
initialisation stage on the strokes, then the full stage of Eq. 13), which
:func:`neural.training.train` runs; after training it re-integrates f (the polish).
torch is imported inside the methods. The choices where this departs from the paper
are listed in :mod:`neural.flow`.
"""

from __future__ import annotations

import numpy as np

from curvenet.core.geometry import face_normals_areas, sample_surface
from curvenet.core.tolerances import COINCIDENT_REL, NORM_EPS

from .frame import Frame, stroke_nodes
from .presets import FlowConfig
from .sampling import StrokeSampler, sample_surface_cells
from .training import GLOBAL_STREAM, Stage, Step, seeded

__all__ = ["FlowFit"]

#: The loss terms a fit records per step (unweighted; NaN where not computed).
_TERMS = ("total", "align", "smooth", "data", "eik", "curl", "normal")


def _sample_triangles(V, F, n, rng):
    """``n`` area-uniform points ``(n, 3)`` on the mesh ``(V, F)``, or None if all degenerate."""
    areas = face_normals_areas(V, F)[1]
    if not areas.sum() > 0:
        return None
    return sample_surface(V, F, n, rng, areas=areas)[0]


def _prefit_targets(init_mesh, frame: Frame, sigma, rng, n=20000):
    """Unit-cube points and targets ``sigma * grad SDF`` of a mesh (refinement).

    Parameters
    ----------
    init_mesh : (vertices (V, 3), faces (F, 3))
        World coordinates.
    frame : Frame
    sigma : float
        Target gradient norm.
    rng : numpy.random.Generator
    n : int
        Points: half near the surface (Gaussian offsets of 0.02), half uniform.

    Returns
    -------
    P : (n, 3) float64
        Unit-cube points.
    target : (n, 3) float64
        ``sigma`` times the unit gradient of the signed distance at ``P``.
    surf : (n // 2, 3) float64
        The surface samples the near points were drawn around.

    Raises
    ------
    ValueError
        If ``init_mesh`` is not a triangle mesh with a face of positive area.
    """
    import igl
    V = frame.to_unit(np.asarray(init_mesh[0], float))
    F = np.asarray(init_mesh[1], dtype=np.int64)
    if V.ndim != 2 or V.shape[1] != 3 or F.ndim != 2 or F.shape[1] != 3 or len(F) == 0:
        raise ValueError("init_mesh must be (vertices (V, 3), faces (F, 3)) with F >= 1")
    surf = _sample_triangles(V, F, n // 2, rng)
    if surf is None:
        raise ValueError("init_mesh has only degenerate faces")
    near = surf + rng.normal(scale=0.02, size=surf.shape)
    vol = rng.random((n - n // 2, 3))
    P = np.clip(np.vstack([near, vol]), 0.0, 1.0)
    S, _, C, N = igl.signed_distance(P, V, F, sign_type=igl.SIGNED_DISTANCE_TYPE_PSEUDONORMAL)
    d = P - C
    dn = np.linalg.norm(d, axis=1, keepdims=True)
    grad = np.where(dn > COINCIDENT_REL, d / np.maximum(dn, NORM_EPS) * np.sign(S)[:, None], N)
    grad /= np.maximum(np.linalg.norm(grad, axis=1, keepdims=True), NORM_EPS)
    return P, sigma * grad, surf


def _smoothness_scale(strokes_unit, cfg: FlowConfig):
    """Per grid node, the smoothness weight relative to ``cfg.w_smooth``: ``(res,)*3``
    float64 (:class:`neural.presets.FlowConfig`, ``w_smooth_near`` and ``smooth_near``),
    or None where the weight is ``w_smooth`` everywhere.

    The distance to the strokes is the grid's Euclidean distance transform from the nodes
    nearest to the stroke samples (half a cell apart), in cells.
    """
    if not (cfg.smooth_near > 0 and cfg.w_smooth > 0 and cfg.w_smooth_near != cfg.w_smooth):
        return None
    from scipy.ndimage import distance_transform_edt

    res = cfg.res
    d = distance_transform_edt(~stroke_nodes(strokes_unit, 0.5 / res, 1.0 / res, (res,) * 3))
    near = cfg.smooth_near / 3.0
    t = np.clip((d - near) / (cfg.smooth_near - near), 0.0, 1.0)
    return (cfg.w_smooth_near + t * (cfg.w_smooth - cfg.w_smooth_near)) / cfg.w_smooth


#: Standard deviation, in cells of its grid, of the Gaussian that low-passes the
#: initialisation's f before the bridge fits g to its gradient: that f carries the
#: Monte-Carlo lumps of the stroke splats at the cell scale, and g fitted to them passes
#: them on to the full stage (a rougher surface).
BRIDGE_BLUR = 1.0


def _init_res(cfg: FlowConfig) -> int:
    """The grid of the initialisation stage: ``cfg.init_res``, never finer than ``cfg.res``
    (a part fitted on a coarser grid, :mod:`neural.parts`); ``cfg.res`` when 0."""
    return min(cfg.init_res, cfg.res) if cfg.init_res else cfg.res


class FlowFit:
    """One flow fit: the network, the samplers, the Poisson solver and the current f.

    Its step functions (:meth:`stages`) are run by :func:`neural.training.train`.

    Parameters
    ----------
    strokes : list of (n_i, 3) float64
        World coordinates, checked (:func:`neural.flow.fit_flow_surface`).
    cfg : FlowConfig
    dev : torch.device
    seed : int
    init_mesh : (vertices (V, 3), faces (F, 3)) or None
        A surface to refine: the first stage regresses g on its signed distance.
    anchors : (points (m, 3), unit normals (m, 3)) float64, optional

    Attributes
    ----------
    frame : Frame
    net : neural.siren.GradientSiren
    f : (res, res, res) tensor or None
        The last solved f (Eq. 11), unit-cube grid.
    history : dict
        Stage -> term -> per-step values.
    """

    def __init__(self, strokes, cfg: FlowConfig, dev, seed: int, init_mesh, anchors=None):
        import torch

        from .poisson import PoissonSolver
        from .siren import GradientSiren

        self.cfg, self.dev = cfg, dev
        self.dtype = torch.float64 if cfg.dtype == "float64" else torch.float32
        self.frame = Frame.from_points(np.vstack(strokes + ([] if anchors is None
                                                            else [anchors[0]])), cfg.padding)
        strokes_unit = [self.frame.to_unit(s) for s in strokes]
        with GLOBAL_STREAM:                 # the weights come from torch's global stream
            self.gen, self.rng = seeded(seed, dev)
            self.net = GradientSiren(cfg.width, cfg.hidden_layers, cfg.omega_0).to(
                device=dev, dtype=self.dtype)
        self.sampler = StrokeSampler(strokes_unit, dev, self.dtype)
        scale = _smoothness_scale(strokes_unit, cfg)
        self.smooth_scale = None if scale is None else torch.as_tensor(scale, device=dev,
                                                                       dtype=self.dtype)
        self.solvers = {r: PoissonSolver(r, device=dev, dtype=self.dtype, boundary=cfg.boundary,
                                         lowpass=cfg.lowpass)
                        for r in {cfg.res, _init_res(cfg)}}
        self.f = None                  # the last solved f (unit-cube grid)
        self.lam = None                # d(data loss) / d(splat), for poisson_every > 1
        self.data = float("nan")       # the last solved data loss
        self.averaged = None           # AveragedModel of the net (average_from < 1, polish)
        self.f_mean = None             # running mean of the solved f over the same steps
        self.anchors = None if anchors is None else tuple(
            torch.as_tensor(a, device=dev, dtype=self.dtype)
            for a in (self.frame.to_unit(anchors[0]), anchors[1]))
        self.bridge_f = None           # the bridge's target field (bridge_steps)
        self.prefit = None
        if init_mesh is not None:
            P, target, mesh_surf = _prefit_targets(init_mesh, self.frame, cfg.sigma, self.rng)
            self.prefit = (torch.as_tensor(P, device=dev, dtype=self.dtype),
                           torch.as_tensor(target, device=dev, dtype=self.dtype), mesh_surf)
        names = ("prefit",) if init_mesh is not None else (
            ("init", "bridge") if cfg.bridge_steps else ("init",))
        self.history = {name: {t: [] for t in _TERMS} for name in names + ("full",)}

    def geometric_stage(self) -> Stage:
        """Fit g to ``sigma (x - c) / |x - c|`` (c: stroke centroid); see :mod:`neural.flow`."""
        import torch
        cfg, gen, dev, dtype = self.cfg, self.gen, self.dev, self.dtype
        c = self.sampler.sample(4096, gen)[0].mean(0)
        n = max(cfg.n_volume, 1000)

        def step(k):
            x = torch.cat([torch.rand(n, 3, generator=gen, device=dev, dtype=dtype),
                           self.sampler.sample(n, gen)[0]])
            d = x - c
            target = cfg.sigma * d / d.norm(dim=-1, keepdim=True).clamp(min=1e-6)  # local: x = c
            return Step(((self.net(x) - target) ** 2).sum(-1).mean())

        return Stage("geometric", cfg.geometric_init_steps, step)

    def stages(self) -> list:
        """The prefit (``init_mesh`` given) or initialisation stage, then the full stage."""
        cfg = self.cfg
        if self.prefit is not None:
            first = Stage("prefit", cfg.prefit_steps, self._prefit_step)
            full = Stage("full", cfg.steps, self._flow_step("full", cfg.steps),
                         start=self._bootstrap)
        else:
            first = Stage("init", cfg.init_steps, self._flow_step("init", cfg.init_steps))
            full = Stage("full", cfg.steps, self._flow_step("full", cfg.steps))
            if cfg.bridge_steps:
                return [first, Stage("bridge", cfg.bridge_steps, self._bridge_step,
                                     start=self._bridge_start), full]
        return [first, full]

    def solve(self, points, values, normalize, need_adjoint, n_stroke=None, mass=None, res=None):
        """Splat -> FFT Poisson -> Eq. 11; returns (f_grid, data loss, raw grid).

        The first ``n_stroke`` (default ``cfg.n_stroke``) points are the data samples
        (the stroke samples, then the anchors'); ``mass`` (optional, (M,)) weighs the
        points in the splat.
        """
        from .losses import data_loss
        from .poisson import interpolate, normalize_scale_shift, normalize_splat, splat
        res = res or self.cfg.res
        grid, wsum = splat(points, values, res, mass)
        raw = grid
        if need_adjoint:
            raw.retain_grad()
        if normalize:
            grid = normalize_splat(grid, wsum)
        f = self.solvers[res].solve(grid)
        f_s = interpolate(f, points[: n_stroke or self.cfg.n_stroke])
        f, f_s = normalize_scale_shift(f, f_s)
        return f, data_loss(f_s), raw

    def polish(self, f):
        """f re-integrated ``cfg.polish_rounds`` times with the trained g, without gradients.

        Each round draws ``cfg.polish`` times the stroke and surface samples of a step
        (the surface ones on the zero set of the round before), in the same proportion,
        and splats them with the normalisation of the last step, leaving out the surface
        samples within ``cfg.polish_strip`` cells of the strokes. The Monte-Carlo noise of
        the splat is down by about ``sqrt(cfg.polish)``; the per-node normalisation sees
        ``cfg.polish`` times the weight, so even one round without strip is not quite a
        step's field. g is the averaged network (:meth:`_average`)
        if there is one, else the last step's; the first round's surface samples lie on
        the zero set of the averaged f if there is one, else of ``f``.
        """
        import torch
        cfg = self.cfg
        normalize = cfg.steps - 1 >= int(cfg.normalize_from * cfg.steps)   # as the last step
        net = self.net if self.averaged is None else self.averaged.module
        f = f if self.f_mean is None else self.f_mean
        with torch.no_grad():
            for _ in range(cfg.polish_rounds):
                x_s = self._data_points(cfg.polish)
                x_u = sample_surface_cells(f, cfg.polish * cfg.n_surface, self.gen)
                keep, mass = self._strip(x_s, x_u, cfg.polish_strip)
                if keep is not None:
                    x_u = x_u[keep]
                pts = x_s if x_u is None else torch.cat([x_s, x_u])
                vals = torch.cat([net(p) for p in pts.split(65536)])
                f = self.solve(pts, vals, normalize, False, n_stroke=len(x_s), mass=mass)[0]
        return f

    def _average(self):
        """Add the net's parameters (``torch.optim.swa_utils``) and the last solved f
        (``self.f``, a (res, res, res) grid normalised by Eq. 11) to their running means.

        Every step's f puts its stroke samples' mean at 0 and the box corner at +-1; each
        is added signed so that the corner is +1 (g's orientation is the fit's choice),
        so their mean does the same, and its zero set has less of the steps'
        Monte-Carlo noise.
        """
        import torch
        from torch.optim.swa_utils import AveragedModel
        if self.averaged is None:
            self.averaged = AveragedModel(self.net)
        self.averaged.update_parameters(self.net)
        n = int(self.averaged.n_averaged)
        f = self.f * torch.sign(self.f[0, 0, 0])
        self.f_mean = f if n == 1 else self.f_mean.add_(f - self.f_mean, alpha=1.0 / n)

    def solve_strokes_only(self, mesh_points=None):
        """f integrated from g at stroke samples (and ``mesh_points``), without gradients."""
        import torch
        with torch.no_grad():
            pts = self._data_points(1)
            n_data = len(pts)
            if mesh_points is not None:
                pts = torch.cat([pts, mesh_points])
            return self.solve(pts, self.net(pts), False, False, n_stroke=n_data)[0]

    def _anchor_sample(self, factor: int = 1):
        """``factor * min(m, n_stroke)`` anchors drawn with replacement: (points, normals)."""
        import torch
        pts, nrm = self.anchors
        idx = torch.randint(len(pts), (factor * min(len(pts), self.cfg.n_stroke),),
                            generator=self.gen, device=self.dev)
        return pts[idx], nrm[idx]

    def _data_points(self, factor: int):
        """``factor`` times a step's stroke samples, then as many times its anchors."""
        import torch
        pts, _ = self.sampler.sample(factor * self.cfg.n_stroke, self.gen)
        if self.anchors is None:
            return pts
        return torch.cat([pts, self._anchor_sample(factor)[0]])

    def _anchor_terms(self, vals, x_s, g_s):
        """Anchor samples after the stroke samples (data, splat, Eikonal); their normal term."""
        import torch

        from .losses import normal_loss
        if self.anchors is None:
            return x_s, g_s
        x_a, n_a = self._anchor_sample()
        g_a = self.net(x_a)
        vals["normal"] = normal_loss(g_a, n_a)
        return torch.cat([x_s, x_a]), torch.cat([g_s, g_a])

    def _bootstrap(self):
        """f from the prefitted g on strokes + init-mesh samples (start of the full stage)."""
        import torch
        ms = torch.as_tensor(self.prefit[2][: self.cfg.n_surface], device=self.dev,
                             dtype=self.dtype)
        self.f = self.solve_strokes_only(ms)
        return self.f

    def _bridge_start(self):
        """The bridge's target: the initialisation's f (from the strokes alone when that
        stage ran no step) low-passed by a Gaussian of :data:`BRIDGE_BLUR` cells."""
        import torch
        from scipy.ndimage import gaussian_filter
        if self.f is None:
            self.f = self.solve_strokes_only()
        mode = "wrap" if self.cfg.boundary == "periodic" else "nearest"
        blurred = gaussian_filter(self.f.detach().cpu().numpy(), BRIDGE_BLUR, mode=mode)
        self.bridge_f = torch.as_tensor(blurred, device=self.dev, dtype=self.dtype)

    def _bridge_step(self, k):
        """g fitted to ``sigma`` times the unit gradient of the initialisation's f, low-passed
        (:meth:`_bridge_start`), at samples of its zero set (``cfg.bridge_steps``; see
        :mod:`neural.presets`), so that the full stage's first surface samples splat a g that
        already points along the surface they lie on. The strokes are not sampled: the
        initialisation fitted g there."""
        from .poisson import interpolate
        x = self._surface_samples(self.cfg.n_surface)
        if x is None:                  # f does not cross zero: the strokes, where it should
            x = self._data_points(1)
        _, grad = interpolate(self.bridge_f, x, with_gradient=True)
        target = self.cfg.sigma * grad / grad.norm(dim=-1, keepdim=True).clamp(min=NORM_EPS)
        loss = ((self.net(x) - target) ** 2).sum(-1).mean()
        row = self._row({"total": loss})
        return Step(loss, dict(zip(_TERMS, row)), after=lambda: self._record("bridge", k, row))

    def _surface_samples(self, n):
        """``n`` samples on the zero set of the last solved f, or None before the first."""
        return None if self.f is None else sample_surface_cells(self.f, n, self.gen)

    def _prefit_step(self, k):
        import torch
        P, target, _ = self.prefit
        idx = torch.randint(len(P), (self.cfg.n_volume,), generator=self.gen, device=self.dev)
        loss = ((self.net(P[idx]) - target[idx]) ** 2).sum(-1).mean()
        row = self._row({"total": loss})
        return Step(loss, dict(zip(_TERMS, row)), after=lambda: self._record("prefit", k, row))

    def _flow_step(self, stage, n_steps):
        """Step function of the initialisation (strokes only) or full stage (Eq. 13)."""
        import torch

        from .losses import alignment_loss, curl_loss
        from .poisson import splat
        cfg, net, gen = self.cfg, self.net, self.gen
        full = stage == "full"
        res = cfg.res if full else _init_res(cfg)

        def step(k):
            x_s, t_s = self.sampler.sample(cfg.n_stroke, gen)
            x_v = torch.rand(cfg.n_volume, 3, generator=gen, device=self.dev, dtype=self.dtype)
            g_sv, G_sv = net.jet(torch.cat([x_s, x_v]), order=1)
            g_s, G_s = g_sv[: cfg.n_stroke], G_sv[: cfg.n_stroke]
            x_u = self._surface_samples(cfg.n_surface) if full else None
            vals = {"align": alignment_loss(g_s, G_s, t_s),
                    "curl": curl_loss(G_sv[cfg.n_stroke:])}
            x_s, g_s = self._anchor_terms(vals, x_s, g_s)
            pts, gv = self._surface_terms(vals, x_u, x_s, g_s)
            normalize = full and k >= int(cfg.normalize_from * n_steps)
            average = full and cfg.polish > 0 and k >= int(cfg.average_from * n_steps)
            do_solve = (k % cfg.poisson_every == 0) or k == n_steps - 1 or self.lam is None
            if do_solve:
                f, vals["data"], raw = self.solve(pts, gv, normalize, cfg.poisson_every > 1,
                                                  n_stroke=len(x_s), res=res)
                data_term = cfg.w_data * vals["data"]
            else:
                data_term = (self.lam * splat(pts, gv, res)[0]).sum()
            loss = (cfg.w_align * vals["align"] + cfg.w_curl * vals["curl"]
                    + cfg.w_eik * vals["eik"] + data_term)
            for term, w in (("smooth", cfg.w_smooth), ("normal", cfg.w_normal)):
                if term in vals:
                    loss = loss + w * vals[term]
            vals["total"] = loss
            row = self._row(vals)
            if do_solve:
                row[3] = float(vals["data"].detach())
                f = f.detach()
            else:
                row[3] = self.data

            def after():
                if do_solve:
                    if cfg.poisson_every > 1:
                        self.lam = raw.grad.detach()
                    self.f, self.data = f, row[3]
                if average:
                    self._average()
                self._record(stage, k, row)

            return Step(loss, dict(zip(_TERMS, row)), state=f if do_solve else None,
                        after=after)

        return step

    def _strip(self, x_s, x_u, cells):
        """``(keep, mass)`` of :func:`neural.poisson.stroke_strip` (``cells`` wide);
        ``(None, None)``, all splatted with mass 1, without x_u or strip (the polish)."""
        if x_u is None or cells <= 0:
            return None, None
        from .poisson import stroke_strip
        return stroke_strip(x_s, x_u, cells / self.cfg.res)

    def _surface_terms(self, vals, x_u, x_s, g_s):
        """Smoothness and Eikonal terms into ``vals``; the points and g to splat."""
        import torch

        from .losses import eikonal_loss, smoothness_loss
        cfg, net = self.cfg, self.net
        if x_u is None:
            vals["eik"] = eikonal_loss(g_s, cfg.sigma)
            return x_s, g_s
        if cfg.w_smooth > 0:
            from .poisson import interpolate
            g_u, G_u, H_u = net.jet(x_u, order=2)
            scale = None if self.smooth_scale is None else interpolate(self.smooth_scale, x_u)
            vals["smooth"] = smoothness_loss(g_u, G_u, H_u, scale)
        else:
            g_u = net(x_u)
        vals["eik"] = eikonal_loss(torch.cat([g_u, g_s]), cfg.sigma)
        return torch.cat([x_s, x_u]), torch.cat([g_s, g_u])

    def _row(self, vals) -> list:
        """The loss terms of :data:`_TERMS` as floats (NaN where not computed)."""
        import torch
        nan = torch.full((), float("nan"), device=self.dev, dtype=self.dtype)
        return torch.stack([vals[t].detach() if t in vals else nan for t in _TERMS]).tolist()

    def _record(self, stage, k, row):
        for t, v in zip(_TERMS, row):
            self.history[stage][t].append(v)
        if not all(np.isfinite(v) for v in row if v == v):
            raise FloatingPointError(f"non-finite loss at {stage} step {k}: {row}")
