"""Mesh files: a surface alone, or with the route of each face and wires beside it.

:func:`write_mesh` writes a ``trimesh.Trimesh`` in any of :data:`MESH_FORMATS`. The
hybrid route of :func:`curvenet.surface` makes one mesh from several surfacers
(classical patches, a neural fill) and keeps strokes that bound nothing as wires.
:func:`write_routed` writes that: OBJ with one group per route (``g classical``,
``g neural``) and the wires as ``l`` records; PLY with a ``route`` face property
(uint8, an index into the route names: 0 classical, 1 neural); other formats the mesh
alone. :func:`read_obj_wires` reads the ``l`` records back.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.atomic import atomic_path
from ..core.errors import InvalidParameterError, SketchFormatError

__all__ = ["MESH_FORMATS", "check_mesh_format", "write_mesh", "write_routed", "read_obj_wires"]

#: Mesh formats written (by extension).
MESH_FORMATS = (".obj", ".ply", ".stl", ".off", ".glb")


def check_mesh_format(path) -> Path:
    """``path`` as a ``Path`` when its extension is one of :data:`MESH_FORMATS`."""
    path = Path(path)
    if path.suffix.lower() not in MESH_FORMATS:
        raise InvalidParameterError(
            f"output {path}: unknown mesh format {path.suffix!r}; use one of {MESH_FORMATS}")
    return path


def write_mesh(path, mesh) -> Path:
    """Write a ``trimesh.Trimesh`` to ``path`` (OBJ / PLY / STL / OFF / GLB) atomically."""
    path = check_mesh_format(path)
    with atomic_path(path) as tmp:
        mesh.export(tmp, file_type=path.suffix.lower()[1:])
    return path


def _obj_text(vertices, faces, face_route, routes, wires) -> str:
    """OBJ text: vertices, then the wires' vertices, faces grouped by route, ``l`` records."""
    lines = [f"# curvenet routes: {' '.join(routes)}"]
    lines += [f"v {x:.10g} {y:.10g} {z:.10g}" for x, y, z in vertices]
    wire_pts = np.concatenate(wires) if wires else np.zeros((0, 3))
    lines += [f"v {x:.10g} {y:.10g} {z:.10g}" for x, y, z in wire_pts]
    for k, name in enumerate(routes):
        sel = np.asarray(faces)[np.asarray(face_route) == k] + 1
        if len(sel):
            lines.append(f"g {name}")
            lines += [f"f {a} {b} {c}" for a, b, c in sel]
    if wires:
        lines.append("g wires")
        start = len(vertices) + 1
        for w in wires:
            lines.append("l " + " ".join(str(i) for i in range(start, start + len(w))))
            start += len(w)
    return "\n".join(lines) + "\n"


def write_routed(path, mesh, face_route, routes, wires) -> Path:
    """Write a mesh with per-face routes and wires, atomically; the format follows ``path``.

    Parameters
    ----------
    path : str or os.PathLike
        ``.obj`` (route groups and ``l`` wires), ``.ply`` (``route`` face property),
        or another of :data:`MESH_FORMATS` (the mesh alone).
    mesh : trimesh.Trimesh
    face_route : (F,) int
        Index into ``routes`` per face.
    routes : list of str
        Route names (``"classical"``, ``"neural"``).
    wires : list of (m, 3) float64
        Polylines written beside the mesh (OBJ only).
    """
    path = check_mesh_format(path)
    ext = path.suffix.lower()
    with atomic_path(path) as tmp:
        if ext == ".obj":
            Path(tmp).write_text(_obj_text(mesh.vertices, mesh.faces, face_route, routes, wires))
        elif ext == ".ply":
            copy = mesh.copy()
            copy.face_attributes["route"] = np.asarray(face_route, np.uint8)
            copy.export(tmp, file_type="ply", include_attributes=True)
        else:
            mesh.export(tmp, file_type=ext[1:])
    return path


def read_obj_wires(path) -> list:
    """The ``l`` records of an OBJ file as polylines, list of (m, 3) float64.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.NamedTemporaryFile("w", suffix=".obj", delete=False) as fh:
    ...     _ = fh.write("v 0 0 0\\nv 1 0 0\\nv 1 1 0\\nl 1 2 3\\n")
    >>> [w.shape for w in read_obj_wires(fh.name)]
    [(3, 3)]
    >>> os.remove(fh.name)
    """
    verts, records = [], []
    with open(path, encoding="utf-8", errors="replace") as fh:
        for n, line in enumerate(fh, 1):
            head, _, rest = line.partition(" ")
            if head == "v":
                verts.append([float(t) for t in rest.split()[:3]])
            elif head == "l":
                try:
                    records.append((n, [int(t.split("/")[0]) for t in rest.split()]))
                except ValueError:
                    raise SketchFormatError("malformed 'l' record", path=path, line=n) from None
    v = np.asarray(verts, np.float64).reshape(-1, 3)
    wires = []
    for n, ids in records:
        idx = np.array([i - 1 if i > 0 else len(v) + i for i in ids])
        if len(idx) < 2 or idx.min() < 0 or idx.max() >= len(v):
            raise SketchFormatError("'l' record with a bad vertex index", path=path, line=n)
        wires.append(v[idx])
    return wires
