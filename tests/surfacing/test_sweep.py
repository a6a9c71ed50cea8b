"""Swept four-sided patches (surfacing.sweep) against surfaces they must reproduce."""

import numpy as np
import pytest

from curvenet.surfacing.sweep import rotations, similarity_fit, sweep_grid, transport


def _sides(F, u, v):
    """Four sides of the patch ``F(u, v)`` over the parameter samples ``u``, ``v``."""
    return F(u, v[0]), F(u[-1], v), F(u, v[-1]), F(u[0], v)


def _torus(R, r):
    def F(th, ph):
        th, ph = np.broadcast_arrays(np.asarray(th, float), np.asarray(ph, float))
        rho = R + r * np.cos(ph)
        return np.stack([rho * np.cos(th), rho * np.sin(th), r * np.sin(ph)], -1)
    return F


def _sphere(th, ph):
    th, ph = np.broadcast_arrays(np.asarray(th, float), np.asarray(ph, float))
    return np.stack([np.cos(ph) * np.cos(th), np.cos(ph) * np.sin(th), np.sin(ph)], -1)


def _cone(th, h):
    th, h = np.broadcast_arrays(np.asarray(th, float), np.asarray(h, float))
    rho = 1.0 - 0.4 * h
    return np.stack([rho * np.cos(th), rho * np.sin(th), h], -1)


@pytest.mark.parametrize("F, u, v", [
    # a fat torus: the outer half, the inner half (a saddle) and a span over the top,
    # spans of 40 to 200 degrees, sampled unevenly in count
    (_torus(1.0, 0.6), np.linspace(0.2, 1.9, 9), np.linspace(-1.5, 1.5, 7)),
    (_torus(1.0, 0.6), np.linspace(-0.4, 1.8, 11), np.linspace(1.6, 4.6, 5)),
    (_torus(2.0, 0.3), np.linspace(0.0, 0.7, 5), np.linspace(0.3, 2.9, 9)),
    # rings carried along meridians round three quarters of the tube: the meridians'
    # tangents turn a long way, the rings do not turn at all
    (_torus(1.0, 0.35), np.radians(np.linspace(47, 137, 5)), np.linspace(0.92, 5.38, 13)),
    (_sphere, np.linspace(0.1, 1.4, 7), np.linspace(-0.9, 1.1, 9)),       # sphere zone
    (_cone, np.linspace(0.0, 2.5, 9), np.linspace(0.0, 1.0, 5)),          # cone frustum
])
def test_patches_of_surfaces_of_revolution_are_reproduced(F, u, v):
    """Their meridians differ by a rotation about the axis and their parallels by a
    scaling about it: the swept patch is the surface itself, to round-off."""
    g = sweep_grid(*_sides(F, u, v))
    truth = F(u[:, None], v[None, :])
    assert g.shape == truth.shape
    assert np.abs(g - truth).max() < 1e-12


def test_the_two_sweeps_agree_where_the_sides_imply_one_surface_and_part_elsewhere():
    """``spread``: the sweep along u and the one along v meet on a surface of revolution
    (each reproduces it), and part where the four sides are of no one sweep (a patch of
    a hyperbolic paraboloid whose sides bulge by different amounts)."""
    F = _torus(1.0, 0.6)
    u, v = np.linspace(0.2, 1.9, 9), np.linspace(-1.5, 1.5, 7)
    g, gap = sweep_grid(*_sides(F, u, v), spread=True)
    assert gap.shape == g.shape[:-1] and gap.max() < 1e-12
    assert np.array_equal(g, sweep_grid(*_sides(F, u, v)))

    def odd(a, b):
        a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
        return np.stack([a, b, a * b + 0.3 * np.sin(np.pi * a) * (1 + 2 * b)
                         + 0.2 * np.sin(np.pi * b) * a ** 2], -1)

    w = np.linspace(0, 1, 9)
    _, gap = sweep_grid(*_sides(odd, w, w), spread=True)
    assert gap[1:-1, 1:-1].max() > 1e-2
    assert not gap[[0, -1]].any() and not gap[:, [0, -1]].any()


