"""B-rep output: STEP and 3DM through OpenCascade and rhino3dm (the ``[cad]`` extra).

:mod:`.faces` makes the shared edges and the trimmed analytic faces, :mod:`.brep` sews
them and the B-spline pieces into the shape, :mod:`.rhino` writes it as a joined 3DM
Brep (its trims as openNURBS checks them: :mod:`.trims`), :mod:`.export` as STEP;
:mod:`.occ` holds the helpers they share.
"""

from .brep import CAD_KINDS, CadModel, brep_shape, face_kinds
from .faces import CadInputError, TrimCheckError
from .export import CAD_FORMATS, STEP_SCHEMAS, cad_model, read_step, write_cad, write_step
from .occ import require_cad, shape_report
from .rhino import read_3dm_breps, write_3dm

__all__ = ["CAD_KINDS", "CAD_FORMATS", "STEP_SCHEMAS", "CadModel", "CadInputError",
           "TrimCheckError", "brep_shape", "cad_model",
           "face_kinds", "write_cad", "write_step", "write_3dm", "read_step",
           "read_3dm_breps", "shape_report", "require_cad"]
