import numpy as np
import pytest

from curvenet.core.geometry import arc_length_params
from curvenet.surfacing.soap import (_cotan_laplacian, disk_triangulation, soapfilm_mesh,
                                     soapfilm_patch)


def test_disk_triangulation_border_and_orientation():
    uv, F = disk_triangulation(40)
    a, b, c = uv[F[:, 0]], uv[F[:, 1]], uv[F[:, 2]]
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    assert (area > 0).all()
    # total area is the inscribed 40-gon's
    np.testing.assert_allclose(0.5 * area.sum(), 0.5 * 40 * np.sin(2 * np.pi / 40), rtol=1e-12)


def test_planar_boundary_gives_the_plane():
    a = np.linspace(0, 2 * np.pi, 50, endpoint=False)
    B = np.stack([np.cos(a) * (1 + 0.3 * np.cos(3 * a)), np.sin(a), 0 * a], 1)
    B = B @ np.array([[1, 0, 0], [0, 0.6, 0.8], [0, -0.8, 0.6]])     # tilted plane
    V, F = soapfilm_patch(B)
    n = np.array([0, -0.8, 0.6])
    assert np.abs(V @ n).max() < 1e-12
    np.testing.assert_array_equal(V[:50], B)


def test_interior_is_harmonic():
    a = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    B = np.stack([np.cos(a), np.sin(a), 0.3 * np.cos(2 * a)], 1)
    V, F = soapfilm_patch(B)
    t = arc_length_params(np.concatenate([B, B[:1]]))[:-1]
    uv, F2 = disk_triangulation(40, t)
    np.testing.assert_array_equal(F, F2)
    Lap = _cotan_laplacian(uv, F)
    assert np.abs((Lap @ V)[40:]).max() < 1e-10
    # z = 0.3 (x^2 - y^2) is harmonic: the discrete solution is close to it inside
    x, y = uv[:, 0], uv[:, 1]
    assert np.abs(V[:, 2] - 0.3 * (x * x - y * y)).max() < 0.02


def test_mesh_welds_shared_curves():
    t = np.linspace(0, 1, 5)[:, None]
    c = [t * [1, 0, 0], [1, 0, 0] + t * [0, 1, 0], [1, 1, 0] - t * [1, 0, 0],
         [0, 1, 0] - t * [0, 1, 0], [1, 0, 0] + t * [1, 0, 0], [2, 0, 0] + t * [-1, 1, 0]]
    loops = [[(0, True), (1, True), (2, True), (3, True)], [(4, True), (5, True), (1, False)]]
    V, F, fp = soapfilm_mesh(c, loops, resolution=8)
    import trimesh
    m = trimesh.Trimesh(V, F, process=False)
    assert m.is_winding_consistent
    assert len(trimesh.graph.split(m, only_watertight=False)) == 1
    assert set(fp.tolist()) == {0, 1}


def test_bad_boundary():
    with pytest.raises(ValueError, match="boundary"):
        soapfilm_patch(np.zeros((2, 3)))
