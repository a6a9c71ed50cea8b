"""The data model: sketches (strokes and labels), curve networks, patch sets."""

from .network import CurveNetwork, Edge, indexed_network
from .patchset import PATCH_SOURCES, Patch, PatchSet
from .sketch import LABELS, Sketch, label_counts

__all__ = ["LABELS", "Sketch", "label_counts", "Edge", "CurveNetwork", "indexed_network",
           "Patch", "PatchSet", "PATCH_SOURCES"]
