import numpy as np
import pytest

from curvenet.surfacing.sides import group_sides, junction_angles


def _seg(a, b, n=5):
    return np.linspace(np.asarray(a, float), np.asarray(b, float), n)


def test_five_curves_with_a_t_junction_are_four_sides():
    loop = [_seg([0, 0, 0], [0.4, 0, 0]), _seg([0.4, 0, 0], [1, 0, 0]),
            _seg([1, 0, 0], [1, 1, 0]), _seg([1, 1, 0], [0, 1, 0]), _seg([0, 1, 0], [0, 0, 0])]
    assert group_sides(loop) == [[0, 1], [2], [3], [4]]


def test_triangle_and_square_angles():
    tri = [_seg([0, 0, 0], [1, 0, 0]), _seg([1, 0, 0], [0, 1, 0]), _seg([0, 1, 0], [0, 0, 0])]
    np.testing.assert_allclose(junction_angles(tri), [90, 135, 135], atol=1e-9)
    assert len(group_sides(tri)) == 3


def test_smooth_closed_loop_has_no_corner():
    a = np.linspace(0, 2 * np.pi, 33)
    circle = np.stack([np.cos(a), np.sin(a), 0 * a], 1)
    arcs = [circle[i:i + 9] for i in range(0, 32, 8)]
    assert group_sides(arcs) == []


def test_straight_angle_is_validated():
    with pytest.raises(ValueError, match="straight_angle"):
        group_sides([_seg([0, 0, 0], [1, 0, 0])], straight_angle=200)


def test_a_smooth_curve_split_near_a_tight_bend_has_no_corner():
    """Half an ellipse of axes 1 and 0.25, split just before its tip: chords of a tenth of
    each piece's own length read the long piece's sag as a 35 degree turn (a corner);
    at the same arc length on both sides the turn is the curve's own, a few degrees."""
    def arc(t0, t1):
        t = np.linspace(t0, t1, 200)
        return np.c_[np.cos(t), 0.25 * np.sin(t), 0 * t]
    chord = np.c_[np.linspace(1, -1, 50), np.zeros(50), np.zeros(50)]
    angles = junction_angles([arc(np.pi, 0.1), arc(0.1, 0.0), chord])
    assert angles[1] < 5.0 and angles[0] > 90.0 and angles[2] > 90.0
    assert group_sides([arc(np.pi, 0.1), arc(0.1, 0.0), chord]) == [[0, 1], [2]]
