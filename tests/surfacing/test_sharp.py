import numpy as np
import pytest

from curvenet.datasets import shapes
from curvenet.surfacing.controlmesh import build_control_mesh
from curvenet.surfacing.sharp import dihedral_angles, sharp_structure


def _cm(name):
    s = shapes.SHAPES[name]()
    curves = [e.curve for e in s.network.edges]
    return s, curves, build_control_mesh(curves, s.faces, 4)


def test_box_dihedral_angles_are_right_angles():
    s, curves, cm = _cm("box")
    np.testing.assert_allclose(dihedral_angles(cm, curves), 90.0, atol=1e-6)


@pytest.mark.parametrize("name", ["sphere", "ellipsoid", "torus", "saddle"])
def test_smooth_shapes_detect_no_crease(name):
    s, curves, cm = _cm(name)
    crease, detected, se, corners, dih = sharp_structure(cm, curves)
    assert not crease.any() and detected == []
    # dihedral estimate of smooth lat-long networks: far below the 30 degree default
    assert np.nanmax(dih) < 10.0


def test_cylinder_rims_detected_as_labelled():
    s, curves, cm = _cm("capped_cylinder")
    labelled = {i for i, e in enumerate(s.network.edges) if e.label == "crease"}
    crease, detected, _, _, _ = sharp_structure(cm, curves)
    assert set(np.flatnonzero(crease)) == labelled == set(detected)


def test_labels_win_without_detection():
    s, curves, cm = _cm("sphere")
    crease, detected, se, _, _ = sharp_structure(cm, curves, [0, 1], crease_angle=None)
    assert list(np.flatnonzero(crease)) == [0, 1] and detected == []
    assert len(se) == 2 * 4


def test_l_prism_corners():
    s, curves, cm = _cm("l_prism")
    crease, _, _, corners, _ = sharp_structure(cm, curves)
    assert crease.all()
    assert corners.sum() == 12          # every junction of the L-prism is a corner


def test_bad_crease_input():
    s, curves, cm = _cm("box")
    with pytest.raises(ValueError, match="crease_curves"):
        sharp_structure(cm, curves, [99])
    with pytest.raises(ValueError, match="crease_angle"):
        sharp_structure(cm, curves, crease_angle=-1)
