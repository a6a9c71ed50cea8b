"""Differential geometry of the level sets of a gradient field g.

Second fundamental form ``II = P (grad g) P / |g|`` (Zhang et al. 2025,
Eq. 14-15), its principal directions, the 4-symmetric alignment of a tangent
with them (Eq. 4, 16-17) and the covariant derivative used by the smoothness
term (Eq. 5, 18).

Conventions
-----------
* ``g : (N, 3)``, ``G : (N, 3, 3)`` with ``G[n, i, a] = d g_i / d x_a``,
  ``H : (N, 3, 3, 3)`` with ``H[n, i, a, b] = d2 g_i / d x_a d x_b`` (as
  returned by :meth:`neural.siren.GradientSiren.jet`).
* ``n = g / |g|``; II is a symmetric 3x3 matrix with ``II n = 0``; for the SDF
  of a sphere of radius r it equals ``P / r`` on the sphere (the sign follows
  the outward gradient).
* ``grad g`` is symmetrised before projection: for an integrable g it is the
  Hessian of f (symmetric); for a non-integrable g its antisymmetric part is
  the curl, which the curl term penalises, and has no place in a shape
  operator. (The paper writes ``grad g`` and leaves this implicit.)
* Divisions by |g| and by the anisotropy of II are clamped by ``EPS`` with a
  validity mask returned alongside, never NaN.
"""

from __future__ import annotations

import torch

from curvenet.core.tolerances import NORM_EPS

__all__ = ["EPS", "tangent_frame", "second_fundamental_form", "principal_curvatures",
           "alignment_cos4", "directional_derivative_II", "covariant_tv", "curl"]

#: Guard for divisions by |g|, by |t_uv|^2 and by the anisotropy of II (unit-cube units).
EPS = NORM_EPS


def tangent_frame(n: torch.Tensor):
    """Orthonormal tangent vectors ``(t1, t2)`` of unit normals ``n`` (N, 3).

    Branch-free construction of Duff et al., "Building an Orthonormal Basis,
    Revisited", JCGT 2017; ``(t1, t2, n)`` is right-handed.
    """
    x, y, z = n.unbind(-1)
    sign = torch.where(z >= 0, torch.ones_like(z), -torch.ones_like(z))
    a = -1.0 / (sign + z)
    b = x * y * a
    t1 = torch.stack([1.0 + sign * x * x * a, sign * b, -sign * x], -1)
    t2 = torch.stack([b, sign + y * y * a, -y], -1)
    return t1, t2


def _normal_projector(g: torch.Tensor):
    norm = g.norm(dim=-1, keepdim=True).clamp(min=EPS)            # (N, 1)
    n = g / norm
    eye = torch.eye(3, dtype=g.dtype, device=g.device)
    P = eye - n.unsqueeze(-1) * n.unsqueeze(-2)                   # (N, 3, 3)
    return n, norm, P


def second_fundamental_form(g: torch.Tensor, G: torch.Tensor) -> torch.Tensor:
    """``II = P sym(grad g) P / |g|`` (Eq. 14-15).

    Parameters
    ----------
    g : (N, 3)
    G : (N, 3, 3)

    Returns
    -------
    II : (N, 3, 3) symmetric, ``II n = 0``
    """
    _, norm, P = _normal_projector(g)
    Gs = 0.5 * (G + G.transpose(-1, -2))
    return P @ Gs @ P / norm.unsqueeze(-1)


def _II_in_frame(II: torch.Tensor, t1: torch.Tensor, t2: torch.Tensor):
    a = torch.einsum("ni,nij,nj->n", t1, II, t1)
    b = torch.einsum("ni,nij,nj->n", t1, II, t2)
    c = torch.einsum("ni,nij,nj->n", t2, II, t2)
    return a, b, c


def principal_curvatures(g: torch.Tensor, G: torch.Tensor):
    """Principal curvatures and directions of the level set through each point.

    Returns
    -------
    k : (N, 2), ``k[:, 0] >= k[:, 1]``
    d : (N, 2, 3), unit principal directions (``d[:, 0]`` for ``k[:, 0]``)
    """
    II = second_fundamental_form(g, G)
    n, _, _ = _normal_projector(g)
    t1, t2 = tangent_frame(n)
    a, b, c = _II_in_frame(II, t1, t2)
    M = torch.stack([torch.stack([a, b], -1), torch.stack([b, c], -1)], -2)   # (N, 2, 2)
    k, V = torch.linalg.eigh(M)                                   # ascending
    k = k.flip(-1)
    V = V.flip(-1)
    J = torch.stack([t1, t2], -1)                                 # (N, 3, 2)
    d = (J @ V).transpose(-1, -2)
    return k, d


