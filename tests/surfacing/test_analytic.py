"""Analytic faces: fits of planes, cylinders, cones, spheres and tori to boundary curves."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from curvenet.surfacing.analytic import AnalyticSurface, fit_analytic, fit_circle
from curvenet.surfacing.sectors import surface_boundaries

T = np.linspace(0, 2 * np.pi, 33)
Q = np.linspace(0, np.pi / 2, 17)
S = np.linspace(0, 1, 17)


def _circle(r, z):
    return np.c_[r * np.cos(T), r * np.sin(T), np.full_like(T, z)]


def _line(a, b):
    return np.asarray(a, float) + S[:, None] * (np.asarray(b, float) - a)


#: boundary curves of one face of each kind, and the parameters they imply
FACES = {
    "plane": ([_circle(1.0, 0.0)], {}),
    # a bore wall: two circles and the seam line between them
    "cylinder": ([_circle(1.0, 1.0), _circle(1.0, 0.0), _line((1, 0, 1), (1, 0, 0))],
                 {"radius": 1.0}),
    # a quarter-round fillet along x: two lines and two quarter arcs
    "cylinder-fillet": ([np.c_[0 * Q, 0.2 * np.cos(Q), 0.2 * np.sin(Q)],
                         _line((0, 0.2, 0), (1, 0.2, 0)),
                         np.c_[1 + 0 * Q, 0.2 * np.cos(Q), 0.2 * np.sin(Q)],
                         _line((0, 0, 0.2), (1, 0, 0.2))], {"radius": 0.2}),
    # a countersink: a frustum of semi-angle atan(0.5)
    "cone": ([_circle(1.0, 1.0), _circle(0.5, 0.0), _line((1, 0, 1), (0.5, 0, 0))],
             {"minor": np.arctan(0.5)}),
    # a rounded box corner: three quarter circles at right angles
    "sphere": ([np.c_[np.cos(Q), np.sin(Q), 0 * Q], np.c_[0 * Q, np.cos(Q), np.sin(Q)],
                np.c_[np.sin(Q), 0 * Q, np.cos(Q)]], {"radius": 1.0}),
    # a revolved fillet: two parallels and a meridian quarter arc as the seam
    "torus": ([_circle(2.0, 0.5), _circle(2.5, 0.0),
               np.c_[2 + 0.5 * np.cos(Q), 0 * Q, 0.5 * np.sin(Q)]],
              {"radius": 2.0, "minor": 0.5}),
}


def _moved(curves, seed=3):
    R = Rotation.from_rotvec(np.random.default_rng(seed).normal(size=3))
    return [R.apply(c) * 7.0 + [1.0, -2.0, 3.0] for c in curves], 7.0


@pytest.mark.parametrize("name", sorted(FACES))
def test_each_kind_is_found_exactly_in_any_frame(name):
    curves, params = FACES[name]
    curves, scale = _moved(curves)
    s = fit_analytic(curves, tol=1e-9 * scale, diagonal=5.0 * scale)
    assert s is not None and s.kind == name.split("-")[0]
    # the residual is measured at every sample, and the surface is the true one
    assert s.residual < 1e-9 * scale
    assert np.abs(s.distance(np.concatenate(curves))).max() == pytest.approx(s.residual)
    for key, value in params.items():
        length = key == "radius" or name == "torus"      # a cone's minor is an angle
        want = value * (scale if length else 1.0)
        assert getattr(s, key) == pytest.approx(want, rel=1e-9)


def test_a_saddle_boundary_is_no_elementary_surface():
    # four lines of the hyperbolic paraboloid z = x y / 2: on none of the kinds
    u = np.linspace(-1, 1, 17)
    curves = [np.c_[u, -1 + 0 * u, -u / 2], np.c_[1 + 0 * u, u, u / 2],
              np.c_[u, 1 + 0 * u, u / 2], np.c_[-1 + 0 * u, u, -u / 2]]
    assert fit_analytic(curves, tol=1e-5, diagonal=3.0) is None


def test_a_slightly_bent_curve_is_refused_at_the_tolerance():
    curves = [c.copy() for c in FACES["cylinder"][0]]
    curves[2][8, 0] += 1e-4                     # one seam sample off the cylinder by 1e-4
    assert fit_analytic(curves, tol=1e-5, diagonal=2.0, kinds=("cylinder",)) is None
    assert fit_analytic(curves, tol=2e-4, diagonal=2.0, kinds=("cylinder",)).kind == "cylinder"


def test_a_loop_of_too_few_samples_is_no_curved_surface():
    # three curves of three samples (mingzou/Boat, flowrep/espresso): six points lie on
    # some cone and eight on some torus whatever they are, and an arc through three says
    # nothing of the curve between them; the same loops drawn with five samples a curve
    # are free-form too
    rng = np.random.default_rng(0)
    for samples in (3, 5):
        for _ in range(20):
            c = rng.normal(size=(3, 3))
            s = np.linspace(0, 1, samples)[:, None]
            curves = [c[i] + s * (c[(i + 1) % 3] - c[i])
                      + 0.15 * rng.normal(size=(samples, 3)) * (s * (1 - s) > 0)
                      for i in range(3)]
            d = float(np.linalg.norm(np.ptp(np.concatenate(curves), axis=0)))
            assert fit_analytic(curves, tol=1e-5 * d, diagonal=d) is None
    # a planar loop of three-sample curves is still its plane
    plane = [np.c_[cu, np.zeros(3)] for cu in ([[0, 0], [1, 0.2], [2, 0]],
                                               [[2, 0], [1.2, 1], [1, 2]],
                                               [[1, 2], [0.3, 1], [0, 0]])]
    assert fit_analytic(plane, tol=1e-6, diagonal=3.0).kind == "plane"


def test_huge_radii_are_refused():
    # a shallow arc of radius 1000 on a face of size 1 is taken for no cylinder
    a = np.linspace(-5e-4, 5e-4, 17)
    arc = np.c_[1000 * np.sin(a), 1000 * (np.cos(a) - 1), 0 * a]
    curves = [arc, arc + [0, 0, 1], _line(arc[-1], arc[-1] + [0, 0, 1])]
    assert fit_analytic(curves, tol=1e-9, diagonal=1.5, kinds=("cylinder",)) is None



def _cone_loop(semi, drawn):
    """A closed, non-planar loop once around the apex of a cone of semi-angle ``semi``
    (apex at the origin, axis z), split in four curves as a network gives it: half of it
    a circle about the axis when ``drawn``, else free-form all round."""
    t = np.linspace(0, 2 * np.pi, 129)
    rho = 1.0 + 0.3 * np.sin(t) ** 2 * (t > np.pi if drawn else 1.0 + np.cos(t) / 3)
    loop = np.c_[rho * np.cos(t), rho * np.sin(t), rho / np.tan(semi)]
    return [loop[i:i + 33] for i in range(0, 128, 32)], loop[:-1]


def test_a_free_form_loop_near_a_cone_is_no_cone():
    # a nearly flat free-form loop lies on a wide cone through no circle, ruling or apex
    curves, _ = _cone_loop(np.radians(89.5), drawn=False)
    assert fit_analytic(curves, tol=1e-9, diagonal=3.0, kinds=("cone",)) is None


def test_a_cone_face_around_its_apex_is_refused_given_its_loops():
    # the face inside the loop holds the apex, which no trimmed face can carry
    curves, loop = _cone_loop(np.radians(60.0), drawn=True)
    s = fit_analytic(curves, tol=1e-9, diagonal=3.0, kinds=("cone",))
    assert s is not None and s.kind == "cone"           # the boundary alone lies on it
    assert fit_analytic(curves, tol=1e-9, diagonal=3.0, kinds=("cone",), loops=[loop]) is None


def test_a_cone_band_and_a_cone_ending_at_its_apex_are_kept_given_their_loops():
    curves = FACES["cone"][0]
    top, bottom, seam = curves
    band = np.concatenate([top[:-1], seam[:-1], bottom[::-1][:-1], seam[::-1][:-1]])
    s = fit_analytic(curves, tol=1e-9, diagonal=3.0, loops=[band])
    assert s is not None and s.kind == "cone"           # winding 0 about the axis
    # a pin's point: the base circle and a seam to the apex
    apex_seam = _line((0.5, 0, 0), (0, 0, -1))
    point = np.concatenate([bottom[:-1], apex_seam[:-1], apex_seam[::-1][:-1]])
    s = fit_analytic([bottom, apex_seam], tol=1e-9, diagonal=3.0, kinds=("cone",),
                     loops=[point])
    assert s is not None and s.kind == "cone"


def _torus_patch(major):
    """Two meridian arcs (80 degrees apart) and two parallels of a torus of minor radius 1."""
    a = np.linspace(-1.0, 1.0, 17)
    phi = np.radians(np.linspace(0, 80, 17))
    meridian = np.c_[major + np.cos(a), 0 * a, np.sin(a)]
    turn = Rotation.from_euler("z", 80, degrees=True).apply(meridian)
    rho = major + np.cos(1.0)
    par = np.c_[rho * np.cos(phi), rho * np.sin(phi), np.full(17, np.sin(1.0))]
    return [meridian, turn, par, par * [1, 1, -1]]


def test_a_torus_that_crosses_itself_is_refused():
    # a spindle torus (major radius 0.3 < minor 1) holds singular points on its axis
    got = fit_analytic(_torus_patch(3.0), tol=1e-9, diagonal=8.0, kinds=("torus",))
    assert got is not None and got.radius == pytest.approx(3.0, rel=1e-9)
    assert fit_analytic(_torus_patch(0.3), tol=1e-9, diagonal=3.0, kinds=("torus",)) is None


def _tilted_ring(phi, R, r, height, tilt, towards, psi):
    """Tube angles ``psi (n,)`` where the plane ``z = height + tan(tilt) x . (cos towards,
    sin towards)`` cuts the meridians at ``phi (n,)`` (Newton from ``psi``)."""
    k, c = np.tan(tilt), np.cos(phi - towards)
    for _ in range(60):
        g = r * np.sin(psi) - height - k * (R + r * np.cos(psi)) * c
        psi = psi - g / (r * np.cos(psi) + k * r * np.sin(psi) * c)
    return psi


@pytest.mark.parametrize("span, tilt", [(130.0, 7.0), (190.0, 3.0)])
def test_a_torus_face_between_meridians_and_rings_of_tilted_planes(span, tilt):
    """Two meridian arcs and two rings cut by tilted planes, which are no circles: the
    meridians' planes meet in the axis, and the face is found to be the torus in any
    frame (the first was refused when only the arcs' own axes and the principal axes
    were tried)."""
    R, r = 1.0, 0.43
    phi = np.linspace(0.0, np.radians(span), 33)

    def on_torus(f, p):
        return np.c_[(R + r * np.cos(p)) * np.cos(f), (R + r * np.cos(p)) * np.sin(f),
                     r * np.sin(p)]
    t = np.radians(tilt)
    low = _tilted_ring(phi, R, r, -0.1, t, 0.3, np.full_like(phi, -0.3))
    high = _tilted_ring(phi, R, r, 0.25, t, 2.0, np.full_like(phi, 1.0))
    v = np.linspace(0.0, 1.0, 17)
    curves = [on_torus(phi, low),
              on_torus(np.full_like(v, phi[-1]), low[-1] + v * (high[-1] - low[-1])),
              on_torus(phi, high)[::-1],
              on_torus(np.zeros_like(v), high[0] + v * (low[0] - high[0]))]
    assert [fit_circle(c) is not None for c in curves] == [False, True, False, True]
    moved, scale = _moved(curves)
    got = fit_analytic(moved, tol=1e-7 * scale, diagonal=3.0 * scale)
    assert got is not None and got.kind == "torus"
    assert (got.radius, got.minor) == pytest.approx((R * scale, r * scale), rel=1e-6)


@pytest.mark.parametrize("name", ["cylinder", "cone", "sphere", "torus"])
def test_projection_lands_on_the_surface_and_is_closest(name):
    curves, _ = FACES[name]
    s = fit_analytic(curves, tol=1e-9, diagonal=5.0)
    rng = np.random.default_rng(0)
    p = np.concatenate(curves) + rng.normal(scale=0.05, size=(sum(map(len, curves)), 3))
    q = s.project(p)
    assert np.abs(s.distance(q)).max() < 1e-12
    # the closest point: as far as the signed distance says
    assert np.allclose(np.linalg.norm(p - q, axis=1), np.abs(s.distance(p)), atol=1e-12)


def test_round_trip_of_the_dict():
    s = fit_analytic(FACES["torus"][0], tol=1e-9, diagonal=5.0)
    t = AnalyticSurface.from_dict(s.to_dict())
    p = np.random.default_rng(1).normal(size=(10, 3))
    assert np.array_equal(s.distance(p), t.distance(p))


def test_fit_circle_tells_arcs_from_lines():
    c, n, r = fit_circle(FACES["torus"][0][2])
    assert r == pytest.approx(0.5) and abs(n[1]) == pytest.approx(1.0)
    assert fit_circle(_line((0, 0, 0), (1, 2, 3))) is None


def test_a_bore_wall_mesh_lies_on_its_cylinder():
    """A tube with one seam (the loop walks the seam twice): the least-squares
    Catmull-Clark fit sinks between the circles (the swept fit much less); the analytic
    face puts the mesh back on the cylinder."""
    top, bottom, seam = _circle(1.0, 1.0), _circle(1.0, 0.0), _line((1, 0, 1), (1, 0, 0))
    boundary = [[[(0, True), (2, True), (1, False), (2, False)]]]
    free = surface_boundaries([top, bottom, seam], boundary, analytic_tol=None, subdiv=2,
                              fit="lsq")
    swept = surface_boundaries([top, bottom, seam], boundary, analytic_tol=None, subdiv=2)
    assert swept.report["fit"] == "sweep"
    assert np.abs(np.hypot(*swept.vertices[:, :2].T) - 1).max() < 0.05
    on = surface_boundaries([top, bottom, seam], boundary, subdiv=2)
    assert np.abs(np.hypot(*free.vertices[:, :2].T) - 1).max() > 0.05
    assert np.abs(np.hypot(*on.vertices[:, :2].T) - 1).max() < 1e-12
    assert on.report["analytic"][0]["kind"] == "cylinder"
