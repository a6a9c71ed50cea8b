"""Flow-aligned neural surfacing of 3D strokes: the optimisation driver.

Implements the method of Zhang, Wang, Bessmeltsev 2025 (Sec. 4-5): a SIREN
predicts the gradient field g; at each step g is evaluated at Monte-Carlo
samples on the strokes, the current iso-surface and the volume, splatted to a
grid and integrated by FFT (Eq. 8-11) into f; the losses of Eq. 13 (alignment,
covariant smoothness of II, data, Eikonal, curl) are minimised with Adam, first
in an initialisation stage (no smoothness, stroke samples only), then in the
full stage. The result is the marching-cubes zero set of f in world
coordinates, cut along boundary strokes.

Engineering choices (documented deviations / gap fills)
------------------------------------------------------
* Derivatives of g come from a closed-form second-order jet of the SIREN
  (:meth:`neural.siren.GradientSiren.jet`), not nested autograd; the covariant
  derivative of II is the chain rule through Eq. 14-15 on that jet.
* Surface samples (Sec. 5.2 samples the marching-cubes mesh) are drawn on the
  device: random points in the grid cells where f changes sign, projected on the
  zero level of the trilinear interpolant by two Newton steps.
* ``poisson_every = k > 1`` solves the Poisson equation every k steps; between
  solves the data term is replaced by its linearisation
  ``<lambda, splat(g)>`` with ``lambda`` the gradient of the weighted data loss
  with respect to the rasterised g at the last solve (exact first-order
  surrogate: same gradient as long as the normalisation and the signs of f on
  the strokes do not change). The history logs the last solved data loss.
* The rasterised g is normalised per node ("once stabilised", Sec. 5.1) from
  ``normalize_from`` of the full stage on: each node's sum is divided by
  ``max(weight sum, mean positive weight sum)``, which removes the density bias
  of the stroke samples without inflating sparsely hit nodes.
* ``geometric_init_steps > 0`` (draft, default) first fits g to the gradient
  ``sigma (x - c) / |x - c|`` of a sphere around the stroke centroid c (cheap:
  no derivatives), a geometric initialisation like the published code's
  sphere/MFGI init. The plain SIREN initialisation (paper text, ``paper``
  preset) starts from |g| ~ 0.05 and a rough, curl-heavy field, which a short
  CPU budget cannot recover from.
* The padded box is a cube (longest side + 20 % on every side) so the grid is
  isotropic.
* Ctrl-C (KeyboardInterrupt) stops the optimisation
  (:func:`neural.training.train`); the surface of the last completed Poisson
  solve whose f is finite ("the best so far") is returned with
  ``report["interrupted"] = True``.
* In the full stage the Eikonal term uses surface *and* stroke samples (the
  paper names S; strokes lie on the surface too, and the published code does
  the same).
* Known limitation: a zero set may leave through the periodic box where no
  stroke holds it (a capped cylinder whose caps carry no strokes becomes an
  open tube: the smoothness term prefers it); such surfaces are not watertight.
  ``boundary="dirichlet"`` closes them inside the box, but not at the rims (see
  :class:`neural.presets.FlowConfig`). The smoothness term charges a rounded
  crease like 1 / (rounding width), so where strokes bound a region without
  strokes it prefers tangent-continuous surfaces: its minimiser for that
  cylinder is a capsule, and box faces bulge into pillows
  (``benchmarks/bench_flow_limits.py`` measures both; the figures, and the
  terms tried against it, are in ``benchmarks/README.md``).
* ``polish = k > 0`` re-integrates the final f (forward passes only) from k times
  the stroke and surface samples of one step, ``polish_rounds`` times, optionally
  with the stroke strip (``polish_strip``): less Monte-Carlo noise in the splat and,
  with the strip, no shrinking between smooth strokes. With
  ``average_from < 1`` its g is the running mean of the network's parameters over the
  full stage from that fraction on (stochastic weight averaging), which has less of
  the last steps' noise than the last step's network, and it starts from the running
  mean of those steps' f (Polyak averaging of the field): the last step's zero set
  carries its splat's Monte-Carlo bumps, and a round of the polish moves a surface
  only part of the way, so it keeps much of them. The polished
  surface is returned only when its stroke fidelity is at least the last step's
  (:func:`_polished`): on sketches whose surface the strokes' extra density holds
  in place (open rims), the re-integration moves it off them.
* Final mesh: pieces of the zero set with no stroke within 4 grid cells are
  dropped (spurious level-set components of the periodic f).
* ``anchors`` (not in the paper): oriented points of another surface the fit must
  meet (a hybrid fill beside classical patches). Each step draws
  ``min(m, n_stroke)`` of them; they join the stroke samples in the data term
  (f = 0 there), the splat and the Eikonal term, and their normals are a target of
  g through the orientation-free :func:`neural.losses.normal_loss` (weight
  ``w_normal``). The padded box covers them too.

References
----------
Zhang, Wang, Bessmeltsev, "Variational Neural Surfacing of 3D Sketches",
SIGGRAPH Asia 2025, Sec. 4.4-5.2, Eq. 4-18.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from curvenet.core.geometry import face_normals_areas, sample_surface
from curvenet.core.result import MeshResult
from curvenet.core.strokes import check_strokes
from curvenet.core.tolerances import COINCIDENT_REL, NORM_EPS, TINY_F32

from .presets import FlowConfig, get_config
from .training import Stage, Step, seeded, torch_device, train

__all__ = ["FlowResult", "fit_flow_surface", "StrokeSampler", "sample_surface_cells", "Frame"]

_TERMS = ("total", "align", "smooth", "data", "eik", "curl", "normal")


@dataclass
class Frame:
    """World <-> unit-cube map of the padded box.

    Attributes
    ----------
    box_min : (3,) float64, world corner of the padded cube
    side : float, world side length of the cube
    """

    box_min: np.ndarray
    side: float

    @classmethod
    def from_points(cls, points: np.ndarray, padding: float) -> "Frame":
        lo, hi = points.min(0), points.max(0)
        ext = float((hi - lo).max())
        if not ext > 0:
            raise ValueError("strokes have a zero-size bounding box")
        side = ext * (1.0 + 2.0 * padding)
        return cls((lo + hi) / 2.0 - side / 2.0, side)

    def to_unit(self, x):
        return (np.asarray(x, float) - self.box_min) / self.side

    def to_world(self, u):
        return np.asarray(u, float) * self.side + self.box_min


@dataclass(repr=False, kw_only=True)
class FlowResult(MeshResult):
    """Output of :func:`fit_flow_surface`: a :class:`~curvenet.core.MeshResult` and its field.

    Attributes
    ----------
    vertices : (V, 3) float64, world coordinates
    faces : (F, 3) int64, oriented along grad f (outwards for f > 0 outside)
    report : dict, ``steps`` done per stage, ``interrupted``, ``device``,
        ``seed``, ``quality``, ``config``, mesh stats
    f_grid : (n, n, n) float32, normalised f (Eq. 11) at the grid nodes, signed so
        that the box corner (outside) is +1
    origin : (3,) float64, world position of node ``[0, 0, 0]``
    spacing : float, world node spacing
    timings : dict, seconds per stage (``prefit``, ``init``, ``full``,
        ``extract``, ``total``)
    history : dict, stage -> term -> list of per-step values
        (terms ``total, align, smooth, data, eik, curl, normal``; unweighted)
    """

    f_grid: np.ndarray
    origin: np.ndarray
    spacing: float
    timings: dict = field(default_factory=dict)
    history: dict = field(default_factory=dict)

    def f(self, points: np.ndarray) -> np.ndarray:
        """Trilinear f at world points (M, 3) -> (M,) (periodic outside the box)."""
        import torch

        from .poisson import interpolate
        n = self.f_grid.shape[0]
        u = (np.asarray(points, float) - self.origin) / (self.spacing * n) + 0.5 / n
        return interpolate(torch.from_numpy(self.f_grid.astype(np.float64)),
                           torch.from_numpy(u)).numpy()


class StrokeSampler:
    """Uniform arc-length Monte-Carlo samples with unit tangents on polylines.

    Parameters
    ----------
    strokes_unit : list of (n_i, 3) float64, unit-cube coordinates
    device, dtype : torch placement of the samples
    """

    def __init__(self, strokes_unit, device, dtype):
        import torch
        a = np.vstack([s[:-1] for s in strokes_unit])
        b = np.vstack([s[1:] for s in strokes_unit])
        length = np.linalg.norm(b - a, axis=1)
        ok = length > 0
        if not ok.any():
            raise ValueError("strokes have zero total length")
        a, b, length = a[ok], b[ok], length[ok]
        self.total_length = float(length.sum())
        self.a = torch.as_tensor(a, device=device, dtype=dtype)
        self.d = torch.as_tensor(b - a, device=device, dtype=dtype)
        self.t = torch.as_tensor((b - a) / length[:, None], device=device, dtype=dtype)
        self.cum = torch.as_tensor(np.cumsum(length) / length.sum(), device=device, dtype=dtype)

    def sample(self, n: int, gen):
        """``(points (n, 3), tangents (n, 3))`` distributed uniformly by length."""
        import torch
        r = torch.rand(n, generator=gen, device=self.a.device, dtype=self.a.dtype)
        seg = torch.searchsorted(self.cum, r).clamp(max=len(self.cum) - 1)
        s = torch.rand(n, 1, generator=gen, device=self.a.device, dtype=self.a.dtype)
        return self.a[seg] + s * self.d[seg], self.t[seg]


def sample_surface_cells(f_grid, n: int, gen, *, newton_steps: int = 2):
    """Samples on the zero level of a node grid, computed on its device.

    Random points in uniformly chosen sign-change cells, moved onto the zero set
    of the trilinear interpolant by Newton steps (each clamped to one cell).

    Parameters
    ----------
    f_grid : (res, res, res) tensor
    n : int
    gen : torch.Generator on the grid's device

    Returns
    -------
    points : (n, 3) unit-cube coordinates, or None when f does not cross zero
    """
    import torch
    import torch.nn.functional as F

    from .poisson import interpolate
    res = f_grid.shape[0]
    f5 = f_grid.detach()[None, None]
    cmax = F.max_pool3d(f5, 2, stride=1)[0, 0]
    cmin = -F.max_pool3d(-f5, 2, stride=1)[0, 0]
    cells = torch.nonzero((cmin < 0) & (cmax > 0))                # (K, 3)
    if len(cells) == 0:
        return None
    pick = torch.randint(len(cells), (n,), generator=gen, device=f_grid.device)
    jitter = torch.rand(n, 3, generator=gen, device=f_grid.device, dtype=f_grid.dtype)
    p = (cells[pick].to(f_grid.dtype) + 0.5 + jitter) / res
    h = 1.0 / res
    for _ in range(newton_steps):
        v, gr = interpolate(f5[0, 0], p, with_gradient=True)
        step = (v / (gr * gr).sum(-1).clamp(min=NORM_EPS)).unsqueeze(-1) * gr
        norm = step.norm(dim=-1, keepdim=True)
        step = step * torch.clamp(h / norm.clamp(min=TINY_F32), max=1.0)
        p = p - step
    return p.clamp(0.0, 1.0)


def _sample_triangles(V, F, n, rng):
    """``n`` area-uniform points ``(n, 3)`` on the mesh ``(V, F)``, or None if all degenerate."""
    areas = face_normals_areas(V, F)[1]
    if not areas.sum() > 0:
        return None
    return sample_surface(V, F, n, rng, areas=areas)[0]


def _prefit_targets(init_mesh, frame: Frame, sigma, rng, n=20000):
    """Unit-cube points and targets sigma * grad SDF of a mesh (refinement)."""
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


def _check_strokes(strokes, labels):
    out, labels = check_strokes(strokes, labels, default_label="crease", allow_empty=False)
    keep = [i for i, lab in enumerate(labels) if lab != "construction"]
    if not keep:
        raise ValueError("all strokes are construction strokes; nothing to surface")
    return [out[i] for i in keep], [labels[i] for i in keep]


def fit_flow_surface(strokes, *, labels=None, quality: str = "draft", device="cpu", seed: int = 0,
                     init_mesh=None, anchors=None, progress: bool = True,
                     cut_boundary: bool = True, **overrides) -> FlowResult:
    """Fit a flow-aligned implicit surface to 3D strokes (Zhang et al. 2025).

    Parameters
    ----------
    strokes : list of (n_i, 3) float64
        Polylines in world coordinates (any units).
    labels : list of str, optional
        Per stroke ``"boundary"``, ``"crease"`` or ``"construction"``
        (ignored). Boundary strokes may cut the closed surface
        (:func:`neural.extract.cut_along_boundary`). Default: all ``"crease"``.
    quality : {"draft", "default", "paper"}
        Preset of :mod:`neural.presets`.
    device : str or torch.device
        ``"cpu"`` or ``"cuda"`` (``"cuda:1"``...).
    seed : int
        Seeds the network initialisation and every sample; CPU runs are
        bit-for-bit reproducible.
    init_mesh : (vertices (V, 3), faces (F, 3)), optional
        A classical surface to refine: g is first regressed on ``sigma`` times
        the gradient of its signed distance (``prefit_steps``; no curl term: the
        target is already a gradient, and a curl penalty on the random initial
        SIREN drives g to a constant), then the full stage runs (no
        initialisation stage).
    anchors : (points (m, 3), normals (m, 3)) float64, optional
        Oriented points, world coordinates, that the surface should pass through with
        its normal along ``normals`` (either sign; normalised here), e.g. samples of
        classical patches a fill must meet (see the module notes).
    progress : bool
        Show a tqdm bar with the loss terms.
    cut_boundary : bool
        Apply the boundary cut.
    **overrides
        Any :class:`neural.presets.FlowConfig` field (``res=96``, ``steps=50``,
        ``w_smooth=0``...).

    Returns
    -------
    FlowResult

    Raises
    ------
    ValueError
        Bad strokes, labels, preset, setting or device (the message names it).

    Examples
    --------
    >>> t = np.linspace(0, 2 * np.pi, 64)
    >>> circles = [np.c_[np.cos(t), np.sin(t), 0 * t], np.c_[np.cos(t), 0 * t, np.sin(t)],
    ...            np.c_[0 * t, np.cos(t), np.sin(t)]]
    >>> res = fit_flow_surface(circles, quality="draft", progress=False)   # doctest: +SKIP
    >>> res.report["interrupted"]                                          # doctest: +SKIP
    False
    """
    cfg = get_config(quality, **overrides)
    strokes, labels = _check_strokes(strokes, labels)
    dev = torch_device(device)
    return _fit(strokes, labels, cfg, dev, int(seed), init_mesh, progress, cut_boundary, quality,
                anchors=_check_anchors(anchors))


def _check_anchors(anchors):
    """``(points (m, 3), unit normals (m, 3))`` as float64 arrays, or None."""
    if anchors is None:
        return None
    try:
        pts, nrm = (np.asarray(a, dtype=np.float64) for a in anchors)
    except (TypeError, ValueError):
        raise ValueError("anchors must be a pair (points (m, 3), normals (m, 3))") from None
    if pts.ndim != 2 or pts.shape[1] != 3 or nrm.shape != pts.shape or not len(pts):
        raise ValueError(f"anchors must be (points (m, 3), normals (m, 3)) with m >= 1, got "
                         f"shapes {pts.shape} and {nrm.shape}")
    length = np.linalg.norm(nrm, axis=1, keepdims=True)
    if not (np.isfinite(pts).all() and np.isfinite(nrm).all() and (length > NORM_EPS).all()):
        raise ValueError("anchors must be finite, with non-zero normals")
    return pts, nrm / length


class _FlowFit:
    """One flow fit: the network, the samplers, the Poisson solver and the current f.

    Its step functions (:meth:`stages`) are run by :func:`neural.training.train`.
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
        self.gen, self.rng = seeded(seed, dev)
        self.net = GradientSiren(cfg.width, cfg.hidden_layers, cfg.omega_0).to(
            device=dev, dtype=self.dtype)
        self.sampler = StrokeSampler(strokes_unit, dev, self.dtype)
        self.solver = PoissonSolver(cfg.res, device=dev, dtype=self.dtype, boundary=cfg.boundary)
        self.f = None                  # the last solved f (unit-cube grid)
        self.lam = None                # d(data loss) / d(splat), for poisson_every > 1
        self.data = float("nan")       # the last solved data loss
        self.averaged = None           # AveragedModel of the net (average_from < 1, polish)
        self.f_mean = None             # running mean of the solved f over the same steps
        self.anchors = None if anchors is None else tuple(
            torch.as_tensor(a, device=dev, dtype=self.dtype)
            for a in (self.frame.to_unit(anchors[0]), anchors[1]))
        self.prefit = None
        if init_mesh is not None:
            P, target, mesh_surf = _prefit_targets(init_mesh, self.frame, cfg.sigma, self.rng)
            self.prefit = (torch.as_tensor(P, device=dev, dtype=self.dtype),
                           torch.as_tensor(target, device=dev, dtype=self.dtype), mesh_surf)
        names = ("prefit",) if init_mesh is not None else ("init",)
        self.history = {name: {t: [] for t in _TERMS} for name in names + ("full",)}

    def geometric_stage(self) -> Stage:
        """Fit g to ``sigma (x - c) / |x - c|`` (c: stroke centroid); see the module notes."""
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
        return [first, full]

    def solve(self, points, values, normalize, need_adjoint, n_stroke=None, mass=None):
        """Splat -> FFT Poisson -> Eq. 11; returns (f_grid, data loss, raw grid).

        The first ``n_stroke`` (default ``cfg.n_stroke``) points are the data samples
        (the stroke samples, then the anchors'); ``mass`` (optional, (M,)) weighs the
        points in the splat.
        """
        from .losses import data_loss
        from .poisson import interpolate, normalize_scale_shift, normalize_splat, splat
        grid, wsum = splat(points, values, self.cfg.res, mass)
        raw = grid
        if need_adjoint:
            raw.retain_grad()
        if normalize:
            grid = normalize_splat(grid, wsum)
        f = self.solver.solve(grid)
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
                                                  n_stroke=len(x_s))
                data_term = cfg.w_data * vals["data"]
            else:
                data_term = (self.lam * splat(pts, gv, cfg.res)[0]).sum()
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
            g_u, G_u, H_u = net.jet(x_u, order=2)
            vals["smooth"] = smoothness_loss(g_u, G_u, H_u)
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


