"""What the review page draws, as plain arrays: patch meshes, curve segments, the camera.

No 3D library here (:mod:`curvenet.review.web` hands these arrays to viser), so the
geometry is tested without the ``[view]`` extra.
"""

from __future__ import annotations

import numpy as np

from ..core.errors import InvalidParameterError
from ..core.geometry import as_polyline
from ..core.tolerances import ZERO_LENGTH
from ..view.preview import patch_polygons

__all__ = ["patch_mesh", "polyline_segments", "camera_pose", "UP_AXES"]

#: Up axis name -> unit vector (the page turns the scene so that it points up).
UP_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
#: Camera distance from the scene's centre, in bounding-sphere radii (a 50 degree
#: field of view sees a sphere whole from 1 / sin(25 deg) = 2.4 radii).
CAMERA_DISTANCE = 2.6


def patch_mesh(network, edges) -> tuple[np.ndarray, np.ndarray]:
    """A triangle fan over each closed polygon a patch's curves trace.

    Parameters
    ----------
    network : CurveNetwork
    edges : iterable of int
        The patch's edge ids (any order).

    Returns
    -------
    vertices : (V, 3) float32
        Every polygon's points, then its centroid, polygon after polygon.
    faces : (F, 3) uint32
        Triangles (centroid, p_i, p_i+1); ``F`` is the number of polygon points.

    Raises
    ------
    InvalidParameterError
        An edge id out of range, or curves that trace no closed polygon.

    Notes
    -----
    The fan is the patch as :func:`curvenet.view.render_preview` fills it: exact for a
    polygon that is star-shaped from its centroid (every convex face, an L's), a
    picture of the patch otherwise, not a surface. Inner loops (holes) are not cut
    out: the page shows which curves bound a patch, the surfacer makes the surface.
    """
    polygons = patch_polygons(network, edges)
    if not polygons:
        raise InvalidParameterError(f"patch {sorted(int(e) for e in edges)}: its curves "
                                    "trace no closed loop")
    verts, faces, base = [], [], 0
    for poly in polygons:
        k = len(poly)
        i = np.arange(k)
        faces.append(np.column_stack([np.full(k, base + k), base + i, base + (i + 1) % k]))
        verts += [poly, poly.mean(axis=0, keepdims=True)]
        base += k + 1
    return (np.concatenate(verts).astype(np.float32),
            np.concatenate(faces).astype(np.uint32))


def polyline_segments(polylines) -> np.ndarray:
    """``(S, 2, 3) float32``: the consecutive point pairs of every polyline.

    Parameters
    ----------
    polylines : list of (n, 3) array_like
        ``n >= 2`` finite points each.
    """
    parts = [np.stack([p[:-1], p[1:]], axis=1)
             for p in (as_polyline(x, name=f"polylines[{i}]") for i, x in enumerate(polylines))]
    return (np.concatenate(parts) if parts else np.zeros((0, 2, 3))).astype(np.float32)


def camera_pose(points, up: str = "z") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A camera that sees all of ``points`` from the front, above and to the side.

    Parameters
    ----------
    points : (n, 3) array_like
        What must be in view (the strokes and curves).
    up : {"x", "y", "z"}

    Returns
    -------
    position, look_at, up_direction : (3,) float64 each
        ``look_at`` is the bounding box centre; ``position`` lies
        :data:`CAMERA_DISTANCE` bounding-sphere radii away, along the direction
        elevation 20 degrees, azimuth -60 degrees about ``up`` (the first view of
        :data:`curvenet.view.DEFAULT_VIEWS`, so the page opens as the preview shows).
    """
    if up not in UP_AXES:
        raise InvalidParameterError(f"up must be one of {sorted(UP_AXES)}, got {up!r}")
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(pts) == 0 or not np.isfinite(pts).all():
        raise InvalidParameterError("camera_pose: needs finite points")
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = 0.5 * (lo + hi)
    radius = max(0.5 * float(np.linalg.norm(hi - lo)), ZERO_LENGTH)
    z = np.asarray(UP_AXES[up])
    x = np.roll(z, 1)                   # up z: x; up y: z; up x: y (a right-handed frame)
    y = np.cross(z, x)
    e, a = np.radians(20.0), np.radians(-60.0)
    direction = np.cos(e) * (np.cos(a) * x + np.sin(a) * y) + np.sin(e) * z
    return centre + CAMERA_DISTANCE * radius * direction, centre, z
