"""Piece grids of a control net and their refinement through subdivision levels."""

import numpy as np

from curvenet.surfacing import subdivision_step
from curvenet.surfacing.levels import piece_grids, refine_grid


def _grid(p, q, off=0):
    G = off + np.arange((p + 1) * (q + 1)).reshape(p + 1, q + 1)
    return np.stack([G[:-1, :-1].ravel(), G[1:, :-1].ravel(), G[1:, 1:].ravel(),
                     G[:-1, 1:].ravel()], 1)


def test_piece_grids_recovers_row_major_grids():
    Q = np.concatenate([_grid(2, 3), _grid(1, 1, 100)])
    fp = np.r_[np.zeros(6, int), np.ones(1, int)]
    g = piece_grids(Q, fp)
    assert [p for p, _ in g] == [0, 1]
    assert g[0][1].shape == (3, 4) and g[1][1].shape == (2, 2)
    # another face order still covers every quad exactly once (as smaller grids)
    g = piece_grids(Q[[1, 0, 2, 3, 4, 5, 6]], fp)
    got = np.concatenate([np.stack([G[:-1, :-1].ravel(), G[1:, :-1].ravel(), G[1:, 1:].ravel(),
                                    G[:-1, 1:].ravel()], 1) for _, G in g])
    assert sorted(map(tuple, got)) == sorted(map(tuple, Q))


def test_refine_grid_is_the_grid_of_the_subdivided_quads():
    # oracle: the subdivided mesh's quads are exactly the quads of the refined grid
    Q = _grid(2, 3)
    st = subdivision_step(Q, 12)
    H = refine_grid(piece_grids(Q, np.zeros(len(Q), int))[0][1], Q, st.topo)
    assert H.shape == (5, 7)
    quads = np.stack([H[:-1, :-1].ravel(), H[1:, :-1].ravel(), H[1:, 1:].ravel(),
                      H[:-1, 1:].ravel()], 1)
    assert sorted(map(tuple, np.sort(quads, 1))) == sorted(map(tuple, np.sort(st.quads, 1)))