def _fit(strokes, labels, cfg: FlowConfig, dev, seed, init_mesh, progress, cut_boundary, quality,
         anchors=None):
    t_start = time.perf_counter()
    fit = _FlowFit(strokes, cfg, dev, seed, init_mesh, anchors)
    stages = fit.stages()
    interrupted = False
    if init_mesh is None and cfg.geometric_init_steps > 0:
        interrupted = train(fit.net.parameters(), [fit.geometric_stage()], lr=1e-3).interrupted
    run = train(fit.net.parameters(), [] if interrupted else stages, lr=cfg.lr,
                grad_clip=cfg.grad_clip, progress=progress, desc="neural")
    interrupted = interrupted or run.interrupted
    timings = {s.name: run.timings.get(s.name, 0.0) for s in stages}
    steps_done = {s.name: run.steps.get(s.name, 0) for s in stages}

    t0 = time.perf_counter()
    f_final = run.best if run.best is not None else fit.solve_strokes_only()
    mesh = _extract(f_final, fit.frame, strokes, labels, cut_boundary)
    polish = None
    if cfg.polish > 0 and not interrupted:
        mesh, polish = _polished(fit, f_final, mesh, strokes, labels, cut_boundary)
    V, F, f_np, origin, h_world, n_cut = mesh
    timings["extract"] = time.perf_counter() - t0
    timings["total"] = time.perf_counter() - t_start
    report = {"steps": steps_done, "interrupted": interrupted, "device": str(dev), "seed": seed,
              "quality": quality, "config": cfg.as_dict(), "n_vertices": len(V),
              "n_faces": len(F), "cut_faces": n_cut,
              "stroke_length_unit": fit.sampler.total_length}
    if polish is not None:
        report["polish"] = polish
    return FlowResult(V, F, report, f_grid=f_np, origin=origin, spacing=h_world, timings=timings,
                      history=fit.history)


