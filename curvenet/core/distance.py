"""Distances from points to a triangle mesh, and mesh arguments read into arrays.

The measuring primitives of :mod:`curvenet.evaluate` and of the stroke fidelity
(:mod:`curvenet.core.fidelity`): libigl's AABB tree for point-to-triangle distances,
and one reader that turns a ``trimesh.Trimesh``, a ``(vertices, faces)`` pair or a
mesh file into checked arrays.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .errors import InvalidParameterError, SketchFormatError
from .geometry import face_normals_areas
from .tolerances import DEGENERATE_AREA_REL, DIVISION_GUARD

__all__ = ["load_mesh_arrays", "drop_degenerate", "point_surface_distance"]


def load_mesh_arrays(mesh, *, name: str = "mesh") -> tuple[np.ndarray, np.ndarray]:
    """Turn a mesh argument into validated ``(vertices, faces)`` arrays.

    Parameters
    ----------
    mesh : trimesh.Trimesh, (vertices, faces) pair, object with ``.vertices`` and
        ``.faces``, or str / os.PathLike
        A path is loaded with ``trimesh.load(path, force="mesh")`` (OBJ, PLY, STL, OFF, ...).
    name : str
        Parameter name used in error messages.

    Returns
    -------
    vertices : (n, 3) float64 ndarray
    faces : (m, 3) int64 ndarray
        ``m >= 1``; degenerate (zero-area) triangles are kept here.

    Raises
    ------
    SketchFormatError
        A file that cannot be read or holds no triangles (the message names the file).
    InvalidParameterError
        Arrays of the wrong shape, NaN/inf coordinates, out-of-range face indices, no
        faces, or zero total area.
    """
    path = None
    if isinstance(mesh, (str, os.PathLike)):
        path = Path(mesh)
        import trimesh

        kind = path.suffix.lstrip(".").upper() or "mesh"
        try:
            # process=False: trimesh's clean-up would drop NaN vertices before the check below
            loaded = trimesh.load(str(path), force="mesh", process=False)
        except Exception as err:  # trimesh raises many types (ValueError, KeyError, ...)
            # an ImportError here is trimesh guessing a text encoding, not a missing feature
            why = "" if isinstance(err, ImportError) else f" ({err})"
            raise SketchFormatError(f"not a readable {kind} mesh{why}", path=path) from None
        if not hasattr(loaded, "faces") or len(loaded.faces) == 0:
            # with charset_normalizer installed (requests brings it) trimesh reads
            # garbage as an empty ASCII file instead of failing: name the format here too
            raise SketchFormatError(f"no triangles in the {kind} mesh file", path=path)
        vertices, faces = loaded.vertices, loaded.faces
    elif hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        vertices, faces = mesh.vertices, mesh.faces
    elif isinstance(mesh, (tuple, list)) and len(mesh) == 2:
        vertices, faces = mesh
    else:
        raise InvalidParameterError(
            f"{name}: expected a trimesh.Trimesh, a (vertices, faces) pair or a path, "
            f"got {type(mesh).__name__}")

    def fail(message):
        if path is not None:
            raise SketchFormatError(message, path=path)
        raise InvalidParameterError(f"{name}: {message}")

    try:
        v = np.asarray(vertices, dtype=np.float64)
        f = np.asarray(faces)
    except (TypeError, ValueError) as err:
        fail(f"cannot convert to arrays ({err})")
    if v.ndim != 2 or v.shape[1] != 3:
        fail(f"vertices must be (n, 3), got shape {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3 or len(f) == 0:
        fail(f"faces must be (m, 3) with m >= 1, got shape {f.shape}")
    if not np.issubdtype(f.dtype, np.integer):
        fail(f"faces must be integers, got dtype {f.dtype}")
    if not np.isfinite(v).all():
        fail("vertices contain NaN or infinite coordinates")
    f = f.astype(np.int64)
    if f.min() < 0 or f.max() >= len(v):
        fail(f"face indices out of range 0..{len(v) - 1}")
    return np.ascontiguousarray(v), np.ascontiguousarray(f)


def drop_degenerate(vertices, faces):
    """Faces, unit normals and areas of the non-degenerate triangles only."""
    normals, areas = face_normals_areas(vertices, faces)
    diag2 = float(np.sum(np.ptp(vertices, axis=0) ** 2))
    keep = areas > DEGENERATE_AREA_REL * max(diag2, DIVISION_GUARD)
    return faces[keep], normals[keep], areas[keep]


def point_surface_distance(points, vertices, faces, *, closest: bool = False) -> tuple:
    """Unsigned distance from points to a triangle mesh's surface, and the closest triangle.

    Parameters
    ----------
    points : (n, 3) float64
    vertices : (V, 3) float64
    faces : (F, 3) int64

    Returns
    -------
    distance : (n,) float64
    face_index : (n,) int64
        Index (into ``faces``) of a closest triangle; at a point equidistant from several
        triangles (closest point on a shared edge or vertex) one of them.
    closest_points : (n, 3) float64
        Only with ``closest=True``: the closest point of the surface to each point.

    Raises
    ------
    InvalidParameterError
        The mesh has no triangle (libigl's tree would crash on it).

    Notes
    -----
    Uses libigl's AABB tree (``igl.point_mesh_squared_distance``), O((n + F) log F).
    """
    import igl

    if len(faces) == 0:
        raise InvalidParameterError("distance to a mesh with no triangle")
    sq, idx, near = igl.point_mesh_squared_distance(
        np.ascontiguousarray(points, dtype=np.float64),
        np.ascontiguousarray(vertices, dtype=np.float64),
        np.ascontiguousarray(faces, dtype=np.int64))
    out = np.sqrt(np.maximum(sq, 0.0)), np.asarray(idx, dtype=np.int64)
    return out + (np.asarray(near, dtype=np.float64),) if closest else out
