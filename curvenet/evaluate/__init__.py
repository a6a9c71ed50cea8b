"""Scores of a surface: against a reference mesh (Chamfer, Hausdorff, normal error,
F-score), against its strokes (distance, fidelity), on its own (roughness, topology), over
folders of pairs."""

from ..core.distance import load_mesh_arrays, point_surface_distance
from ..core.fidelity import format_fidelity, sketch_fidelity, stroke_fidelity, stroke_samples
from ..core.geometry import sample_surface
from .metrics import UNIT_MISMATCH_RATIO, evaluate_mesh, format_report, stroke_distance
from .smoothness import roughness
from .topology import format_topology, surface_topology

__all__ = ["evaluate_mesh", "stroke_distance", "format_report", "UNIT_MISMATCH_RATIO",
           "stroke_fidelity", "sketch_fidelity", "format_fidelity", "stroke_samples",
           "load_mesh_arrays", "point_surface_distance", "sample_surface", "roughness",
           "surface_topology", "format_topology"]
