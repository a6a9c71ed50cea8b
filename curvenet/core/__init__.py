"""The bottom floor: primitives, tolerances and the mesh result type shared by all packages.

``curvenet.core`` may be imported by the graph code (``curvenet.*``) and by both
backends (``curvenet.surfacing``, ``curvenet.neural``); it imports none of them,
and nothing heavier than numpy, scipy and trimesh (never torch).
"""

from .geometry import (arc_length, arc_length_params, as_polyline, boundary_edges,
                       cumulative_length, densify_polyline, densify_polylines,
                       face_normals_areas, fit_plane, interpolate_polyline, resample_polyline,
                       sample_at, sample_surface)
from .result import MeshResult
from .strokes import LABELS, check_labels, check_strokes

__all__ = [
    "as_polyline", "cumulative_length", "arc_length", "arc_length_params",
    "interpolate_polyline", "sample_at", "resample_polyline", "densify_polyline",
    "densify_polylines", "face_normals_areas", "boundary_edges", "sample_surface", "fit_plane",
    "LABELS", "check_labels", "check_strokes", "MeshResult",
]
