"""Strokes to a curve network: crossings, T-junctions, gaps, overdraw, corners
(Abbasinejad et al. 2011, Sec. 6.1)."""

from .graph import (DEFAULT_SNAP_TOL, SnapOptions, dangling_vertices, prune_dangling, snap,
                    summary_line)

__all__ = ["SnapOptions", "DEFAULT_SNAP_TOL", "snap", "prune_dangling", "dangling_vertices",
           "summary_line"]
