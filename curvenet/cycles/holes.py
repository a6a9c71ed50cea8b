"""Faces with holes: nested coplanar loops chosen as holes of the face around them.

A GF(2) cycle basis (Abbasinejad et al. 2011) only holds simple cycles, so a
planar face with a hole comes out as two patches: its outer loop filled over
the hole, and the hole's loop filled as a disc. In the cycle space the face
is the sum of its boundary cycles; geometry decides which sum is meant:

* an *inner* patch whose loop lies in the plane of a planar *outer* patch,
  strictly inside its outline and sharing no junction with it, is a hole of
  the innermost such outer patch (the outer patch becomes a
  :class:`~curvenet.model.patchset.Patch` with ``holes``), provided the outer patch
  lies on a manifold stretch of the surface (none of its curves is shared by
  three or more patches): a flat fin or plate attached where other surfaces
  meet is a sheet, with no solid behind it for a hole to open into, and a
  loop drawn on it (the base of a fin standing on it) stays a disc;
* the inner patch itself is dropped when a wall continues through its loop
  (every one of its curves is also used by another patch: a bore, a boss),
  and kept as a disc when nothing does (a face drawn inside a face).

A loop that no planar face surrounds (a boss's end cap, a blind hole's
bottom) is left a disc.
"""

from __future__ import annotations

import numpy as np

from ..core.geometry import fit_plane
from .loops import cycle_to_loop, loop_points
from ..model.network import CurveNetwork
from ..model.patchset import Patch

__all__ = ["hole_patches", "PLANE_TOL"]

#: Largest distance of a loop's points to its plane, fraction of the network diagonal,
#: for the loop to count as planar (and an inner loop as lying in an outer loop's plane).
PLANE_TOL = 1e-4




def hole_patches(network: CurveNetwork, patches, *, plane_tol: float = PLANE_TOL):
    """Turn nested coplanar patches into faces with holes (see the module docstring).

    Parameters
    ----------
    network : CurveNetwork
    patches : list of Patch
        Simple-cycle patches (``holes`` empty), e.g. from the basis.
    plane_tol : float
        Planarity / coplanarity tolerance, fraction of ``network.diagonal``.

    Returns
    -------
    patches : list of Patch
        Same order, each outer patch carrying its holes, dropped inner patches removed.
    report : list of dict
        One entry per hole: ``face`` (index in the returned list), ``loop`` (edge
        ids), ``disc_kept`` (whether the loop's own patch stays as a disc),
        ``source`` (that patch's source).
    """
    from matplotlib.path import Path
    tol = plane_tol * max(network.diagonal, 1e-300)
    n = len(patches)
    info = []
    for p in patches:
        pts = loop_points(network, cycle_to_loop(network, p.edges))
        c, nrm, axes = fit_plane(pts)
        planar = not p.holes and float(np.abs((pts - c) @ nrm).max()) <= tol
        verts = {network.edges[e].u for e in p.edges} | {network.edges[e].v for e in p.edges}
        info.append((pts, c, nrm, axes, planar, verts))
    uses = np.zeros(network.number_of_edges, dtype=np.int64)
    for p in patches:
        uses[list(p.edges)] += 1
    manifold = [bool((uses[list(p.edges)] <= 2).all()) for p in patches]
    parent = {}
    for i in range(n):
        pi, _, _, _, planar_i, vi = info[i]
        if not planar_i:
            continue
        best = None
        for j in range(n):
            pj, cj, nj, aj, planar_j, vj = info[j]
            if j == i or not planar_j or not manifold[j] or vi & vj:
                continue
            if float(np.abs((pi - cj) @ nj).max()) > tol:
                continue
            outline = Path((pj - cj) @ aj.T)
            if not outline.contains_points((pi - cj) @ aj.T).all():
                continue
            area = abs(_area2d((pj - cj) @ aj.T))
            if best is None or area < best[0]:
                best = (area, j)
        if best is not None:
            parent[i] = best[1]
    holes: dict = {}
    dropped = set()
    for i, j in sorted(parent.items()):
        holes.setdefault(j, []).append(i)
        if (uses[list(patches[i].edges)] >= 2).all():
            dropped.add(i)
    out, index = [], {}
    for k, p in enumerate(patches):
        if k in dropped:
            continue
        index[k] = len(out)
        hs = tuple(patches[i].edges for i in holes.get(k, ()))
        out.append(Patch(p.edges, p.source, hs) if hs else p)
    report = [{"face": index[j], "loop": list(patches[i].edges), "disc_kept": i not in dropped,
               "source": patches[i].source} for i, j in sorted(parent.items())]
    return out, report


def _area2d(xy) -> float:
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
