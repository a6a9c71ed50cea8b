"""Implicit surfaces with PyTorch: flow-aligned neural surfacing (Zhang et al. 2025) and
SharpNet feature functions (Niu et al. 2025).

Strokes (arrays) in, meshes out: this package knows nothing of graphs. torch is
imported by the submodules, never by this file.
"""
