"""Separately drawn parts of a sketch, each fitted on its own.

One implicit field for the whole sketch joins parts that are drawn apart: the
Poisson integration of g spans the gap between two close bodies with a web or a
fin, which no stroke holds and no term of Eq. 13 charges (two spheres of three great
circles each, a fifth of a radius apart, come out as one bridged body). Zhang et al.
(2025, Fig. 10) compute the coffee machine's body and handle separately for every
method they compare; :func:`stroke_parts` finds such parts and :func:`fit_parts`
fits each on its own and returns the meshes together.

What counts as a part (deviation: the paper splits by hand):

1. strokes closer than the stroke-fidelity tolerance (1 % of the diagonal) touch;
   the touching strokes form groups (connected components);
2. only a drawing whose strokes are connected is split: at least
   :data:`CONNECTED_ENDS` of the stroke ends touch another stroke or their own
   stroke's other end. In a rough sketch strokes end short of each other all
   over one body, so a gap there says nothing about parts;
3. a group is a part when it can bound a volume: at least :data:`PART_MIN_STROKES`
   strokes spanning three dimensions (the smallest principal extent of its points
   at least :data:`PART_MIN_THICKNESS` of the largest). A fin or a flat detail alone
   has no inside, so it and every other group join the part nearest to them.

Each part is fitted on a grid of the same cell size as the whole sketch's (its
``res`` scaled by its longest side, at least :data:`PART_MIN_RES`), with the
Monte-Carlo sample counts scaled to the same density (stroke samples by the
part's share of the stroke length, surface ones by the square of the scale,
volume ones by its cube; at least :data:`PART_MIN_SAMPLES` each), so every
setting given in cells means what it means for the whole sketch. The grids and the
samples of the parts together cost about what the whole's do, but every fit also pays
the per-step cost of the network's backward, which does not shrink with the part.
That cost is mostly Python's (the dispatch of small tensor operations) on a small
part, so :data:`PART_WORKERS` parts are fitted at once, in threads: a small part's
steps run beside the large part's tensor operations. Every fit draws from its own
seeded streams, so the meshes are those of the parts fitted one after the other.

References
----------
Zhang, Wang, Bessmeltsev, "Variational Neural Surfacing of 3D Sketches",
SIGGRAPH Asia 2025, Sec. 6 and Fig. 10 (the coffee machine's parts).
"""

from __future__ import annotations

from dataclasses import fields

import numpy as np

from curvenet.core.fidelity import FIDELITY_TOL_REL
from curvenet.core.geometry import arc_length, bbox_diagonal, densify_polylines

__all__ = ["stroke_parts", "fit_parts", "CONNECTED_ENDS", "PART_MIN_STROKES",
           "PART_MIN_THICKNESS", "PART_MIN_RES", "PART_MIN_SAMPLES", "PART_WORKERS"]

#: Share of stroke ends that must touch another stroke for a drawing to be split.
CONNECTED_ENDS = 0.9
#: Fewest strokes of a part fitted on its own.
PART_MIN_STROKES = 3
#: Smallest principal extent of a part's points, relative to its largest.
PART_MIN_THICKNESS = 0.1
#: Coarsest grid of a part's fit.
PART_MIN_RES = 32
#: Fewest Monte-Carlo samples of each kind per step in a part's fit.
PART_MIN_SAMPLES = 256
#: Parts fitted at once, each in a thread. A small part's fit is mostly the Python side
#: of its steps, which the other fit's tensor operations run beside; more threads
#: would only wait for each other.
PART_WORKERS = 2


