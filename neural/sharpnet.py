"""SharpNet: an MLP on (positional encoding of x, feature functions f(x)) with exact C0 creases.

``Phi(x, f^(1)(x), ..., f^(n)(x))`` (Niu et al. 2025, Sec. 3, Fig. 9) is smooth wherever the
feature functions are and inherits their normal-derivative jumps on the feature set M
(Theorem 3.1). This module holds:

- :class:`FeatureSet` -- M as a learnable (or fixed) set of vertices with segments (2D) or
  triangles (3D), split into channels, evaluated globally (Eq. 5) or mollified (Eq. 6);
- :class:`SharpNet` -- the network, Softplus (beta = 100) or sine activations; with no
  feature set it is the plain MLP of the same size (the paper's "Raw MLP" baseline);
- :func:`edge_coloring` -- the feature splitting of Sec. 3.3 (incident edges at every junction
  get distinct channels);
- :func:`smoothness_regulariser` -- ``L_R`` of Sec. 4 (lambda = 0.3), with
  :func:`polyline_triples` / :func:`boundary_triples` choosing where it applies.

References
----------
Niu et al. 2025, "SharpNet", Sec. 3.1-3.3 (network, splitting), Sec. 4 (Eq. 8, ``L_R``),
Sec. 5.2 (``L_R`` on the boundary curves of a 3D feature surface).
"""

from __future__ import annotations

import math
from collections import defaultdict

import numpy as np
import torch
from torch import nn

from curvenet.core.geometry import boundary_edges
from curvenet.core.tolerances import NORM_EPS

from .feature import feature_function, mollified_feature_function

__all__ = [
    "FeatureSet",
    "SharpNet",
    "positional_encoding",
    "edge_coloring",
    "polyline_triples",
    "boundary_triples",
    "smoothness_regulariser",
]

#: Softplus sharpness of the paper's networks (Sec. 4, "Softplus with beta = 100").
SOFTPLUS_BETA = 100.0
#: ``L_R`` balance (Sec. 4: "We choose lambda = 0.3").
LR_LAMBDA = 0.3


def positional_encoding(x: torch.Tensor, n_freqs: int) -> torch.Tensor:
    """NeRF positional encoding ``[x, sin(2^k pi x), cos(2^k pi x)]_{k < n_freqs}``.

    Parameters
    ----------
    x : (n, d) tensor
    n_freqs : int
        Number of octaves (paper: 4 for the geodesic experiment, 8 for medial axes).

    Returns
    -------
    (n, d * (1 + 2 n_freqs)) tensor
    """
    if n_freqs <= 0:
        return x
    freqs = (2.0 ** torch.arange(n_freqs, dtype=x.dtype, device=x.device)) * math.pi
    xf = x[..., None, :] * freqs[:, None]  # (n, L, d)
    return torch.cat([x, torch.sin(xf).flatten(-2), torch.cos(xf).flatten(-2)], dim=-1)


def edge_coloring(edges, n_vertices: int | None = None, *, junctions_only: bool = True
                  ) -> np.ndarray:
    """Greedy colouring of a graph's edges so that edges meeting at a junction differ.

    Parameters
    ----------
    edges : (m, 2) integer array
        Undirected edges (vertex index pairs), e.g. the segments of a 2D feature set or the
        crease strokes between their end points.
    n_vertices : int, optional
        Number of vertices (default: max index + 1).
    junctions_only : bool
        Sec. 3.3 only requires distinct colours at junctions (degree >= 3), so that paths
        through degree-2 vertices keep one colour; ``False`` colours properly everywhere.

    Returns
    -------
    (m,) int64 array
        Colour (feature channel) per edge, from 0; at most ``max degree + 1`` colours (greedy,
        edges in order of decreasing endpoint degree).
    """
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if len(e) == 0:
        return np.zeros(0, dtype=np.int64)
    nv = int(n_vertices) if n_vertices is not None else int(e.max()) + 1
    deg = np.bincount(e.ravel(), minlength=nv)
    strict = deg >= (3 if junctions_only else 0)
    order = np.argsort(-(deg[e[:, 0]] + deg[e[:, 1]]), kind="stable")
    used: dict[int, set] = defaultdict(set)
    colors = np.zeros(len(e), dtype=np.int64)
    for k in order:
        u, v = e[k]
        forbid = (used[u] if strict[u] else set()) | (used[v] if strict[v] else set())
        c = 0
        while c in forbid:
            c += 1
        colors[k] = c
        used[u].add(c)
        used[v].add(c)
    return colors


def polyline_triples(segments) -> np.ndarray:
    """``(left, centre, right)`` index triples at the degree-2 vertices of a segment graph.

    Returns an ``(t, 3)`` int64 array (Sec. 4: ``L_R`` sums over the degree-2 vertices ``a_i``
    of M with their two neighbours ``a_i^l, a_i^r``).
    """
    s = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
    nbrs: dict[int, list] = defaultdict(list)
    for u, v in s:
        nbrs[int(u)].append(int(v))
        nbrs[int(v)].append(int(u))
    rows = [(n[0], c, n[1]) for c, n in sorted(nbrs.items()) if len(n) == 2 and n[0] != n[1]]
    return np.asarray(rows, dtype=np.int64).reshape(-1, 3)


