"""Loss terms of the flow-aligned variational formulation (Zhang et al. 2025, Eq. 13).

Each term is the Monte-Carlo mean of its integrand over the matching sample
set (Sec. 5.1): alignment and data on stroke samples, smoothness and Eikonal on
iso-surface samples, curl on volume samples. The terms are unweighted; their
weights (paper: 1, 0.01, 30, 7, 7) are the ``w_*`` fields of
:class:`neural.presets.FlowConfig`, applied by :mod:`neural.flow`.
:func:`normal_loss` is not in the paper: it aligns g with the normals of oriented
anchor points (samples of another surface the fit must meet), which also enter the
data term as stroke samples do.

References
----------
Zhang, Wang, Bessmeltsev 2025: Eq. 4 (alignment), 5 (smoothness), 7 (data),
the Eikonal term of Sec. 4.3, 12 (curl), 13 (weights).
"""

from __future__ import annotations


from curvenet.core.tolerances import NORM_EPS

from .level_sets import alignment_cos4, covariant_tv, curl

__all__ = ["alignment_loss", "smoothness_loss", "data_loss", "eikonal_loss", "curl_loss",
           "normal_loss"]


def alignment_loss(g, G, tangents):
    """Eq. 4: mean of ``(cos 4 alpha - 1)^2`` over stroke samples.

    Parameters
    ----------
    g : (N, 3), G : (N, 3, 3), tangents : (N, 3)

    Returns
    -------
    scalar tensor in ``[0, 4]``; samples with no defined principal direction (umbilic
    or tangent normal to the surface) contribute 0.
    """
    cos4, _ = alignment_cos4(g, G, tangents)
    return ((cos4 - 1.0) ** 2).mean()


def smoothness_loss(g, G, H, scale=None):
    """Eq. 5: mean over surface samples of ``||nabla_S II||_F`` (covariant TV), each
    sample's term times ``scale`` ((N,), optional: a weight that varies in space)."""
    tv = covariant_tv(g, G, H)
    return (tv if scale is None else tv * scale).mean()


def data_loss(f_strokes):
    """Eq. 7: mean of ``|f|`` at stroke samples (f normalised by Eq. 11)."""
    return f_strokes.abs().mean()


def eikonal_loss(g, sigma: float = 0.5):
    """Sec. 4.3: ``1/2 mean (|g| - sigma)^2`` on surface samples (sigma = 0.5)."""
    return 0.5 * ((g.norm(dim=-1) - sigma) ** 2).mean()


def curl_loss(G):
    """Eq. 12: mean of ``|curl g|^2`` over volume samples."""
    c = curl(G)
    return (c * c).sum(-1).mean()


def normal_loss(g, normals, *, eps: float = NORM_EPS):
    """Mean of ``1 - cos^2`` between g and the unit normals of anchor points.

    Orientation-free: g parallel or antiparallel to the normal costs 0, g in the
    tangent plane costs 1, so the anchors' normals need no consistent orientation
    (the sign of g is the fit's own choice, see :mod:`neural.flow`).

    Parameters
    ----------
    g : (N, 3), normals : (N, 3) unit vectors

    Returns
    -------
    scalar tensor in ``[0, 1]``; a sample with ``|g| = 0`` costs 1.
    """
    cos = (g * normals).sum(-1) / g.norm(dim=-1).clamp(min=eps)
    return (1.0 - cos * cos).mean()
