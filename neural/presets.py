"""Quality presets for the flow-aligned neural surfacing (Zhang, Wang, Bessmeltsev 2025).

A preset is a :class:`FlowConfig`: every setting of the optimisation in one
place, each overridable by keyword (``fit_flow_surface(..., res=96)``).

Notes
-----
``paper`` reproduces the published settings (Sec. 4.3, 5.1, 5.2): a 4 x 256
SIREN with omega_0 = 30, 10k / 15k / 15k Monte-Carlo samples on strokes,
surface and volume, 200 initialisation + 800 full Adam steps, a 256^3 grid on
the bounding box padded by 20 %, loss weights 1, 0.01, 30, 7, 7 and Eikonal
sigma = 0.5. The learning rate and gradient clipping are not given in the
paper; we take the published code's values (Adam lr 5e-5, clip 10). It is
meant for a GPU: 44-58 s per sketch on one H100 (0.05-0.06 s per full step at
128^3 and 256^3 alike, 5.5 GB of GPU memory).

``draft`` is sized for a 2-core CPU in about a minute; ``default`` balances
quality and time (a tenth of the reference's time on a CPU; 12-13 s per vns
sketch on an H100). Both raise the smoothness weight from the paper's 0.01 to
0.1: with their short budgets the paper's weight leaves mid-frequency bumps.
Measured on rough re-drawn shapes at draft (seed 0, F-score at 0.01): sphere
0.923 -> 0.994, ellipsoid 0.950 -> 0.978, torus 0.734 -> 0.953, capped
cylinder 0.568 -> 0.635.

On a GPU, ``default`` is the better choice in this implementation. Rough
shapes on an H100 (seed 0, F-score at 0.01): ``default`` sphere 0.999 in 7.7 s;
``paper`` sphere 0.701 (faceted between the strokes), ellipsoid 0.987, torus
0.960 (a small hole at the box wall). No change of ``paper`` was better on all
three: sphere / ellipsoid / torus with the smoothness weight 0.1 and the
published code's sphere initialisation 0.999 / 1.000 / 0.580 (torus genus
lost); 0.1 alone 1.000 / 0.998 / 0.783; the sphere initialisation alone 0.719
(sphere), 0.578 (torus); lr 2e-4 0.373, a 128^3 grid 0.739, a Gaussian
low-pass of one cell 0.676 (torus). ``paper`` therefore keeps the published
constants. Both solve the Poisson equation every ``poisson_every`` steps and
use the linearised data term in between (see :mod:`neural.flow`).

References
----------
Zhang, Wang, Bessmeltsev, "Variational Neural Surfacing of 3D Sketches",
SIGGRAPH Asia 2025, Sec. 4.3 (weights), 5.1 (samples), 5.2 (steps).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields, replace

__all__ = ["FlowConfig", "PRESETS", "get_config", "parse_setting"]


@dataclass(frozen=True)
class FlowConfig:
    """All settings of :func:`neural.flow.fit_flow_surface`.

    Attributes
    ----------
    res : int
        Poisson grid resolution per axis (paper: 256).
    padding : float
        Padding of the sketch's bounding box on every side, as a fraction of its
        longest side (paper: 0.2, Sec. 4.4.1).
    boundary : str
        ``"periodic"`` (the paper: the padded box is a 3-torus) or ``"dirichlet"``
        (f = 0 on the box walls, a sine series: one solve takes 0.01 s vs 0.007 s
        at 64^3, 0.11 s vs 0.05 s at 128^3 and 2.8-3.9 s vs 0.6-0.7 s at 256^3 on
        2 CPU cores, with less memory than the FFT). On the torus a zero set may
        close by wrapping around the box where no stroke holds it: the rough
        capped cylinder, whose caps carry no strokes, comes out as a tube through
        the walls (not watertight; F-score 0.64 at draft).
        ``"dirichlet"`` makes the walls outside, so every surface closes inside
        the box: the same cylinder becomes watertight with genus 0, but its ends
        close as domes in the padding (F-score 0.54, Chamfer 0.040 vs 0.046, 17 s
        vs 13 s at draft); nothing in the energy puts the closure at the rims.
        Other rough shapes at draft, dirichlet vs periodic: sphere 0.992 vs 0.996,
        ellipsoid 0.993 vs 0.978, torus 0.881 vs 0.953; rough box normal error
        20.1 vs 27.8 degrees (its faces no longer bulge through the walls).
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
    lr : float
        Adam learning rate. grad_clip : float, gradient-norm clip (0 = off).
    w_align, w_smooth, w_data, w_eik, w_curl : float
        Loss weights of Eq. 13 (paper: 1, 0.01, 30, 7, 7).
    sigma : float
        Eikonal target gradient norm (paper: 0.5, Sec. 4.3).
    poisson_every : int
        Solve the Poisson equation every this many steps (1 = every step).
    normalize_from : float
        Fraction of the full stage after which the rasterised g is normalised
        per grid point (Sec. 5.1, "once the optimization has stabilized").
    smooth_cells : float
        Gaussian low-pass of the Poisson solution, standard deviation in grid
        cells (0 = the exact Eq. 10).
    surface_sampler : str
        ``"cells"`` (zero-crossing cells + Newton projection, on the device) or
        ``"marching_cubes"`` (scikit-image, on the host).
    smooth_mode : str
        ``"jet"`` (closed-form third derivatives of the SIREN) or ``"autograd"``
        (double backward) for the covariant derivative of II (Eq. 18).
    prefit_steps : int
        Steps fitting g to sigma * grad SDF of ``init_mesh`` (refinement only).
    geometric_init_steps : int
        Steps fitting g to the gradient of a sphere around the strokes before
        the initialisation stage (0 = plain SIREN initialisation, as the paper
        text; the published code uses a sphere initialisation).
    splat_volume : bool
        Also splat g at the volume samples into the Poisson right-hand side, so
        that f follows g away from the surface too (the paper splats stroke and
        surface samples only, Sec. 5.1; without the volume samples the zero set
        can escape through the periodic box where no stroke holds it, e.g. a
        capped cylinder becomes an infinite tube). Off by default: it did not
        close that tube in our tests (the smoothness term itself prefers it).
    dtype : str
        ``"float32"`` or ``"float64"``.
    """

    res: int = 128
    padding: float = 0.2
    boundary: str = "periodic"
    width: int = 96
    hidden_layers: int = 2
    omega_0: float = 30.0
    n_stroke: int = 3000
    n_surface: int = 2500
    n_volume: int = 1500
    init_steps: int = 60
    steps: int = 200
    lr: float = 2e-4
    grad_clip: float = 10.0
    w_align: float = 1.0
    w_smooth: float = 0.01
    w_data: float = 30.0
    w_eik: float = 7.0
    w_curl: float = 7.0
    sigma: float = 0.5
    poisson_every: int = 1
    normalize_from: float = 0.6
    smooth_cells: float = 0.0
    surface_sampler: str = "cells"
    smooth_mode: str = "jet"
    prefit_steps: int = 150
    geometric_init_steps: int = 100
    splat_volume: bool = False
    dtype: str = "float32"

    def as_dict(self) -> dict:
        """The settings as a plain dict (for reports)."""
        return asdict(self)


PRESETS: dict[str, FlowConfig] = {
    "draft": FlowConfig(res=64, width=64, hidden_layers=2, n_stroke=1200, n_surface=1000,
                        n_volume=600, init_steps=40, steps=100, lr=3e-4, poisson_every=1,
                        w_smooth=0.1),
    "default": FlowConfig(w_smooth=0.1),
    "paper": FlowConfig(res=256, width=256, hidden_layers=4, n_stroke=10000, n_surface=15000,
                        n_volume=15000, init_steps=200, steps=800, lr=5e-5,
                        geometric_init_steps=0),
}

_CHOICES = {"boundary": ("periodic", "dirichlet"), "surface_sampler": ("cells", "marching_cubes"),
            "smooth_mode": ("jet", "autograd"), "dtype": ("float32", "float64")}


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
    if quality not in PRESETS:
        raise ValueError(f"quality must be one of {sorted(PRESETS)}, got {quality!r}")
    names = {f.name for f in fields(FlowConfig)}
    unknown = sorted(set(overrides) - names)
    if unknown:
        raise ValueError(f"unknown neural setting(s) {unknown}; valid: {sorted(names)}")
    cfg = replace(PRESETS[quality], **overrides)
    positive_int = ("res", "width", "n_stroke", "n_surface", "n_volume", "poisson_every")
    for name in positive_int:
        v = getattr(cfg, name)
        if int(v) != v or v < 1:
            raise ValueError(f"{name} must be a positive integer, got {v!r}")
    for name in ("hidden_layers", "init_steps", "steps", "prefit_steps",
                 "geometric_init_steps"):
        v = getattr(cfg, name)
        if int(v) != v or v < 0:
            raise ValueError(f"{name} must be a non-negative integer, got {v!r}")
    if cfg.res < 8:
        raise ValueError(f"res must be at least 8, got {cfg.res}")
    if cfg.res > MAX_RES:
        need = GRID_BYTES_PER_VOXEL * cfg.res ** 3 / 2**30
        raise ValueError(f"res {cfg.res} needs about {need:.3g} GiB for its grids; "
                         f"the limit is res <= {MAX_RES}")
    for name in ("padding", "lr", "sigma", "omega_0"):
        if not getattr(cfg, name) > 0:
            raise ValueError(f"{name} must be positive, got {getattr(cfg, name)!r}")
    for name in ("w_align", "w_smooth", "w_data", "w_eik", "w_curl", "grad_clip", "smooth_cells"):
        if not getattr(cfg, name) >= 0:
            raise ValueError(f"{name} must be non-negative, got {getattr(cfg, name)!r}")
    if not 0.0 <= cfg.normalize_from <= 1.0:
        raise ValueError(f"normalize_from must lie in [0, 1], got {cfg.normalize_from!r}")
    for name, allowed in _CHOICES.items():
        if getattr(cfg, name) not in allowed:
            raise ValueError(f"{name} must be one of {allowed}, got {getattr(cfg, name)!r}")
    return cfg


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
    >>> parse_setting("splat_volume=yes")
    ('splat_volume', True)
    """
    name, sep, raw = text.partition("=")
    name, raw = name.strip(), raw.strip()
    kinds = {f.name: type(f.default) for f in fields(FlowConfig)}
    if not sep or not name:
        raise ValueError(f"expected NAME=VALUE, got {text!r}")
    if name not in kinds:
        raise ValueError(f"unknown neural setting {name!r}; valid: {sorted(kinds)}")
    kind = kinds[name]
    if kind is bool:
        truth = {"true": True, "yes": True, "1": True, "false": False, "no": False, "0": False}
        if raw.lower() not in truth:
            raise ValueError(f"{name} takes true or false, got {raw!r}")
        return name, truth[raw.lower()]
    try:
        return name, kind(raw)
    except ValueError:
        raise ValueError(f"{name} takes a {kind.__name__}, got {raw!r}") from None