def boundary_triples(triangles) -> np.ndarray:
    """Triples of :func:`polyline_triples` on the boundary curves of a triangle mesh.

    Sec. 5.2: for a 3D feature surface ``L_R`` is imposed on its boundary curves dM.
    """
    return polyline_triples(boundary_edges(triangles))


def smoothness_regulariser(vertices: torch.Tensor, triples, lam: float = LR_LAMBDA
                           ) -> torch.Tensor:
    """``L_R(M) = lam/m sum |v_i| + (1 - lam)/m sum |v_i . u_i|`` (Sec. 4).

    Parameters
    ----------
    vertices : (k, d) tensor
        Vertices of M.
    triples : (m, 3) integer array
        ``(a^l, a, a^r)`` index triples (see :func:`polyline_triples`).
    lam : float
        Balance between straightness/uniformity and uniformity only (paper: 0.3).

    Returns
    -------
    () tensor
        ``v_i = (a^l + a^r)/2 - a`` (differential coordinate), ``u_i`` the unit chord; 0 when
        there are no triples.
    """
    tr = torch.as_tensor(np.asarray(triples, dtype=np.int64).reshape(-1, 3),
                         device=vertices.device)
    if tr.shape[0] == 0:
        return vertices.sum() * 0.0
    al, a, ar = vertices[tr[:, 0]], vertices[tr[:, 1]], vertices[tr[:, 2]]
    v = 0.5 * (al + ar) - a
    chord = ar - al
    u = chord / chord.norm(dim=-1, keepdim=True).clamp_min(NORM_EPS)
    vn = torch.sqrt((v * v).sum(-1) + 1e-24)
    return lam * vn.mean() + (1.0 - lam) * (v * u).sum(-1).abs().mean()


class FeatureSet(nn.Module):
    """A feature set M with its feature functions (one per channel).

    Parameters
    ----------
    vertices : (k, d) array, d in {2, 3}
        Vertices of M.
    elements : (m, d) integer array
        Segments (2D) or triangles (3D).
    channels : (m,) integer array, optional
        Channel per element (Sec. 3.3 splitting); default all 0.
    radius : float, optional
        Mollifier support radius (Eq. 6); ``None`` uses the global integral (Eq. 5).
    learnable : bool
        Make the vertices a trainable parameter (Sec. 4.2 / 5.2); ``freeze`` (a boolean mask
        of vertices) keeps some of them fixed, e.g. the vertices of degree one.
    scale : float
        Multiplier on the output (the normal-derivative jump of each channel becomes
        ``scale`` times phi); 1 keeps the paper's g = 1.
    dtype : torch dtype

    Notes
    -----
    ``forward(x)`` returns ``(n, n_channels)``. The regulariser ``L_R`` of the vertices is
    :meth:`regulariser`, on the polyline (2D) or on the strip's boundary curves (3D).
    """

    def __init__(self, vertices, elements, *, channels=None, radius: float | None = None,
                 learnable: bool = False, freeze=None, scale: float = 1.0,
                 dtype: torch.dtype = torch.float32):
        super().__init__()
        v = torch.as_tensor(np.asarray(vertices, dtype=np.float64), dtype=dtype)
        el = np.asarray(elements, dtype=np.int64)
        if v.ndim != 2 or v.shape[1] not in (2, 3):
            raise ValueError(f"vertices must be (k, 2) or (k, 3), got {tuple(v.shape)}")
        if el.ndim != 2 or el.shape[1] != v.shape[1] or len(el) == 0:
            raise ValueError(f"elements must be a non-empty (m, {v.shape[1]}) array, "
                             f"got {el.shape}")
        if radius is not None and not (math.isfinite(radius) and radius > 0):
            raise ValueError(f"radius must be positive, got {radius!r}")
        self.dim = int(v.shape[1])
        self.radius = None if radius is None else float(radius)
        self.scale = float(scale)
        ch = np.zeros(len(el), dtype=np.int64) if channels is None else np.asarray(
            channels, dtype=np.int64)
        if ch.shape != (len(el),) or ch.min() < 0:
            raise ValueError("channels must hold one non-negative integer per element")
        self.n_channels = int(ch.max()) + 1
        self.register_buffer("elements", torch.from_numpy(el))
        self.register_buffer("channels", torch.from_numpy(ch))
        if learnable:
            self.vertices = nn.Parameter(v)
        else:
            self.register_buffer("vertices", v)
        mask = torch.zeros(len(v), dtype=torch.bool)
        if freeze is not None:
            mask = torch.as_tensor(np.asarray(freeze, dtype=bool))
        self.register_buffer("frozen", mask)
        self._triples = (polyline_triples(el) if self.dim == 2 else boundary_triples(el))

    def current_vertices(self) -> torch.Tensor:
        """Vertices with the frozen ones detached (their gradient is zero)."""
        v = self.vertices
        if self.frozen.any():
            v = torch.where(self.frozen[:, None], v.detach(), v)
        return v

    def forward(self, x: torch.Tensor) -> torch.Tensor:  # (n, d) -> (n, C)
        v = self.current_vertices()
        if self.radius is None:
            f = feature_function(x, v, self.elements, channels=self.channels,
                                 n_channels=self.n_channels)
        else:
            f = mollified_feature_function(x, v, self.elements, radius=self.radius,
                                           channels=self.channels, n_channels=self.n_channels)
        return f * self.scale

    def regulariser(self, lam: float = LR_LAMBDA) -> torch.Tensor:
        """``L_R`` (Sec. 4) of the current vertices."""
        return smoothness_regulariser(self.current_vertices(), self._triples, lam)


