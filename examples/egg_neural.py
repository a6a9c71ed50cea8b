"""Disjoint cross-section strokes form no cycles: auto mode takes the neural route.

Writes ``out/egg.obj`` and ``out/egg.png``. Run: ``python examples/egg_neural.py``
(about a minute or two on a laptop CPU at draft quality; ``--device cuda`` style
runs: pass ``device="cuda"``).
"""

from pathlib import Path

import curvenet
from curvenet.view.preview import render_preview

HERE = Path(__file__).resolve().parent
OUT = Path("out")

result = curvenet.surface(HERE / "data" / "egg_sections.json", quality="draft", progress=True)
print(result.diagnostics["decision"])
result.save(OUT / "egg.obj")
render_preview(OUT / "egg.png", strokes=result.sketch, mesh=result.mesh,
               title="flow-aligned neural surface")