def alignment_cos4(g: torch.Tensor, G: torch.Tensor, tangents: torch.Tensor):
    """``cos(4 alpha)`` between stroke tangents and the principal directions (Eq. 4, 16-17).

    Parameters
    ----------
    g : (N, 3), G : (N, 3, 3)
    tangents : (N, 3), stroke tangents (any length)

    Returns
    -------
    cos4 : (N,)
    valid : (N,) bool, False where the tangent is normal to the level set or II
        is umbilic (no principal direction); cos4 is 1 there.

    Notes
    -----
    Eigenvector-free closed form. In any orthonormal tangent frame II is
    ``[[a, b], [b, c]]`` with principal angle ``theta``,
    ``exp(2i theta) = ((a - c) + 2ib) / r``, and the projected tangent
    ``(t_u, t_v)`` (Eq. 17) has angle ``phi``; then
    ``cos 4 alpha = Re(exp(4i phi) exp(-4i theta))``. It does not depend on the
    frame and is smooth away from umbilics, so no ``eigh`` and no ``atan2`` are
    differentiated.
    """
    II = second_fundamental_form(g, G)
    n, _, _ = _normal_projector(g)
    t1, t2 = tangent_frame(n)
    a, b, c = _II_in_frame(II, t1, t2)
    tu = (tangents * t1).sum(-1)
    tv = (tangents * t2).sum(-1)
    # exp(2i theta) ~ (p, q), exp(2i phi) ~ (x, y), unnormalised
    p, q = a - c, 2.0 * b
    x, y = tu * tu - tv * tv, 2.0 * tu * tv
    r2 = p * p + q * q
    R2 = x * x + y * y
    valid = (r2 > EPS) & (R2 > EPS)
    # exp(4i.) = (p^2 - q^2, 2pq) / r2 ; cos(4phi - 4theta)
    c4t, s4t = (p * p - q * q) / r2.clamp(min=EPS), 2 * p * q / r2.clamp(min=EPS)
    c4p, s4p = (x * x - y * y) / R2.clamp(min=EPS), 2 * x * y / R2.clamp(min=EPS)
    cos4 = c4p * c4t + s4p * s4t
    return torch.where(valid, cos4, torch.ones_like(cos4)), valid


def directional_derivative_II(g, G, H, d):
    """Euclidean derivative of the 3x3 field II along directions ``d`` (N, 3).

    Chain rule through Eq. 14-15 with ``dg = G d`` and ``dG = H . d``:
    ``dII = (dP Gs P + P dGs P + P Gs dP) / |g| - II (n . dg) / |g|``,
    ``dP = -(dn n^T + n dn^T)``, ``dn = P dg / |g|``.

    Returns
    -------
    dII : (N, 3, 3)
    """
    n, norm, P = _normal_projector(g)
    nrm = norm.unsqueeze(-1)                                      # (N, 1, 1)
    Gs = 0.5 * (G + G.transpose(-1, -2))
    dg = torch.einsum("nia,na->ni", G, d)
    dG = torch.einsum("niab,nb->nia", H, d)
    dGs = 0.5 * (dG + dG.transpose(-1, -2))
    dn = torch.einsum("nij,nj->ni", P, dg) / norm
    dP = -(dn.unsqueeze(-1) * n.unsqueeze(-2) + n.unsqueeze(-1) * dn.unsqueeze(-2))
    II = P @ Gs @ P / nrm
    dnorm = (n * dg).sum(-1).view(-1, 1, 1)
    return (dP @ Gs @ P + P @ dGs @ P + P @ Gs @ dP) / nrm - II * dnorm / nrm


def covariant_tv(g, G, H, *, eps: float = EPS):
    """Pointwise ``|| nabla_S II ||_F`` (Eq. 5, 18).

    The covariant derivative of the tangential tensor field II on the level set
    is the tangential projection of its Euclidean derivative,
    ``(nabla_S II)(X) = P (D_X II) P`` for tangent X; its Frobenius norm sums
    over an orthonormal tangent frame ``(t1, t2)``.

    Returns
    -------
    tv : (N,), ``sqrt(|P D_t1 II P|^2 + |P D_t2 II P|^2 + eps)``

    Notes
    -----
    Eq. 18 writes ``P grad II_uv`` in an eigenvector frame ``(u, v)``; in that
    frame ``II_uv = diag(k1, k2)`` and its derivative would only see the
    principal curvatures, not the turning of the principal directions. Working
    with the frame-free 3x3 tensor keeps both, which is what Eq. 5 asks for.
    """
    n, _, P = _normal_projector(g)
    t1, t2 = tangent_frame(n)
    total = 0.0
    for t in (t1, t2):
        D = P @ directional_derivative_II(g, G, H, t) @ P
        total = total + (D * D).sum((-1, -2))
    return torch.sqrt(total + eps)


def curl(G: torch.Tensor) -> torch.Tensor:
    """Curl of g from its Jacobian ``G`` (N, 3, 3) -> (N, 3) (Eq. 12)."""
    return torch.stack([G[:, 2, 1] - G[:, 1, 2], G[:, 0, 2] - G[:, 2, 0],
                        G[:, 1, 0] - G[:, 0, 1]], -1)
