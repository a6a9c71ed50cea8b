"""Preset values (paper settings) and validation of overrides."""

import pytest

from curvenet.neural.presets import PRESETS, get_config


def test_paper_preset_matches_published_settings():
    c = get_config("paper")
    assert (c.res, c.width, c.hidden_layers, c.omega_0) == (256, 256, 4, 30.0)
    assert (c.n_stroke, c.n_surface, c.n_volume) == (10000, 15000, 15000)
    assert (c.init_steps, c.steps) == (200, 800)
    assert (c.w_align, c.w_smooth, c.w_data, c.w_eik, c.w_curl) == (1.0, 0.01, 30.0, 7.0, 7.0)
    assert (c.sigma, c.padding) == (0.5, 0.2)


def test_overrides_and_presets():
    assert set(PRESETS) == {"draft", "default", "paper"}
    assert get_config("draft", res=96, w_smooth=0.0).res == 96
    assert get_config("draft").res < get_config("default").res < get_config("paper").res


@pytest.mark.parametrize("kw,match", [({"res": 4}, "res"), ({"steps": -1}, "steps"),
                                      ({"bogus": 1}, "unknown"), ({"lr": 0}, "lr"),
                                      ({"boundary": "x"}, "boundary"),
                                      ({"normalize_from": 2.0}, "normalize_from"),
                                      ({"average_from": -0.1}, "average_from"),
                                      ({"dtype": "float16"}, "dtype"),
                                      ({"polish": 1.5}, "polish"),
                                      ({"attach_reach": -1.0}, "attach_reach"),
                                      ({"attach_normals": -1.0}, "attach_normals"),
                                      ({"smooth_near": -1.0}, "smooth_near"),
                                      ({"w_smooth_near": -0.1}, "w_smooth_near"),
                                      ({"subdivide": 3}, "subdivide"),
                                      ({"subdivide": 0.5}, "subdivide"),
                                      ({"init_res": 4}, "init_res"),
                                      ({"init_res": 32.5}, "init_res"),
                                      ({"bridge_steps": -1}, "bridge_steps"),
                                      ({"bridge_steps": 2.5}, "bridge_steps")])
def test_bad_overrides(kw, match):
    with pytest.raises(ValueError, match=match):
        get_config("draft", **kw)


def test_a_coarser_grid_takes_the_initialisation_stage_with_it():
    """``default`` with a grid coarser than its ``init_res`` (a small part's, or one set by
    hand) is valid."""
    assert get_config("default", res=32).init_res == 64
    assert get_config("default", res=48, init_res=256).res == 48


def test_bad_quality():
    with pytest.raises(ValueError, match="quality"):
        get_config("best")


def test_the_smoothness_weight_falls_to_the_papers_next_to_the_strokes():
    """Per grid node, the weight relative to ``w_smooth`` with ``smooth_near``: the
    paper's 0.01 within a third of ``smooth_near`` cells of a stroke, ``w_smooth`` from
    ``smooth_near`` cells on, linear in between; uniform (None) in every preset."""
    import numpy as np

    from curvenet.neural.flowfit import _smoothness_scale
    t = np.linspace(0.2, 0.8, 100)
    line = [np.c_[t, 0.5 + 0 * t, 0.5 + 0 * t]]          # along x through the middle nodes
    for quality, near in (("draft", 3.0), ("default", 6.0)):
        cfg = get_config(quality, smooth_near=near)
        assert cfg.w_smooth_near == 0.01 and cfg.w_smooth == 0.1
        scale = _smoothness_scale(line, cfg)
        mid = cfg.res // 2
        profile = scale[mid, mid, :] * cfg.w_smooth              # across the stroke, in z
        d = np.abs(np.arange(cfg.res) - mid)                     # cells from the stroke
        expect = 0.01 + np.clip((d - near / 3) / (near * 2 / 3), 0, 1) * (cfg.w_smooth - 0.01)
        np.testing.assert_allclose(profile, expect, atol=1e-12)
    for quality in PRESETS:
        assert _smoothness_scale(line, get_config(quality)) is None
