"""A third rough-redraw generator, with a noise model neither snapping nor
:mod:`tests.curvenet._redraw2` was designed with (issue 16).

Where ``_redraw2`` draws chains with smooth Gaussian wobble and gaps between the
pieces of a split, this one draws the way a hurried hand does:

* **Feathered strokes.** Each curve is drawn on its own (chains only through
  nearly straight vertices, turn under 20 degrees), as 1 to 3 pieces that
  either overlap by 0.5-3% of the diagonal (feathering, half the cases) or
  leave a gap of ``U(0, gap)`` times the diagonal.
* **End hooks.** Each stroke end curls off with probability 0.3: its last
  0.3-0.8% of the diagonal bends away by 50-110 degrees (the pen's landing and
  lift-off flick).
* **Wobble spectrum.** One to three sinusoids across the stroke (wavelengths
  15-60% of the stroke length, random phases and directions; peak ``wobble``
  times the diagonal) plus white tremor of a tenth of that.
* **Sampling density.** Each stroke is sampled uniformly at one of three
  densities: sparse (2% of the diagonal), medium (0.5%) or dense (0.08%).
* Ends short or long by ``U(-ends, ends)`` times the diagonal; random order and
  direction.
"""

from __future__ import annotations

import numpy as np

from curvenet.model.sketch import Sketch

from ._redraw2 import _along, _arclen, _leaving


def _chains_straight(net, rng, max_turn=20.0):
    """Edge chains joined only through nearly straight vertices (both ends free)."""
    ends = {}
    for e_id, e in enumerate(net.edges):
        ends.setdefault(e.u, []).append((e_id, True))
        ends.setdefault(e.v, []).append((e_id, False))
    partner = {}
    lim = np.cos(np.radians(180.0 - max_turn))
    for lst in ends.values():
        for x in rng.permutation(len(lst)):
            p = lst[x]
            if p in partner:
                continue
            for q in lst:
                if q in partner or q[0] == p[0]:
                    continue
                a = _leaving(net.edges[p[0]].curve, p[1])
                b = _leaving(net.edges[q[0]].curve, q[1])
                if a @ b <= lim:
                    partner[p], partner[q] = q, p
                    break
    seen, out = set(), []
    for e_id in range(len(net.edges)):
        if e_id in seen:
            continue
        e0, f0, guard = e_id, True, set()
        while (back := partner.get((e0, f0))) is not None and back[0] not in guard \
                and back[0] != e_id:
            guard.add(back[0])
            e0, f0 = back[0], not back[1]
        chain, e, f = [], e0, f0
        while e not in seen:
            seen.add(e)
            c = net.edges[e].curve
            chain.append(c if f else c[::-1])
            nxt = partner.get((e, not f))
            if nxt is None:
                break
            e, f = nxt[0], nxt[1]
        poly = chain[0]
        for c in chain[1:]:
            poly = np.vstack([poly, c[1:]])
        out.append(poly)
    return out


def _hook(stroke, rng, diag, at_start):
    """Curl the last 0.3-0.8% of the diagonal of one end off by 50-110 degrees."""
    c = stroke if not at_start else stroke[::-1]
    cum = _arclen(c)
    d = rng.uniform(0.003, 0.008) * diag
    if cum[-1] < 4 * d:
        return stroke
    k = int(np.searchsorted(cum, cum[-1] - d))
    tan = c[k] - c[max(k - 2, 0)]
    tan /= max(np.linalg.norm(tan), 1e-300)
    side = rng.normal(size=3)
    side -= (side @ tan) * tan
    side /= max(np.linalg.norm(side), 1e-300)
    ang = np.radians(rng.uniform(50, 110))
    t = np.linspace(0, 1, 6)[1:, None]
    r = d / ang  # an arc of length d turning by ang towards `side`
    curl = c[k] + r * (np.sin(t * ang) * tan + (1 - np.cos(t * ang)) * side)
    c = np.vstack([c[:k + 1], curl])
    return c if not at_start else c[::-1]


def _draw(rng, poly, s0, s1, diag, wobble):
    """A stroke along arc parameters ``[s0, s1]``: sinusoidal wobble, tremor, one density."""
    cum = _arclen(poly)
    spacing = rng.choice([0.02, 0.005, 0.0008]) * diag
    n = max(4, int(abs(s1 - s0) / spacing) + 1)
    u = np.linspace(0, 1, n)
    pts = _along(poly, cum, s0 + (s1 - s0) * u)
    off = np.zeros((n, 3))
    for _ in range(rng.integers(1, 4)):
        lam = rng.uniform(0.15, 0.6)
        d = rng.normal(size=3)
        off += np.sin(2 * np.pi * u[:, None] / lam + rng.uniform(0, 2 * np.pi)) * d
    off *= wobble * diag * rng.uniform(0.5, 1.0) / max(np.linalg.norm(off, axis=1).max(), 1e-300)
    return pts + off + rng.normal(scale=0.1 * wobble * diag, size=(n, 3))


def redraw3(network, *, seed, gap=0.015, ends=0.01, wobble=0.003, hook=0.3):
    """Re-draw a clean network with feathered, hooked strokes; see the module docstring.

    Parameters
    ----------
    network : CurveNetwork
    seed : int
    gap : float
        Largest gap between the pieces of a split curve, fraction of the diagonal.
    ends : float
        Largest end over- or undershoot, fraction of the diagonal.
    wobble : float
        Peak sinusoidal offset, fraction of the diagonal.
    hook : float
        Probability that a stroke end curls off.

    Returns
    -------
    Sketch
    """
    rng = np.random.default_rng(seed)
    diag = network.diagonal
    strokes = []
    for poly in _chains_straight(network, rng):
        L = _arclen(poly)[-1]
        if np.linalg.norm(poly[0] - poly[-1]) < 1e-9 * diag:  # closed: start anywhere
            poly = np.vstack([poly, poly[1:]])                 # two laps to draw on
            a = rng.uniform(0, L)
            b = a + L + rng.uniform(-ends, ends) * diag
        else:
            a = -rng.uniform(-ends, ends) * diag
            b = L + rng.uniform(-ends, ends) * diag
        n_piece = int(rng.integers(1, 4)) if L > 0.15 * diag else 1
        cuts = np.sort(rng.uniform(a + 0.05 * diag, b - 0.05 * diag, n_piece - 1))
        lo = a
        for c in [*cuts, None]:
            if c is None:
                hi, nxt = b, None
            elif rng.random() < 0.5:   # feathered: the pieces overlap
                w = rng.uniform(0.005, 0.03) * diag
                hi, nxt = c + 0.5 * w, c - 0.5 * w
            else:
                g = rng.uniform(0, gap) * diag
                hi, nxt = c - 0.5 * g, c + 0.5 * g
            s = _draw(rng, poly, lo, hi, diag, wobble)
            for at_start in (True, False):
                if rng.random() < hook:
                    s = _hook(s, rng, diag, at_start)
            strokes.append(s)
            lo = nxt
    order = rng.permutation(len(strokes))
    flip = rng.random(len(strokes)) < 0.5
    return Sketch([strokes[i][::-1].copy() if flip[i] else strokes[i] for i in order])