def _groups(strokes, tol):
    """Touching strokes: ``(labels (K,) int64, ends_touching (K, 2) bool)``."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree
    pts, counts = densify_polylines(strokes, tol / 2)
    owner = np.repeat(np.arange(len(strokes)), counts)
    pairs = cKDTree(pts).query_pairs(tol, output_type="ndarray")
    a, b = owner[pairs[:, 0]], owner[pairs[:, 1]]
    other = a != b
    k = len(strokes)
    graph = coo_matrix((np.ones(int(other.sum())), (a[other], b[other])), shape=(k, k))
    labels = connected_components(graph, directed=False)[1]
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    last = first + counts - 1
    closed = np.array([np.linalg.norm(s[0] - s[-1]) <= tol for s in strokes])
    touching = np.zeros(len(pts), dtype=bool)       # a point near another stroke's point
    touching[pairs[other].reshape(-1)] = True
    ends = np.stack([touching[first], touching[last]], axis=1) | closed[:, None]
    return labels, ends


def _thick(points) -> bool:
    ext = np.sqrt(np.maximum(np.linalg.eigvalsh(np.cov(points.T)), 0.0))   # ascending
    return bool(ext[0] >= PART_MIN_THICKNESS * ext[-1])


def stroke_parts(strokes) -> list:
    """The separately drawn parts of a sketch (module docstring).

    Parameters
    ----------
    strokes : list of (n_i, 3) float64

    Returns
    -------
    list of (k,) int64 arrays
        Stroke indices of each part, ascending, the part with the most stroke length
        first; every stroke is in exactly one. One part (every stroke) when the
        drawing is not split.

    Examples
    --------
    >>> t = np.linspace(0, 2 * np.pi, 60)
    >>> ring = lambda c, k: c + np.roll(np.c_[np.cos(t), np.sin(t), 0 * t], k, axis=1)
    >>> ball = lambda c: [ring(np.array(c, float), k) for k in range(3)]
    >>> [p.tolist() for p in stroke_parts(ball([0, 0, 0]) + ball([3, 0, 0]))]
    [[0, 1, 2], [3, 4, 5]]
    """
    everything = [np.arange(len(strokes))]
    if len(strokes) < 2 * PART_MIN_STROKES:
        return everything
    tol = FIDELITY_TOL_REL * bbox_diagonal(list(strokes))
    labels, ends = _groups(strokes, tol)
    if labels.max() == 0 or ends.mean() < CONNECTED_ENDS:
        return everything
    groups = [np.flatnonzero(labels == g) for g in range(labels.max() + 1)]
    points = [np.vstack([strokes[i] for i in g]) for g in groups]
    solid = [len(g) >= PART_MIN_STROKES and _thick(p) for g, p in zip(groups, points)]
    if sum(solid) < 2:
        return everything
    from scipy.spatial import cKDTree
    bodies = np.flatnonzero(solid)
    parts = [[groups[i]] for i in bodies]
    body_of = np.repeat(np.arange(len(bodies)), [len(points[i]) for i in bodies])
    tree = cKDTree(np.vstack([points[i] for i in bodies]))
    for g, p, s in zip(groups, points, solid):
        if not s:                                   # to the body nearest to any of its points
            d, j = tree.query(p)
            parts[body_of[j[np.argmin(d)]]].append(g)
    length = np.array([arc_length(s) for s in strokes])
    out = [np.sort(np.concatenate(p)) for p in parts]
    return sorted(out, key=lambda p: -length[p].sum())


def _part_settings(cfg, part_strokes, extent: float, share: float) -> dict:
    """``res`` and sample counts of the fit of one part (module docstring), given the
    whole sketch's longest side ``extent`` and the part's ``share`` of its stroke length."""
    scale = np.ptp(np.vstack(part_strokes), axis=0).max() / extent
    res = int(min(cfg.res, max(PART_MIN_RES, 8 * np.ceil(cfg.res * scale / 8))))
    k = res / cfg.res
    counts = {"n_stroke": cfg.n_stroke * share, "n_surface": cfg.n_surface * k * k,
              "n_volume": cfg.n_volume * k ** 3}
    return {"res": res, **{name: int(max(PART_MIN_SAMPLES, round(n)))
                           for name, n in counts.items()}}


def fit_parts(strokes, labels=None, *, quality: str = "draft", **kwargs):
    """:func:`neural.flow.fit_flow_surface` of each part of :func:`stroke_parts`.

    Parameters
    ----------
    strokes, labels, quality
        As :func:`neural.flow.fit_flow_surface`.
    **kwargs
        Its other arguments (``device``, ``seed``, ``progress``, ``cut_boundary``,
        ``init_mesh``, ``anchors``, ``box``: each part's is the whole sketch's unless
        given) and :class:`neural.presets.FlowConfig` overrides.
        The whole sketch is fitted at once with ``split_parts=0``, and with
        ``init_mesh`` or ``anchors`` (a refinement or a hybrid fill is one surface).

    Returns
    -------
    curvenet.core.MeshResult
        The parts' meshes together. With one part, the
        :class:`neural.flow.FlowResult` itself; with several, ``report`` is the
        largest part's, with ``split`` the list of every part's ``strokes`` (indices
        into the strokes that are not ``construction`` strokes),
        ``settings`` (its ``res`` and sample counts) and ``report``, and the totals
        ``n_vertices``, ``n_faces``, ``open_at_box``, ``rims_closed`` and
        ``interrupted``.
    """
    from curvenet.core.result import MeshResult

    from .flow import fit_flow_surface, fit_strokes
    from .presets import FlowConfig, get_config
    from .rims import strokes_box
    names = {f.name for f in fields(FlowConfig)}
    cfg = get_config(quality, **{k: v for k, v in kwargs.items() if k in names})
    whole = (not cfg.split_parts or kwargs.get("init_mesh") is not None
             or kwargs.get("anchors") is not None)
    if not whole:
        strokes, labels = fit_strokes(strokes, labels)          # construction strokes out
        parts = stroke_parts(strokes)
    if whole or len(parts) == 1:
        return fit_flow_surface(strokes, labels=labels, quality=quality, **kwargs)
    length = np.array([arc_length(s) for s in strokes])
    box = strokes_box(strokes)      # a rim closes on the whole sketch's box, not a part's
    extent = (box[1] - box[0]).max()
    settings = [_part_settings(cfg, [strokes[i] for i in part], extent,
                               length[part].sum() / length.sum()) for part in parts]
    kwargs = {"box": box, **kwargs}
    results = _fit_side_by_side(parts, settings, strokes, labels, quality, kwargs)
    Vs, Fs, split, offset = [], [], [], 0
    for part, setting, res in zip(parts, settings, results):
        if res is None:                         # not started: the others were stopped
            continue
        Vs.append(res.vertices)
        Fs.append(res.faces + offset)
        offset += len(res.vertices)
        split.append({"strokes": part.tolist(), "settings": setting, "report": res.report})
    report = {**split[0]["report"], "split": split, "n_vertices": offset,
              "n_faces": sum(len(f) for f in Fs),
              "open_at_box": sum(s["report"].get("open_at_box", 0) for s in split),
              "rims_closed": sum(s["report"].get("rims_closed", 0) for s in split),
              "interrupted": len(split) < len(parts)
              or any(s["report"]["interrupted"] for s in split)}
    return MeshResult(np.vstack(Vs), np.vstack(Fs), report)


def _fit_side_by_side(parts, settings, strokes, labels, quality, kwargs) -> list:
    """Each part's :func:`neural.flow.fit_flow_surface`, :data:`PART_WORKERS` at a time.

    Returns one result per part, in order (None for a part not started before a Ctrl-C).
    A Ctrl-C stops every running fit at its next step (their best so far is returned,
    ``interrupted``); the parts not yet started are not fitted, except the first (the
    largest), which gives at least the surface of its strokes alone. An error in one part
    stops the others and is raised. Each fit draws from its own seeded streams
    (:data:`neural.training.GLOBAL_STREAM`), so the meshes are those of the parts fitted
    one after the other.
    """
    import threading
    from concurrent.futures import FIRST_EXCEPTION, ThreadPoolExecutor, wait

    from .flow import fit_flow_surface
    stop = threading.Event()

    def fit(k):
        if stop.is_set() and k:
            return None
        return fit_flow_surface([strokes[i] for i in parts[k]], quality=quality,
                                labels=[labels[i] for i in parts[k]],
                                desc=f"neural part {k + 1}/{len(parts)}", stop=stop,
                                **{**kwargs, **settings[k]})

    with ThreadPoolExecutor(min(PART_WORKERS, len(parts))) as pool:
        futures = []
        try:
            for k in range(len(parts)):                       # largest first
                futures.append(pool.submit(fit, k))
            pending = futures
            # in short waits: a Ctrl-C's KeyboardInterrupt is raised when this thread
            # next runs, and a blocking wait might not be woken by the signal
            while pending and not any(f.exception() for f in futures if f.done()):
                pending = wait(pending, timeout=0.1, return_when=FIRST_EXCEPTION).not_done
        except KeyboardInterrupt:
            stop.set()
            if not futures:                    # the largest part still gives a surface
                futures.append(pool.submit(fit, 0))
            wait(futures)
            return ([None if f.exception() else f.result() for f in futures]
                    + [None] * (len(parts) - len(futures)))
        failed = [f.exception() for f in futures if f.done() and f.exception()]
        if failed:
            stop.set()                         # the others stop at their next step
            raise failed[0]
        return [f.result() for f in futures]
