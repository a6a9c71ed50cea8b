"""Scores of a surface: against a reference mesh (Chamfer, Hausdorff, normals, F-score), against its strokes, over folders of pairs."""

from .metrics import (evaluate_mesh, stroke_distance, stroke_fidelity, sketch_fidelity, format_report,
    load_mesh_arrays, sample_surface, point_surface_distance, stroke_samples)

__all__ = ['evaluate_mesh', 'stroke_distance', 'stroke_fidelity', 'sketch_fidelity', 'format_report',
    'load_mesh_arrays', 'sample_surface', 'point_surface_distance', 'stroke_samples']
