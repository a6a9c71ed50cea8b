"""Junctions of curves recovered from point samples: where they lie, what is noise.

Helpers of :mod:`curvenet.io.points`. A junction is placed at the
least-squares meeting point of the lines along the chain ends that reach it
(:func:`junction_point`), a quadratic's tangent where an end is curved
(:func:`end_line`). Where curves converge at small angles, noise links
them near their junction; :func:`bridges` finds the short chains so made.
"""

from __future__ import annotations

import numpy as np

from ..core.geometry import cumulative_length
from ..core.tolerances import DIVISION_GUARD

_END_FROM, _END_TO = 2.0, 10.0  # a chain end spans these many cells from its junction
_CURVED = 3.0                   # line over quadratic residual (RMS) of a curved end
_WELL_POSED = 0.3               # smallest eigenvalue of the normal matrix to trust the fit
_MAX_SHIFT = 2.0                # a fitted point this many cells off the junction nodes: refused
_BRIDGE = 12.0                  # longest chain (cells) that noise can lay near a junction


def end_line(x, nodes, c):
    """Point and direction at the start of a chain, from its nodes ``2 c`` to ``10 c`` along.

    The nodes nearest the junction are left out: their projection onto the
    local line mixes in the other chains there. A straight line through the
    rest is used unless a quadratic in arc length fits them with a residual
    :data:`_CURVED` times smaller (the end is curved); then the quadratic's
    value and tangent at the chain's start, where a line fitted to a curved
    end would miss the junction towards the inside of the bend.

    Parameters
    ----------
    x : (n, 3) float64 ndarray
        Node positions.
    nodes : (k,) int64 ndarray
        The chain, starting at the junction.
    c : float
        Sampling scale.

    Returns
    -------
    ((3,) float64 ndarray, (3,) float64 ndarray) or None
        A point on the line and its unit direction; None when the chain is too short.
    """
    p = x[nodes]
    s = cumulative_length(p)
    m = (s >= _END_FROM * c) & (s <= _END_TO * c)
    sel, t = p[m], s[m]
    if len(sel) < 2:
        return None
    mu = sel.mean(axis=0)
    d = np.linalg.svd(sel - mu)[2][0]
    if len(sel) < 5:
        return mu, d
    line = np.linalg.norm((sel - mu) - np.outer((sel - mu) @ d, d), axis=1)
    basis = np.vander(t, 3, increasing=True)
    coef = np.linalg.lstsq(basis, sel, rcond=None)[0]
    quad = np.linalg.norm(basis @ coef - sel, axis=1)
    if (line ** 2).sum() < _CURVED ** 2 * (quad ** 2).sum():
        return mu, d
    return coef[0], coef[1] / max(float(np.linalg.norm(coef[1])), DIVISION_GUARD)


def junction_point(x, members, ends, c):
    """Least-squares meeting point of the lines along the chains ending at a junction.

    Parameters
    ----------
    x : (n, 3) float64 ndarray
        Node positions.
    members : (m,) int64 ndarray
        The junction's nodes.
    ends : list of (k,) int64 ndarray
        The chains reaching it, each starting at the junction.
    c : float
        Sampling scale.

    Returns
    -------
    (3,) float64 ndarray
        The meeting point; the members' mean where the lines do not pin one
        down or it lies more than ``2 c`` away.
    """
    centre = x[members].mean(axis=0)
    a, rhs = np.zeros((3, 3)), np.zeros(3)
    for nodes in ends:
        line = end_line(x, nodes, c)
        if line is not None:
            proj = np.eye(3) - np.outer(line[1], line[1])
            a += proj
            rhs += proj @ line[0]
    if np.linalg.eigvalsh(a)[0] < _WELL_POSED:
        return centre
    p = np.linalg.solve(a, rhs)
    return p if np.linalg.norm(p - centre) < _MAX_SHIFT * c else centre


def bridges(chains, lengths, cluster, keep, c):
    """Chains that noise laid across curves converging at a junction.

    Two curves that meet at a small angle run within the linking distance of
    each other near their junction, and noise can link them there: a short
    chain from the junction back to itself, or a short chain between two
    points of the curves that makes a triangle of short chains with the
    junction, whose ends have degree three (the curves pass through them).
    No curve of a network resolved at the sampling scale is that small.

    Parameters
    ----------
    chains : list of (k,) int64 ndarray
        All chains of the thinned graph.
    lengths : (C,) float64 ndarray
        Their lengths.
    cluster : (n,) int64 ndarray
        Junction label of every node.
    keep : (C,) bool ndarray
        The chains between junctions that stay curves.
    c : float
        Sampling scale.

    Returns
    -------
    (C,) bool ndarray
        Kept chains shorter than ``_BRIDGE * c`` that are such loops or bridges.
    """
    a = np.array([cluster[ch[0]] for ch in chains], np.int64).reshape(-1)
    b = np.array([cluster[ch[-1]] for ch in chains], np.int64).reshape(-1)
    small = keep & (lengths < _BRIDGE * c)
    out = small & (a == b)
    kept = np.flatnonzero(keep)
    deg = np.bincount(np.concatenate([a[kept], b[kept]]), minlength=len(cluster))
    nbr = {}
    for j in np.flatnonzero(small & (a != b)):
        nbr.setdefault(a[j], set()).add(b[j])
        nbr.setdefault(b[j], set()).add(a[j])
    for i in np.flatnonzero(small & (a != b) & (deg[a] == 3) & (deg[b] == 3)):
        out[i] = bool((nbr[a[i]] & nbr[b[i]]) - {a[i], b[i]})
    return out