class _Sine(nn.Module):
    def __init__(self, omega_0: float):
        super().__init__()
        self.omega_0 = omega_0

    def forward(self, x):
        return torch.sin(self.omega_0 * x)


class SharpNet(nn.Module):
    """``Phi(PE(x), f(x))``: MLP on the positional encoding of x and the feature channels.

    Parameters
    ----------
    dim : int
        Spatial dimension (2 or 3).
    features : FeatureSet, optional
        The feature set; ``None`` gives the plain MLP of the same widths (baseline).
    hidden : int
        Width of each hidden layer (paper: 256).
    layers : int
        Number of hidden layers (paper: 4).
    n_freqs : int
        Positional-encoding octaves (paper: 4 in the geodesic experiment); 0 disables it.
    activation : {"softplus", "sine"}
        Softplus with ``beta`` (paper: 100; C-infinity, so the only creases are on M), or
        sine with SIREN initialisation (Sec. 5 training details, ``omega_0``).
    beta, omega_0 : float
        Activation constants.
    out_bias : float
        Initial bias of the output layer.
    geometric_init : float, optional
        Softplus only: the geometric initialisation of Atzmon & Lipman (SAL, 2020) so that
        the initial network is about the SDF of a sphere of this radius; the positional-
        encoding and feature columns of the first layer start at 0 (as in IDR/NeuS). Not in
        the SharpNet paper; it makes short CPU fits of SDFs converge.

    Notes
    -----
    Input layout: ``[PE(x) (d(1 + 2 L)), f^(1..C)(x)]``. ``forward`` returns ``(n,)``.
    """

    def __init__(self, dim: int, features: FeatureSet | None = None, *, hidden: int = 256,
                 layers: int = 4, n_freqs: int = 4, activation: str = "softplus",
                 beta: float = SOFTPLUS_BETA, omega_0: float = 30.0, out_bias: float = 0.0,
                 geometric_init: float | None = None):
        super().__init__()
        if dim not in (2, 3):
            raise ValueError(f"dim must be 2 or 3, got {dim!r}")
        if activation not in ("softplus", "sine"):
            raise ValueError(f"activation must be 'softplus' or 'sine', got {activation!r}")
        if features is not None and features.dim != dim:
            raise ValueError(f"features are {features.dim}D but dim={dim}")
        if hidden < 1 or layers < 1:
            raise ValueError(f"hidden and layers must be >= 1, got {hidden}, {layers}")
        self.dim = dim
        self.features = features
        self.n_freqs = int(n_freqs)
        n_in = dim * (1 + 2 * self.n_freqs) + (features.n_channels if features else 0)
        widths = [n_in] + [hidden] * layers
        mods: list[nn.Module] = []
        for i in range(layers):
            lin = nn.Linear(widths[i], widths[i + 1])
            if activation == "sine":
                with torch.no_grad():  # SIREN initialisation (Sitzmann et al. 2020, Sec. 3.2)
                    bound = 1.0 / widths[i] if i == 0 else math.sqrt(6.0 / widths[i]) / omega_0
                    lin.weight.uniform_(-bound, bound)
                mods += [lin, _Sine(omega_0)]
            else:
                mods += [lin, nn.Softplus(beta=beta)]
        last = nn.Linear(hidden, 1)
        with torch.no_grad():
            last.bias.fill_(out_bias)
        mods.append(last)
        self.mlp = nn.Sequential(*mods)
        if geometric_init is not None and activation == "softplus":
            lins = [m for m in mods if isinstance(m, nn.Linear)]
            with torch.no_grad():
                for i, lin in enumerate(lins[:-1]):
                    lin.weight.normal_(0.0, math.sqrt(2.0) / math.sqrt(lin.out_features))
                    lin.bias.zero_()
                    if i == 0:
                        lin.weight[:, dim:] = 0.0
                last.weight.normal_(math.sqrt(math.pi) / math.sqrt(hidden), 1e-4)
                last.bias.fill_(-float(geometric_init))

    def encode(self, x: torch.Tensor) -> torch.Tensor:
        """Network input ``[PE(x), f(x)]``, ``(n, n_in)``."""
        z = positional_encoding(x, self.n_freqs)
        if self.features is not None:
            z = torch.cat([z, self.features(x).to(z.dtype)], dim=-1)
        return z

    def forward(self, x: torch.Tensor) -> torch.Tensor:  # (n, d) -> (n,)
        return self.mlp(self.encode(x))[..., 0]
