"""Periodic faces: two loops joined by a seam that one face walks twice.

A CAD part's bore wall is one cylinder whose B-rep boundary is its top circle, a
single seam line, its bottom circle, and the seam again; a cone frustum, a revolved
fillet (a torus band) and any surface of revolution cut by two parallels look the
same. In the cycle space the seam is a bridge: no cycle uses it, so the GF(2) basis
(and any face of a rotation system that is a simple cycle) never holds the wall,
the seam stays a wire and the bore is not surfaced.

:func:`seam_patches` adds those faces. A *seam* is a chain of curves no patch uses,
through junctions where nothing else meets, from a junction of one patch loop (an
outer loop or a hole of some patch) to a junction of another, each end on exactly one
such loop, the two loops sharing no junction. The face is both loops and the seam
walked twice (``Patch.edges`` lists the seam's curves twice;
:func:`curvenet.cycles.loops.cycle_to_loop` walks it as ``L1, seam, L2, seam
reversed``). A loop's disc that :func:`curvenet.cycles.holes.hole_patches` kept
inside the face it is a hole of is dropped then: the wall now continues through it,
so the hole's face and the wall are the two sides of the loop's curves.

A seam is only taken where every curve of both loops then bounds at most two
patches, so a seam face never makes a curve non-manifold, and where the two loops
face each other as two parallels of one surface of revolution do: their planes
within 45 degrees of parallel and the line between their centres within 45 degrees
of their common normal (two leaves on a stem, side by side in one plane, are not the
ends of a tube).
"""

from __future__ import annotations

import numpy as np

from ..model.network import CurveNetwork
from ..model.patchset import Patch
from .loops import edge_components

__all__ = ["seam_patches", "seam_chains"]


def _loops_of(patch, ends) -> list:
    """The loops of a patch as sorted edge-id tuples: its outer loop and holes, or for a
    seam face (edges listed twice) the one or two loops beside its seam."""
    counts: dict = {}
    for e in patch.edges:
        counts[e] = counts.get(e, 0) + 1
    if max(counts.values(), default=1) < 2:
        return [tuple(sorted(lp)) for lp in (patch.edges, *patch.holes)]
    once = [e for e, c in counts.items() if c == 1]
    return [tuple(g) for g in edge_components(once, ends)]


def seam_chains(network: CurveNetwork, patches) -> list:
    """Chains of unused curves between two patch loops, or from one to an apex.

    Parameters
    ----------
    network : CurveNetwork
    patches : list of Patch
        Seam faces among them count by the loops beside their seams.

    Returns
    -------
    list of (seam, loop_a, loop_b)
        ``seam`` the chain's edge ids from its end on ``loop_a`` to its end on
        ``loop_b`` (sorted edge-id tuples of the patch loops they end on; ``loop_b``
        empty for a chain ending at an *apex*, a junction of that one curve on no loop:
        a cone's tip, a dome's pole), in the order of the chains' smallest edge ids.
    """
    ne = network.number_of_edges
    ends = [(e.u, e.v) for e in network.edges]
    used = np.zeros(ne, bool)
    for p in patches:
        used[list(p.all_edges)] = True
    at: dict = {}
    for i, (u, v) in enumerate(ends):
        at.setdefault(u, []).append(i)
        at.setdefault(v, []).append(i)
    loops_at: dict = {}
    for p in patches:
        for lp in _loops_of(p, ends):
            for e in lp:
                for x in ends[e]:
                    loops_at.setdefault(x, set()).add(lp)
    seen = np.zeros(ne, bool)
    out = []
    for i in range(ne):
        if used[i] or seen[i] or ends[i][0] == ends[i][1]:
            continue
        chain, tips = _chain(i, ends, at, used, seen)
        if chain is None:
            continue
        la, lb = (loops_at.get(t, set()) for t in tips)
        if not la and len(at[tips[0]]) == 1:       # the apex first: turn the chain round
            la, lb, chain, tips = lb, la, chain[::-1], tips[::-1]
        apex = not lb and len(at[tips[1]]) == 1
        if len(la) != 1 or (len(lb) != 1 and not apex):
            continue
        (a,) = la
        b = () if apex else next(iter(lb))
        va = {x for e in a for x in ends[e]}
        vb = {x for e in b for x in ends[e]}
        inner = {x for e in chain for x in ends[e]} - set(tips)
        if a == b or va & vb or inner & set(loops_at):
            continue
        if not (_pointing(network, a, tips[1]) if apex else _facing(network, a, b)):
            continue
        out.append((chain, a, b))
    return out


#: cosine of the largest angle between the loops' normals, and between their common
#: normal and the line between their centres
_FACING_COS = np.cos(np.radians(45.0))


def _frame(network: CurveNetwork, loop):
    """Arc-length weighted centre (3,) and unit normal (3,) of a loop's curve points
    (each point weighs half its two segments on its own curve)."""
    curves = [np.asarray(network.edges[e].curve, np.float64) for e in loop]
    pts = np.concatenate(curves)
    seg = [np.linalg.norm(np.diff(c, axis=0), axis=1) for c in curves]
    w = np.concatenate([np.r_[d, 0.0] + np.r_[0.0, d] for d in seg])
    w = w / w.sum() if w.sum() > 0 else np.full(len(pts), 1.0 / len(pts))
    centre = w @ pts
    _, _, vt = np.linalg.svd((pts - centre) * np.sqrt(w)[:, None], full_matrices=False)
    return centre, vt[-1]


