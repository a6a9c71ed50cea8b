"""The topology of a triangle mesh: pieces, closure, boundary loops, genus.

A surface through every stroke can still be the wrong shape, and its topology is the
first thing that says so: a sketch of a closed solid whose surface has boundary loops
(a face that leaked out of the neural route's padded box), handles a genus-0 drawing
does not have, or stray pieces. :func:`surface_topology` counts them with sparse
connected components (no Python loop over faces); :func:`format_topology` writes the
line ``curvenet surface --explain`` prints.
"""

from __future__ import annotations

import numpy as np

from ..core.geometry import mesh_edges

__all__ = ["surface_topology", "format_topology"]


def _components(n: int, edges: np.ndarray) -> np.ndarray:
    """Connected-component label (n,) int of each of ``n`` nodes joined by ``edges`` (k, 2)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    return connected_components(graph, directed=False)[1]


def surface_topology(vertices, faces) -> dict:
    """Pieces, boundary loops and Euler characteristics of the mesh ``(vertices, faces)``.

    Parameters
    ----------
    vertices : (V, 3) float64
        Only their number is used; vertices of no face are not counted.
    faces : (F, 3) int64

    Returns
    -------
    dict
        ``pieces`` (edge-connected pieces), ``closed`` (pieces with every edge in two
        faces), ``boundary_loops`` (connected chains of edges in one face), ``nonmanifold_edges``
        (edges in three or more faces), ``euler`` (V - E + F of the whole mesh) and
        ``genus`` (the summed ``(2 - chi) / 2`` of the closed pieces, or None when none is
        closed).

    Examples
    --------
    >>> import trimesh
    >>> torus = trimesh.creation.torus(1.0, 0.3)
    >>> t = surface_topology(torus.vertices, torus.faces)
    >>> t["pieces"], t["closed"], t["boundary_loops"], t["genus"]
    (1, 1, 0, 1)
    """
    F = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if not len(F):
        return {"pieces": 0, "closed": 0, "boundary_loops": 0, "nonmanifold_edges": 0,
                "euler": 0, "genus": None}
    n = max(len(vertices), int(F.max()) + 1)
    edges, count = mesh_edges(F)
    used = np.unique(F)
    label = _components(n, edges)
    pieces, piece = np.unique(label[used], return_inverse=True)      # relabel 0..k-1
    lookup = np.full(n, -1, np.int64)
    lookup[used] = piece
    k = len(pieces)
    v_count = np.bincount(piece, minlength=k)
    e_piece = lookup[edges[:, 0]]
    e_count = np.bincount(e_piece, minlength=k)
    f_count = np.bincount(lookup[F[:, 0]], minlength=k)
    closed = np.bincount(e_piece[count != 2], minlength=k) == 0      # every edge in 2 faces
    chi = v_count - e_count + f_count
    boundary = edges[count == 1]
    loops = 0
    if len(boundary):
        ends = np.unique(boundary)
        loops = len(np.unique(_components(n, boundary)[ends]))
    return {"pieces": int(k), "closed": int(closed.sum()), "boundary_loops": int(loops),
            "nonmanifold_edges": int((count > 2).sum()), "euler": int(chi.sum()),
            "genus": int((2 * closed.sum() - chi[closed].sum()) // 2) if closed.any() else None}


def format_topology(topology: dict) -> str:
    """One line for :func:`surface_topology`'s dict (with ``open_at_box``, the neural
    route's :func:`neural.extract.edges_at_walls` count, and ``rims_closed``, the sides of
    the strokes' box it closed flat at a rim, :func:`neural.rims.close_rims`, when they
    are not 0).

    Examples
    --------
    >>> format_topology({"pieces": 1, "closed": 1, "boundary_loops": 0,
    ...                  "nonmanifold_edges": 0, "euler": 2, "genus": 0})
    'surface: 1 piece, closed, genus 0'
    >>> format_topology({"pieces": 2, "closed": 1, "boundary_loops": 3,
    ...                  "nonmanifold_edges": 0, "euler": 1, "genus": 0})
    'surface: 2 pieces, 1 closed (genus 0), 3 boundary loops, Euler characteristic 1'
    >>> format_topology({"pieces": 1, "closed": 1, "boundary_loops": 0,
    ...                  "nonmanifold_edges": 0, "euler": 2, "genus": 0, "rims_closed": 2})
    "surface: 1 piece, closed, genus 0, flat at 2 rims on the strokes' bounding box"
    """
    k, closed = topology["pieces"], topology["closed"]
    text = f"surface: {k} piece{'s' if k != 1 else ''}"
    if closed == k and k:
        text += f", closed, genus {topology['genus']}"
    else:
        if closed:
            text += f", {closed} closed (genus {topology['genus']})"
        loops = topology["boundary_loops"]
        text += (f", {loops} boundary loop{'s' if loops != 1 else ''}, Euler characteristic "
                 f"{topology['euler']}")
    rims = topology.get("rims_closed", 0)
    if rims:
        text += f", flat at {rims} rim{'s' if rims != 1 else ''} on the strokes' bounding box"
    if topology.get("open_at_box"):
        text += (" (open where the neural field's zero set reaches its padded box; "
                 "--closed-box keeps the surface inside)")
    bad = topology["nonmanifold_edges"]
    if bad:
        text += f", {bad} edge{'s' if bad != 1 else ''} in three or more faces"
    return text
