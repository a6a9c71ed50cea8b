"""B-rep output: STEP and 3DM through OpenCascade and rhino3dm (the ``[cad]`` extra)."""

from .export import (CAD_FORMATS, STEP_SCHEMAS, manifold_groups, occ_faces, read_step,
                     require_cad, sew, shape_report, write_3dm, write_cad, write_step)

__all__ = ["CAD_FORMATS", "STEP_SCHEMAS", "write_cad", "write_step", "write_3dm", "read_step",
           "occ_faces", "sew", "manifold_groups", "shape_report", "require_cad"]
