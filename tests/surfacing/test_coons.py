import numpy as np
import pytest

from curvenet.surfacing.coons import coons_eval, coons_grid, hermite_blend


def _sides(p, q, f):
    """Boundary samples of the surface f(u, v) on a p x q grid."""
    u, v = np.linspace(0, 1, p + 1), np.linspace(0, 1, q + 1)
    return f(u, 0 * u), f(1 + 0 * v, v), f(u, 1 + 0 * u), f(0 * v, v)


def test_blend_end_conditions():
    h = hermite_blend(np.array([0.0, 0.5, 1.0]))
    np.testing.assert_allclose(h, [0, 0.5, 1])


def test_planar_loop_gives_the_plane():
    # a skewed planar quadrilateral with curved (in-plane) sides: every point stays in
    # the plane n.x = d (Coons is an affine combination of boundary points)
    e1, e2 = np.array([1.0, 0.2, 0.3]), np.array([-0.1, 1.0, 0.5])
    n = np.cross(e1, e2)

    def f(u, v):
        a = u + 0.2 * np.sin(np.pi * v) * u * (1 - u)
        b = v + 0.3 * np.sin(2 * np.pi * u) * v * (1 - v)
        return a[:, None] * e1 + b[:, None] * e2 + [0.5, -1.0, 2.0]

    g = coons_grid(*_sides(7, 5, f))
    d = g.reshape(-1, 3) @ n - np.dot([0.5, -1.0, 2.0], n)
    assert np.abs(d).max() < 1e-12


def test_reproduces_its_four_boundary_curves_exactly():
    rng = np.random.default_rng(1)
    b, r, t, lf = (rng.normal(size=(9, 3)), rng.normal(size=(6, 3)),
                   rng.normal(size=(9, 3)), rng.normal(size=(6, 3)))
    # make the corners agree
    r[0], t[-1], lf[-1], lf[0] = b[-1], r[-1], t[0], b[0]
    g = coons_grid(b, r, t, lf)
    assert np.array_equal(g[:, 0], b) and np.array_equal(g[:, -1], t)
    assert np.array_equal(g[0, :], lf) and np.array_equal(g[-1, :], r)


def test_bilinear_surface_is_reproduced_inside():
    # a hyperbolic paraboloid (bilinear patch) is in the Coons patch's precision set
    # for linear sides and Hermite blending only along the blend: check with the
    # straight sides of z = u v, whose Coons patch is z = h(u) v + u h(v) - h(u) h(v)
    def f(u, v):
        return np.stack([u, v, u * v], -1)

    g = coons_grid(*_sides(8, 8, f))
    u = np.linspace(0, 1, 9)[:, None]
    v = np.linspace(0, 1, 9)[None, :]
    hu, hv = hermite_blend(u), hermite_blend(v)
    np.testing.assert_allclose(g[..., 2], hv * u + hu * v - hu * hv, atol=1e-12)


def test_coons_eval_matches_grid_for_straight_sides():
    def f(u, v):
        return np.stack([u, v, 0.3 * u - 0.2 * v + 0.1], -1)

    sides = _sides(4, 4, f)
    g = coons_grid(*sides)
    uu, vv = np.meshgrid(np.linspace(0, 1, 5), np.linspace(0, 1, 5), indexing="ij")
    e = coons_eval(*sides, np.stack([uu.ravel(), vv.ravel()], 1))
    np.testing.assert_allclose(e, g.reshape(-1, 3), atol=1e-12)


def test_mismatched_opposite_sides_raise():
    a = np.zeros((5, 3))
    with pytest.raises(ValueError, match="opposite sides"):
        coons_grid(a, np.zeros((4, 3)), np.zeros((6, 3)), np.zeros((4, 3)))
