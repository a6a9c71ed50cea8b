"""A rough lat-long ellipsoid sketch: picture of the patches found, then the smooth surface.

Writes ``out/ellipsoid_patches.png``, ``out/ellipsoid.ply`` and ``out/ellipsoid.png``.
Run: ``python examples/ellipsoid_patches.py``.
"""

from pathlib import Path

import curvenet
from curvenet.view.preview import render_preview

HERE = Path(__file__).resolve().parent
OUT = Path("out")

patchset = curvenet.patches(HERE / "data" / "ellipsoid_sketch.obj")
render_preview(OUT / "ellipsoid_patches.png", network=patchset.network, patches=patchset,
               title=f"{len(patchset.patches)} patches")
result = curvenet.surface(patchset, method="classical")
result.save(OUT / "ellipsoid.ply")
render_preview(OUT / "ellipsoid.png", network=result.network, mesh=result.mesh,
               title="Catmull-Clark limit surface through the curves")
print(f"{len(patchset.patches)} patches; max curve deviation (fraction of the diagonal) "
      f"{result.diagnostics['classical']['max_curve_deviation']:.2e}")