def _facing(network: CurveNetwork, a, b) -> bool:
    """Whether loops ``a`` and ``b`` face each other as the ends of a tube do."""
    (ca, na), (cb, nb) = _frame(network, a), _frame(network, b)
    cos = float(na @ nb)
    if abs(cos) < _FACING_COS:
        return False
    n = na + np.sign(cos) * nb
    chord = cb - ca
    length = float(np.linalg.norm(chord))
    return length > 0 and abs(float(chord @ n)) >= _FACING_COS * length * np.linalg.norm(n)


def _pointing(network: CurveNetwork, a, tip) -> bool:
    """Whether junction ``tip`` lies off loop ``a``'s plane as a cone's apex or a dome's
    pole does: the line from the loop's centre to it within 45 degrees of the normal."""
    c, n = _frame(network, a)
    chord = network.positions[tip] - c
    length = float(np.linalg.norm(chord))
    return length > 0 and abs(float(chord @ n)) >= _FACING_COS * length


def _chain(i, ends, at, used, seen):
    """The maximal chain of unused curves through ``i`` whose inner junctions have two
    curves: ``(edge ids from one tip to the other, (tip, tip))``, or ``(None, None)``
    when it closes on itself or meets a used curve inside."""
    seen[i] = True
    sides = []
    for x in ends[i]:
        path, prev, e = [], i, None
        while len(at[x]) == 2:
            e = at[x][0] if at[x][1] == prev else at[x][1]
            if e == i or used[e]:
                return None, None
            seen[e] = True
            path.append(e)
            x = ends[e][1] if ends[e][0] == x else ends[e][0]
            prev = e
        sides.append((path, x))
    (back, a), (fwd, b) = sides
    return back[::-1] + [i] + fwd, (a, b)


def seam_patches(network: CurveNetwork, patches, holes_report=()):
    """Add the periodic faces of :func:`seam_chains` (see the module docstring).

    Parameters
    ----------
    network : CurveNetwork
    patches : list of Patch
        As :func:`curvenet.cycles.holes.hole_patches` returns them.
    holes_report : list of dict
        Its report: the hole entries are updated (``face`` renumbered, ``disc_kept``
        False for a disc a seam face replaced).

    Returns
    -------
    patches : list of Patch
        The patches (less the replaced discs), then one patch per seam,
        ``source="auto"``, whose ``edges`` list the seam's curves twice.
    report : list of dict
        Per seam face: ``face`` (index in ``patches``), ``seam`` (edge ids),
        ``loops`` (the two loops' edge ids), ``discs_dropped`` (their count).
    holes_report : list of dict
        The updated hole entries.
    """
    patches = list(patches)
    holes = {tuple(sorted(h)) for p in patches for h in p.holes}
    uses = np.zeros(network.number_of_edges, np.int64)
    for p in patches:
        np.add.at(uses, list(p.all_edges), 1)
    drop, faces = set(), []
    discs = {k: tuple(sorted(p.edges)) for k, p in enumerate(patches)
             if not p.holes and len(set(p.edges)) == len(p.edges)}
    added = True
    while added:            # a seam face's loops can end the next seam (stacked walls)
        added = False
        current = [p for k, p in enumerate(patches) if k not in drop] + [
            Patch(a + b + tuple(seam) * 2, "auto") for seam, a, b, _ in faces]
        for seam, a, b in seam_chains(network, current):
            on = [k for k, lp in discs.items() if k not in drop and lp in (a, b)]
            gone = [k for k in on if discs[k] in holes]
            after = uses.copy()
            for k in gone:
                np.add.at(after, list(patches[k].edges), -1)
            np.add.at(after, list(a + b), 1)
            # a disc between two walls would make its curves bound three patches
            for k in on:
                if k not in gone and (after[list(patches[k].edges)] > 2).any():
                    np.add.at(after, list(patches[k].edges), -1)
                    gone.append(k)
            if (after[list(a + b)] > 2).any():
                continue
            uses = after
            drop |= set(gone)
            faces.append((seam, a, b, len(gone)))
            added = True
    index = {}
    out = []
    for k, p in enumerate(patches):
        if k not in drop:
            index[k] = len(out)
            out.append(p)
    report = []
    for seam, a, b, n_gone in faces:
        report.append({"face": len(out), "seam": list(seam), "loops": [list(a), list(b)],
                       "discs_dropped": n_gone})
        out.append(Patch(a + b + tuple(seam) * 2, "auto"))
    gone_loops = {tuple(sorted(patches[k].edges)) for k in drop}
    new_holes = []
    for h in holes_report:
        # a face with holes is never dropped (only discs are)
        h = dict(h, face=index[h["face"]])
        if h["disc_kept"] and tuple(sorted(h["loop"])) in gone_loops:
            h["disc_kept"] = False
        new_holes.append(h)
    return out, report, new_holes
