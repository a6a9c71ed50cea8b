"""Small handles of a grid function's zero set (:mod:`neural.topology`), against
hand-built solids whose surfaces' Euler characteristics are known."""

import numpy as np
import pytest
from scipy import ndimage

from neural.extract import marching_cubes_world
from neural.topology import remove_small_handles, simple_points


def _field(solid: np.ndarray) -> np.ndarray:
    """Signed distance of a voxel solid (negative inside), float32."""
    return (ndimage.distance_transform_edt(~solid)
            - ndimage.distance_transform_edt(solid)).astype(np.float32)


def _euler(f: np.ndarray) -> int:
    V, F = marching_cubes_world(f, np.zeros(3), 1.0)
    E = np.unique(np.sort(F[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1), axis=0)
    return len(np.unique(F)) - len(E) + len(F)


def _slab(n=40):
    """A thick square slab in the middle of an n^3 grid."""
    solid = np.zeros((n, n, n), bool)
    solid[8:-8, 8:-8, 16:24] = True
    return solid


def _simple_by_definition(block: np.ndarray) -> bool:
    """Bertrand and Malandain's test on one 3 x 3 x 3 block, with scipy's labelling."""
    face = ndimage.generate_binary_structure(3, 1)
    n18 = ndimage.generate_binary_structure(3, 2)
    solid = block & n18
    solid[1, 1, 1] = False
    lab, _ = ndimage.label(solid, structure=face)
    n_solid = len(set(lab[face & ~np.eye(1, 27, 13, dtype=bool).reshape(3, 3, 3)]) - {0})
    air = ~block
    air[1, 1, 1] = False
    n_air = ndimage.label(air, structure=np.ones((3, 3, 3)))[1]
    return n_solid == 1 and n_air == 1


def test_simple_points_agree_with_the_definition_on_random_neighbourhoods():
    rng = np.random.default_rng(0)
    blocks = rng.random((600, 3, 3, 3)) < rng.uniform(0.2, 0.8, (600, 1, 1, 1))
    blocks[:, 1, 1, 1] = True
    grid = np.zeros((5, 5, 4 * 600 + 1), bool)   # the blocks in a row, a blank layer apart
    for i, b in enumerate(blocks):
        grid[1:4, 1:4, 4 * i + 1:4 * i + 4] = b
    index = np.ravel_multi_index((2, 2, 4 * np.arange(600) + 2), grid.shape)
    got = simple_points(grid, index)
    want = np.array([_simple_by_definition(b) for b in blocks])
    assert want.any() and not want.all()
    np.testing.assert_array_equal(got, want)


def test_a_small_hole_through_a_slab_is_plugged_and_nothing_else_moves():
    solid = _slab()
    solid[19:21, 19:21, 16:24] = False                      # a 2 x 2 hole: a handle
    f = _field(solid)
    assert _euler(f) == 0
    g, rep = remove_small_handles(f, 3)
    assert _euler(g) == 2
    changed = g != f
    assert changed.sum() == rep["plugged"] + rep["cut"] and rep["cut"] == 0
    assert 1 <= rep["plugged"] <= 4                          # a plug one voxel thick
    assert np.argwhere(changed).min(axis=0)[:2].tolist() >= [19, 19]
    assert g.dtype == f.dtype


def test_a_hole_wider_than_the_cube_is_left_open():
    solid = _slab()
    solid[16:24, 16:24, 16:24] = False                      # 8 cells across
    f = _field(solid)
    g, rep = remove_small_handles(f, 5)
    assert rep == {"specks": 0, "plugged": 0, "cut": 0}
    np.testing.assert_array_equal(g, f)
    assert _euler(g) == 0


def test_a_thin_strand_looping_over_a_slab_is_cut():
    solid = _slab()
    solid[12, 20, 24:30] = solid[28, 20, 24:30] = True       # two posts 1 cell thick
    solid[12:29, 20, 29] = True                              # and a bar: a loop
    f = _field(solid)
    assert _euler(f) == 0
    g, rep = remove_small_handles(f, 3)
    assert _euler(g) == 2 and rep["plugged"] == 0 and 1 <= rep["cut"] <= 2


def test_a_thin_neck_between_two_blocks_is_not_cut():
    solid = np.zeros((40, 40, 40), bool)
    solid[8:18, 10:30, 10:30] = solid[22:32, 10:30, 10:30] = True
    solid[18:22, 20, 20] = True                              # a rod 1 cell thick, no loop
    f = _field(solid)
    g, rep = remove_small_handles(f, 5)
    np.testing.assert_array_equal(g, f)
    assert rep == {"specks": 0, "plugged": 0, "cut": 0} and ndimage.label(g < 0)[1] == 1


def test_a_thin_cavity_and_a_narrow_gap_are_kept():
    solid = np.zeros((40, 40, 40), bool)
    solid[8:32, 8:32, 8:32] = True
    solid[12:28, 12:28, 19:21] = False                      # a cavity 2 cells thin
    solid[8:32, 8:32, 30:32] = False
    solid[8:32, 8:32, 32:35] = True                          # a box 2 cells above
    f = _field(solid)
    g, rep = remove_small_handles(f, 5)
    np.testing.assert_array_equal(g, f)
    assert ndimage.label(g < 0)[1] == 2


def test_sizes_that_change_nothing_and_sizes_refused():
    f = _field(_slab())
    for size in (0, 1):
        np.testing.assert_array_equal(remove_small_handles(f, size)[0], f)
    for size in (2, -3, 2.5):
        with pytest.raises(ValueError, match="size"):
            remove_small_handles(f, size)


def test_the_default_preset_takes_out_handles_and_the_others_do_not():
    from neural.presets import get_config
    assert get_config("default").handles == 5
    assert get_config("draft").handles == get_config("paper").handles == 0
    with pytest.raises(ValueError, match="handles"):
        get_config("default", handles=4)


def test_a_speck_in_a_small_hole_is_dropped_unless_a_stroke_passes_through_it():
    solid = _slab()
    solid[18:22, 18:22, 16:24] = False                      # a 4 x 4 hole
    solid[19:21, 19:21, 19:21] = True                       # a speck of 8 voxels in it
    f = _field(solid)
    # the speck and the slab are two pieces, and a plug may not join them: the hole stays
    g, rep = remove_small_handles(f, 5)
    assert rep["plugged"] == 0 and ndimage.label(g < 0)[1] == 2
    assert _euler(g) == 0 + 2                               # the slab's handle, the speck
    g, rep = remove_small_handles(f, 5, np.zeros(f.shape, bool))
    assert rep["specks"] == 8 and rep["plugged"] >= 1
    assert ndimage.label(g < 0)[1] == 1 and _euler(g) == 2
    keep = np.zeros(f.shape, bool)
    keep[20, 20, 20] = True                                 # a stroke through the speck
    g, rep = remove_small_handles(f, 5, keep)
    assert rep["specks"] == 0 and ndimage.label(g < 0)[1] == 2
    with pytest.raises(ValueError, match="keep"):
        remove_small_handles(f, 5, keep[:-1])


def test_the_stroke_voxels_are_the_nodes_next_to_a_stroke():
    from neural.flow import _stroke_voxels
    stroke = np.array([[2.0, 5.0, 5.0], [8.0, 5.0, 5.0]])   # along x through node row (., 5, 5)
    keep = _stroke_voxels([stroke], np.zeros(3), 1.0, (12, 12, 12))
    want = np.zeros((12, 12, 12), bool)
    want[1:10, 4:7, 4:7] = True
    np.testing.assert_array_equal(keep, want)
    assert not _stroke_voxels([], np.zeros(3), 1.0, (4, 4, 4)).any()