def test_the_sides_are_interpolated_exactly_and_a_plane_stays_flat():
    rng = np.random.default_rng(3)
    u, v = np.linspace(0, 1, 8), np.linspace(0, 1, 6)

    def wavy(a, b):
        return np.stack(np.broadcast_arrays(a + 0.1 * np.sin(5 * b), b + 0.05 * a ** 2, 0 * a),
                        -1)

    b, r, t, lf = _sides(wavy, u, v)
    g = sweep_grid(b, r, t, lf)
    assert np.array_equal(g[:, 0], b) and np.array_equal(g[:, -1], t)
    assert np.array_equal(g[0, 1:-1], lf[1:-1]) and np.array_equal(g[-1, 1:-1], r[1:-1])
    assert np.abs(g[..., 2]).max() < 1e-12                  # the plane z = 0
    # a rigid motion and a scaling of the sides move the patch the same way
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    Q *= np.sign(np.linalg.det(Q))

    def move(x):
        return 3.0 * x @ Q.T + [1.0, -2.0, 0.5]

    assert np.allclose(sweep_grid(*map(move, (b, r, t, lf))), move(g), atol=1e-12)


def test_transport_carries_one_profile_to_the_other_on_the_rails():
    a = np.linspace(0, np.pi, 9)
    A = np.stack([np.cos(a), 0 * a, np.sin(a)], 1)            # half circle in y = 0
    rot = rotations(np.array([0.0, 0.0, 1.0]), [np.pi / 3])[0]
    B = 0.5 * A @ rot.T                                         # turned and shrunk
    s = np.linspace(0, 1, 6)
    ang = s * np.pi / 3
    rad = 1 - 0.5 * s
    rail0 = np.stack([rad * np.cos(ang), rad * np.sin(ang), 0 * s], 1)
    rail1 = -rail0
    out = transport(A, B, rail0, rail1)
    assert np.array_equal(out[0], A) and np.array_equal(out[-1], B)
    assert np.allclose(out[:, 0], rail0) and np.allclose(out[:, -1], rail1)
    k = 2                    # in between: the profile turned and scaled as the rails say
    want = (1 - 0.5 * s[k]) ** 0 * A @ rotations(np.array([0.0, 0, 1]), [ang[k]])[0].T * rad[k]
    assert np.allclose(out[k], want, atol=1e-12)
    s_fit, R = similarity_fit(A, B)
    assert s_fit == pytest.approx(0.5) and np.allclose(R, rot)


def test_a_small_profile_s_own_wobble_is_not_scaled_up_on_the_way():
    """A cone frustum whose small end (a quarter of the large one) is drawn with a bump:
    between the ends the patch stays within the bump's height of the true cone. Carried
    as a part of the small profile's shape, the bump grew with the profile (to 1.3 times
    its height halfway)."""
    th = np.linspace(0, np.pi, 17)

    def half_ring(rad, h):
        return np.stack([rad * np.cos(th), rad * np.sin(th), np.full_like(th, h)], 1)

    u = np.linspace(0, 1, 9)
    rad = 1.0 - 0.75 * u
    bump = 0.01
    B = half_ring(0.25, 1.0) + bump * np.sin(th)[:, None] ** 2 * [0, 0, 1]
    out = transport(half_ring(1.0, 0.0), B, np.stack([rad, 0 * u, u], 1),
                    np.stack([-rad, 0 * u, u], 1))
    truth = np.stack([half_ring(r, h) for r, h in zip(rad, u)])
    off = np.linalg.norm(out - truth, axis=-1).max(axis=-1)
    assert off[-1] == pytest.approx(bump)
    assert off.max() <= bump * (1 + 1e-9)


