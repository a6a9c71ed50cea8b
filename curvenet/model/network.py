"""The curve network: junction vertices joined by 3D curves.

Edges are stored in a list, so an edge's index is stable and is the id used by
patch sets and ``PATCHES.json``. A networkx ``MultiGraph`` view (edge key = edge
index) is built on demand for graph algorithms (networkx is imported only then).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..core.geometry import arc_length, as_polyline, bbox_diagonal
from ..core.strokes import LABELS
from ..core.errors import InvalidParameterError, NetworkError, SketchFormatError
from .sketch import label_counts

if TYPE_CHECKING:
    import networkx as nx

__all__ = ["Edge", "CurveNetwork", "indexed_network"]


@dataclass
class Edge:
    """One curve of the network.

    Attributes
    ----------
    u, v : int
        End vertices; ``u == v`` for a closed curve (a loop edge, a 1-cycle).
    curve : (m, 3) float64 ndarray
        Polyline from ``positions[u]`` to ``positions[v]`` (``m >= 2``; first and
        last points equal the vertex positions).
    strokes : tuple of int
        Ids of the sketch strokes this curve came from.
    label : str
        ``"boundary"`` or ``"crease"``.
    """

    u: int
    v: int
    curve: np.ndarray
    strokes: tuple = ()
    label: str = "boundary"

    def length(self) -> float:
        """Polyline length."""
        return arc_length(self.curve)

    def __repr__(self) -> str:
        return f"<Edge(u={self.u}, v={self.v}, points={len(self.curve)}, label={self.label!r})>"


@dataclass
class CurveNetwork:
    """Vertex positions and a list of curve edges.

    Attributes
    ----------
    positions : (V, 3) float64 ndarray
        Junction (and corner) vertex positions.
    edges : list of Edge
        Edge ``i`` is the curve with id ``i``.
    report : dict
        What built it (snapping statistics, warnings), free-form.

    Examples
    --------
    >>> net = CurveNetwork(np.array([[0., 0, 0], [1, 0, 0]]))
    >>> net.add_edge(0, 1, [[0, 0, 0], [0.5, 0.1, 0], [1, 0, 0]])
    0
    >>> net.number_of_vertices, net.number_of_edges, net.number_of_components()
    (2, 1, 1)
    """

    positions: np.ndarray
    edges: list = field(default_factory=list)
    report: dict = field(default_factory=dict)

    def __post_init__(self):
        self.positions = np.asarray(self.positions, dtype=np.float64).reshape(-1, 3)

    def __repr__(self) -> str:
        pts = self.positions
        bounds = np.round([pts.min(0), pts.max(0)], 4).tolist() if len(pts) else None
        return (f"<CurveNetwork(vertices={self.number_of_vertices}, edges={self.number_of_edges}, "
                f"labels={label_counts(e.label for e in self.edges)}, bounds={bounds})>")

    # --- construction -----------------------------------------------------
    def add_vertex(self, point) -> int:
        """Append a vertex; returns its index."""
        self.positions = np.vstack([self.positions, np.asarray(point, dtype=np.float64)[None]])
        return len(self.positions) - 1

    def add_edge(self, u: int, v: int, curve, *, strokes=(), label: str = "boundary") -> int:
        """Append a curve edge from ``u`` to ``v``; returns its id.

        The curve's end points are set to the vertex positions exactly.
        """
        n = len(self.positions)
        if not (0 <= u < n and 0 <= v < n):
            raise NetworkError(f"edge ({u}, {v}): vertex index out of range 0..{n - 1}")
        try:
            c = as_polyline(np.reshape(np.asarray(curve, dtype=np.float64), (-1, 3)),
                            name=f"edge ({u}, {v}) curve")
        except InvalidParameterError as err:
            raise NetworkError(str(err)) from None
        if label not in LABELS:
            raise NetworkError(f"edge ({u}, {v}): unknown label {label!r}")
        c[0] = self.positions[u]
        c[-1] = self.positions[v]
        self.edges.append(Edge(int(u), int(v), c, tuple(int(s) for s in strokes), label))
        return len(self.edges) - 1

    # --- queries ------------------------------------------------------------
    @property
    def number_of_vertices(self) -> int:
        return len(self.positions)

    @property
    def number_of_edges(self) -> int:
        return len(self.edges)

    @property
    def endpoints(self) -> np.ndarray:
        """``(E, 2) int64``: ``[u, v]`` per edge."""
        if not self.edges:
            return np.zeros((0, 2), dtype=np.int64)
        return np.array([[e.u, e.v] for e in self.edges], dtype=np.int64)

    def graph(self) -> nx.MultiGraph:
        """networkx view: nodes ``0..V-1`` with ``pos``; edge key = edge id, data ``curve``."""
        import networkx as nx
        g = nx.MultiGraph()
        g.add_nodes_from((i, {"pos": p}) for i, p in enumerate(self.positions))
        g.add_edges_from((e.u, e.v, i, {"curve": e.curve, "label": e.label})
                         for i, e in enumerate(self.edges))
        return g

    def number_of_components(self) -> int:
        """Connected components of the graph (isolated vertices count)."""
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components
        n, ends = self.number_of_vertices, self.endpoints
        graph = coo_matrix((np.ones(len(ends)), (ends[:, 0], ends[:, 1])), shape=(n, n))
        return int(connected_components(graph, directed=False)[0])

    def cycle_rank(self) -> int:
        """Dimension of the GF(2) cycle space, ``E - V + C``."""
        return self.number_of_edges - self.number_of_vertices + self.number_of_components()

    @property
    def diagonal(self) -> float:
        """Bounding-box diagonal of all curve points."""
        return bbox_diagonal([self.positions] + [e.curve for e in self.edges])

    # --- serialisation ------------------------------------------------------
    def to_dict(self) -> dict:
        """JSON-ready dict in the ``curvenet.model.network`` version-1 layout."""
        sizes = [len(e.curve) for e in self.edges]
        points = np.concatenate([e.curve for e in self.edges]).tolist() if sizes else []
        ends = np.cumsum(sizes).tolist()
        return {
            "format": "curvenet.network",
            "version": 1,
            "vertices": self.positions.tolist(),
            "edges": [
                {"u": e.u, "v": e.v, "curve": points[b - n:b], "strokes": list(e.strokes),
                 "label": e.label}
                for e, n, b in zip(self.edges, sizes, ends)
            ],
        }

    @classmethod
    def from_dict(cls, data: dict, *, path=None) -> "CurveNetwork":
        """Inverse of :meth:`to_dict` (also accepts a ``curvenet.patches`` dict).

        Raises
        ------
        SketchFormatError
            Missing keys, bad shapes, NaN, or out-of-range vertex indices.
        """
        try:
            verts = np.asarray(data["vertices"], dtype=np.float64).reshape(-1, 3)
            if not np.isfinite(verts).all():
                raise SketchFormatError("vertices contain NaN or infinity", path=path)
            net = cls(verts)
            for i, e in enumerate(data["edges"]):
                try:
                    net.add_edge(int(e["u"]), int(e["v"]), e["curve"],
                                 strokes=e.get("strokes", ()), label=e.get("label", "boundary"))
                except NetworkError as err:
                    raise SketchFormatError(f"edges[{i}]: {err}", path=path) from None
        except (KeyError, TypeError, ValueError) as err:
            raise SketchFormatError(f"not a curvenet network: {err!r}", path=path) from None
        return net


def indexed_network(verts, polys, labels, sources) -> CurveNetwork:
    """Exact graph of polylines given as index arrays into ``verts`` (no tolerance).

    Parameters
    ----------
    verts : (n, 3) float64 ndarray
        Point positions.
    polys : list of (m_k,) int64 ndarray
        Each polyline as indices into ``verts``, ``m_k >= 2``; a polyline whose first
        and last index are equal (and ``m_k > 2``) is closed.
    labels : list of str
        Per polyline; ``"crease"`` stays a crease, anything else becomes ``"boundary"``.
    sources : sequence of int
        Per polyline, the stroke id stored in its pieces' ``edge.strokes``.

    Returns
    -------
    CurveNetwork

    Notes
    -----
    Vertices are the indices that end an open polyline, occur two or more times
    (over all polylines, a closed polyline's repeated end counted once), or
    where three or more segments meet; each closed polyline with none of those
    gets a loop edge at its first point. Used by the OBJ network reader and by
    exact-mode snapping.

    Examples
    --------
    >>> verts = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [1, 1, 0]])
    >>> net = indexed_network(verts, [np.array([0, 1, 2]), np.array([1, 3])],
    ...                       ["boundary", "crease"], [0, 1])
    >>> net.number_of_vertices, net.number_of_edges
    (4, 3)
    """
    nv = len(verts)
    key = np.zeros(nv, dtype=bool)
    if polys:
        sizes = np.array([len(p) for p in polys], np.int64)
        flat = np.concatenate(polys).astype(np.int64)
        last = np.cumsum(sizes) - 1
        first = last - sizes + 1
        closed = (flat[first] == flat[last]) & (sizes > 2)
        body, not_first, not_last = (np.ones(len(flat), bool) for _ in range(3))
        body[last[closed]] = False                   # a closed polyline's end counted once
        not_first[first], not_last[last] = False, False
        use = np.bincount(flat[body], minlength=nv)
        seg_deg = (np.bincount(flat[not_last], minlength=nv)
                   + np.bincount(flat[not_first], minlength=nv))
        key[flat[first[~closed]]] = key[flat[last[~closed]]] = True
        key |= (use >= 2) | (seg_deg >= 3)
    vid = -np.ones(nv, dtype=np.int64)
    net_v = list(np.flatnonzero(key))
    vid[net_v] = np.arange(len(net_v))
    pieces = []
    for k, p in enumerate(polys):
        if p[0] == p[-1] and len(p) > 2:  # closed polyline
            inner = np.flatnonzero(key[p[:-1]])
            if inner.size == 0:  # nothing else on it: a loop edge at its first point
                key[p[0]] = True
                vid[p[0]] = len(net_v)
                net_v.append(p[0])
            else:  # rotate so that it starts (and ends) at its first vertex
                r = inner[0]
                p = np.concatenate([p[r:-1], p[:r + 1]])
        cut = np.flatnonzero(key[p])
        for a, b in zip(cut[:-1], cut[1:]):
            pieces.append((p[a:b + 1], labels[k], k))
    net = CurveNetwork(verts[np.asarray(net_v, dtype=np.int64)])
    for idx, lab, k in pieces:
        net.add_edge(int(vid[idx[0]]), int(vid[idx[-1]]), verts[idx], strokes=(int(sources[k]),),
                     label="crease" if lab == "crease" else "boundary")
    return net
