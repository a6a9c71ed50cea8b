"""Monte-Carlo samples of a flow fit: along the strokes and on the zero set of f.

Zhang et al. 2025, Sec. 5.1: each step draws samples uniformly by arc length on the
strokes and on the current iso-surface. The surface samples are drawn on the grid's
device (random points in the cells where f changes sign, moved onto the zero level of
the trilinear interpolant), not on a marching-cubes mesh on the host as the paper
does. torch is imported inside the functions.
"""

from __future__ import annotations

import numpy as np

from curvenet.core.tolerances import NORM_EPS, TINY_F32

__all__ = ["StrokeSampler", "sample_surface_cells"]


class StrokeSampler:
    """Uniform arc-length Monte-Carlo samples with unit tangents on polylines.

    Parameters
    ----------
    strokes_unit : list of (n_i, 3) float64, unit-cube coordinates
    device, dtype : torch placement of the samples
    """

    def __init__(self, strokes_unit, device, dtype):
        import torch
        a = np.vstack([s[:-1] for s in strokes_unit])
        b = np.vstack([s[1:] for s in strokes_unit])
        length = np.linalg.norm(b - a, axis=1)
        ok = length > 0
        if not ok.any():
            raise ValueError("strokes have zero total length")
        a, b, length = a[ok], b[ok], length[ok]
        self.total_length = float(length.sum())
        self.a = torch.as_tensor(a, device=device, dtype=dtype)
        self.d = torch.as_tensor(b - a, device=device, dtype=dtype)
        self.t = torch.as_tensor((b - a) / length[:, None], device=device, dtype=dtype)
        self.cum = torch.as_tensor(np.cumsum(length) / length.sum(), device=device, dtype=dtype)

    def sample(self, n: int, gen):
        """``(points (n, 3), tangents (n, 3))`` distributed uniformly by length."""
        import torch
        r = torch.rand(n, generator=gen, device=self.a.device, dtype=self.a.dtype)
        seg = torch.searchsorted(self.cum, r).clamp(max=len(self.cum) - 1)
        s = torch.rand(n, 1, generator=gen, device=self.a.device, dtype=self.a.dtype)
        return self.a[seg] + s * self.d[seg], self.t[seg]


def sample_surface_cells(f_grid, n: int, gen, *, newton_steps: int = 2):
    """Samples on the zero level of a node grid, computed on its device.

    Random points in uniformly chosen sign-change cells, moved onto the zero set
    of the trilinear interpolant by Newton steps (each clamped to one cell).

    Parameters
    ----------
    f_grid : (res, res, res) tensor
    n : int
    gen : torch.Generator on the grid's device

    Returns
    -------
    points : (n, 3) unit-cube coordinates, or None when f does not cross zero
    """
    import torch

    from .poisson import interpolate
    res = f_grid.shape[0]
    f = f_grid.detach()
    cells = torch.nonzero(_in_some_cell(f > 0) & _in_some_cell(f < 0))    # (K, 3)
    if len(cells) == 0:
        return None
    pick = torch.randint(len(cells), (n,), generator=gen, device=f_grid.device)
    jitter = torch.rand(n, 3, generator=gen, device=f_grid.device, dtype=f_grid.dtype)
    p = (cells[pick].to(f_grid.dtype) + 0.5 + jitter) / res
    h = 1.0 / res
    for _ in range(newton_steps):
        v, gr = interpolate(f, p, with_gradient=True)
        step = (v / (gr * gr).sum(-1).clamp(min=NORM_EPS)).unsqueeze(-1) * gr
        norm = step.norm(dim=-1, keepdim=True)
        step = step * torch.clamp(h / norm.clamp(min=TINY_F32), max=1.0)
        p = p - step
    return p.clamp(0.0, 1.0)


def _in_some_cell(mask):
    """(res - 1,) * 3 bool: cells with at least one of their 8 corners in ``mask``
    ((res,) * 3 bool); three pairwise ORs, one per axis (a 2^3 max pooling of floats
    costs thirty times as much on a CPU)."""
    mask = mask[:-1] | mask[1:]
    mask = mask[:, :-1] | mask[:, 1:]
    return mask[:, :, :-1] | mask[:, :, 1:]
