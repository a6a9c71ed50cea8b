"""Readers and writers of every format: sketches, networks and patch sets, meshes, report tables."""

from .sketch import (FORMATS, WRITE_FORMATS, MAX_FILE_BYTES, read_sketch, write_sketch, write_network_obj,
    read_network_obj, detect_format, MAX_ABS_COORDINATE)

__all__ = ['FORMATS', 'WRITE_FORMATS', 'MAX_FILE_BYTES', 'read_sketch', 'write_sketch',
    'write_network_obj', 'read_network_obj', 'detect_format', 'MAX_ABS_COORDINATE']
