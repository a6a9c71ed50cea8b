"""Tests of curvenet.view.preview: pictures are written, show what they should, and are headless."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import trimesh

from curvenet.core.errors import InvalidParameterError
from curvenet.model.patchset import Patch, PatchSet
from curvenet.view.preview import (HIGHLIGHT_COLOUR, MAX_PREVIEW_FACES, decimate_clustering,
                              patch_polygons, render_preview)
from curvenet.datasets.shapes import box, house


def read_png(path):
    from matplotlib.image import imread

    img = imread(str(path))  # (H, W, 3|4) float in [0, 1]
    return img[..., :3]


def non_white(img):
    return np.any(img < 0.97, axis=-1)


def count_colour(img, rgb, tol=0.03):
    """Pixels within ``tol`` of ``rgb`` in every channel."""
    return int(np.all(np.abs(img - np.asarray(rgb)) < tol, axis=-1).sum())


def test_missing_folder_is_an_error_not_created(tmp_path):
    from curvenet.core.errors import OutputError
    with pytest.raises(OutputError, match="does not exist"):
        render_preview(tmp_path / "sub" / "sphere.png", mesh=trimesh.creation.icosphere())
    assert not (tmp_path / "sub").exists()


def true_patchset(shape):
    return PatchSet(shape.network, [Patch(edges=[e for e, _ in loop]) for loop in shape.faces])


def test_sphere_mesh_picture(tmp_path):
    out = render_preview(tmp_path / "sphere.png",
                         mesh=trimesh.creation.icosphere(subdivisions=3), size=(400, 300))
    assert out == tmp_path / "sphere.png"
    img = read_png(out)
    assert img.shape == (300, 400, 3)
    mask = non_white(img)
    # two spheres, each of radius ~0.3 of a 200 px panel: a few % of the picture at least
    assert 0.05 < mask.mean() < 0.6
    # Lambert shading: the grey varies across the sphere (ambient 0.3 .. full light)
    grey = img[mask].mean(axis=1)
    assert grey.max() - grey.min() > 0.3
    assert sorted(p.name for p in out.parent.iterdir()) == ["sphere.png"]  # no temp file


def test_patches_coloured_and_highlight(tmp_path):
    ps = true_patchset(house())
    plain = read_png(render_preview(tmp_path / "plain.png", patches=ps, view=(20, -60)))
    # distinct patch colours: several hues among the saturated pixels
    from matplotlib.colors import rgb_to_hsv

    hsv = rgb_to_hsv(plain[non_white(plain)])
    hues = np.round(hsv[hsv[:, 1] > 0.3, 0] * 12) % 12
    assert len(np.unique(hues)) >= 3
    assert count_colour(plain, HIGHLIGHT_COLOUR) == 0  # the palette never makes it
    hl = read_png(render_preview(tmp_path / "hl.png", patches=ps, highlight=[1],
                                 view=(20, -60)))
    assert count_colour(hl, HIGHLIGHT_COLOUR) > 200  # 3 px wide outline, ~100 px long
    # a suggested cycle given by edge ids (not in the set) is drawn the same way
    loop = [e for e, _ in house().faces[2]]
    sug = read_png(render_preview(tmp_path / "sug.png", network=ps.network,
                                  highlight=[loop], view=(20, -60)))
    assert count_colour(sug, HIGHLIGHT_COLOUR) > 200


def test_list_of_patches_needs_network(tmp_path):
    shape = box()
    patches = true_patchset(shape).patches
    render_preview(tmp_path / "a.png", patches=patches, network=shape.network)
    with pytest.raises(InvalidParameterError, match="network"):
        render_preview(tmp_path / "b.png", patches=patches)


def test_sketch_strokes(tmp_path, data_dir):
    from curvenet.io.sketch import read_sketch

    sketch = read_sketch(data_dir / "sketches" / "vns" / "car.obj")
    img = read_png(render_preview(tmp_path / "car.png", strokes=sketch, up="y",
                                  title="car"))
    dark = np.all(img < 0.6, axis=-1)  # stroke pixels (grey 0.25 at alpha 0.8)
    assert dark.mean() > 0.003


def test_strokes_and_mesh_together_and_views(tmp_path):
    shape = box()
    img = read_png(render_preview(tmp_path / "x.png", strokes=shape.sketch(),
                                  mesh=shape.reference_mesh(2),
                                  view=[(20, -60), (20, 30), (60, 0)], size=(600, 200)))
    assert img.shape == (200, 600, 3)
    for k in range(3):  # every panel has something in it
        assert non_white(img[:, 200 * k:200 * (k + 1)]).mean() > 0.02


def test_decimation_keeps_the_surface():
    """Clustering 81,920 faces to <= 60,000 moves the surface by a second-order amount.

    The cell is about h = sqrt(2 A / 60000) ~ 0.016 (A ~ 7.9 for this ellipsoid). Merged
    vertices are cell means of points on the surface, so they leave it by about the
    sagitta kappa h^2 / 2 <= 2.8 * 0.016^2 / 2 ~ 3.6e-4 (kappa <= 1 / 0.6^2 at the tips),
    1.8e-4 after normalising by the longest side 2: Hausdorff < 5e-4 and Chamfer (a mean,
    measured 2.3e-5) < 1e-4.
    """
    from curvenet.evaluate import evaluate_mesh

    m = trimesh.creation.icosphere(subdivisions=6)
    m.vertices *= [1.0, 0.8, 0.6]
    v, f = decimate_clustering(m.vertices, m.faces, MAX_PREVIEW_FACES)
    assert MAX_PREVIEW_FACES // 3 < len(f) <= MAX_PREVIEW_FACES
    assert f.min() >= 0 and f.max() == len(v) - 1
    r = evaluate_mesh((v, f), m, n_samples=20_000)
    assert r["chamfer"] < 1e-4 and r["hausdorff"] < 5e-4
    same_v, same_f = decimate_clustering(m.vertices, m.faces[:100], MAX_PREVIEW_FACES)
    assert len(same_f) == 100


def test_patch_polygons_walk_the_cycle():
    shape = box(samples=9)
    net = shape.network
    loop = [e for e, _ in shape.faces[0]]
    (poly,) = patch_polygons(net, sorted(loop, reverse=True))
    assert poly.shape == (4 * 8, 3)  # four curves of 9 points, shared ends once
    # a closed walk: consecutive points (and last -> first) are one curve step apart
    steps = np.linalg.norm(np.diff(np.vstack([poly, poly[:1]]), axis=0), axis=1)
    assert np.allclose(steps, 1.0 / 8)
    # planar face: all points on one plane
    centred = poly - poly.mean(axis=0)
    assert np.linalg.svd(centred, compute_uv=False)[-1] < 1e-12
    # cutting the fan into rings keeps the surface: same area, same plane
    from curvenet.view.preview import _fan

    def area(t):
        return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)

    one, four = _fan(poly), _fan(poly, rings=4)
    assert four.shape == (32 * 7, 3, 3)
    assert area(four).sum() == pytest.approx(area(one).sum(), rel=1e-12)
    assert area(one).sum() == pytest.approx(1.0, rel=1e-12)  # a unit square face
    assert patch_polygons(net, loop[:3]) == []  # an open chain gives no polygon
    with pytest.raises(InvalidParameterError, match="out of range"):
        patch_polygons(net, [999])


def test_bad_arguments(tmp_path):
    m = trimesh.creation.box()
    with pytest.raises(InvalidParameterError, match="nothing to draw"):
        render_preview(tmp_path / "a.png")
    with pytest.raises(InvalidParameterError, match="size"):
        render_preview(tmp_path / "a.png", mesh=m, size=(0, 10))
    with pytest.raises(InvalidParameterError, match="view"):
        render_preview(tmp_path / "a.png", mesh=m, view=(1, 2, 3))
    with pytest.raises(InvalidParameterError, match="up"):
        render_preview(tmp_path / "a.png", mesh=m, up="w")
    with pytest.raises(InvalidParameterError, match="highlight"):
        render_preview(tmp_path / "a.png", patches=true_patchset(box()), highlight=[6])
    assert not any(tmp_path.iterdir())


def test_import_is_light():
    code = ("import sys, curvenet, curvenet.view.preview, curvenet.evaluate; "
            "bad = [m for m in ('matplotlib', 'torch') if m in sys.modules]; "
            "sys.exit(1 if bad else 0)")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


def test_faces_coloured_by_route_and_wires_drawn(tmp_path):
    from curvenet.view import ROUTE_COLOURS, WIRE_COLOUR
    a = trimesh.creation.icosphere(subdivisions=3)
    b = a.copy()
    b.vertices += [3.0, 0.0, 0.0]
    both = trimesh.util.concatenate([a, b])
    route = np.r_[np.zeros(len(a.faces), int), np.ones(len(b.faces), int)]
    wire = np.c_[np.linspace(0, 3, 20), np.zeros(20), np.full(20, 1.5)]
    kw = dict(mesh=both, size=(500, 300), view=(20, -90))
    plain = read_png(render_preview(tmp_path / "plain.png", **kw))
    routed = read_png(render_preview(tmp_path / "routed.png", face_route=route,
                                     routes=("classical", "neural"), wires=[wire], **kw))

    def hue_share(img, rgb):
        # shaded faces keep the hue: the colour's channel order (warm vs cool)
        warm = np.asarray(rgb)[0] > np.asarray(rgb)[2]
        d = img[..., 0] - img[..., 2]
        return float(np.mean((d > 0.15) if warm else (d < -0.15)))

    assert hue_share(plain, ROUTE_COLOURS["neural"]) == 0.0
    assert hue_share(routed, ROUTE_COLOURS["neural"]) > 0.02
    assert hue_share(routed, ROUTE_COLOURS["classical"]) > 0.02
    # the neural sphere (x = 3) is the right one in this view: warm pixels lie right
    warm = (routed[..., 0] - routed[..., 2]) > 0.15
    cols = np.flatnonzero(warm.any(axis=0))
    assert np.median(cols) > routed.shape[1] / 2
    assert count_colour(routed, WIRE_COLOUR, tol=0.05) > 20
    with pytest.raises(InvalidParameterError, match="face_route"):
        render_preview(tmp_path / "bad.png", face_route=route[:-1], routes=("classical",),
                       **kw)


def test_decimation_index_names_the_source_faces():
    m = trimesh.creation.icosphere(subdivisions=5)
    v, f, index = decimate_clustering(m.vertices, m.faces, 2000, return_index=True)
    assert len(index) == len(f) <= 2000
    # each output face lies where its source face was (within a clustering cell ~ 0.06)
    moved = np.linalg.norm(v[f].mean(axis=1) - m.triangles_center[index], axis=1)
    assert moved.max() < 0.15
    _v, small_f, same = decimate_clustering(m.vertices, m.faces[:50], 2000, return_index=True)
    np.testing.assert_array_equal(same, np.arange(50))


def _panels(img, n):
    w = img.shape[1] // n
    return [img[:, k * w:(k + 1) * w] for k in range(n)]


@pytest.mark.parametrize("size", [(900, 700), (400, 700), (1400, 300)])
@pytest.mark.parametrize("shape", ["l_prism", "long_bar"])
def test_the_whole_shape_is_in_every_panel(tmp_path, shape, size):
    # background along all four borders of each panel: nothing is cut off, for any aspect
    from curvenet.datasets import shapes

    s = shapes.l_prism() if shape == "l_prism" else shapes.grid_box(1, size=(10, 1, 0.5))
    img = read_png(render_preview(tmp_path / "p.png", patches=true_patchset(s), size=size))
    for panel in _panels(img, 2):
        ink = non_white(panel)
        assert ink.mean() > 0.01                                  # the shape is drawn
        for border in (ink[0], ink[-1], ink[:, 0], ink[:, -1]):
            assert not border.any()
        # and it fills the panel: its picture spans most of the width or the height
        rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
        assert max(np.ptp(cols) / panel.shape[1], np.ptp(rows) / panel.shape[0]) > 0.6


def test_default_views_are_front_and_back(tmp_path):
    from curvenet.datasets import shapes
    from curvenet.view.preview import DEFAULT_VIEWS

    (e1, a1), (e2, a2) = DEFAULT_VIEWS
    assert (a2 - a1) % 360 == 180 and e2 == -e1            # antipodal cameras
    # the L-prism's top face is seen by the front camera only, its bottom by the back
    s = shapes.l_prism()
    ps = true_patchset(s)
    z = [np.mean([s.network.edges[e].curve[:, 2].mean() for e in p.edges]) for p in ps.patches]
    for face, seen_by in ((int(np.argmax(z)), 0), (int(np.argmin(z)), 1)):
        img = read_png(render_preview(tmp_path / "v.png", patches=ps, highlight=[face]))
        counts = [_orange(p).sum() for p in _panels(img, 2)]
        # the outline is drawn over everything in both; the fill only where the face shows
        assert counts[seen_by] > 5 * counts[1 - seen_by], counts


def _orange(img):
    """The highlight's hue at full saturation, however shaded."""
    from matplotlib.colors import rgb_to_hsv

    hsv = rgb_to_hsv(img)
    return (np.abs(hsv[..., 0] - 0.075) < 0.02) & (hsv[..., 1] > 0.9) & (hsv[..., 2] > 0.5)


def _overlap(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


@pytest.mark.parametrize("width", [360, 200, 900])
def test_legend_entries_do_not_overlap_their_text(width):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from curvenet.view.preview import _legend

    fig = Figure(figsize=(width / 100, 3.0), dpi=100)
    FigureCanvasAgg(fig)
    legend = _legend(fig, ("classical", "neural", "hybrid"), True)
    renderer = fig.canvas.get_renderer()
    fig.draw(renderer)
    texts = [t.get_window_extent(renderer) for t in legend.get_texts()]
    swatches = [h.get_window_extent(renderer) for h in legend.legend_handles]
    assert [t.get_text() for t in legend.get_texts()] == ["classical", "neural", "hybrid",
                                                         "wires"]
    boxes = texts + swatches
    for i, a in enumerate(boxes):
        for b in boxes[i + 1:]:
            assert not _overlap(a, b), (a, b)
    for a, b in zip(swatches, texts):                     # each swatch left of its name
        assert a.x1 <= b.x0
    assert _legend(fig, (), False) is None