def test_degenerate_profiles_give_finite_patches():
    """A closed profile (zero chord) and profiles a half turn apart are still patches."""
    t = np.linspace(0, 2 * np.pi, 13)
    ring = np.stack([np.cos(t), np.sin(t), 0 * t], 1)
    up = np.linspace(0, 1, 5)[:, None] * [0, 0, 1]
    g = sweep_grid(ring, ring[-1] + up, ring + [0, 0, 1], ring[0] + up)   # a tube, one seam
    assert np.isfinite(g).all()
    assert np.abs(np.hypot(g[..., 0], g[..., 1]) - 1).max() < 1e-12
    a = np.linspace(0, np.pi, 7)
    bump = np.stack([0 * a, -np.cos(a), 0.3 * np.sin(a)], 1)   # up at x = 0, down at x = 1
    dip = bump * [1, 1, -1] + [1, 0, 0]
    x = np.linspace(0, 1, 5)[:, None]
    g = sweep_grid(bump[0] + x * [1, 0, 0], dip, bump[-1] + x * [1, 0, 0], bump)
    assert np.isfinite(g).all()
    assert np.abs(g[2, :, 2]).max() < 0.3                      # blended through, not turned out


def test_a_crest_that_becomes_a_trough_is_blended_all_the_way():
    """Profiles a half turn apart about their chord with straight rails: the rails say
    they did not turn, and the rows pass from the crest to the trough evenly, the one
    before the last next to the trough (not the crest carried unturned and then the
    trough at the last row)."""
    a = np.linspace(0, np.pi, 7)
    bump = np.stack([0 * a, -np.cos(a), 0.3 * np.sin(a)], 1)
    dip = bump * [1, 1, -1] + [1, 0, 0]
    x = np.linspace(0, 1, 9)[:, None]
    out = transport(bump, dip, bump[0] + x * [1, 0, 0], bump[-1] + x * [1, 0, 0])
    assert np.allclose(out[:, 3, 2], np.linspace(0.3, -0.3, 9), atol=1e-12)


def test_a_batch_of_patches_is_each_patch_alone():
    rng = np.random.default_rng(7)
    sides = []
    for _ in range(5):
        b, r, t, lf = rng.normal(size=(9, 3)), rng.normal(size=(6, 3)), rng.normal(size=(9, 3)), \
            rng.normal(size=(6, 3))
        r[0], lf[0], t[0], r[-1] = b[-1], b[0], lf[-1], t[-1]
        sides.append((b, r, t, lf))
    batch = sweep_grid(*(np.stack(s) for s in zip(*sides)))
    for k, s in enumerate(sides):
        assert np.allclose(batch[k], sweep_grid(*s), atol=1e-13)


def test_axis_and_angle_of_rotations_round_trip_up_to_a_half_turn():
    """The turn between two profiles is read off their best rotation; near a half turn
    its skew part vanishes, and the axis must come from the symmetric part."""
    from curvenet.surfacing.sweep import _axis_angle
    rng = np.random.default_rng(2)
    for angle in [0.0, 1e-12, 1e-6, 0.5, np.pi / 2, 2.5, np.pi - 1e-6, np.pi - 1e-12, np.pi]:
        k = rng.normal(size=3)
        k /= np.linalg.norm(k)
        R = rotations(k, [angle])[0]
        axis, got = _axis_angle(R)
        assert np.abs(rotations(axis, [got])[0] - R).max() < 1e-12


def test_the_rails_decide_which_way_round_the_profiles_turned():
    """Two meridians of a torus 200 degrees apart: their best rotation turns 160 degrees
    the short way; the rings (the rails) go the long way, and so does the patch."""
    F = _torus(1.0, 0.4)
    u, v = np.radians(np.linspace(20, 220, 17)), np.linspace(-1.2, 1.2, 7)
    g = sweep_grid(*_sides(F, u, v))
    assert np.abs(g - F(u[:, None], v[None, :])).max() < 1e-12
