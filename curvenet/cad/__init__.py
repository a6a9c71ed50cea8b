"""B-rep output: STEP and 3DM through OpenCascade and rhino3dm (the ``[cad]`` extra)."""

from .export import (CAD_FORMATS, STEP_SCHEMAS, write_cad, write_step, write_3dm, read_step, occ_faces, sew,
    manifold_groups, shape_report, require_cad)

__all__ = ['CAD_FORMATS', 'STEP_SCHEMAS', 'write_cad', 'write_step', 'write_3dm', 'read_step',
    'occ_faces', 'sew', 'manifold_groups', 'shape_report', 'require_cad']
