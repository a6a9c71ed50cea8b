"""Feature strips from crease strokes (Niu et al. 2025, Appendix A; oracles: a box's
bisectors and the unit jump of the feature function's normal derivative across a strip)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from curvenet.neural.feature import feature_function
from curvenet.neural.sharpnet import boundary_triples
from curvenet.neural.strips import (
    crease_feature_set,
    guide_directions,
    segment_strip_2d,
    stroke_guides_from_mesh,
    strip_from_polyline,
)

from ._box import BOX_CORNERS, box_edges, box_mesh

D = torch.float64


def test_guides_on_a_box_edge_are_the_bisector():
    v, f = box_mesh()
    # edge from (1, 1, 0) to (1, 1, 1): sides x = 1 (normal +x) and y = 1 (normal +y)
    p = np.stack([np.ones(9), np.ones(9), np.linspace(0.3, 0.7, 9)], 1)  # away from corners
    ge = stroke_guides_from_mesh(p, v, f, radius=0.2)
    expect = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    assert np.allclose(ge, expect, atol=1e-9)
    g = guide_directions(p, ge)
    assert np.allclose(g, expect, atol=1e-9)


def test_vertex_guide_lies_on_both_bisector_planes():
    # a bent polyline whose two edges' bisector planes meet in a known line: the planes
    # contain the edges' directions and the common direction z, so the vertex guide is z
    p = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.5, 1.0, 0.0]])
    z = np.array([0.0, 0.0, 1.0])
    tilt = np.array([[0.0, -0.3, 1.0], [0.3, -0.15, 1.0]])  # per-edge guides, not exact
    e = np.diff(p, axis=0)
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    ge = tilt - (tilt * e).sum(1, keepdims=True) * e  # orthogonal to each edge
    ge /= np.linalg.norm(ge, axis=1, keepdims=True)
    g = guide_directions(p, ge, lam=1e-6)
    b = np.cross(ge, e)
    assert abs(g[1] @ b[0]) < 1e-4 and abs(g[1] @ b[1]) < 1e-4  # on both planes
    line = np.cross(b[0], b[1])
    assert abs(abs(g[1] @ line / np.linalg.norm(line)) - 1) < 1e-6
    assert np.allclose(g[0], ge[0]) and np.allclose(g[2], ge[1])  # end vertices
    del z


def test_strip_geometry():
    p = np.stack([np.linspace(0, 1, 6), np.zeros(6), np.zeros(6)], 1)
    g = np.tile([0.0, 0.0, 1.0], (6, 1))
    v, t = strip_from_polyline(p, g, 0.1)
    assert v.shape == (12, 3) and t.shape == (10, 3)
    assert np.allclose(v[:6], p - [0, 0, 0.1]) and np.allclose(v[6:], p + [0, 0, 0.1])
    area = 0.5 * np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]),
                                axis=1)
    assert np.allclose(area.sum(), 1.0 * 0.2)
    assert len(boundary_triples(t)) == 12  # the boundary is one closed loop of 12 vertices
    with pytest.raises(ValueError, match="width"):
        strip_from_polyline(p, g, 0.0)


def test_box_feature_set_channels_and_crease():
    v, f = box_mesh()
    strokes = box_edges()
    mv, mt, mc = crease_feature_set(strokes, v, f, width=0.05, spacing=0.1, guide_radius=0.2)
    assert mc.max() + 1 == 3 or mc.max() + 1 == 4  # cube graph: >= 3 channels at corners
    # strokes meeting at a corner carry different channels
    tri_c = mv[mt].mean(1)
    for corner in BOX_CORNERS:
        near = np.linalg.norm(tri_c - corner, axis=1) < 0.06
        assert len(set(mc[near])) >= 3
    # the feature function is C0 with a derivative jump across the strip (which contains the
    # bisector plane direction), so across the box surface near the edge: one-sided
    # derivatives along the strip normal differ by 1 (g = 1, global version)
    k = int(np.argmin(np.linalg.norm(tri_c - [1.0, 1.0, 0.5], axis=1)))
    tri = mv[mt[k]]
    nrm = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    nrm /= np.linalg.norm(nrm)
    assert abs(_normal_jump(mv, mt, tri.mean(0), nrm) - 1.0) < 1e-5


def _normal_jump(verts, elements, p, n, eps=1e-8):
    """One-sided normal derivatives of the global feature function at p, + minus -."""
    p = torch.tensor(p, dtype=D)
    n = torch.tensor(n, dtype=D)
    vt = torch.tensor(verts, dtype=D)
    d = []
    for s in (1.0, -1.0):
        q = (p + s * eps * n).reshape(1, -1).clone().requires_grad_(True)
        (g,) = torch.autograd.grad(feature_function(q, vt, elements).sum(), q)
        d.append((g[0] @ n).item())
    return d[0] - d[1]


def test_segment_strip_2d_gives_corner_crease():
    v, s = segment_strip_2d([1.0, 1.0], [1.0, 1.0], 0.2, pieces=3)
    assert v.shape == (4, 2) and s.shape == (3, 2)
    h = 0.2 / np.sqrt(2)
    assert np.allclose(v[0], [1 - h] * 2) and np.allclose(v[-1], [1 + h] * 2)
    # across the bisector near the corner the feature function kinks (jump 1)
    n = np.array([1.0, -1.0]) / np.sqrt(2)
    assert abs(_normal_jump(v, s, [1.05, 1.05], n) - 1.0) < 1e-5
