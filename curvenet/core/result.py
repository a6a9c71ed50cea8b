"""The one result type every surfacer returns: a triangle mesh and a report.

Backends (``curvenet.surfacing``, ``curvenet.neural``) return :class:`MeshResult`
or a thin subclass that adds what only that backend has (per-face patch ids, a
control mesh, an implicit field); the graph code reads only the three fields
below, so any surfacer can stand in for any other.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["MeshResult"]


@dataclass(repr=False)
class MeshResult:
    """A triangle mesh and what its backend reports about it.

    Attributes
    ----------
    vertices : (n, 3) float64
        Vertex positions in the input's coordinates.
    faces : (f, 3) int64
        Triangles, indices into ``vertices``, consistently oriented.
    report : dict
        Backend diagnostics (timings, deviations, settings); JSON-serialisable values.
    face_route : (f,) uint8 or None
        For a surface several surfacers made (a composite such as the hybrid route):
        per face, an index into ``routes``. None: one surfacer made every face.
    routes : tuple of str
        The route of each index of ``face_route`` (empty when it is None).

    Examples
    --------
    >>> res = MeshResult([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    >>> res
    <MeshResult(vertices.shape=(3, 3), faces.shape=(1, 3))>
    >>> res.vertices.dtype, res.faces.dtype
    (dtype('float64'), dtype('int64'))
    """

    vertices: np.ndarray
    faces: np.ndarray
    report: dict = field(default_factory=dict)
    face_route: np.ndarray | None = None
    routes: tuple = ()

    def __post_init__(self):
        # no copy when the arrays already have the documented dtypes
        self.vertices = _rows3(self.vertices, np.float64, "vertices")
        self.faces = _rows3(self.faces, np.int64, "faces")
        if self.face_route is not None:
            self.face_route = np.asarray(self.face_route, np.uint8)
            if self.face_route.shape != (len(self.faces),) or (
                    len(self.faces) and int(self.face_route.max()) >= len(self.routes)):
                raise ValueError(f"face_route: expected ({len(self.faces)},) indices into "
                                 f"routes {tuple(self.routes)}")

    def to_trimesh(self):
        """The mesh as a ``trimesh.Trimesh`` (not processed: vertices and faces as they are)."""
        import trimesh
        return trimesh.Trimesh(self.vertices, self.faces, process=False)

    def __repr__(self) -> str:
        return (f"<{type(self).__name__}(vertices.shape={self.vertices.shape}, "
                f"faces.shape={self.faces.shape})>")


def _rows3(a, dtype, name: str) -> np.ndarray:
    """``a`` as an ``(k, 3)`` array of ``dtype``; an empty input becomes ``(0, 3)``."""
    a = np.asarray(a, dtype=dtype)
    if a.size == 0:
        return a.reshape(0, 3)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name}: expected a (k, 3) array, got shape {a.shape}")
    return a
