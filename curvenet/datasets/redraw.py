"""Rough re-drawings of clean curve networks, and a network-matching oracle.

:func:`rough_sketch` imitates a person re-drawing a clean network in VR: every
curve becomes one or more wobbly strokes whose ends over- or undershoot the
junctions, some strokes are broken with small gaps, and some curves are drawn
twice. It is the generator behind the snapping tests (issue 2: "wobble ~0.3%
of the diagonal, end over/undershoot up to 1.5%, strokes split with 1% gaps,
15% overdrawn"), the neural tests and the benchmarks. :func:`match_networks`
checks a snapped network against the clean original.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..core.geometry import arc_length, interpolate_polyline, resample_polyline
from ..core.tolerances import DIVISION_GUARD
from ..core.errors import InvalidParameterError
from ..model.network import CurveNetwork
from ..model.sketch import Sketch

__all__ = ["rough_sketch", "match_networks"]


def _wobble(rng, n, amplitude):
    """Smooth random offsets ``(n, 3)`` with max norm about ``amplitude``.

    A sum of four sine modes per axis (1 to 4 half-periods over the stroke,
    random phases, amplitudes ~ 1/k): low-frequency hand tremor.
    """
    t = np.linspace(0.0, 1.0, n)[:, None]
    k = np.arange(1, 5)[None, :]
    out = np.zeros((n, 3))
    for ax in range(3):
        ph = rng.uniform(0, 2 * np.pi, 4)
        amp = rng.normal(size=4) / k[0]
        out[:, ax] = (amp[None, :] * np.sin(np.pi * k * t + ph[None, :])).sum(axis=1)
    peak = np.linalg.norm(out, axis=1).max()
    return out * (amplitude / max(peak, DIVISION_GUARD))


def _stroke(rng, curve, s0, s1, diag, wobble, spacing):
    """A wobbly stroke along arc parameters ``[s0, s1]`` of ``curve`` (may extrapolate)."""
    n = max(8, int(np.ceil(abs(s1 - s0) / spacing)) + 1)
    pts = interpolate_polyline(curve, np.linspace(s0, s1, n), extrapolate=True)
    return pts + _wobble(rng, n, wobble * diag * rng.uniform(0.5, 1.0))


def rough_sketch(network: CurveNetwork, *, seed: int, wobble: float = 0.003,
                 overshoot: float = 0.015, gap: float = 0.01, overdraw: float = 0.15,
                 split: float = 0.25, samples: int = 40, jitter: float = 0.0) -> Sketch:
    """Re-draw a clean network as rough strokes.

    Parameters
    ----------
    network : CurveNetwork
        The clean network (edge curves).
    seed : int
        Seed of ``numpy.random.default_rng``; same seed, same sketch.
    wobble : float
        Peak smooth offset of a stroke from its curve, fraction of the diagonal.
    overshoot : float
        Each open stroke end moves along the curve by ``U(-overshoot, overshoot)``
        times the diagonal: past the junction (extrapolated along the end
        tangent) or short of it.
    gap : float
        Length of the gap (fraction of the diagonal) where a stroke is split.
    overdraw : float
        Probability that a curve is drawn a second time, over a random 60-100%
        of its length (a full re-draw in half of the cases).
    split : float
        Probability that a curve's stroke is split in two with a ``gap``.
    samples : int
        Points per curve-length stroke (about; shorter pieces get fewer, min 8).
    jitter : float
        Standard deviation of an independent Gaussian offset of every sample (each
        coordinate), fraction of the diagonal: a tracker's or a hand's per-sample
        noise, on top of the smooth wobble. Drawn after everything else, so a seed gives
        the same strokes with and without it.

    Returns
    -------
    Sketch
        Strokes in random order and direction; labels copied from the edges;
        ``metadata["redraw"]`` records the parameters.

    Notes
    -----
    Loop edges (closed curves) keep their ends where they are up to the wobble
    and the over/undershoot, so they are re-drawn as nearly closed strokes.

    Examples
    --------
    >>> from curvenet.datasets.shapes import box
    >>> sk = rough_sketch(box().network, seed=0)
    >>> len(sk) >= 12
    True
    """
    for name, v in (("wobble", wobble), ("overshoot", overshoot), ("gap", gap),
                    ("overdraw", overdraw), ("split", split), ("jitter", jitter)):
        if not (np.isfinite(v) and v >= 0):
            raise InvalidParameterError(f"{name} must be a finite number >= 0, got {v!r}")
    if overdraw > 1 or split > 1:
        raise InvalidParameterError("overdraw and split are probabilities in [0, 1]")
    rng = np.random.default_rng(seed)
    diag = network.diagonal
    strokes, labels = [], []
    for e in network.edges:
        c = e.curve
        L = arc_length(c)
        spacing = L / max(samples - 1, 1)
        a = -rng.uniform(-overshoot, overshoot) * diag
        b = L + rng.uniform(-overshoot, overshoot) * diag
        if rng.random() < split and b - a > 4 * gap * diag:
            m = rng.uniform(a + 0.3 * (b - a), a + 0.7 * (b - a))
            parts = [(a, m - 0.5 * gap * diag), (m + 0.5 * gap * diag, b)]
        else:
            parts = [(a, b)]
        for s0, s1 in parts:
            strokes.append(_stroke(rng, c, s0, s1, diag, wobble, spacing))
            labels.append(e.label)
        if rng.random() < overdraw:
            if rng.random() < 0.5:
                s0 = -rng.uniform(-overshoot, overshoot) * diag
                s1 = L + rng.uniform(-overshoot, overshoot) * diag
            else:
                frac = rng.uniform(0.6, 1.0)
                s0 = rng.uniform(0.0, 1.0 - frac) * L
                s1 = s0 + frac * L
            strokes.append(_stroke(rng, c, s0, s1, diag, wobble, spacing))
            labels.append(e.label)
    order = rng.permutation(len(strokes))
    flip = rng.random(len(strokes)) < 0.5
    out = [strokes[i][::-1].copy() if flip[i] else strokes[i] for i in order]
    if jitter > 0:                                  # drawn last: the strokes stay the same
        out = [st + rng.normal(scale=jitter * diag, size=st.shape) for st in out]
    return Sketch(out, [labels[i] for i in order],
                  {"redraw": {"seed": int(seed), "wobble": wobble, "overshoot": overshoot,
                              "gap": gap, "overdraw": overdraw, "split": split,
                              "jitter": jitter}})


def match_networks(reference: CurveNetwork, result: CurveNetwork, *, tol: float = 0.02,
                   samples: int = 64) -> dict:
    """Compare a snapped network with the clean one it should reproduce.

    Parameters
    ----------
    reference, result : CurveNetwork
    tol : float
        Largest allowed curve distance, fraction of the reference diagonal.
    samples : int
        Points per curve for the distance.

    Returns
    -------
    dict
        ``same_counts`` (equal vertex and edge counts), ``max_distance``
        (over reference curves, the symmetric Hausdorff distance to the
        closest result curve, as a fraction of the diagonal), ``matched``
        (a one-to-one assignment exists: every reference curve's closest
        result curve is distinct), ``ok`` (all three within ``tol``).

    Notes
    -----
    Distances are between curves resampled uniformly in arc length, point to
    point-set; with 64 samples the discretisation adds at most half a sample
    spacing (under 1% of a curve's length).
    """
    diag = reference.diagonal

    def res(c):
        return resample_polyline(c, samples - 1)

    ref = [res(e.curve) for e in reference.edges]
    out = [res(e.curve) for e in result.edges]
    same = (reference.number_of_vertices == result.number_of_vertices
            and reference.number_of_edges == result.number_of_edges)
    if not ref or not out:
        return {"same_counts": same, "max_distance": float("inf"), "matched": False,
                "ok": False}
    owner = np.repeat(np.arange(len(out)), samples)
    big = cKDTree(np.concatenate(out))
    best, worst = [], 0.0
    for r in ref:
        # candidates: the result curves that own the nearest samples of this curve
        _, nn = big.query(r)
        cand = np.unique(owner[nn])
        rt = cKDTree(r)
        d = [max(cKDTree(out[c]).query(r)[0].max(), rt.query(out[c])[0].max()) for c in cand]
        j = int(np.argmin(d))
        best.append(int(cand[j]))
        worst = max(worst, d[j] / diag)
    matched = len(set(best)) == len(best)
    return {"same_counts": bool(same), "max_distance": float(worst), "matched": matched,
            "ok": bool(same and matched and worst <= tol)}
