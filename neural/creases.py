"""True creases at crease strokes: SharpNet feature strips and the crease-refinement fit.

A crease stroke becomes a feature set M: a strip surface along the stroke (Niu et al. 2025,
Appendix A) that approximates the medial surface near the sharp edge. A SharpNet SDF fitted to
the current surface and the strokes with these strips as features is C0 exactly on the strips,
so its zero set can have a true crease where a strip crosses it, and is smooth elsewhere.

Public pieces:

- :func:`guide_directions` -- per-vertex guiding directions from per-edge ones (Appendix A,
  the energy with a squared relaxation, solved in closed form);
- :func:`stroke_guides_from_mesh` -- per-edge guides of a stroke estimated from the current
  surface's normals on both sides (mean of the face normals around the stroke, which is the
  bisector direction of the two sides);
- :func:`strip_from_polyline` -- the strip M (offset each vertex by +-w along its guide);
- :func:`crease_feature_set` -- strips for all crease strokes, channels split by
  :func:`neural.sharpnet.edge_coloring` of the stroke graph (Sec. 3.3);
- :func:`segment_strip_2d` -- the 2D analogue (a segment through a polygon corner along its
  bisector), used by the tests;
- :func:`crease_refine` -- the refinement stage of the pipeline.

Deviations of the crease refit
------------------------------
* Convergence at CPU budgets: besides Eq. 9, near-surface samples are regressed
  (``w_sdf``, L1) on the point-to-plane distance to their nearest kept input sample. Away
  from creases that is the input's signed distance; near a crease, where the input samples
  are dropped, it is the distance to the extrapolated planes of the two sides, i.e. the
  sharp SDF whose kink on the bisector the strip lets the network represent.
* Gap fill (speed): the strips are fixed, so the feature values and their gradients are
  computed once for a sample pool; the network sees ``f0 + grad f0 . (x - x0)`` with
  ``x0`` the detached sample, which has exactly f's value and first derivatives there (all
  Eq. 9 needs), so training costs no more than a plain MLP. Extraction evaluates f exactly.

References
----------
Niu et al. 2025, "SharpNet", Appendix A (strips), Sec. 3.3 (splitting), Sec. 5.1 (Eq. 9).
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict

import numpy as np
from scipy.spatial import cKDTree

from curvenet.core.geometry import arc_length, face_normals_areas, resample_polyline, sample_surface
from curvenet.core.result import MeshResult
from curvenet.core.strokes import check_strokes
from curvenet.core.tolerances import NORM_EPS, ZERO_LENGTH

from .presets import CREASE_PRESETS, CreaseConfig, crease_config
from .training import Stage, Step, seeded, torch_device, train

__all__ = [
    "CreaseConfig",
    "crease_config",
    "CREASE_PRESETS",
    "guide_directions",
    "stroke_guides_from_mesh",
    "strip_from_polyline",
    "crease_feature_set",
    "segment_strip_2d",
    "crease_refine",
]

#: lambda of the Appendix A energy (the paper leaves its value open).
GUIDE_LAMBDA = 0.5


# ---------------------------------------------------------------------------------------------
# guiding directions and strips (Appendix A)
# ---------------------------------------------------------------------------------------------
def _unit(v, eps=NORM_EPS):
    v = np.asarray(v, dtype=np.float64)
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), eps)


def guide_directions(points, edge_guides, *, lam: float = GUIDE_LAMBDA) -> np.ndarray:
    """Vertex guiding directions of a polyline from its per-edge guides (Appendix A).

    Parameters
    ----------
    points : (n, 3) float64
        Polyline vertices (n >= 2).
    edge_guides : (n - 1, 3) float64
        Unit guide of each edge ``e_i = (p_i, p_{i+1})``, orthogonal to it, in the bisector
        plane of its two sides.
    lam : float
        Weight of the pull towards the mean edge guide.

    Returns
    -------
    (n, 3) float64
        Unit vertex guides. End vertices take their edge's guide. Interior vertices minimise
        ``sum_e (g . b_e)^2 + lam |g - mean_e g_e|^2`` with ``b_e = g_e x e / |e|`` the normal
        of edge e's bisector plane, then normalise: ``g = lam (B + lam I)^-1 mean g_e``,
        ``B = sum b_e b_e^T``.

    Notes
    -----
    Deviation: the paper's energy uses ``|g . b_e|`` and ``|g - mean|`` on the unit sphere;
    the squared relaxation has this closed form and the same minimiser when the bisector
    planes meet in a line (the case the paper targets).
    """
    p = np.asarray(points, dtype=np.float64)
    ge = _unit(edge_guides)
    n = len(p)
    if n < 2 or ge.shape != (n - 1, 3):
        raise ValueError(f"need n >= 2 points and (n - 1, 3) edge guides, got {p.shape}, "
                         f"{ge.shape}")
    # sign consistency along the polyline (the strip must not twist)
    for i in range(1, n - 1):
        if ge[i] @ ge[i - 1] < 0:
            ge[i] = -ge[i]
    e = _unit(np.diff(p, axis=0))
    b = _unit(np.cross(ge, e))  # (n-1, 3) bisector-plane normals
    out = np.empty((n, 3))
    out[0], out[-1] = ge[0], ge[-1]
    if n > 2:
        mean = 0.5 * (ge[:-1] + ge[1:])  # (n-2, 3)
        bb = (b[:-1, :, None] * b[:-1, None, :]) + (b[1:, :, None] * b[1:, None, :])
        mat = bb + lam * np.eye(3)[None]
        g = np.linalg.solve(mat, lam * mean[..., None])[..., 0]
        out[1:-1] = g
    return _unit(out)


def _tangents(p):
    d = np.diff(p, axis=0)
    return _unit(d)


def stroke_guides_from_mesh(points, vertices, faces, *, radius: float) -> np.ndarray:
    """Per-edge guides of a stroke from the surface normals on both of its sides.

    Parameters
    ----------
    points : (n, 3) float64
        Stroke polyline.
    vertices : (V, 3) float64, faces : (F, 3) int
        The current surface (e.g. the flow-aligned fit), consistently oriented.
    radius : float
        Faces whose centroid lies within ``radius`` of an edge midpoint contribute.

    Returns
    -------
    (n - 1, 3) float64
        Unit guides ``n1 + n2`` made orthogonal to the edge, where n1, n2 are the mean unit
        normals of the two sides (2-means of the face normals whose centroids lie within
        ``radius`` of the edge midpoint). For a crease this is the bisector of the two sides,
        pointing outside (Appendix A); a rounded surface gives the same direction. Where the
        two sides cancel the normal of the nearest face is used.
    """
    p = np.asarray(points, dtype=np.float64)
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    tri = v[f]
    cen = tri.mean(1)
    fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])  # area-weighted normals
    area = np.linalg.norm(fn, axis=1)
    tree = cKDTree(cen)
    mid = 0.5 * (p[1:] + p[:-1])
    t = _tangents(p)
    lists = tree.query_ball_point(mid, radius)
    _, nearest = tree.query(mid)
    out = np.empty((len(mid), 3))
    unit_fn = _unit(fn)
    for i, li in enumerate(lists):  # one small clustering per stroke edge (not per point)
        g = _two_sided_mean(unit_fn[li], area[li]) if len(li) else unit_fn[nearest[i]]
        g = g - (g @ t[i]) * t[i]
        if np.linalg.norm(g) < 1e-3:  # both sides cancel (a sheet folded flat): nearest face
            g = unit_fn[nearest[i]] - (unit_fn[nearest[i]] @ t[i]) * t[i]
        out[i] = g
    return _unit(out)


def _two_sided_mean(normals, weights, iters: int = 8):
    """Sum of the unit mean normals of the two sides (2-means on the normals).

    Seeded with the two most different normals; each side counts once whatever its number
    of faces, so an uneven triangulation does not tilt the bisector.
    """
    dots = normals @ normals.T
    i, j = np.unravel_index(np.argmin(dots), dots.shape)
    if dots[i, j] > 0.999:  # one side only (flat): its mean normal
        return (weights[:, None] * normals).sum(0)
    a, b = normals[i], normals[j]
    for _ in range(iters):
        side = (normals @ a) >= (normals @ b)
        if side.all() or not side.any():
            break
        a = _unit((weights[side, None] * normals[side]).sum(0))
        b = _unit((weights[~side, None] * normals[~side]).sum(0))
    return a + b


def strip_from_polyline(points, guides, width: float) -> tuple[np.ndarray, np.ndarray]:
    """Strip surface along a polyline: each vertex offset by ``+-width`` along its guide.

    Parameters
    ----------
    points : (n, 3) float64
    guides : (n, 3) float64
        Unit vertex guides (see :func:`guide_directions`).
    width : float
        Half-width w of the strip (Appendix A).

    Returns
    -------
    vertices : (2n, 3) float64
        ``points - w g`` (rows 0..n-1) then ``points + w g``.
    triangles : (2(n - 1), 3) int64
        Two triangles per polyline edge.
    """
    p = np.asarray(points, dtype=np.float64)
    g = _unit(guides)
    if p.shape != g.shape or p.ndim != 2 or len(p) < 2:
        raise ValueError(f"points and guides must both be (n >= 2, d), got {p.shape}, {g.shape}")
    if not (width > 0):
        raise ValueError(f"width must be positive, got {width!r}")
    n = len(p)
    verts = np.concatenate([p - width * g, p + width * g])
    i = np.arange(n - 1)
    tris = np.concatenate([np.stack([i, i + 1, n + i], 1), np.stack([i + 1, n + i + 1, n + i], 1)])
    return verts, tris.astype(np.int64)


def segment_strip_2d(corner, direction, width: float, *, pieces: int = 2
                     ) -> tuple[np.ndarray, np.ndarray]:
    """2D analogue of a strip: a segment through ``corner`` along ``direction``, ``+-width``.

    Parameters
    ----------
    corner : (2,) float64
        The crease point (a corner of a planar curve).
    direction : (2,) float64
        Guide (the corner's angle bisector).
    width : float
        Half-length.
    pieces : int
        Number of segments.

    Returns
    -------
    vertices : (pieces + 1, 2) float64, segments : (pieces, 2) int64
    """
    c = np.asarray(corner, dtype=np.float64)
    d = _unit(direction)
    s = np.linspace(-width, width, pieces + 1)
    verts = c[None] + s[:, None] * d[None]
    segs = np.stack([np.arange(pieces), np.arange(1, pieces + 1)], 1)
    return verts, segs.astype(np.int64)


def _resample(p, step):
    """Equal arc-length pieces of at most ``step`` (one piece for a zero-length stroke)."""
    return resample_polyline(p, max(1, math.ceil(arc_length(p) / step)))


def _stroke_graph(strokes, tol):
    """End points merged within ``tol`` -> (edges (m, 2)) for the edge colouring."""
    ends = np.concatenate([[s[0], s[-1]] for s in strokes])
    tree = cKDTree(ends)
    pairs = tree.query_pairs(tol, output_type="ndarray")
    parent = np.arange(len(ends))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b in pairs:
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    roots = np.array([find(i) for i in range(len(ends))])
    _, ids = np.unique(roots, return_inverse=True)
    return ids.reshape(-1, 2)


def _extend(p, length):
    """Polyline extended at both ends by ``length`` along its end tangents."""
    if length <= 0:
        return p
    a = _unit(p[0] - p[min(2, len(p) - 1)])
    b = _unit(p[-1] - p[max(len(p) - 3, 0)])
    return np.concatenate([[p[0] + length * a], p, [p[-1] + length * b]])


def crease_feature_set(strokes, vertices, faces, *, width: float, spacing: float,
                       guide_radius: float, junction_tol: float | None = None,
                       extend: float | None = None):
    """Strips along crease strokes, guided by the surface, split into channels.

    Parameters
    ----------
    strokes : list of (n_i, 3) float64
        Crease strokes (same coordinates as the mesh).
    vertices, faces : the current surface.
    width : float
        Strip half-width.
    spacing : float
        Resampling step along the strokes (strip element size).
    guide_radius : float
        Neighbourhood of :func:`stroke_guides_from_mesh`.
    junction_tol : float, optional
        Stroke ends closer than this meet at a junction (default ``2 * spacing``).
    extend : float, optional
        Each stroke is prolonged by this much along its end tangents (default ``width``):
        the gradient of a feature function is log-singular on the strip's border dM, so the
        strip's ends must not cross the surface at corners or at gaps of split strokes.

    Returns
    -------
    verts : (k, 3) float64, tris : (m, 3) int64, channels : (m,) int64
        All strips; each stroke's triangles get the colour of the stroke in the stroke graph
        (strokes meeting at a junction get different channels, Sec. 3.3).
    """
    if not strokes:
        raise ValueError("crease_feature_set needs at least one crease stroke")
    from .sharpnet import edge_coloring

    tol = 2.0 * spacing if junction_tol is None else junction_tol
    colors = edge_coloring(_stroke_graph(strokes, tol), junctions_only=True)
    vs, ts, cs = [], [], []
    base = 0
    for k, s in enumerate(strokes):
        p = _resample(_extend(np.asarray(s, dtype=np.float64),
                              width if extend is None else extend), spacing)
        if len(p) < 2:
            continue
        ge = stroke_guides_from_mesh(p, vertices, faces, radius=guide_radius)
        g = guide_directions(p, ge)
        v, t = strip_from_polyline(p, g, width)
        vs.append(v)
        ts.append(t + base)
        cs.append(np.full(len(t), colors[k], dtype=np.int64))
        base += len(v)
    return np.concatenate(vs), np.concatenate(ts), np.concatenate(cs)


# ---------------------------------------------------------------------------------------------
# crease refinement
# ---------------------------------------------------------------------------------------------
def _sample_mesh(v, f, n, rng):
    """``n`` area-uniform points ``(n, 3)`` on the mesh and the unit normals of their faces."""
    normals, areas = face_normals_areas(v, f)
    pts, fid = sample_surface(v, f, n, rng, areas=areas)
    return pts, normals[fid]


def _check_inputs(vertices, faces, strokes, labels):
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    if v.ndim != 2 or v.shape[1] != 3 or len(v) < 3 or not np.isfinite(v).all():
        raise ValueError(f"vertices must be a finite (V >= 3, 3) array, got shape {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3 or len(f) == 0 or f.min() < 0 or f.max() >= len(v):
        raise ValueError(f"faces must be a non-empty (F, 3) index array into vertices, "
                         f"got shape {f.shape}")
    st, lab = check_strokes(list(strokes), labels, default_label="crease")
    return v, f, st, lab


def crease_refine(vertices, faces, strokes, labels=None, *, quality: str = "draft",
                  device="cpu", seed: int = 0, progress: bool = True, **overrides
                  ) -> MeshResult:
    """Refit a surface as a SharpNet SDF with true creases along the crease strokes.

    Parameters
    ----------
    vertices : (V, 3) float64, faces : (F, 3) int
        The current surface (e.g. :func:`neural.flow.fit_flow_surface`'s result, or a
        classical mesh), world coordinates, consistently oriented (outward normals give an
        SDF that is positive outside).
    strokes : list of (n_i, 3) float64
        The sketch's strokes (world coordinates).
    labels : list of str, optional
        Per stroke ``'boundary'``, ``'crease'`` or ``'construction'`` (ignored); default all
        ``'crease'``.
    quality : {"draft", "default", "paper"}
        Preset (:data:`CREASE_PRESETS`).
    device : str
        ``"cpu"`` or ``"cuda"``.
    seed : int
        Seeds network initialisation and sampling (CPU runs are reproducible).
    progress : bool
        tqdm bar with the loss.
    **overrides
        Any :class:`CreaseConfig` field.

    Returns
    -------
    MeshResult
        The marching-cubes zero set of the fitted SDF in world coordinates; ``report`` has
        ``timings`` (seconds: ``setup``, ``train``, ``extract``), ``n_strip_triangles``,
        ``n_channels``, ``final_loss``, ``config``, ``interrupted``, ``seed``, ``device``.

    Raises
    ------
    ValueError
        Bad arrays, labels, preset, setting or device.

    Notes
    -----
    Method: data in a unit frame ([-0.8, 0.8]^3); strips M along the crease strokes
    (:func:`crease_feature_set`, guides from the input's normals), mollified feature functions
    (Eq. 6) split by the colouring of the stroke graph; a SharpNet trained with the losses of
    Eq. 9 (surface |Phi| on input samples and stroke points, exterior exp(-alpha |Phi|) on
    uniform samples, Eikonal on surface + near-surface samples, normal alignment on input
    samples). Input samples within ``exclude`` of a crease stroke are dropped, because the
    input is rounded there; the strokes pin the crease. With no crease stroke the fit runs
    without features (a plain SDF refit).

    Ctrl-C during training stops it (:func:`neural.training.train`) and extracts the
    current network (``report["interrupted"]``). The deviations from the paper are listed
    in the module notes.

    Examples
    --------
    >>> import trimesh
    >>> box = trimesh.creation.box().subdivide().subdivide()
    >>> c = box.vertices[:8]                         # the corners of the unsubdivided box
    >>> edges = [np.linspace(c[a], c[b], 20) for a in range(8) for b in range(a + 1, 8)
    ...          if np.count_nonzero(c[a] != c[b]) == 1]
    >>> res = crease_refine(box.vertices, box.faces, edges, ["crease"] * len(edges),
    ...                     progress=False)                              # doctest: +SKIP
    """
    import torch

    from .sharpnet import SharpNet

    cfg = crease_config(quality, overrides)
    v, f, st, lab = _check_inputs(vertices, faces, strokes, labels)
    dev = torch_device(device)
    t_start = time.perf_counter()
    gen, rng = seeded(seed)
    dtype = torch.float32

    centre, scale = _unit_frame(v, st, lab)
    vu = (v - centre) / scale
    creases = [(s - centre) / scale for s, lb in zip(st, lab) if lb == "crease"]
    others = [(s - centre) / scale for s, lb in zip(st, lab) if lb == "boundary"]
    feats = _crease_features(cfg, creases, vu, f)
    pools, spts = _sample_pools(cfg, vu, f, creases, others, feats, rng, dev, dtype)
    t_setup = time.perf_counter() - t_start

    net = SharpNet(3, feats, hidden=cfg.hidden, layers=cfg.layers, n_freqs=cfg.n_freqs,
                   activation=cfg.activation,
                   geometric_init=cfg.geometric_init)
    # the pools carry the feature values; the feature set stays on the host in float64 and
    # is only used again for extraction (moving it with the network would cast it to float32)
    net.features = None
    net = net.to(dev, dtype)

    t0 = time.perf_counter()
    run = train(net.parameters(), [Stage("refit", cfg.steps, _refit_step(net, cfg, pools, gen))],
                lr=cfg.lr, schedule="cosine", lr_min=0.05 * cfg.lr, progress=progress,
                desc="crease refine")
    t_train = time.perf_counter() - t0

    t1 = time.perf_counter()
    mv_, mf_ = _extract_sdf(net, feats, cfg, dev, dtype)
    mv_, mf_ = _trim_to_input(mv_, mf_, vu, f, spts, rng, cfg.keep_tol)
    t_extract = time.perf_counter() - t1
    report = {
        "timings": {"setup": t_setup, "train": t_train, "extract": t_extract,
                    "total": time.perf_counter() - t_start},
        "n_strip_triangles": int(len(feats.elements)) if feats is not None else 0,
        "n_channels": int(feats.n_channels) if feats is not None else 0,
        "n_crease_strokes": len(creases),
        "final_loss": run.log.get("loss", float("nan")),
        "interrupted": run.interrupted,
        "quality": quality,
        "seed": int(seed),
        "device": str(dev),
        "config": asdict(cfg),
        "frame": {"centre": centre.tolist(), "scale": scale},
    }
    return MeshResult(mv_ * scale + centre, mf_, report)


def _unit_frame(v, strokes, labels):
    """``(centre (3,), scale)`` mapping the mesh and the used strokes into [-0.8, 0.8]^3."""
    used = [s for s, lb in zip(strokes, labels) if lb != "construction"]
    allp = np.concatenate([v] + used) if used else v
    lo, hi = allp.min(0), allp.max(0)
    return 0.5 * (lo + hi), max(float((hi - lo).max()) / 1.6, ZERO_LENGTH)


def _crease_features(cfg: CreaseConfig, creases, vu, f):
    """The SharpNet feature set of the crease strips (float64, host), or None."""
    if not (cfg.use_features and creases):
        return None
    import torch

    from .sharpnet import FeatureSet
    mv, mt, mc = crease_feature_set(creases, vu, f, width=cfg.strip_width,
                                    spacing=cfg.strip_spacing, guide_radius=cfg.guide_radius)
    return FeatureSet(mv, mt, channels=mc, radius=cfg.mollifier_radius,
                      scale=cfg.feature_scale, dtype=torch.float64)


def _sample_pools(cfg: CreaseConfig, vu, f, creases, others, feats, rng, dev, dtype):
    """Training samples drawn once, with their feature values and gradients.

    Returns
    -------
    pools : dict
        ``surface``, ``strokes`` (or None), ``near``, ``ambient``: ``(x, f0, grad f0)``
        tensors (:func:`_with_features`); ``normals`` (P, 3) of the surface samples;
        ``near_target`` (N,), the value target of the near-surface samples.
    spts : (K, 3) float64
        The stroke points (unit frame).
    """
    import torch
    sp, sn = _sample_mesh(vu, f, cfg.pool, rng)
    stroke_pts = [_resample(s, 0.25 * cfg.strip_spacing) for s in creases + others]
    if creases:
        cpts = np.concatenate([_resample(s, 0.25 * cfg.strip_spacing) for s in creases])
        dmin, _ = cKDTree(cpts).query(sp)
        keep = dmin > cfg.exclude
        sp, sn = sp[keep], sn[keep]
    spts = np.concatenate(stroke_pts) if stroke_pts else np.zeros((0, 3))
    n_near = cfg.pool
    near = sp[rng.integers(0, len(sp), n_near)] + rng.normal(scale=cfg.near_sigma,
                                                             size=(n_near, 3))
    # point-to-plane distance to the nearest kept input sample: the input's signed distance
    # away from the creases, the extrapolated side planes (a sharp SDF) near them
    _, jn = cKDTree(sp).query(near)
    near_target = torch.tensor(((near - sp[jn]) * sn[jn]).sum(1), dtype=dtype, device=dev)
    amb = rng.uniform(-1.0, 1.0, size=(cfg.pool, 3))
    pools = {"surface": _with_features(feats, sp, dev, dtype),
             "normals": torch.tensor(sn, dtype=dtype, device=dev),
             "strokes": _with_features(feats, spts, dev, dtype) if len(spts) else None,
             "near": _with_features(feats, near, dev, dtype),
             "near_target": near_target,
             "ambient": _with_features(feats, amb, dev, dtype)}
    return pools, spts


def _with_features(feats, x, dev, dtype, chunk: int = 20000):
    """``(x, f0, grad f0)`` tensors on ``dev``: points, feature values (B, C), gradients (B, C, 3).

    Features are evaluated exactly in float64 on the host; ``f0, grad f0`` are None without
    features.
    """
    import torch
    xt = torch.tensor(x, dtype=torch.float64)
    if feats is None:
        return xt.to(dev, dtype), None, None
    fs, gs = [], []
    for s in range(0, len(xt), chunk):
        xc = xt[s:s + chunk].clone().requires_grad_(True)
        fv = feats(xc)  # (B, C)
        if fv.requires_grad:
            g = torch.stack([torch.autograd.grad(fv[:, c].sum(), xc, retain_graph=True)[0]
                             for c in range(fv.shape[1])], 1)  # (B, C, 3)
        else:  # no strip element near any point of this chunk: f = 0, grad f = 0
            g = torch.zeros(fv.shape + (3,), dtype=fv.dtype)  # (B, C, 3)
        fs.append(fv.detach())
        gs.append(g.detach())
    return (xt.to(dev, dtype), torch.cat(fs).to(dev, dtype), torch.cat(gs).to(dev, dtype))


def _phi(net, n_freqs, pool, idx):
    """SDF values (B,) and gradients (B, 3) at ``pool[idx]`` (linearised features)."""
    import torch

    from .sharpnet import positional_encoding
    x, f0, g0 = pool
    xb = x[idx].clone().requires_grad_(True)  # (B, 3)
    inp = positional_encoding(xb, n_freqs)
    if f0 is not None:
        lin = f0[idx] + torch.einsum("bcd,bd->bc", g0[idx], xb - xb.detach())
        inp = torch.cat([inp, lin], -1)
    out = net.mlp(inp)[:, 0]
    (grad,) = torch.autograd.grad(out.sum(), xb, create_graph=True)
    return out, grad


def _refit_step(net, cfg: CreaseConfig, pools, gen):
    """Step function of the refit: the losses of Eq. 9 plus the near-surface value term."""
    import torch
    dev = pools["near_target"].device
    pool_s, pool_k, pool_near, pool_a = (pools[k] for k in ("surface", "strokes", "near",
                                                             "ambient"))
    nb = cfg.batch
    nk = int(round(cfg.stroke_weight * nb)) if pool_k is not None else 0
    ns = nb - nk

    def step(k):
        i_s = torch.randint(0, len(pool_s[0]), (ns,), generator=gen).to(dev)
        i_n = torch.randint(0, len(pool_near[0]), (nb,), generator=gen).to(dev)
        i_a = torch.randint(0, len(pool_a[0]), (nb,), generator=gen).to(dev)
        ps, gs_ = _phi(net, cfg.n_freqs, pool_s, i_s)
        pn, gn = _phi(net, cfg.n_freqs, pool_near, i_n)
        l_sdf = (pn - pools["near_target"][i_n]).abs().mean()
        pa, _ = _phi(net, cfg.n_freqs, pool_a, i_a)
        l_sur = ps.abs().mean()
        if nk:
            i_k = torch.randint(0, len(pool_k[0]), (nk,), generator=gen).to(dev)
            pk, gk = _phi(net, cfg.n_freqs, pool_k, i_k)
            l_sur = (ns * l_sur + nk * pk.abs().mean()) / nb
            geik = torch.cat([gs_, gn, gk])
        else:
            geik = torch.cat([gs_, gn])
        l_ext = torch.exp(-cfg.ext_alpha * pa.abs()).mean()
        l_ekl = (1.0 - geik.norm(dim=-1)).abs().mean()
        l_nor = (gs_ - pools["normals"][i_s]).norm(dim=-1).mean()
        loss = (cfg.w_sur * l_sur + cfg.w_ext * l_ext + cfg.w_ekl * l_ekl
                + cfg.w_nor * l_nor + cfg.w_sdf * l_sdf)
        return Step(loss, {"loss": float(loss.detach())})

    return step


def _extract_sdf(net, feats, cfg: CreaseConfig, dev, dtype):
    """Marching cubes of the network's zero set on ``cfg.res``^3 nodes over [-1, 1]^3.

    The features are evaluated exactly (not linearised) at the grid nodes.
    """
    import torch

    from .extract import marching_cubes_world
    from .feature import mollified_feature_function
    from .sharpnet import positional_encoding
    n = cfg.res
    axis = np.linspace(-1.0, 1.0, n)
    grid = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), -1).reshape(-1, 3)
    vals = np.empty(len(grid), dtype=np.float32)
    with torch.no_grad():
        chunk = 1 << 17
        for s in range(0, len(grid), chunk):
            xg = torch.tensor(grid[s:s + chunk], dtype=torch.float64)
            z = positional_encoding(xg, cfg.n_freqs)
            if feats is not None:
                fv = mollified_feature_function(xg, feats.vertices, feats.elements,
                                                radius=feats.radius, channels=feats.channels,
                                                n_channels=feats.n_channels) * feats.scale
                z = torch.cat([z, fv], -1)
            vals[s:s + chunk] = net.mlp(z.to(dev, dtype))[:, 0].cpu().numpy()
    return marching_cubes_world(vals.reshape(n, n, n), np.full(3, -1.0), 2.0 / (n - 1))


def _trim_to_input(mv, mf, vu, f, spts, rng, keep_tol):
    """Drop faces farther than ``keep_tol`` from the input surface and the stroke points."""
    if not len(mf):
        return mv, mf
    ref = np.concatenate([_sample_mesh(vu, f, 50000, rng)[0], spts]) if len(spts) else \
        _sample_mesh(vu, f, 50000, rng)[0]
    dist, _ = cKDTree(ref).query(mv[mf].mean(1))
    mf = mf[dist < keep_tol]
    usedv = np.unique(mf)
    remap = np.full(len(mv), -1, dtype=np.int64)
    remap[usedv] = np.arange(len(usedv))
    return mv[usedv], remap[mf]
