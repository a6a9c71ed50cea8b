"""Tests of curvenet.review.scene: the arrays the review page draws (no viser needed).

Oracles: the analytic shapes' faces (a unit box's face is a unit square, area 1), the
camera's field of view (50 degrees, viser's default).
"""

from __future__ import annotations

import numpy as np
import pytest

from curvenet.core.errors import InvalidParameterError
from curvenet.datasets import shapes
from curvenet.review.scene import camera_pose, patch_mesh, polyline_segments


def _area(v, f):
    t = v[f].astype(np.float64)
    return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum()


def test_patch_mesh_fills_each_face_exactly():
    shape = shapes.box(samples=9)
    for face in shape.faces:
        v, f = patch_mesh(shape.network, [e for e, _ in face])
        assert v.dtype == np.float32 and f.dtype == np.uint32
        assert f.shape == (4 * 8, 3) and len(v) == 4 * 8 + 1     # the loop's points + centroid
        assert _area(v, f) == pytest.approx(1.0, rel=1e-6)      # float32 corners
    # the L-shaped top of the prism is star-shaped from its centroid: the fan is exact
    prism = shapes.l_prism()
    top = max(prism.faces, key=len)
    v, f = patch_mesh(prism.network, [e for e, _ in top])
    assert _area(v, f) == pytest.approx(3.0, rel=1e-5)


def test_patch_mesh_refuses_an_open_chain():
    shape = shapes.box()
    loop = [e for e, _ in shape.faces[0]]
    with pytest.raises(InvalidParameterError, match="no closed loop"):
        patch_mesh(shape.network, loop[:3])


def test_polyline_segments():
    a = np.zeros((3, 3))
    a[:, 0] = [0, 1, 2]
    seg = polyline_segments([a, a[:2] + 5])
    assert seg.shape == (3, 2, 3) and seg.dtype == np.float32
    np.testing.assert_array_equal(seg[1], [[1, 0, 0], [2, 0, 0]])
    assert polyline_segments([]).shape == (0, 2, 3)
    with pytest.raises(InvalidParameterError):
        polyline_segments([np.zeros((1, 3))])


@pytest.mark.parametrize("up", ["x", "y", "z"])
def test_camera_sees_every_point_from_above(up):
    rng = np.random.default_rng(0)
    pts = rng.normal(size=(500, 3)) * [3.0, 1.0, 0.2] + 10.0
    pos, look, upv = camera_pose(pts, up)
    np.testing.assert_allclose(look, 0.5 * (pts.min(0) + pts.max(0)))
    view = (look - pos) / np.linalg.norm(look - pos)
    assert np.dot(-view, upv) == pytest.approx(np.sin(np.radians(20.0)))  # 20 deg above
    rays = pts - pos
    cos = rays @ view / np.linalg.norm(rays, axis=1)
    assert np.degrees(np.arccos(cos.min())) < 25.0       # all inside half of a 50 deg view


def test_camera_bad_input():
    with pytest.raises(InvalidParameterError, match="up"):
        camera_pose(np.zeros((2, 3)), "w")
    with pytest.raises(InvalidParameterError, match="finite"):
        camera_pose(np.full((2, 3), np.nan))
