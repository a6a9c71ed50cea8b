"""Roughness (local-quadric residual) of surfaces: an oracle on spheres with and without
bumps of known amplitude, independent of scale and of the triangulation."""

import numpy as np
import pytest
import trimesh

from curvenet.core.errors import InvalidParameterError
from curvenet.evaluate.smoothness import roughness


def _bumpy(amp, level=5):
    s = trimesh.creation.icosphere(level)
    v = s.vertices
    n = v / np.linalg.norm(v, axis=1)[:, None]
    return v + amp * (np.sin(40 * v[:, 0]) * np.sin(40 * v[:, 1]))[:, None] * n, s.faces


def test_smooth_surfaces_are_near_zero_at_any_scale_and_triangulation():
    ico = trimesh.creation.icosphere(5)
    a = roughness(ico, n_centres=1000)
    assert a["median"] < 1e-3 and a["centres"] == 1000
    b = roughness((ico.vertices * 300.0, ico.faces), n_centres=1000)
    assert b["median"] == pytest.approx(a["median"], rel=1e-6)
    assert b["radius"] == pytest.approx(300.0 * a["radius"])
    # the same sphere as a marching-cubes mesh (another triangulation)
    from skimage.measure import marching_cubes
    x = np.linspace(-1.2, 1.2, 97)
    X = np.stack(np.meshgrid(x, x, x, indexing="ij"), axis=-1)
    v, f, _, _ = marching_cubes(np.linalg.norm(X, axis=-1) - 1.0, 0.0,
                                spacing=(x[1] - x[0],) * 3)
    assert roughness((v, f), n_centres=1000)["median"] < 1e-3


def test_bumps_raise_it_with_their_amplitude():
    smooth = roughness(_bumpy(0.0), n_centres=1000)["median"]
    rough = [roughness(_bumpy(a), n_centres=1000)["median"] for a in (0.002, 0.005, 0.01)]
    assert smooth < rough[0] < rough[1] < rough[2]
    assert rough[1] > 5 * smooth
    # well above the facets' floor the residual is linear in the bumps' amplitude
    assert rough[2] / rough[1] == pytest.approx(2.0, rel=0.1)


def test_a_crease_shows_in_the_upper_percentile_only():
    box = trimesh.creation.box().subdivide().subdivide().subdivide()
    r = roughness(box, n_centres=2000)
    assert r["median"] < 1e-6 and r["p90"] > 0.02


def test_each_centre_is_reported_where_it_is():
    # the unit box's faces are flat: the centres whose ball holds a crease are those
    # within the ball's radius of an edge, where two coordinates are near +-0.5
    box = trimesh.creation.box().subdivide().subdivide().subdivide()
    r = roughness(box, n_centres=2000)
    values, points = r["values"], r["points"]
    assert values.shape == (r["centres"],) and points.shape == (r["centres"], 3)
    assert np.median(values) == r["median"]
    gap = np.sort(0.5 - np.abs(points), axis=1)[:, 1]     # distance to the nearest edge
    assert (gap[values > 0.02] < r["radius"]).all()
    assert (values[gap > r["radius"]] < 1e-6).all()


@pytest.mark.parametrize("kw", [dict(radius=0.0), dict(radius=0.7), dict(n_centres=0)])
def test_bad_options_are_refused(kw):
    with pytest.raises(InvalidParameterError):
        roughness(trimesh.creation.icosphere(2), **kw)
