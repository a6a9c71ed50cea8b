"""The data model: sketches (strokes and labels), curve networks, patch sets."""

from .sketch import LABELS, Sketch, label_counts
from .network import Edge, CurveNetwork, indexed_network
from .patchset import (Patch, PatchSet, PATCH_SOURCES, save_patchset, save_network, load_network_file)

__all__ = ['LABELS', 'Sketch', 'label_counts', 'Edge', 'CurveNetwork', 'indexed_network', 'Patch',
    'PatchSet', 'PATCH_SOURCES', 'save_patchset', 'save_network', 'load_network_file']
