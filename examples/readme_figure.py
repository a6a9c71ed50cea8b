"""The picture at the top of the README: a rough sketch, its patches, its surface.

Writes ``docs/images/ellipsoid_pipeline.png`` (three panels, one per stage, drawn with
:func:`curvenet.view.render_preview` and set side by side). Run from the repository
root: ``python examples/readme_figure.py``.
"""

import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

import curvenet
from curvenet.view import render_preview

HERE = Path(__file__).resolve().parent
OUT = HERE.parent / "docs" / "images" / "ellipsoid_pipeline.png"
VIEW = (25.0, -60.0)
SIZE = (520, 420)


def _crop(path: Path) -> Image.Image:
    """The picture without its white margin (a few pixels kept)."""
    img = Image.open(path).convert("RGB")
    dark = np.asarray(img).min(axis=2) < 245
    rows, cols = np.flatnonzero(dark.any(axis=1)), np.flatnonzero(dark.any(axis=0))
    pad = 6
    return img.crop((max(cols[0] - pad, 0), max(rows[0] - pad, 0),
                     min(cols[-1] + pad, img.width), min(rows[-1] + pad, img.height)))


def main():
    result = curvenet.surface(HERE / "data" / "ellipsoid_sketch.obj", method="classical")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        panels = [
            render_preview(tmp / "1.png", strokes=result.sketch, view=VIEW, size=SIZE,
                           title=f"1. rough sketch: {len(result.sketch.strokes)} strokes"),
            render_preview(tmp / "2.png", network=result.network, patches=result.patchset,
                           view=VIEW, size=SIZE,
                           title=f"2. snapped network, {len(result.patchset.patches)} patches"),
            render_preview(tmp / "3.png", strokes=result.sketch, mesh=result.mesh, view=VIEW,
                           size=SIZE, title="3. limit surface through the strokes"),
        ]
        images = [_crop(p) for p in panels]
    height = max(im.height for im in images)
    sheet = Image.new("RGB", (sum(im.width for im in images), height), "white")
    x = 0
    for im in images:
        sheet.paste(im, (x, (height - im.height) // 2))
        x += im.width
    OUT.parent.mkdir(parents=True, exist_ok=True)
    sheet.save(OUT, optimize=True)
    print(f"{OUT}: {sheet.width} x {sheet.height}, {OUT.stat().st_size // 1024} KB")


if __name__ == "__main__":
    main()
