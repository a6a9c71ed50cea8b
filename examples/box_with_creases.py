"""A rough box sketch -> snapped network -> 6 patches -> Catmull-Clark surface with sharp edges.

Writes ``out/box.obj`` and ``out/box.png``. Run: ``python examples/box_with_creases.py``.
"""

from pathlib import Path

import curvenet
from curvenet.view.preview import render_preview

HERE = Path(__file__).resolve().parent
OUT = Path("out")

result = curvenet.surface(HERE / "data" / "box_sketch.obj")  # auto: classical route
print(result.diagnostics["decision"])
print(f"{len(result.patchset.patches)} patches, timings {result.timings}")
result.save(OUT / "box.obj")
render_preview(OUT / "box.png", strokes=result.sketch, network=result.network,
               mesh=result.mesh, title="rough box sketch, creases kept")