def _polished(fit: _FlowFit, f, mesh, strokes, labels, cut_boundary):
    """The polished surface (:meth:`_FlowFit.polish`) if it holds as much of the strokes.

    ``mesh`` is :func:`_extract`'s tuple for the last step's ``f``. The re-integration
    removes Monte-Carlo noise and, with the strip, the shrinking of the surface between
    smooth strokes; where the strokes' extra density is what holds the surface on them
    (open rims, sparse sketches) it moves the surface off them instead. So the polished
    surface is kept only when its stroke fidelity
    (:func:`curvenet.evaluate.sketch_fidelity`) is at least that of ``mesh``.

    Returns ``(mesh, {"fidelity": [last step's, polished], "kept": bool})``.
    """
    polished = _extract(fit.polish(f), fit.frame, strokes, labels, cut_boundary)
    fidelity = [_fidelity(m[0], m[1], strokes) for m in (mesh, polished)]
    kept = fidelity[1] >= fidelity[0]
    return (polished if kept else mesh), {"fidelity": fidelity, "kept": kept}


def _fidelity(V, F, strokes) -> float:
    """Stroke fidelity of the mesh ``(V, F)`` (0 when it has no triangle of positive area)."""
    from curvenet.errors import InvalidParameterError
    from curvenet.evaluate import sketch_fidelity
    try:
        return sketch_fidelity((V, F), strokes)["surface"]
    except InvalidParameterError:          # no faces, or only degenerate ones
        return 0.0


def _extract(f_final, frame: Frame, strokes, labels, cut_boundary):
    """World mesh of f's zero set: supported components, cut along boundary strokes.

    Returns ``(V, F, f_np, origin, spacing, n_cut_faces)``; ``f_np`` is signed so that
    the box corner (outside) is positive.
    """
    import torch

    from .extract import cut_along_boundary, keep_supported_components, marching_cubes_world
    f_np = f_final.detach().to("cpu", torch.float32).numpy()
    if f_np[0, 0, 0] < 0:        # the box corner is outside: make f > 0 outside
        f_np = -f_np
    h_world = frame.side / f_np.shape[0]
    origin = frame.box_min + 0.5 * h_world
    V, F = marching_cubes_world(f_np, origin, h_world)
    V, F = keep_supported_components(V, F, strokes, 4.0 * h_world)
    n_before_cut = len(F)
    if cut_boundary and "boundary" in labels:
        V, F = cut_along_boundary(V, F, [s for s, lab in zip(strokes, labels) if lab == "boundary"],
                                  [s for s, lab in zip(strokes, labels) if lab != "boundary"],
                                  1.5 * h_world)
    return V, F, f_np, origin, h_world, n_before_cut - len(F)
