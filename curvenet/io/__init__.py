"""Readers and writers of every format, one ``read_`` / ``write_`` pair each: sketches,
networks and patch sets, meshes (with per-face routes and wires), report tables."""

from .meshes import MESH_FORMATS, read_obj_wires, write_mesh, write_routed
from .network import read_network, read_patches, write_network, write_patches
from .sketch import (FORMATS, MAX_ABS_COORDINATE, MAX_FILE_BYTES, WRITE_FORMATS,
                     detect_format, read_network_obj, read_sketch, write_network_obj,
                     write_sketch)
from .tables import REPORT_FORMATS, write_table

__all__ = ["FORMATS", "WRITE_FORMATS", "MAX_FILE_BYTES", "MAX_ABS_COORDINATE", "detect_format",
           "read_sketch", "write_sketch", "read_network_obj", "write_network_obj",
           "read_patches", "write_patches", "read_network", "write_network",
           "MESH_FORMATS", "write_mesh", "write_routed", "read_obj_wires",
           "REPORT_FORMATS", "write_table"]
