"""Explicit surfaces from patch boundaries (Orbay & Kara 2011; Abbasinejad et al. 2011 Sec. 7).

Arrays in, meshes out: this package knows nothing of graphs.

Main entry points: :func:`surface_loops` (Coons patches -> Catmull-Clark control
mesh -> limit surface fitted to the curves, with creases) and
:func:`soapfilm_loops` (the soap-film baseline).
"""

from .api import (DEFAULT_RESOLUTION, DEFAULT_SUBDIV, PatchMeshResult, check_loops_options,
                  soapfilm_loops, surface_loops)
from .catmull_clark import euler_characteristic, subdivide, subdivision_step
from .coons import coons_eval, coons_grid
from .controlmesh import ControlMesh, build_control_mesh
from .limit import limit_matrix, tangent_matrices
from .sides import group_sides
from .soap import soapfilm_patch

__all__ = [
    "DEFAULT_RESOLUTION", "DEFAULT_SUBDIV", "PatchMeshResult", "check_loops_options",
    "surface_loops", "soapfilm_loops",
    "soapfilm", "euler_characteristic", "subdivide", "subdivision_step", "coons_grid",
    "coons_eval", "ControlMesh", "build_control_mesh", "limit_matrix", "tangent_matrices",
    "group_sides", "soapfilm_patch",
]


def soapfilm(curves, loops, **kwargs):
    """Soap-film baseline as ``(vertices (n, 3) float64, faces (f, 3) int64)``.

    Same inputs as :func:`soapfilm_loops`.
    """
    res = soapfilm_loops(curves, loops, **kwargs)
    return res.vertices, res.faces
