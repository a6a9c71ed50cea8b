"""A second rough-redraw generator, independent of :mod:`curvenet.datasets.redraw` (issue 16).

Written from scratch with a different noise model, to test that snapping holds
on noise it was not tuned to. Where :func:`curvenet.datasets.redraw.rough_sketch` draws
every network edge as its own stroke, this one draws the way people sketch:

* **Chains through junctions.** At every vertex the incident curve ends are
  paired greedily by straightness (a random turn limit per vertex, 35 to 100
  degrees), and paired edges are drawn as one stroke. Meridians run pole to
  pole (a star of 3 to 8 strokes at a pole), rings become closed strokes that
  start and end anywhere (often away from any vertex), box corners are drawn
  around in one go.
* **Overdrawn corners.** Where a chain turns sharply at a vertex, the stroke
  may overshoot the corner and come back (a hook, 0.3-1% of the diagonal).
* **Splits anywhere.** Each chain is split at uniformly random arc positions
  (about one split per diagonal length), with a gap of ``U(0, gap)`` times the
  diagonal (an overlap in a quarter of the cases). Every piece is at least 5%
  of the diagonal long: snapping drops strokes shorter than its tolerance as
  noise, so a shorter piece would widen the gap it sits in.
* **Ends short or long.** Open stroke ends stop short of or run past their end
  vertex by ``U(-ends, ends)`` times the diagonal; a closed stroke's ends gap or
  overlap by the same.
* **Wobble.** Gaussian-filtered white noise in arc length (correlation length
  3-10% of the diagonal), peak ``wobble`` times the diagonal, plus sampling at
  a varying pen speed (spacing 0.3-1.5% of the diagonal, changing along the
  stroke).
* **Overdraw.** A random stretch of some chains is drawn a second time.
* Random stroke order and direction.

:func:`graph_recovered` is the oracle: the snapped network's multigraph (loops
and parallel edges included) is isomorphic to the true one, and its curves
match the true curves one to one (:func:`curvenet.datasets.redraw.match_networks`).
"""

from __future__ import annotations

import networkx as nx
import numpy as np
from scipy.ndimage import gaussian_filter1d

from curvenet.datasets.redraw import match_networks
from curvenet.model.sketch import Sketch


def _arclen(c):
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(c, axis=0), axis=1))])


def _along(c, cum, s):
    """Points at arc parameters ``s``, extrapolated linearly past both ends."""
    j = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(cum) - 2)
    t = (s - cum[j]) / np.maximum(cum[j + 1] - cum[j], 1e-300)
    return c[j] + t[:, None] * (c[j + 1] - c[j])


def _leaving(curve, at_start):
    """Unit direction leaving a curve end along the curve."""
    c = curve if at_start else curve[::-1]
    v = c[min(3, len(c) - 1)] - c[0]
    return v / max(np.linalg.norm(v), 1e-300)


def _chains(net, rng):
    """Edge chains ``[(edge, forward), ...]`` and whether each is closed."""
    ends = {}
    for e_id, e in enumerate(net.edges):
        ends.setdefault(e.u, []).append((e_id, True))
        ends.setdefault(e.v, []).append((e_id, False))
    partner = {}
    for lst in ends.values():
        limit = np.cos(np.radians(rng.choice([35.0, 60.0, 100.0], p=[0.5, 0.3, 0.2])))
        cand = []
        for x in range(len(lst)):
            for y in range(x + 1, len(lst)):
                a = _leaving(net.edges[lst[x][0]].curve, lst[x][1])
                b = _leaving(net.edges[lst[y][0]].curve, lst[y][1])
                straight = -float(a @ b) + rng.uniform(0, 0.05)
                if straight >= limit and lst[x][0] != lst[y][0]:
                    cand.append((straight, lst[x], lst[y]))
        for _, p, q in sorted(cand, key=lambda t: -t[0]):
            if p not in partner and q not in partner:
                partner[p], partner[q] = q, p
    seen, chains = set(), []

    def walk(e_id, fwd):
        out = []
        while e_id not in seen:
            seen.add(e_id)
            out.append((e_id, fwd))
            nxt = partner.get((e_id, not fwd))  # the far end of this edge, as an end key
            if nxt is None:
                return out, False
            e_id, fwd = nxt[0], nxt[1]
        return out, True

    for e_id in rng.permutation(len(net.edges)):
        e_id = int(e_id)
        if e_id in seen:
            continue
        # go back to a free end first, so that open chains are drawn whole
        e0, f0 = e_id, True
        guard = set()
        while (e0, not f0) not in guard:
            guard.add((e0, not f0))
            back = partner.get((e0, f0))
            if back is None or back[0] in seen:
                break
            e0, f0 = back[0], not back[1]
        chains.append(walk(e0, f0))
    return chains


def _chain_curve(net, chain):
    """Polyline of a chain and the arc parameters of its interior vertices."""
    parts, knots = [], []
    for e_id, fwd in chain:
        c = net.edges[e_id].curve
        c = c if fwd else c[::-1]
        if parts:
            knots.append(sum(len(p) for p in parts) - 1)
            c = c[1:]
        parts.append(c)
    poly = np.vstack(parts)
    cum = _arclen(poly)
    return poly, cum, cum[np.array(knots, dtype=np.int64)] if knots else np.zeros(0)


