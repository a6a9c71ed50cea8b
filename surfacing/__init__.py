"""Explicit surfaces from patch boundaries (Orbay & Kara 2011; Abbasinejad et al. 2011 Sec. 7).

Arrays in, meshes out: this package knows nothing of graphs.
"""
