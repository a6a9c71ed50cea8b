"""The curve network: junction vertices joined by 3D curves.

Edges are stored in a list, so an edge's index is stable and is the id used by
patch sets and ``PATCHES.json``. A networkx ``MultiGraph`` view (edge key = edge
index) is built on demand for graph algorithms.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from .errors import NetworkError, SketchFormatError
from .sketch import LABELS

__all__ = ["Edge", "CurveNetwork"]


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
        return float(np.linalg.norm(np.diff(self.curve, axis=0), axis=1).sum())


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
        c = np.array(curve, dtype=np.float64).reshape(-1, 3)
        if len(c) < 2:
            raise NetworkError(f"edge ({u}, {v}): a curve needs at least 2 points")
        if not np.isfinite(c).all():
            raise NetworkError(f"edge ({u}, {v}): curve has NaN or infinite coordinates")
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
        g = nx.MultiGraph()
        g.add_nodes_from((i, {"pos": p}) for i, p in enumerate(self.positions))
        g.add_edges_from((e.u, e.v, i, {"curve": e.curve, "label": e.label})
                         for i, e in enumerate(self.edges))
        return g

    def number_of_components(self) -> int:
        """Connected components of the graph (isolated vertices count)."""
        return nx.number_connected_components(self.graph())

    def cycle_rank(self) -> int:
        """Dimension of the GF(2) cycle space, ``E - V + C``."""
        return self.number_of_edges - self.number_of_vertices + self.number_of_components()

    @property
    def diagonal(self) -> float:
        """Bounding-box diagonal of all curve points."""
        pts = np.concatenate([self.positions] + [e.curve for e in self.edges])
        if len(pts) == 0:
            return 0.0
        return float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))

    # --- serialisation ------------------------------------------------------
    def to_dict(self) -> dict:
        """JSON-ready dict in the ``curvenet.network`` version-1 layout."""
        return {
            "format": "curvenet.network",
            "version": 1,
            "vertices": self.positions.tolist(),
            "edges": [
                {"u": e.u, "v": e.v, "curve": e.curve.tolist(), "strokes": list(e.strokes),
                 "label": e.label}
                for e in self.edges
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