def _hooks(poly, cum, knots, rng, diag, p_hook):
    """Overdrawn corners: at sharp chain vertices, run past the corner and come back."""
    out, last = [], 0
    idx = np.searchsorted(cum, knots)
    for k in idx:
        if k <= 0 or k >= len(poly) - 1:
            continue
        a = poly[k] - poly[max(k - 3, 0)]
        b = poly[min(k + 3, len(poly) - 1)] - poly[k]
        cosang = a @ b / max(np.linalg.norm(a) * np.linalg.norm(b), 1e-300)
        if cosang > 0.5 or rng.random() > p_hook:
            continue
        d = rng.uniform(0.003, 0.01) * diag
        tip = poly[k] + d * a / max(np.linalg.norm(a), 1e-300)
        back = poly[k] + 0.3 * d * b / max(np.linalg.norm(b), 1e-300)
        out += [poly[last:k + 1], tip[None], back[None]]
        last = k + 1
    if not out:
        return poly
    out.append(poly[last:])
    return np.vstack(out)


def _pen(rng, curve, s0, s1, diag, wobble):
    """A stroke along arc parameters ``[s0, s1]`` of ``curve``: varying speed, smooth wobble."""
    cum = _arclen(curve)
    length = abs(s1 - s0)
    base = rng.uniform(0.003, 0.015) * diag
    n0 = max(6, int(length / base) + 1)
    speed = np.exp(gaussian_filter1d(rng.normal(size=n0), 3.0, mode="nearest"))
    t = np.concatenate([[0.0], np.cumsum(speed[:-1])])
    s = s0 + (s1 - s0) * t / t[-1]
    pts = _along(curve, cum, s)
    corr = rng.uniform(0.03, 0.10) * diag / max(length / n0, 1e-300)
    noise = gaussian_filter1d(rng.normal(size=(n0, 3)), max(corr, 1.0), axis=0, mode="nearest")
    peak = np.linalg.norm(noise, axis=1).max()
    amp = wobble * diag * rng.uniform(0.4, 1.0)
    jitter = rng.normal(scale=0.05 * wobble * diag, size=(n0, 3))
    return pts + noise * (amp / max(peak, 1e-300)) + jitter


def redraw2(network, *, seed, gap=0.015, ends=0.012, wobble=0.003, split_rate=1.0,
            overdraw=0.15, hook=0.3):
    """Re-draw a clean network the way a person might; see the module docstring.

    Parameters
    ----------
    network : CurveNetwork
    seed : int
    gap : float
        Largest split gap, fraction of the diagonal (each gap is ``U(0, gap)``).
    ends : float
        Largest end over- or undershoot, fraction of the diagonal.
    wobble : float
        Peak smooth offset, fraction of the diagonal.
    split_rate : float
        Mean number of splits per diagonal length of chain.
    overdraw : float
        Probability that a chain has a stretch drawn twice.
    hook : float
        Probability that a sharp chain vertex is an overdrawn corner (hook).

    Returns
    -------
    Sketch
    """
    rng = np.random.default_rng(seed)
    diag = network.diagonal
    strokes, labels = [], []
    for chain, closed in _chains(network, rng):
        poly, cum, knots = _chain_curve(network, chain)
        label = "crease" if any(network.edges[e].label == "crease" for e, _ in chain) else \
            "boundary"
        poly = _hooks(poly, cum, knots, rng, diag, hook)
        cum = _arclen(poly)
        L = cum[-1]
        if closed:  # start anywhere; the ends gap or overlap at the seam
            shift = rng.uniform(0, L)
            j = int(np.searchsorted(cum, shift))
            poly = np.vstack([poly[j:], poly[1:j + 1]]) if 0 < j < len(poly) - 1 else poly
            cum = _arclen(poly)
            L = cum[-1]
            a, b = 0.0, L + rng.uniform(-ends, ends) * diag
            if b > L:  # overlap past the seam: extend along the start of the loop
                poly = np.vstack([poly, _along(poly, cum, np.linspace(0, b - L, 6)[1:])])
                cum = _arclen(poly)
                b = cum[-1]
        else:
            a = -rng.uniform(-ends, ends) * diag
            b = L + rng.uniform(-ends, ends) * diag
        n_split = rng.poisson(split_rate * (b - a) / diag)
        cuts = np.sort(rng.uniform(a, b, n_split))
        pieces, lo = [], a
        for c in cuts:  # every piece at least 5% of the diagonal long (see the docstring)
            g = rng.uniform(0, gap) * diag * (1 if rng.random() < 0.75 else -0.5)
            if min(c - 0.5 * g - lo, b - c - 0.5 * g) > 0.05 * diag:
                pieces.append((lo, c - 0.5 * g))
                lo = c + 0.5 * g
        pieces.append((lo, b))
        for s0, s1 in pieces:
            strokes.append(_pen(rng, poly, s0, s1, diag, wobble))
            labels.append(label)
        if rng.random() < overdraw and L > 0.1 * diag:
            s0 = rng.uniform(0, 0.5 * L)
            s1 = min(L, s0 + rng.uniform(0.2, 1.0) * L)
            strokes.append(_pen(rng, poly, s0, s1, diag, wobble))
            labels.append(label)
    order = rng.permutation(len(strokes))
    flip = rng.random(len(strokes)) < 0.5
    out = [strokes[i][::-1].copy() if flip[i] else strokes[i] for i in order]
    return Sketch(out, [labels[i] for i in order])


def multigraph(net):
    """networkx MultiGraph of a network's vertices and edges (loops kept)."""
    g = nx.MultiGraph()
    g.add_nodes_from(range(net.number_of_vertices))
    g.add_edges_from((e.u, e.v) for e in net.edges)
    return g


def graph_recovered(reference, result, *, tol=0.05):
    """Isomorphic multigraphs and a one-to-one curve match within ``tol`` of the diagonal."""
    if (reference.number_of_vertices, reference.number_of_edges) != (
            result.number_of_vertices, result.number_of_edges):
        return False
    if not nx.is_isomorphic(multigraph(reference), multigraph(result)):
        return False
    m = match_networks(reference, result, tol=tol)
    return bool(m["matched"] and m["max_distance"] <= tol)
