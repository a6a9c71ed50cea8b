"""The bottom floor: primitives, tolerances and the mesh result type shared by all packages.

``curvenet.core`` may be imported by the graph code (``curvenet.*``) and by both
backends (``curvenet.surfacing``, ``curvenet.neural``); it imports none of them,
and nothing heavier than numpy, scipy and trimesh (never torch).
"""
