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
* ``lowpass > 0`` (no preset) blurs every solved f by a Gaussian of that many cells,
  in the spectral solve (:class:`neural.poisson.PoissonSolver`; the solver of Shape As
  Points has the same filter, the published code about one cell): far from the
  strokes the Monte-Carlo noise of a step's splat otherwise decides the sign of f
  (:class:`neural.presets.FlowConfig` says when it helps).
* The padded box is a cube (longest side + 20 % on every side) so the grid is
  isotropic.
* Ctrl-C (KeyboardInterrupt), or ``stop`` set from another thread, stops the optimisation
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
  (``benchmarks/bench_flow_limits.py`` measures both; the figures are in
  ``benchmarks/README.md``).
* ``polish = k > 0`` re-integrates the final f (forward passes only) from k times
  the stroke and surface samples of one step, ``polish_rounds`` times, optionally
  with the stroke strip (``polish_strip``): less Monte-Carlo noise in the splat and,
  with the strip, no shrinking between smooth strokes. With
  ``average_from < 1`` its g is the running mean of the network's parameters over the
  full stage from that fraction on (stochastic weight averaging), which has less of
  the last steps' noise than the last step's network, and it starts from the running
  mean of those steps' f (Polyak averaging of the field): the last step's zero set
  carries its splat's Monte-Carlo bumps, and a round of the polish moves a surface
  only part of the way, so it keeps much of them. Both surfaces are faired
  (``attach``, below) and the polished one is returned only when its stroke fidelity
  is then at least the last step's, less :data:`POLISH_SLACK` (:func:`_polished`): on
  sketches whose surface the strokes' extra density holds in place (open rims), the
  re-integration moves it off them, farther than the fairing's pull reaches.
* Final mesh: pieces of the zero set with no stroke within 4 grid cells are
  dropped (spurious level-set components of the periodic f), and so are the pieces
  no larger than the zero set around one lone node of the grid
  (:data:`neural.extract.LONE_NODE_AREA`: specks where f dips below zero at a node,
  which carried a stroke sample or two and counted as holding them); after
  the fairing, the closed pieces whose strokes the other pieces already carry within
  the stroke fidelity's tolerance (:func:`neural.extract.drop_redundant_bubbles`: the
  field's small bubbles inside the solid or beside it; not for hybrid fills).
