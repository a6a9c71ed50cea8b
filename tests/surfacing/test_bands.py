"""Bands of revolution: seam patches of cylinders, cones and spheres meshed as rings."""

import numpy as np
import pytest
import trimesh

from curvenet.model.network import CurveNetwork
from curvenet.pipeline import surface
from curvenet.surfacing.analytic import AnalyticSurface
from curvenet.surfacing.bands import band_frame


def _circle(r, z, n=65):
    t = np.linspace(0, 2 * np.pi, n)
    return np.c_[r * np.cos(t), r * np.sin(t), np.full(n, z)]


def _pin(tip):
    """A pin as a CAD B-rep draws it: base and rim circles, a seam line up the wall, and
    a tip ending on the axis at (0, 0, 2): a ruling to the apex (``"cone"``) or a
    quarter meridian to the pole (``"dome"``, a hemisphere of radius 1 on the wall)."""
    net = CurveNetwork(np.array([[1.0, 0, 0], [1.0, 0, 1], [0.0, 0, 2]]))
    net.add_edge(0, 0, _circle(1.0, 0.0))
    net.add_edge(1, 1, _circle(1.0, 1.0))
    net.add_edge(0, 1, np.linspace([1.0, 0, 0], [1.0, 0, 1], 17))
    if tip == "cone":
        net.add_edge(1, 2, np.linspace([1.0, 0, 1], [0.0, 0, 2], 17))
    else:
        a = np.linspace(0, np.pi / 2, 33)
        net.add_edge(1, 2, np.c_[np.cos(a), 0 * a, 1 + np.sin(a)])
    return net


def _off_tip(tip, V):
    """Distance of points to the true tip surface: (n,) float64."""
    rho, z = np.hypot(V[:, 0], V[:, 1]), V[:, 2]
    if tip == "cone":                       # rho = 2 - z, unit normal (1, 1) / sqrt 2
        return np.abs(rho + z - 2.0) / np.sqrt(2.0)
    return np.abs(np.hypot(rho, z - 1.0) - 1.0)


@pytest.mark.parametrize("tip", ["cone", "dome"])
def test_a_tip_to_its_apex_or_pole_is_meshed_on_its_surface(tip):
    """The limit surface folds where a seam patch's sides collapse to the apex (the
    pointed pins of the CAD set came out capped flat, F 83-86 against the part); the tip
    is now the cone or the hemisphere over one turn, welded to the wall."""
    res = surface(_pin(tip), method="classical")
    rep = res.diagnostics["classical"]
    kinds = [a and a["kind"] for a in rep["analytic"]]
    tip_patch = kinds.index("cone" if tip == "cone" else "sphere")
    assert tip_patch in rep["bands"] and kinds.index("cylinder") in rep["bands"]
    m = trimesh.Trimesh(res.mesh.vertices, res.mesh.faces, process=False)
    assert m.is_watertight and m.is_winding_consistent
    # the rings (the rim's own vertices are the fit's, shared with the wall)
    top = res.mesh.vertices[res.mesh.vertices[:, 2] > 1.05]
    assert len(top) > 100 and _off_tip(tip, top).max() < 1e-9
    assert np.isclose(top[:, 2].max(), 2.0, atol=1e-12)          # the apex or the pole
    # the volume of the solid: cylinder + cone (pi / 3) or + half ball (2 pi / 3)
    want = np.pi * (1.0 + (1.0 / 3.0 if tip == "cone" else 2.0 / 3.0))
    assert abs(m.volume) == pytest.approx(want, rel=5e-3)


def test_only_a_seam_loop_of_parallels_and_a_meridian_is_a_band():
    net = _pin("cone")
    curves = [np.asarray(e.curve) for e in net.edges]
    cone = AnalyticSurface("cone", np.array([0.0, 0, 1]), np.array([0.0, 0, 1]),
                           np.array([1.0, 0, 0]), 1.0, -np.pi / 4, 0.0)
    got = band_frame(cone, [[(1, True), (3, True), (3, False)]], curves, 1e-9)
    assert got is not None and got[2] == 3 and np.allclose(np.abs(got[1]), [0, 0, 1])
    # no seam: a loop of distinct curves is no band
    assert band_frame(cone, [[(1, True), (3, True)]], curves, 1e-9) is None
    # a rim that is no parallel of the axis (tilted circle)
    tilt = curves[1] @ np.array([[1, 0, 0], [0, np.cos(0.1), np.sin(0.1)],
                                 [0, -np.sin(0.1), np.cos(0.1)]])
    assert band_frame(cone, [[(1, True), (3, True), (3, False)]],
                      [curves[0], tilt, curves[2], curves[3]], 1e-9) is None
    # a seam that winds about the axis is no meridian
    t = np.linspace(0, 1, 17)
    helix = np.c_[(1 - t) * np.cos(t), (1 - t) * np.sin(t), 1 + t]
    assert band_frame(cone, [[(1, True), (3, True), (3, False)]],
                      [curves[0], curves[1], curves[2], helix], 1e-9) is None
