"""Rough redraws in which every ring is one stroke drawn past, or short of, its own start.

The noise class of issue 33, written apart from :func:`curvenet.datasets.redraw.rough_sketch`
(one stroke per network edge) and from the snapping it tests. It imitates a
designer in VR who draws each smooth closed curve of a network (a parallel or a
meridian loop of a sphere, a rim of a cylinder, a ring of a torus) in one go:

* **Smooth chains.** At every vertex the incident curve ends that continue each
  other within :data:`SMOOTH_TURN` degrees are paired, straightest first; paired
  edges are drawn as one stroke. A chain that comes back to where it began is a
  ring; the others are open (a ruling from rim to rim, a box edge).
* **Rings start anywhere.** Each ring stroke starts at a uniformly random point
  of the ring, in a random direction of travel.
* **Past the start** (probability ``past``): the stroke carries on past its start
  by ``U(0, overshoot)`` of the ring's length, running back along its own
  beginning. The hand drifts sideways as it comes round: the lateral offset
  grows from 0 to ``x0`` over the last ``U(3%, 10%)`` of the lap (the stroke
  passes its start ``|x0|`` away, ``U(0, gap)`` times the diagonal, in a random
  direction across the ring there) and changes by a random ``d`` (also across the
  ring at its start) over the overlap, the offset staying within ``gap``. Both
  changes are smoothsteps, meeting with zero slope where the stroke passes its
  start: the first no steeper than :data:`_DRIFT` (15 degrees; its stretch is
  lengthened where needed), ``|d|`` at most :data:`_DRIFT` times the overlap (no
  steeper than 22 degrees).
* **Short of the start** (otherwise): the stroke stops ``U(0, gap)`` times the
  diagonal short of its start along the ring, drifted sideways (as above) by up to
  half that.
* **Splits.** With probability ``split`` a chain is drawn in two pieces, cut at a
  random place at least 5% of the diagonal from either end, with a gap of
  ``U(0, gap)`` times the diagonal; a ring's tail then runs over its first piece.
* **End errors.** Open chains start and end ``U(-ends, ends)`` times the diagonal
  past or short of their end vertices (extrapolated along the end tangent).
* **Wobble.** A cubic spline through random offsets at knots every ``U(4%,
  12%)`` of the diagonal along the stroke, scaled to a peak of ``U(0.5, 1)`` times
  ``wobble`` times the diagonal; points every ``U(0.4%, 1.2%)`` of the diagonal.
* Random stroke order and direction.

With ``gap=0.015`` every end error and drift stays within the default snapping
tolerance (2.5% of the diagonal) less the wobble; ``gap=0.04`` is the wide
variant (ends up to 2.7 times farther), for the automatic tolerance.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from ..core.errors import InvalidParameterError
from ..core.geometry import cumulative_length, interpolate_polyline
from ..core.tolerances import DIVISION_GUARD
from ..model.network import CurveNetwork
from ..model.sketch import Sketch

__all__ = ["SMOOTH_TURN", "smooth_chains", "loop_sketch"]

#: Largest turn (degrees) between two curve ends at a vertex that one stroke goes through.
SMOOTH_TURN = 30.0
#: Shortest piece of a split stroke, fraction of the diagonal.
_MIN_PIECE = 0.05
#: Steepest sideways drift of the hand coming round to its start, as the largest slope of
#: the lateral offset along the ring (1.5 times the mean slope of a smoothstep): about 15
#: degrees; the change over the overlap is at most this times its length.
_DRIFT = 0.27


def _leaving(curve, at_start):
    """Unit direction ``(3,)`` leaving a curve end, over the first 5% of its length."""
    c = curve if at_start else curve[::-1]
    cum = cumulative_length(c)
    v = interpolate_polyline(c, np.array([0.05 * cum[-1]]), cum=cum)[0] - c[0]
    return v / max(np.linalg.norm(v), DIVISION_GUARD)  # guard: zero-length curve


def smooth_chains(network: CurveNetwork, max_turn: float = SMOOTH_TURN) -> list:
    """The network's curves joined through the vertices they pass smoothly.

    Parameters
    ----------
    network : CurveNetwork
    max_turn : float
        Largest turn, in degrees, between two curve ends paired at a vertex.

    Returns
    -------
    list of (polyline, closed, label)
        ``polyline`` ``(n, 3) float64`` runs through the chain's edges in order;
        ``closed`` says whether it comes back to its first point (its first and
        last points are then equal); ``label`` is ``"crease"`` if any of its
        edges is one, else ``"boundary"``.

    Notes
    -----
    At each vertex the pairs of incident ends (of different edges) are taken
    straightest first while both ends are free: deterministic, no random numbers.
    Chains are listed in the order of their first edge id.
    """
    ends = {}
    for e_id, e in enumerate(network.edges):
        ends.setdefault(e.u, []).append((e_id, True))
        ends.setdefault(e.v, []).append((e_id, False))
    limit = np.cos(np.radians(180.0 - max_turn))
    partner = {}
    for lst in ends.values():
        dirs = np.array([_leaving(network.edges[e].curve, at) for e, at in lst])
        cos = dirs @ dirs.T
        x, y = np.triu_indices(len(lst), 1)
        ok = cos[x, y] <= limit  # leaving in opposite directions: the curve goes through
        for q in np.flatnonzero(ok)[np.argsort(cos[x, y][ok], kind="stable")]:
            p, r = lst[x[q]], lst[y[q]]
            if p[0] != r[0] and p not in partner and r not in partner:
                partner[p], partner[r] = r, p
    seen, out = set(), []
    for e_id in range(len(network.edges)):
        if e_id in seen:
            continue
        # walk back to a free end (or once round a ring), then forward
        e0, fwd0, visited = e_id, True, {e_id}
        while (back := partner.get((e0, fwd0))) is not None and back[0] not in visited:
            e0, fwd0 = back[0], not back[1]
            visited.add(e0)
        parts, labels, e, fwd = [], [], e0, fwd0
        while e not in seen:
            seen.add(e)
            c = network.edges[e].curve
            parts.append(c if fwd else c[::-1])
            labels.append(network.edges[e].label)
            nxt = partner.get((e, not fwd))
            if nxt is None:
                break
            e, fwd = nxt[0], nxt[1]
        poly = np.vstack([parts[0]] + [p[1:] for p in parts[1:]])
        closed = bool(np.linalg.norm(poly[0] - poly[-1]) <= 1e-9 * network.diagonal)
        out.append((poly, closed, "crease" if "crease" in labels else "boundary"))
    return out


def _across(rng, tangent, size):
    """A random offset ``(3,)`` of norm ``size`` perpendicular to the unit ``tangent``."""
    v = rng.normal(size=3)
    v -= (v @ tangent) * tangent
    return size * v / max(np.linalg.norm(v), DIVISION_GUARD)  # guard: v along the tangent


def _smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


class _Pen:
    """Draws strokes along one chain: arc-length lookups (wrapping round a ring) and wobble."""

    def __init__(self, rng, poly, closed, diag, wobble):
        self.rng, self.closed, self.diag, self.wobble = rng, closed, diag, wobble
        self.poly, self.cum = poly, cumulative_length(poly)
        self.L = self.cum[-1]

    def at(self, s):
        """Points ``(m, 3)`` and unit tangents ``(m, 3)`` at arc parameters ``s``."""
        s = np.mod(s, self.L) if self.closed else s
        eps = 1e-4 * self.L
        p = interpolate_polyline(self.poly, s, cum=self.cum, extrapolate=not self.closed)
        lo = s - eps if not self.closed else np.mod(s - eps, self.L)
        hi = s + eps if not self.closed else np.mod(s + eps, self.L)
        t = (interpolate_polyline(self.poly, hi, cum=self.cum, extrapolate=not self.closed)
             - interpolate_polyline(self.poly, lo, cum=self.cum, extrapolate=not self.closed))
        return p, t / np.maximum(np.linalg.norm(t, axis=1, keepdims=True), DIVISION_GUARD)

    def stroke(self, s0, s1, drift=None):
        """Points ``(n, 3)`` from arc parameter ``s0`` to ``s1``, wobbled; ``drift(s)`` adds an
        offset ``(n, 3)`` (the hand coming round beside a ring's start)."""
        rng, diag = self.rng, self.diag
        n = max(6, int(abs(s1 - s0) / (rng.uniform(0.004, 0.012) * diag)) + 1)
        s = np.linspace(s0, s1, n)
        pts = self.at(s)[0]
        if drift is not None:
            pts = pts + drift(s)
        knots = max(4, int(abs(s1 - s0) / (rng.uniform(0.04, 0.12) * diag)) + 2)
        u = np.linspace(0.0, 1.0, knots)
        off = CubicSpline(u, rng.normal(size=(knots, 3)))(np.linspace(0.0, 1.0, n))
        peak = max(np.linalg.norm(off, axis=1).max(), DIVISION_GUARD)  # guard: all-zero draw
        return pts + off * (self.wobble * diag * rng.uniform(0.5, 1.0) / peak)


def _ring_strokes(rng, pen, diag, gap, overshoot, past, split):
    """One ring drawn from a random start, past or short of it, maybe in two pieces."""
    L = pen.L
    s0 = rng.uniform(0.0, L)
    if rng.random() < past:
        o = rng.uniform(0.0, overshoot) * L
        end = s0 + L + o
        e0s = rng.uniform(0.0, gap) * diag
        ds = rng.uniform(0.0, min(_DRIFT * o, gap * diag - e0s))
    else:
        o = ds = 0.0
        end = s0 + L - rng.uniform(0.0, gap) * diag
        e0s = rng.uniform(0.0, 0.5 * gap) * diag
    # the stretch over which the hand drifts off the ring before it passes the start
    r = min(max(rng.uniform(0.03, 0.10) * L, 1.5 * e0s / _DRIFT), 0.5 * L)
    # fixed offsets across the ring where the stroke passes its start (re-projecting them
    # along the ring would swing them round where a random direction nears the tangent)
    t0 = pen.at(np.array([s0]))[1][0]
    x0, d = (_across(rng, t0, size) for size in (e0s, ds))

    def drift(s):
        # lateral offset: 0 -> x0 over [s0 + L - r, s0 + L], then x0 -> x0 + d over the overlap
        a = _smoothstep((s - (s0 + L - r)) / r)[:, None]
        b = (_smoothstep((s - (s0 + L)) / o) if o > 0 else np.zeros(len(s)))[:, None]
        return a * x0 + b * d

    return [pen.stroke(lo, hi, drift) for lo, hi in _split(rng, s0, end, diag, gap, split)]


def _split(rng, s0, s1, diag, gap, split):
    """Arc intervals of one chain's strokes: one, or two around a gap of ``U(0, gap)``."""
    if rng.random() < split and s1 - s0 > 2.0 * _MIN_PIECE * diag + gap * diag:
        g = rng.uniform(0.0, gap) * diag
        m = rng.uniform(s0 + _MIN_PIECE * diag + 0.5 * g, s1 - _MIN_PIECE * diag - 0.5 * g)
        return [(s0, m - 0.5 * g), (m + 0.5 * g, s1)]
    return [(s0, s1)]


def loop_sketch(network: CurveNetwork, *, seed: int, gap: float = 0.015, ends: float = 0.012,
                overshoot: float = 0.10, past: float = 0.6, split: float = 0.25,
                wobble: float = 0.003) -> Sketch:
    """Re-draw a clean network with rings drawn past or short of their start.

    Parameters
    ----------
    network : CurveNetwork
        The clean network.
    seed : int
        Seed of ``numpy.random.default_rng``; same seed, same sketch.
    gap : float
        Largest gap, fraction of the diagonal: a ring's stop short of its start
        and its sideways drift past it, and split gaps.
    ends : float
        Largest run of an open stroke's end past or short of its vertex, fraction
        of the diagonal.
    overshoot : float
        Largest run of a ring past its start, fraction of the ring's length.
    past : float
        Probability that a ring is drawn past its start (else short of it).
    split : float
        Probability that a chain is drawn in two pieces.
    wobble : float
        Peak smooth offset of a stroke from its curve, fraction of the diagonal.

    Returns
    -------
    Sketch
        Strokes ``(n_k, 3) float64`` in random order and direction, labels from
        the edges (``"crease"`` if any edge of the chain is one);
        ``metadata["redraw"]`` records the parameters.

    Examples
    --------
    >>> from curvenet.datasets.shapes import torus
    >>> sk = loop_sketch(torus().network, seed=0)
    >>> len(sk) >= 10   # 6 meridian rings and 4 parallel rings, some split
    True
    """
    for name, v in (("gap", gap), ("ends", ends), ("overshoot", overshoot), ("wobble", wobble)):
        if not (np.isfinite(v) and v >= 0):
            raise InvalidParameterError(f"{name} must be a finite number >= 0, got {v!r}")
    for name, v in (("past", past), ("split", split)):
        if not 0 <= v <= 1:
            raise InvalidParameterError(f"{name} is a probability in [0, 1], got {v!r}")
    if overshoot >= 0.5:
        raise InvalidParameterError(f"overshoot must be under half a lap, got {overshoot!r}")
    rng = np.random.default_rng(seed)
    diag = network.diagonal
    strokes, labels = [], []
    for poly, closed, label in smooth_chains(network):
        if rng.random() < 0.5:
            poly = poly[::-1].copy()
        pen = _Pen(rng, poly, closed, diag, wobble)
        if closed:
            drawn = _ring_strokes(rng, pen, diag, gap, overshoot, past, split)
        else:
            a, b = rng.uniform(-ends, ends, 2) * diag
            drawn = [pen.stroke(lo, hi) for lo, hi in _split(rng, -a, pen.L + b, diag, gap,
                                                              split)]
        strokes += drawn
        labels += [label] * len(drawn)
    order = rng.permutation(len(strokes))
    flip = rng.random(len(strokes)) < 0.5
    out = [strokes[i][::-1].copy() if flip[i] else strokes[i] for i in order]
    return Sketch(out, [labels[i] for i in order],
                  {"redraw": {"model": "loops", "seed": int(seed), "gap": gap, "ends": ends,
                              "overshoot": overshoot, "past": past, "split": split,
                              "wobble": wobble}})
