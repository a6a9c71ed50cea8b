"""Quality presets of the neural fits: every setting in one place, overridable by keyword.

A :class:`FlowConfig` holds the settings of the flow-aligned surfacing (Zhang, Wang,
Bessmeltsev 2025; :func:`neural.flow.fit_flow_surface`), a :class:`CreaseConfig` those
of the crease refit (Niu et al. 2025; :func:`neural.crease_refit.crease_refine`). Each has
three presets, ``draft``, ``default`` and ``paper``; a keyword overrides one field of
the chosen preset (``fit_flow_surface(..., res=96)``).

Notes
-----
Flow presets:

- ``draft``: a short CPU run (64^3 grid, a 2 x 64 SIREN, 40 + 100 steps), seconds per
  sketch on two cores.
- ``default``: 128^3 and a 2 x 96 SIREN, 60 + 140 steps, then the polish; the better
  choice on a GPU as well. 140 full steps rather than 200: the same F-score, Chamfer
  distance and stroke fidelity in less time (``benchmarks/README.md``).
- ``paper``: the published settings (Sec. 4.3, 5.1, 5.2): a 4 x 256 SIREN with
  omega_0 = 30, 10k / 15k / 15k Monte-Carlo samples on strokes, surface and volume,
  200 initialisation + 800 full Adam steps, a 256^3 grid on the bounding box padded by
  20 % (Sec. 4.4.1), loss weights 1, 0.01, 30, 7, 7 (Eq. 13) and Eikonal sigma = 0.5.
  The paper gives no learning rate or gradient clipping; it takes the published code's
  (Adam lr 5e-5, clip 10). It is meant for a GPU.

Besides their budget (network, grid, samples, steps), ``draft`` and ``default`` depart
from the paper in:

- smoothness weight 0.1, not 0.01: with their short budgets the paper's weight leaves
  mid-frequency bumps, and a rough sphere sags between its strokes. The stronger weight
  also rounds off what the strokes outline and fills the concavities between them (the
  space under an espresso machine's head, an iron's handle); ``smooth_near`` lowers it
  to the paper's next to the strokes, which opens those on clean connected drawings but
  webs close strokes together and tears thin parts of rough sketches (a hand's
  fingers, a guitar's neck), so no preset sets it (``benchmarks/README.md``);
- a radial geometric initialisation (``geometric_init_steps``): the plain SIREN
  initialisation starts from a rough, curl-heavy field that a short budget does not
  recover from;
- ``default`` only, an initialisation stage on a 64^3 grid (``init_res``) before the
  full stage's 128^3: that stage fits g to the strokes alone, and on the coarser grid
  it takes half the time, with surfaces as smooth and as close to the strokes
  (``benchmarks/README.md``);
- ``default`` only, a bridge between the two stages (``bridge_steps``): the
  initialisation stage fits g at the strokes alone (its curl term samples the volume,
  not a surface), so at the full stage's first step nothing has fitted g on the rest
  of the zero set yet; splatted with the first surface samples, that g dents the
  surface where no stroke holds it (the top of a torus's tube between its meridians),
  and the later steps keep the dents. The bridge first fits g to ``sigma`` times the
  unit gradient of the initialisation's f, low-passed by a cell, at samples of its
  zero set (not at the strokes, where the initialisation fitted g), as the refinement
  path's prefit fits g to a given surface (``benchmarks/README.md``);
- ``default`` only, the polish (``polish``, ``polish_rounds``, ``polish_strip``,
  ``average_from``): f re-integrated from the network averaged over the last 40 % of
  the full stage, with the stroke samples in place of the surface samples next to
  them, returned only when, both faired, it holds about as much of the strokes as
  the last step's surface: the stroke samples splatted on top of the surface ones shrink smooth
  surfaces between their strokes, and the polish takes that back where it does not
  move the surface off the strokes.

No preset low-passes the Poisson solve (``lowpass``, off as in the paper). At 128^3 a
step's surface samples are sparser per cell than at 64^3, and where no stroke holds the
field (the hole of a torus drawn as a few exact meridians and rings) the sign of f flips
from step to step, so ``default``'s last step can wall the hole; ``lowpass=2`` keeps it
open, but it takes parts of real sketches off their strokes, so it is a setting for
sparse clean wireframes, not a preset's (figures: ``benchmarks/README.md``, "A low-pass
in the Poisson solve").

Both also fair the extracted mesh onto the strokes (``attach``): the zero set carries
the splats' Monte-Carlo lumps and lies off rough strokes, which the fields' extra
training does not take away. Ripples shorter than about 16 % of the padded box's side
are removed (20 cells at ``default``, 10 at ``draft``), and the strokes within about 5 %
of the box's side (``attach_reach``: 6 cells, 3) are held to within half the
stroke-fidelity tolerance (``attach_band``). A short cutoff with the
pull alone (6 cells) leaves the surfaces several times rougher by the local-quadric
measure and further from the classical surfaces; a long cutoff with the pull alone lets
the surface sag off its strokes; a longer cutoff of the positions thins tubes between
their strokes. So the lumps up to twice the cutoff long are first taken out of the
normals, which a tube keeps (``attach_normals``: 40 cells at ``default``), and the
vertices follow them (figures: ``benchmarks/README.md``).

``default`` also takes the small handles out of f's zero set before the extraction
(``handles``, :mod:`neural.topology`): where f is near zero over a wide area its noise
pierces the surface with holes a few cells across and spans it with thin strands, tens
of handles on the surface of a genus-0 sketch, which the fairing turns into pits and
tears.

Both close the surface flat on a side of the strokes' bounding box that it leaves
through a drawn rim (``rims``, :mod:`neural.rims`): Eq. 5 continues a surface past an
open rim, so a capped cylinder drawn by its rims and rulings became a tube through the
box's walls, a portafilter's basket a dome.

Both fit the separately drawn bodies of a connected drawing each on its own, two at
once (``split_parts``, :mod:`neural.parts`): one field for the whole joins close bodies
with a web that no stroke holds.

Crease presets: ``draft`` for a CPU, ``default`` a 4 x 256 MLP trained 3,000 steps,
``paper`` the network size and the 15,000 steps of the paper's 3D examples (Sec. 5),
with the Softplus activation of Sec. 4.

``benchmarks/README.md`` has the scores and timings of the presets, the variants tried
against them, and how the published code differs from both.

References
----------
Zhang, Wang, Bessmeltsev, "Variational Neural Surfacing of 3D Sketches",
SIGGRAPH Asia 2025, Sec. 4.3 (weights), 4.4.1 (box), 5.1 (samples), 5.2 (steps).
Niu et al. 2025, "SharpNet", Sec. 4 (activation), Sec. 5 (network size and training of
the 3D examples).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace

__all__ = ["FlowConfig", "PRESETS", "get_config", "parse_setting", "CreaseConfig",
           "CREASE_PRESETS", "crease_config"]


@dataclass(frozen=True)
class FlowConfig:
    """All settings of :func:`neural.flow.fit_flow_surface`.

    Attributes
    ----------
    res : int
        Poisson grid resolution per axis (paper: 256).
    init_res : int
        Poisson grid resolution of the initialisation stage (strokes only), at most
        ``res`` (a coarser ``res``, a small part's in :mod:`neural.parts` or one set by
        hand, takes the stage with it); 0: ``res``, as in the paper. The full stage
        starts from the zero set of that coarser f.
    padding : float
        Padding of the sketch's bounding box on every side, as a fraction of its
        longest side (paper: 0.2, Sec. 4.4.1).
    boundary : str
        ``"periodic"`` (the paper: the padded box is a 3-torus, the FFT solve) or
        ``"dirichlet"`` (f = 0 on the box walls, a sine series: slower per solve at
        large grids, with less memory than the FFT). On the torus a zero set may
        close by wrapping around the box where no stroke holds it (a capped
        cylinder whose caps carry no strokes becomes a tube through the walls, not
        watertight). ``"dirichlet"`` makes the walls outside, so every surface
        closes inside the box, but nothing in the energy puts the closure at the
        strokes' rims: such ends close as domes in the padding.
    lowpass : float
        Standard deviation, in grid cells, of a Gaussian low-pass of every Poisson
        solve (training and polish; :class:`neural.poisson.PoissonSolver`); 0 (every
        preset, as the paper): none. 2 at ``default`` keeps the holes of sparse
        wireframes open and takes parts of real sketches off their strokes (notes
        above).
    width, hidden_layers : int
        SIREN hidden width and number of hidden (width -> width) layers
        (paper: 256 and 4, Sec. 4.4).
    omega_0 : float
        SIREN frequency (30, Sitzmann et al. 2020).
    n_stroke, n_surface, n_volume : int
        Monte-Carlo samples per step on strokes, iso-surface and volume
        (paper: 10k, 15k, 15k, Sec. 5.1).
    init_steps, steps : int
        Adam steps of the initialisation stage and of the full stage
        (paper: 200 and 800, Sec. 5.2).
    bridge_steps : int
        Adam steps between them fitting g to ``sigma`` times the unit gradient of the
        initialisation stage's f (low-passed, :data:`neural.flowfit.BRIDGE_BLUR`), at
        ``n_surface`` samples of its zero set a step (no Poisson solve); 0: none, as in
        the paper. Not run when refining an
        ``init_mesh`` (its prefit does the same).
    lr : float
        Adam learning rate. grad_clip : float, gradient-norm clip (0 = off).
    w_align, w_smooth, w_data, w_eik, w_curl : float
        Loss weights of Eq. 13 (paper: 1, 0.01, 30, 7, 7).
    w_smooth_near, smooth_near : float
        Near the strokes the smoothness term is weighted ``w_smooth_near`` (the paper's
        0.01), far from them ``w_smooth``: per surface sample, the weight rises
        linearly from ``w_smooth_near`` at a third of ``smooth_near`` grid cells from
        the nearest stroke to ``w_smooth`` at ``smooth_near`` cells and beyond. 0 cells
        (every preset): ``w_smooth`` everywhere. Not in the paper (see the notes above;
        measured with 6 cells at ``default``, the fairing's reach there).
    w_normal : float
        Weight of the anchors' normal term (:func:`neural.losses.normal_loss`; only
        with ``anchors``, not in the paper).
    sigma : float
        Eikonal target gradient norm (paper: 0.5, Sec. 4.3).
    poisson_every : int
        Solve the Poisson equation every this many steps (1 = every step, as in every
        preset); the steps between use the data term's first-order linearisation
        (:mod:`neural.flow`), which skips the solve.
    normalize_from : float
        Fraction of the full stage after which the rasterised g is normalised
        per grid point (Sec. 5.1, "once the optimization has stabilized").
    prefit_steps : int
        Steps fitting g to sigma * grad SDF of ``init_mesh`` (refinement only).
    geometric_init_steps : int
        Steps fitting g to the gradient of a sphere around the strokes before
        the initialisation stage (0 = plain SIREN initialisation, as the paper
        text; the published code uses a sphere initialisation).
    dtype : str
        ``"float32"`` (every preset) or ``"float64"``: the precision of the network,
        the samples and the grids.
    polish : int
        After the last step, integrate f again (no gradients) from this many times
        the stroke and surface samples of a step, ``polish_rounds`` times, each round
        drawing its surface samples on the zero set of the one before; 0 keeps the
        last step's f. Both surfaces are faired (``attach``) and the polished one is
        returned only when it then holds at least as much of the strokes as the last
        step's, less ``neural.flow.POLISH_SLACK`` (stroke fidelity, the share of
        stroke length within 1 % of the strokes' diagonal); ``report["polish"]``
        gives both figures. Not in the paper (see the notes above: ``default``).
    polish_rounds : int
        Rounds of the polish (at least 1).
    polish_strip : float
        Surface samples closer than this many grid cells to a stroke sample are left
        out of the polish's splats and the stroke samples carry their mass
        (:func:`neural.poisson.stroke_strip`); 0 splats every sample with mass 1.
    average_from : float
        Fraction of the full stage from which the network's parameters and the
        solved f are averaged (running means; stochastic weight averaging of the
        parameters) for the polish, which then integrates the averaged network's g
        from the averaged f's zero set; 1 = no averaging (the last step's
        network and f). Training itself is unchanged.
    attach : float
        After the extraction (and the polish), fair the mesh and pull it onto the
        strokes near it (:func:`neural.attach.attach_to_strokes`): ripples shorter
        than this many grid cells are removed next to the strokes, and up to twice as
        long away from them (the displacement onto the strokes at twice that, up to
        four times where the surface is wide); 0 keeps the mesh as extracted. The
        result is returned only when its stroke fidelity is at least the extracted
        mesh's; ``report["attach"]`` gives both. With ``anchors`` (hybrid fills) their
        points pull too and nothing is held to ``attach_band``. Not in the paper.
    attach_weight : float
        Pull of the stroke samples in that fairing (0 = the low-pass alone).
    attach_band : float
        In that fairing, the stroke samples left farther than this fraction of the
        strokes' bounding-box diagonal from the surface are held to it (0 = the pull
        alone); half the stroke-fidelity tolerance in ``draft`` and ``default``.
    attach_reach : float
        In that fairing, the stroke samples farther than this many grid cells from the
        extracted surface are left out (not pulled). The same share of the padded box
        in ``draft`` (3 of 64 cells) and ``default`` (6 of 128), as the cutoff is.
    attach_normals : float
        In that fairing, the vertex normals are first low-passed at this many grid
        cells and the vertices moved to follow them (:func:`neural.attach.normal_faired`):
        ripples up to this long go without the shrinking of a position low-pass; 0 =
        not done. Not in the paper.
    handles : int
        Before the extraction, the holes and strands of f's zero set up to ``handles -
        1`` grid cells across that make handles of the surface are plugged and cut, and
        the specks of solid smaller than that cube that no stroke passes through
        dropped, the rest of the zero set unmoved (:func:`neural.topology.remove_small_handles`;
        odd, 0 = not done). 5 at ``default``, whose extracted surfaces of genus-0
        sketches otherwise carry up to tens of such handles; not in ``draft``, whose
        cells are twice as large. Not in the paper.
    subdivide : int
        Rounds (at most :data:`MAX_SUBDIVIDE`) of curved 1-to-4 subdivision of the final
        mesh (:func:`curvenet.core.geometry.subdivide_curved`): the new vertices on the
        point-normal triangles of the old ones, which takes the facets of a grid-cell
        sized mesh off the surface's curvature (4 times the triangles a round). One round
        in ``draft`` and ``default``; none in ``paper`` (its 256^3 grid). Not with
        ``anchors``. Not in the paper.
    rims : float
        Where the zero set leaves the strokes' bounding box through a drawn rim (at
        least this share of its crossing of a side's plane within
        :data:`neural.rims.RIM_REACH` cells of a stroke), it is closed flat on that
        plane instead of running on past the rim (:func:`neural.rims.close_rims`); 0 =
        never. 0.5 in ``draft`` and ``default``. Not with ``anchors``. Not in the paper.
    split_parts : int
        1: the route fits the separately drawn parts of a connected drawing one at a
        time (:func:`neural.parts.fit_parts`; the paper does so by hand for one
        sketch); 0: one fit of the whole sketch. 1 in ``draft`` and ``default``.
        :func:`neural.flow.fit_flow_surface` itself always fits what it is given.
    """

    res: int = 128
    init_res: int = 0
    padding: float = 0.2
    boundary: str = "periodic"
    lowpass: float = 0.0
    width: int = 96
    hidden_layers: int = 2
    omega_0: float = 30.0
    n_stroke: int = 3000
    n_surface: int = 2500
    n_volume: int = 1500
    init_steps: int = 60
    bridge_steps: int = 0
    steps: int = 200
    lr: float = 2e-4
    grad_clip: float = 10.0
    w_align: float = 1.0
    w_smooth: float = 0.01
    w_smooth_near: float = 0.01
    smooth_near: float = 0.0
    w_data: float = 30.0
    w_eik: float = 7.0
    w_curl: float = 7.0
    w_normal: float = 7.0
    sigma: float = 0.5
    poisson_every: int = 1
    normalize_from: float = 0.6
    prefit_steps: int = 150
    geometric_init_steps: int = 100
    dtype: str = "float32"
    polish: int = 0
    polish_rounds: int = 1
    polish_strip: float = 0.0
    average_from: float = 1.0
    attach: float = 0.0
    attach_weight: float = 100.0
    attach_band: float = 0.0
    attach_reach: float = 3.0
    attach_normals: float = 0.0
    handles: int = 0
    subdivide: int = 0
    rims: float = 0.0
    split_parts: int = 0

    def as_dict(self) -> dict:
        """The settings as a plain dict (for reports)."""
        return asdict(self)


PRESETS: dict[str, FlowConfig] = {
    "draft": FlowConfig(res=64, width=64, hidden_layers=2, n_stroke=1200, n_surface=1000,
                        n_volume=600, init_steps=40, steps=100, lr=3e-4, poisson_every=1,
                        w_smooth=0.1, attach=10.0, attach_band=0.005, subdivide=1,
                        rims=0.5, split_parts=1),
    "default": FlowConfig(init_res=64, bridge_steps=30, steps=140, w_smooth=0.1, polish=4,
                          polish_rounds=4, polish_strip=1.0, average_from=0.6, attach=20.0,
                          attach_band=0.005, attach_reach=6.0, attach_normals=40.0,
                          handles=5, subdivide=1, rims=0.5, split_parts=1),
    "paper": FlowConfig(res=256, width=256, hidden_layers=4, n_stroke=10000, n_surface=15000,
                        n_volume=15000, init_steps=200, steps=800, lr=5e-5,
                        geometric_init_steps=0),
}

_CHOICES = {"boundary": ("periodic", "dirichlet"), "dtype": ("float32", "float64")}


def _from_preset(presets: dict, quality: str, overrides: dict, what: str):
    """``presets[quality]`` with the fields ``overrides`` replaced (names checked, not values)."""
    if quality not in presets:
        raise ValueError(f"quality must be one of {sorted(presets)}, got {quality!r}")
    names = {f.name for f in fields(presets[quality])}
    unknown = sorted(set(overrides) - names)
    if unknown:
        raise ValueError(f"unknown {what} setting(s) {unknown}; valid: {sorted(names)}")
    return replace(presets[quality], **overrides)


def get_config(quality: str = "draft", **overrides) -> FlowConfig:
    """The preset ``quality`` with ``overrides`` applied and validated.

    Parameters
    ----------
    quality : {"draft", "default", "paper"}
    **overrides
        Any :class:`FlowConfig` field.

    Returns
    -------
    FlowConfig

    Raises
    ------
    ValueError
        Unknown preset or field, or a value out of range (the message names it).

    Examples
    --------
    >>> get_config("draft", res=96).res
    96
    """
    cfg = _from_preset(PRESETS, quality, overrides, "neural")
    positive_int = ("res", "width", "n_stroke", "n_surface", "n_volume", "poisson_every",
                    "polish_rounds")
    for name in positive_int:
        v = getattr(cfg, name)
        if int(v) != v or v < 1:
            raise ValueError(f"{name} must be a positive integer, got {v!r}")
    for name in ("hidden_layers", "init_steps", "bridge_steps", "steps", "prefit_steps",
                 "geometric_init_steps", "polish"):
        v = getattr(cfg, name)
        if int(v) != v or v < 0:
            raise ValueError(f"{name} must be a non-negative integer, got {v!r}")
    if cfg.split_parts not in (0, 1):
        raise ValueError(f"split_parts must be 0 or 1, got {cfg.split_parts!r}")
    if int(cfg.subdivide) != cfg.subdivide or not 0 <= cfg.subdivide <= MAX_SUBDIVIDE:
        raise ValueError(f"subdivide must be an integer in [0, {MAX_SUBDIVIDE}], "
                         f"got {cfg.subdivide!r}")
    h = cfg.handles
    if int(h) != h or h < 0 or (h > 0 and h % 2 == 0):
        raise ValueError(f"handles must be 0 or an odd positive integer, got {cfg.handles!r}")
    if cfg.res < 8:
        raise ValueError(f"res must be at least 8, got {cfg.res}")
    if int(cfg.init_res) != cfg.init_res or not (cfg.init_res == 0 or cfg.init_res >= 8):
        raise ValueError(f"init_res must be 0 or an integer of at least 8, got {cfg.init_res!r}")
    if cfg.res > MAX_RES:
        need = GRID_BYTES_PER_VOXEL * cfg.res ** 3 / 2**30
        raise ValueError(f"res {cfg.res} needs about {need:.3g} GiB for its grids; "
                         f"the limit is res <= {MAX_RES}")
    for name in ("padding", "lr", "sigma", "omega_0"):
        if not getattr(cfg, name) > 0:
            raise ValueError(f"{name} must be positive, got {getattr(cfg, name)!r}")
    for name in ("w_align", "w_smooth", "w_smooth_near", "smooth_near", "w_data", "w_eik",
                 "w_curl", "w_normal", "grad_clip", "polish_strip", "attach", "attach_weight",
                 "attach_band", "attach_reach", "attach_normals", "lowpass"):
        if not getattr(cfg, name) >= 0:
            raise ValueError(f"{name} must be non-negative, got {getattr(cfg, name)!r}")
    for name in ("normalize_from", "average_from"):
        if not 0.0 <= getattr(cfg, name) <= 1.0:
            raise ValueError(f"{name} must lie in [0, 1], got {getattr(cfg, name)!r}")
    for name, allowed in _CHOICES.items():
        if getattr(cfg, name) not in allowed:
            raise ValueError(f"{name} must be one of {allowed}, got {getattr(cfg, name)!r}")
    return cfg


#: Most rounds of the final mesh's subdivision (each quadruples the triangles).
MAX_SUBDIVIDE = 2
#: Largest Poisson grid accepted (``res``); larger grids are refused before any allocation.
MAX_RES = 512
#: Rough bytes per grid voxel of a fit (float32 field, FFT buffers, splats), for the message.
GRID_BYTES_PER_VOXEL = 40


def parse_setting(text: str) -> tuple[str, object]:
    """``"name=value"`` (a command-line override) -> ``(name, value)`` typed as the field.

    Ranges are checked later by :func:`get_config`.

    Raises
    ------
    ValueError
        No ``=``, an unknown field, or a value that does not parse as the field's type.

    Examples
    --------
    >>> parse_setting("w_smooth=0.01")
    ('w_smooth', 0.01)
    >>> parse_setting("boundary=dirichlet")
    ('boundary', 'dirichlet')
    """
    name, sep, raw = text.partition("=")
    name, raw = name.strip(), raw.strip()
    kinds = {f.name: type(f.default) for f in fields(FlowConfig)}
    if not sep or not name:
        raise ValueError(f"expected NAME=VALUE, got {text!r}")
    if name not in kinds:
        raise ValueError(f"unknown neural setting {name!r}; valid: {sorted(kinds)}")
    kind = kinds[name]
    try:
        return name, kind(raw)
    except ValueError:
        raise ValueError(f"{name} takes a {kind.__name__}, got {raw!r}") from None


# ---------------------------------------------------------------------------------------------
# crease refit (neural.crease_refit.crease_refine)
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CreaseConfig:
    """Settings of :func:`neural.crease_refit.crease_refine` (lengths in its unit frame:
    the data in [-0.8, 0.8]^3).

    Attributes
    ----------
    hidden, layers : int
        SharpNet MLP size (paper Sec. 5: 4 x 256).
    activation : {"softplus", "sine"}
        Softplus(beta = 100) (Sec. 4) or SIREN sine (Sec. 5).
    n_freqs : int
        Positional-encoding octaves.
    geometric_init : float or None
        Radius of the initial sphere SDF (Softplus; see :class:`neural.sharpnet.SharpNet`).
    steps, lr, batch : Adam steps, learning rate, surface points per step (the ambient
        and near-surface batches have the same size).
    res : int
        Marching-cubes grid per axis over [-1, 1]^3.
    strip_width : float
        Half-width w of the crease strips (Appendix A).
    strip_spacing : float
        Strip element size along the stroke.
    mollifier_radius : float
        Support radius of each strip triangle's mollifier (Eq. 6).
    feature_scale : float
        Multiplier of the feature channels (network input scaling).
    exclude : float
        Surface samples of the input mesh closer than this to a crease stroke are dropped
        (the input is rounded there); the strokes themselves constrain the crease.
    guide_radius : float
        Neighbourhood for the guide estimate from the input surface normals.
    w_sur, w_ext, w_ekl, w_nor : float
        Loss weights of Eq. 9 (``w_nor`` as in Eq. 10).
    w_sdf : float
        Weight of the value term on near-surface samples (not in the paper; see
        :func:`neural.crease_refit.crease_refine`).
    ext_alpha : float
        alpha of ``L_ext = exp(-alpha |Phi|)`` (not given in the paper; SIREN uses 100).
    near_sigma : float
        Std of the Gaussian offsets of the near-surface (Eikonal) samples.
    pool : int
        Surface samples drawn once from the input (their feature values are computed once).
    stroke_weight : float
        Share of the surface batch taken from stroke points.
    use_features : bool
        False fits the same network without feature channels (the no-crease baseline).
    keep_tol : float
        Output faces farther than this from the input surface and strokes are dropped
        (removes stray level-set pieces; trims open surfaces to their input extent).
    """

    hidden: int = 128
    layers: int = 3
    activation: str = "softplus"
    n_freqs: int = 2
    geometric_init: float | None = 0.5
    steps: int = 800
    lr: float = 2e-3
    batch: int = 3000
    res: int = 128
    strip_width: float = 0.08
    strip_spacing: float = 0.025
    mollifier_radius: float = 0.1
    feature_scale: float = 10.0
    exclude: float = 0.1
    guide_radius: float = 0.12
    w_sur: float = 7000.0
    w_ext: float = 600.0
    w_ekl: float = 50.0
    w_nor: float = 15.0
    w_sdf: float = 3000.0
    ext_alpha: float = 100.0
    near_sigma: float = 0.03
    pool: int = 60000
    stroke_weight: float = 0.2
    use_features: bool = True
    keep_tol: float = 0.1


CREASE_PRESETS = {
    "draft": CreaseConfig(),
    "default": CreaseConfig(hidden=256, layers=4, steps=3000, res=192, pool=150000),
    "paper": CreaseConfig(hidden=256, layers=4, steps=15000, res=256, pool=300000,
                          batch=20000),
}


def crease_config(quality: str = "draft", overrides: dict | None = None) -> CreaseConfig:
    """The preset ``quality`` with ``overrides`` (field name -> value) applied and checked.

    Raises
    ------
    ValueError
        Unknown preset or field, or a value out of range.
    """
    cfg = _from_preset(CREASE_PRESETS, quality, overrides or {}, "crease_refine")
    if cfg.activation not in ("softplus", "sine"):
        raise ValueError(f"activation must be 'softplus' or 'sine', got {cfg.activation!r}")
    for k in ("steps", "batch", "res", "pool", "hidden", "layers"):
        if int(getattr(cfg, k)) < 1:
            raise ValueError(f"{k} must be >= 1, got {getattr(cfg, k)!r}")
    return cfg
