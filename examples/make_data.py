"""Regenerate the bundled example sketches in ``examples/data/``.

They are drawn here, by curvenet's own generators: clean analytic networks
(:mod:`curvenet.datasets.shapes`) re-drawn rough (:func:`curvenet.datasets.redraw.rough_sketch`),
and a set of disjoint cross-section strokes that form no cycles. Run::

    python examples/make_data.py
"""

from pathlib import Path

import numpy as np

from curvenet import Sketch
from curvenet.datasets import shapes
from curvenet.io.sketch import write_sketch
from curvenet.datasets.redraw import rough_sketch

HERE = Path(__file__).resolve().parent / "data"


def cross_sections(n: int = 7, seed: int = 0) -> Sketch:
    """Disjoint strokes on an egg-shaped body: ``n`` cross-section rings (open, with a gap)
    and two open profile strokes; no two strokes touch, so no patch cycles exist."""
    rng = np.random.default_rng(seed)
    strokes = []
    for z in np.linspace(-0.8, 0.8, n):
        r = np.sqrt(1 - z * z) * (1 + 0.15 * z)
        t = np.linspace(0.15, 2 * np.pi - 0.15, 60) + rng.uniform(0, 2 * np.pi)
        wob = 1 + 0.01 * np.sin(3 * t + rng.uniform(0, 6))
        strokes.append(np.c_[r * wob * np.cos(t), 0.7 * r * wob * np.sin(t), np.full_like(t, z)])
    for phi in (0.3, 0.3 + np.pi):
        s = np.linspace(-0.95, 0.95, 60) * np.pi / 2
        z, r = np.sin(s), np.cos(s) * (1 + 0.15 * np.sin(s))
        strokes.append(np.c_[1.03 * r * np.cos(phi), 0.7 * 1.03 * r * np.sin(phi), z])
    return Sketch(strokes, metadata={"example": "disjoint cross-sections"})


def main():
    HERE.mkdir(exist_ok=True)
    write_sketch(HERE / "box_sketch.obj", rough_sketch(shapes.box().network, seed=1))
    write_sketch(HERE / "ellipsoid_sketch.obj",
                 rough_sketch(shapes.ellipsoid((1.0, 0.7, 0.5)).network, seed=2))
    write_sketch(HERE / "cylinder_sketch.curves",
                 rough_sketch(shapes.capped_cylinder().network, seed=3))
    write_sketch(HERE / "egg_sections.json", cross_sections())
    for f in sorted(HERE.iterdir()):
        print(f)


if __name__ == "__main__":
    main()