* ``attach > 0`` (draft, default): the extracted mesh is faired and pulled onto the
  strokes near it (:mod:`neural.attach`, a stroke-constrained bi-Laplacian low-pass of
  the vertices, at ``default`` after a low-pass of their normals that the vertices
  follow, ``attach_normals``; the stroke samples it leaves farther than ``attach_band`` of the
  strokes' diagonal are held to that band), and returned so only when its stroke
  fidelity is at least the extracted mesh's. ``FlowResult.f_grid`` stays the field
  whose zero set was extracted. With ``anchors`` (a hybrid fill) the anchor points
  pull like stroke samples, so the faired fill still meets the patches, and nothing
  is held to the band: a fill's strokes are the loose ones no patch closes, and
  holding each of them drags thin sheets of the fill onto the strays (spikes).
* ``handles`` (default): before the extraction, the small holes and thin strands that
  the Monte-Carlo noise of f leaves in its zero set (each a handle of the surface, a
  pit or a tear once faired) are plugged and cut on the grid, after the specks of
  solid that no stroke passes through, the rest of the zero set unmoved
  (:func:`neural.topology.remove_small_handles`).
* ``subdivide`` (draft, default): the final mesh is subdivided once, its new vertices
  on the curved point-normal triangles of the old ones
  (:func:`curvenet.core.geometry.subdivide_curved`): the facets of a mesh extracted
  at the grid's cell size are flat where the surface is curved. Not with ``anchors``
  (a fill's border is trimmed against the patches beside it).
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

from curvenet.core.geometry import bbox_diagonal, subdivide_curved
from curvenet.core.result import MeshResult
from curvenet.core.strokes import check_strokes
from curvenet.core.tolerances import NORM_EPS

from .extract import edges_at_walls
from .flowfit import FlowFit
from .frame import Frame, stroke_nodes
from .presets import FlowConfig, get_config
from .training import torch_device, train

__all__ = ["FlowResult", "fit_flow_surface", "fit_strokes", "POLISH_SLACK"]

#: Share of the stroke length the faired polished surface may hold less of than the last
#: step's and still be returned: a short stretch of stroke at the edge of the fidelity's
#: tolerance (on the vns ellipsetorus the polished surface holds 0.2% less, and is one
#: closed genus-0 piece where the last step's is twelve pieces, one with a handle).
POLISH_SLACK = 0.01
#: The fairing also carries the surface onto some stroke samples beyond its pull's reach:
#: up to this share of the stroke length more than the samples within reach.
_BEYOND_REACH = 0.05


@dataclass(repr=False, kw_only=True)
class FlowResult(MeshResult):
    """Output of :func:`fit_flow_surface`: a :class:`~curvenet.core.MeshResult` and its field.

    Attributes
    ----------
    vertices : (V, 3) float64, world coordinates
    faces : (F, 3) int64, oriented along grad f (outwards for f > 0 outside)
    report : dict, ``steps`` done per stage, ``interrupted``, ``device``,
        ``seed``, ``quality``, ``config``, mesh stats, ``open_at_box`` (the surface's
        boundary edges at the padded box's walls, :func:`neural.extract.edges_at_walls`:
        where the zero set left the box), ``rims_closed`` (the sides of the strokes'
        box the surface was closed on, :func:`neural.rims.close_rims`)
    f_grid : (n, n, n) float32, normalised f (Eq. 11) at the grid nodes, signed so
        that the box corner (outside) is +1; intersected with the half-spaces behind
        the closed rims' planes
    origin : (3,) float64, world position of node ``[0, 0, 0]``
    spacing : float, world node spacing
    timings : dict, seconds per stage (``prefit``, ``init``, ``full``,
        ``extract``, ``total``)
    history : dict, stage -> term -> list of per-step values
        (terms ``total, align, smooth, data, eik, curl, normal``; without their
        ``w_*`` weights, ``smooth`` with the spatial scale of ``smooth_near``)
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


def fit_strokes(strokes, labels):
    """The strokes a fit uses: validated float64 copies, construction strokes left out.

    Returns ``(strokes, labels)``; labels default to ``"crease"``.

    Raises
    ------
    InvalidParameterError
        A malformed stroke or label (:func:`curvenet.core.strokes.check_strokes`).
    ValueError
        Only construction strokes.
    """
    out, labels = check_strokes(strokes, labels, default_label="crease", allow_empty=False)
    keep = [i for i, lab in enumerate(labels) if lab != "construction"]
    if not keep:
        raise ValueError("all strokes are construction strokes; nothing to surface")
    return [out[i] for i in keep], [labels[i] for i in keep]


def fit_flow_surface(strokes, *, labels=None, quality: str = "draft", device="cpu", seed: int = 0,
                     init_mesh=None, anchors=None, progress: bool = True,
                     cut_boundary: bool = True, desc: str = "neural", stop=None,
                     box=None, **overrides) -> FlowResult:
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
    desc : str
        Label of the progress bar.
    stop : threading.Event, optional
        Set from another thread, the optimisation stops as at Ctrl-C (see the module
        notes).
    box : ((3,), (3,)) array_like, optional
        Lowest and highest corner of the bounding box whose sides may be closed at a rim
        (``rims``, :func:`neural.rims.close_rims`). Default: the strokes'; a part of a
        sketch (:func:`neural.parts.fit_parts`) takes the whole sketch's.
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
    strokes, labels = fit_strokes(strokes, labels)
    dev = torch_device(device)
    if box is None:
        from .rims import strokes_box
        box = strokes_box(strokes)
    box = tuple(np.asarray(c, np.float64).reshape(3) for c in box)
    return _fit(strokes, labels, cfg, dev, int(seed), init_mesh, progress, cut_boundary, quality,
                anchors=_check_anchors(anchors), desc=desc, stop=stop, box=box)


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


def _fit(strokes, labels, cfg: FlowConfig, dev, seed, init_mesh, progress, cut_boundary, quality,
         anchors=None, desc="neural", stop=None, box=None):
    t_start = time.perf_counter()
    fit = FlowFit(strokes, cfg, dev, seed, init_mesh, anchors)
    stages = fit.stages()
    interrupted = False
    if init_mesh is None and cfg.geometric_init_steps > 0:
        interrupted = train(fit.net.parameters(), [fit.geometric_stage()], lr=1e-3,
                            stop=stop).interrupted
    run = train(fit.net.parameters(), [] if interrupted else stages, lr=cfg.lr,
                grad_clip=cfg.grad_clip, progress=progress, desc=desc, stop=stop)
    interrupted = interrupted or run.interrupted
    timings = {s.name: run.timings.get(s.name, 0.0) for s in stages}
    steps_done = {s.name: run.steps.get(s.name, 0) for s in stages}

    t0 = time.perf_counter()
    f_final = run.best if run.best is not None else fit.solve_strokes_only()
    anchor_points = None if anchors is None else anchors[0]
    rims = (box, cfg.rims if anchors is None else 0.0)
    mesh = _extract(f_final, fit.frame, strokes, labels, cut_boundary, cfg.handles, rims)
    polish = attach = None
    if not interrupted:
        if cfg.polish > 0:
            done, polish = _polished(fit, f_final, mesh, strokes, labels, cut_boundary, cfg,
                                     anchor_points, rims)
        else:
            done = _faired(mesh, strokes, cfg, anchor_points)
        mesh, attach = done[:2]
    V, F, f_np, origin, h_world, n_cut, planes = mesh
    n_bubbles = 0
    if anchors is None and len(F):
        from curvenet.core.fidelity import FIDELITY_TOL_REL

        from .extract import drop_redundant_bubbles
        V, F, n_bubbles = drop_redundant_bubbles(V, F, strokes,
                                                 FIDELITY_TOL_REL * bbox_diagonal(list(strokes)))
    for _ in range(int(cfg.subdivide) if anchors is None and len(F) else 0):
        V, F = subdivide_curved(V, F)
    timings["extract"] = time.perf_counter() - t0
    timings["total"] = time.perf_counter() - t_start
    report = {"steps": steps_done, "interrupted": interrupted, "device": str(dev), "seed": seed,
              "quality": quality, "config": cfg.as_dict(), "n_vertices": len(V),
              "n_faces": len(F), "cut_faces": n_cut, "bubbles_dropped": n_bubbles,
              "rims_closed": int(np.isfinite(planes).sum()),
              "open_at_box": edges_at_walls(V, F, origin, h_world, f_np.shape[0]),
              "stroke_length_unit": fit.sampler.total_length}
    if polish is not None:
        report["polish"] = polish
    if attach is not None:
        report["attach"] = attach
    return FlowResult(V, F, report, f_grid=f_np, origin=origin, spacing=h_world, timings=timings,
                      history=fit.history)


def _faired(mesh, strokes, cfg: FlowConfig, anchors=None, before: float | None = None):
    """``mesh`` (:func:`_extract`'s tuple) faired onto its strokes (:func:`_attached`) when
    ``cfg.attach`` > 0, then put back within its closed rims' planes
    (:func:`neural.rims.clamp_to`): ``(mesh, attach report or None, stroke fidelity)``.
    ``before``: the stroke fidelity of ``mesh`` when known."""
    from .rims import clamp_to
    V, F = mesh[:2]
    if cfg.attach > 0 and len(F):
        V, attach = _attached(V, F, strokes, mesh[4], cfg, anchors, before)
        V = clamp_to(V, *mesh[6])
        return (V,) + tuple(mesh[1:]), attach, attach["fidelity"][int(attach["kept"])]
    return mesh, None, _fidelity(V, F, strokes) if before is None else before


def _polished(fit: FlowFit, f, mesh, strokes, labels, cut_boundary, cfg: FlowConfig,
              anchors=None, rims=(None, 0.0)):
    """The polished surface (:meth:`FlowFit.polish`) if, faired, it holds as much of the
    strokes as the last step's surface faired.

    ``mesh`` is :func:`_extract`'s tuple for the last step's ``f``; the polished f is
    extracted (``cfg.handles`` as there) and both are faired (:func:`_faired`). The
    re-integration removes Monte-Carlo noise and, with the strip, the shrinking of the
    surface between smooth strokes; where the strokes' extra density is what holds the
    surface on them (open rims, sparse sketches) it moves the surface off them instead,
    farther than the fairing's pull reaches. So the polished surface is kept only when
    its stroke fidelity (:func:`curvenet.core.fidelity.sketch_fidelity`) after the
    fairing is at least the last step's less :data:`POLISH_SLACK`: the surfaces compared
    are the ones that would be returned, and a difference of a few samples is no reason
    to return the noisier field.

    A surface is faired only where the choice needs it (:func:`_fidelity_and_ceiling`):
    the polished one not when it cannot reach the last step's extracted fidelity, the
    last step's not when the faired polished one is within the slack of all it could
    reach.

    Returns ``(the kept triple of _faired, {"fidelity": [last step's, polished],
    "faired": [bool, bool], "kept": bool})``: each fidelity as faired, or as extracted
    where that surface was not faired.
    """
    polished = _extract(fit.polish(f), fit.frame, strokes, labels, cut_boundary, cfg.handles,
                        rims)
    (last, last_ceiling), (raw, ceiling) = (_fidelity_and_ceiling(m, strokes, cfg)
                                            for m in (mesh, polished))
    out = [None, None]                  # the fairing keeps no less than ``last``
    if ceiling >= last - POLISH_SLACK:
        out[1] = _faired(polished, strokes, cfg, anchors, raw)
        if out[1][2] < last_ceiling - POLISH_SLACK:
            out[0] = _faired(mesh, strokes, cfg, anchors, last)
    else:
        out[0] = _faired(mesh, strokes, cfg, anchors, last)
    fidelity = [last if out[0] is None else out[0][2], raw if out[1] is None else out[1][2]]
    kept = out[1] is not None and fidelity[1] >= fidelity[0] - POLISH_SLACK
    info = {"fidelity": fidelity, "faired": [o is not None for o in out], "kept": kept}
    return (out[1] if kept else out[0]), info


def _fidelity_and_ceiling(mesh, strokes, cfg: FlowConfig) -> tuple[float, float]:
    """The stroke fidelity of ``mesh`` (:func:`_extract`'s tuple) and the most it can have
    after :func:`_faired`: the same without the fairing; with it, the share of stroke
    length within the pull's reach (``cfg.attach_reach`` cells) plus
    :data:`_BEYOND_REACH`. One distance from each stroke sample to the mesh serves both
    (0, 0 when the mesh has no triangle of positive area)."""
    from curvenet.core.fidelity import FIDELITY_TOL_REL
    d, diag = _stroke_distances(*mesh[:2], strokes)
    if d is None:
        return 0.0, 0.0
    fidelity = float(np.mean(d < FIDELITY_TOL_REL))
    if cfg.attach > 0:
        within = min(cfg.attach_reach * mesh[4] / diag, 0.99)
        return fidelity, min(1.0, float(np.mean(d < within)) + _BEYOND_REACH)
    return fidelity, fidelity


def _attached(V, F, strokes, h_world, cfg: FlowConfig, anchors=None,
              before: float | None = None):
    """The mesh faired onto its strokes (:func:`neural.attach.attach_to_strokes`) if it
    holds at least as much of them; ``(V, {"fidelity": [before, after], "kept": bool,
    "samples", "pulled", "held"})``. ``before``: the stroke fidelity of ``(V, F)`` when
    known.

    ``anchors`` ((m, 3) float64, a hybrid fill's anchor points) pull like stroke samples,
    and nothing is held to the band: a fill's strokes are the loose strokes no patch
    closes, and holding every one of them drags thin sheets of the fill onto the strays.
    """
    from .attach import attach_to_strokes
    band = 0.0 if anchors is not None else cfg.attach_band * bbox_diagonal(list(strokes))
    X, rep = attach_to_strokes(V, F, strokes, h_world, cutoff=cfg.attach,
                               weight=cfg.attach_weight, band=band, reach=cfg.attach_reach,
                               normals=cfg.attach_normals,
                               points=anchors)
    fidelity = [_fidelity(V, F, strokes) if before is None else before,
                _fidelity(X, F, strokes)]
    kept = bool(np.isfinite(X).all() and fidelity[1] >= fidelity[0])
    return (X if kept else V), dict(rep, fidelity=fidelity, kept=kept)


def _fidelity(V, F, strokes) -> float:
    """Stroke fidelity of the mesh ``(V, F)`` (:func:`curvenet.core.fidelity.sketch_fidelity`'s
    ``surface``; 0 when it has no triangle of positive area)."""
    from curvenet.core.fidelity import FIDELITY_TOL_REL
    d = _stroke_distances(V, F, strokes)[0]
    return 0.0 if d is None else float(np.mean(d < FIDELITY_TOL_REL))


def _stroke_distances(V, F, strokes):
    """``(d, diag)``: the distance (k,) float64 of each stroke sample of the fidelity
    (:func:`curvenet.core.fidelity.stroke_sample_distances`) to the mesh ``(V, F)``
    divided by the sketch's diagonal ``diag``; ``(None, None)`` when the mesh has no
    triangle of positive area."""
    from curvenet.core.errors import InvalidParameterError
    from curvenet.core.fidelity import STROKE_SPACING_REL, stroke_sample_distances
    try:
        d, diag = stroke_sample_distances((V, F), strokes, STROKE_SPACING_REL)[:2]
    except InvalidParameterError:          # no faces, or only degenerate ones
        return None, None
    return d / diag, diag


def _extract(f_final, frame: Frame, strokes, labels, cut_boundary, handles: int = 0,
             rims=(None, 0.0)):
    """World mesh of f's zero set, its small handles removed
    (:func:`neural.topology.remove_small_handles` up to ``handles`` cells) and closed at
    the rims on the sides of ``rims[0]`` (a box, :func:`neural.rims.close_rims` with
    share ``rims[1]``): supported components, cut along boundary strokes.

    Returns ``(V, F, f_np, origin, spacing, n_cut_faces, (lo, hi))``; ``f_np`` is signed
    so that the box corner (outside) is positive; ``lo, hi`` (3,) float64 the closed
    rims' planes (``-inf`` / ``inf`` where none).
    """
    import torch

    from .extract import (LONE_NODE_AREA, cut_along_boundary, keep_supported_components,
                          marching_cubes_world)
    from .rims import close_rims
    f_np = f_final.detach().to("cpu", torch.float32).numpy()
    if f_np[0, 0, 0] < 0:        # the box corner is outside: make f > 0 outside
        f_np = -f_np
    h_world = frame.side / f_np.shape[0]
    origin = frame.box_min + 0.5 * h_world
    if handles > 1:
        from .topology import remove_small_handles
        f_np = remove_small_handles(f_np, handles, _stroke_voxels(strokes, origin, h_world,
                                                                  f_np.shape))[0]
    f_np, lo, hi = close_rims(f_np, origin, h_world, rims[0], strokes, rims[1])
    V, F = marching_cubes_world(f_np, origin, h_world)
    V, F = keep_supported_components(V, F, strokes, 4.0 * h_world, LONE_NODE_AREA * h_world ** 2)
    n_before_cut = len(F)
    if cut_boundary and "boundary" in labels:
        V, F = cut_along_boundary(V, F, [s for s, lab in zip(strokes, labels) if lab == "boundary"],
                                  [s for s, lab in zip(strokes, labels) if lab != "boundary"],
                                  1.5 * h_world)
    return V, F, f_np, origin, h_world, n_before_cut - len(F), (lo, hi)


def _stroke_voxels(strokes, origin, h: float, shape) -> np.ndarray:
    """The grid nodes (``shape`` bool) within one node of a stroke: the 3 x 3 x 3 block
    around each of :func:`neural.frame.stroke_nodes` (node ``(i, j, k)`` at ``origin +
    (i, j, k) * h``)."""
    from scipy.ndimage import binary_dilation
    return binary_dilation(stroke_nodes(strokes, origin, h, shape), np.ones((3, 3, 3), bool))
