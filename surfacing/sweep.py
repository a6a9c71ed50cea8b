"""Swept four-sided patches: each pair of opposite sides carried along the other pair.

A designer who draws a torus as a few meridians and rings, or a cylinder as rings and
rulings, draws *sections*: the surface between two meridians is the meridian swept
along the rings. The bicubically blended Coons patch (:mod:`.coons`) knows only the
boundary positions, and the fairness energies of the fit (:mod:`.fit`) shape the
inside of a large sparse patch by their own preference (a fat torus's 180-degree span
comes out flattened). :func:`sweep_grid` instead transports the patch's profiles:

* **Profile pair** (left ``c3`` and right ``c1``, say): the similarity ``M = (s, R)``
  that best maps the left profile onto the right one (Umeyama's least-squares fit of
  corresponding arc-length samples, centred) is split into its powers ``M^u``. Both
  profiles are read as one common shape ``a*`` plus each one's own part: ``a*`` is
  the shape nearest to both in the least-squares sense, ``(a + s R^T b) / (1 + s^2)``
  (``a``, ``b`` the centred profiles), and the own parts are ``a - a*`` and
  ``b - M a*``. At ``u`` the profile is ``M^u a*`` plus the own parts blended
  ``(1 - u) : u``, each turned by the rotation of ``M^u`` (or ``M^(u-1)``) but not
  scaled.
* **Rails** (bottom ``c0`` and top ``c2``): the blended profile is placed on the rail
  points ``c0(u)``, ``c2(u)`` by the similarity that maps its chord onto theirs with
  the smallest rotation (scale, rotation, translation).

The surface swept along ``u`` and the one swept along ``v`` (the roles exchanged) both
interpolate all four sides; their mean is returned. Curves of a surface of revolution
are carried exactly: two meridians are related by a rotation about the axis, two
rings by a scaling about it, so a torus's, cylinder's or sphere zone's four-sided
patch is reproduced from its boundary alone.

Notes
-----
Why the own parts are not scaled: a stroke's wobble has the same size on a small
profile as on a large one. Carried as part of the small profile's shape (each profile
carried whole by ``M^u`` and blended), it would grow with the profile on its way to the
large one: the inner ring of a fat torus would put its wobble into the patch magnified
by the ratio of the rings. Split off and carried at its own size, it stays within the
profiles' own deviation; profiles related by a similarity have no own part and are
carried exactly.

Not in Orbay & Kara 2011, whose control mesh is sampled from the Coons patch: the
swept grid is the *rest shape* of the ``sweep`` fit (:func:`surfacing.fit.fit_lsq`'s
``rest``), which keeps the shape it implies between sparse curves, and the ``auto``
fit keeps it where its limit surface bends less than the others
(:func:`surfacing.fit.bending_energy`), or where the least-squares fit departs from it
by more than its two sweeps (``spread``) part. The best rotation from one profile to
the other does not say which way round they turned (meridians of a torus more than half
a turn apart) or whether they turned at all (a crest that becomes a trough); the rails
do, and decide it. The corner-numbering convention is :mod:`.coons`'s.

References
----------
S. Umeyama. Least-squares estimation of transformation parameters between two point
patterns. IEEE TPAMI 13(4), 1991.
"""

from __future__ import annotations

import numpy as np

from curvenet.core.tolerances import DIVISION_GUARD

__all__ = ["sweep_grid", "transport", "similarity_fit", "rotations"]

#: Scores (mean cosines) of two turns closer than this are a tie.
_TIE = 1e-6
#: A blended profile whose chord is shorter than this fraction of the rails' chord has
#: none to place it by: it is moved by the offsets of its ends instead.
_CHORD_MIN = 1e-6


def similarity_fit(A, B):
    """Best similarities of centred point sets: ``B - mean(B) ~ s R (A - mean(A))``.

    Parameters
    ----------
    A, B : (..., m, 3) float64
        Corresponding points (any leading batch shape).

    Returns
    -------
    s : (...,) float64
        Scales (1 where ``A`` or ``B`` is a single point).
    R : (..., 3, 3) float64
        Proper rotations (the identity where ``A`` or ``B`` is a single point).

    References
    ----------
    Umeyama 1991, Eq. 38-42.
    """
    a = A - A.mean(axis=-2, keepdims=True)
    b = B - B.mean(axis=-2, keepdims=True)
    var = (a * a).sum(axis=(-2, -1))
    ok = (var > DIVISION_GUARD) & ((b * b).sum(axis=(-2, -1)) > DIVISION_GUARD)
    U, S, Vt = np.linalg.svd(np.einsum("...mi,...mj->...ij", b, a))
    d = np.ones(S.shape)
    d[..., 2] = np.where(np.linalg.det(U) * np.linalg.det(Vt) < 0, -1.0, 1.0)
    R = np.einsum("...ij,...j,...jk->...ik", U, d, Vt)
    scale = (S * d).sum(axis=-1) / np.maximum(var, DIVISION_GUARD)
    return np.where(ok, scale, 1.0), np.where(ok[..., None, None], R, np.eye(3))


def rotations(axis, angles) -> np.ndarray:
    """Rotations by ``angles (..., k)`` about the unit axes ``axis (..., 3)``:
    ``(..., k, 3, 3) float64`` (Rodrigues)."""
    axis = np.asarray(axis, np.float64)
    K = np.zeros(axis.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = -axis[..., 2], axis[..., 1], -axis[..., 0]
    K[..., 1, 0], K[..., 2, 0], K[..., 2, 1] = axis[..., 2], -axis[..., 1], axis[..., 0]
    K = K[..., None, :, :]
    t = np.asarray(angles, np.float64)[..., None, None]
    return np.eye(3) + np.sin(t) * K + (1.0 - np.cos(t)) * (K @ K)


def _axis_angle(R):
    """Unit axes ``(..., 3)`` and angles in ``[0, pi]`` ``(...,)`` of rotation matrices
    (axis z where the angle is zero).

    The axis comes from the skew part ``R - R^T = 2 sin(angle) [k]x`` up to a quarter
    turn, and beyond it from the symmetric part ``(R + R^T) / 2 - cos(angle) I =
    (1 - cos(angle)) k k^T``, whose column of largest diagonal is exact at a half turn
    where the skew part vanishes (its sign from the skew part).
    """
    cos = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    w = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                  R[..., 1, 0] - R[..., 0, 1]], axis=-1)
    angle = np.arctan2(np.linalg.norm(w, axis=-1) / 2.0, cos)     # accurate near 0 and pi
    Bk = (R + np.swapaxes(R, -1, -2)) / 2.0 - cos[..., None, None] * np.eye(3)
    j = np.argmax(np.diagonal(Bk, axis1=-2, axis2=-1), axis=-1)
    col = np.take_along_axis(Bk, j[..., None, None], axis=-1)[..., 0]        # (..., 3)
    col = np.where(((col * w).sum(-1) < 0)[..., None], -col, col)
    k = np.where((cos < 0)[..., None], col, w)
    norm = np.linalg.norm(k, axis=-1)
    ok = norm > DIVISION_GUARD
    axis = np.where(ok[..., None], k / np.maximum(norm, DIVISION_GUARD)[..., None],
                    [0.0, 0.0, 1.0])
    return axis, np.where(ok, angle, 0.0)


def _chord_rotations(da, db):
    """Smallest rotations taking the unit directions ``da`` to ``db`` (both ``(..., 3)``):
    ``(..., 3, 3)``; identity where they are (anti)parallel (the caller's fallback)."""
    v = np.cross(da, db)
    c = (da * db).sum(axis=-1)
    s2 = (v * v).sum(axis=-1)
    K = np.zeros(v.shape[:-1] + (3, 3))
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    K[..., 1, 0], K[..., 2, 0], K[..., 2, 1] = v[..., 2], -v[..., 1], v[..., 0]
    f = np.where(s2 > DIVISION_GUARD, (1.0 - c) / np.maximum(s2, DIVISION_GUARD), 0.0)
    return np.eye(3) + K + (K @ K) * f[..., None, None]


def _turn_with_the_rails(A, axis, angle, rail0, rail1, u) -> np.ndarray:
    """How far the profiles turn about ``axis`` on their way: ``(...,)`` radians.

    The best rotation from one profile to the other turns by ``angle`` in ``[0, pi]``;
    the profiles may as well have turned the other way round (``angle - 2 pi``: the
    meridians of a torus more than half a turn apart), or not at all, the difference
    being the profiles' own (a wave whose crest becomes a trough). The rails decide.
    First their chord: the turn that carries the first profile's chord closest to the
    rails' chord along the way (mean cosine over the samples); a chord along the axis
    does not turn, and then the rails' tangents decide, the turn that carries their
    mean tangent at each end closest to it along the way (from both ends). On a tie the
    shortest turn, then none.
    """
    def unit(v):
        return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), DIVISION_GUARD)

    chord, rails = unit(A[..., -1, :] - A[..., 0, :]), unit(rail1 - rail0)
    T = unit(np.gradient(rail0, axis=-2) + np.gradient(rail1, axis=-2))      # (..., n, 3)
    turns = np.stack([angle, np.zeros_like(angle), angle - 2.0 * np.pi], axis=-1)
    by_chord, by_tangent = [], []
    for k in range(3):
        phi = turns[..., k, None]                                          # (..., 1)
        fwd = rotations(axis, u * phi)                                     # (..., n, 3, 3)
        back = rotations(axis, (u - 1.0) * phi)
        by_chord.append((np.einsum("...kij,...j->...ki", fwd, chord) * rails).sum(-1).mean(-1))
        moved = (np.einsum("...kij,...j->...ki", fwd, T[..., 0, :])
                 + np.einsum("...kij,...j->...ki", back, T[..., -1, :]))
        by_tangent.append((moved * T).sum(axis=-1).mean(axis=-1) / 2.0)
    by_chord, by_tangent = np.stack(by_chord, -1), np.stack(by_tangent, -1)  # (..., 3)
    level = by_chord >= by_chord.max(axis=-1, keepdims=True) - _TIE
    by_tangent = np.where(level, by_tangent, -np.inf)
    best = np.argmax(by_tangent >= by_tangent.max(axis=-1, keepdims=True) - _TIE, axis=-1)
    return np.take_along_axis(turns, best[..., None], axis=-1)[..., 0]


def transport(A, B, rail0, rail1) -> np.ndarray:
    """Profile ``A`` carried to profile ``B`` along two rails.

    Parameters
    ----------
    A, B : (..., m, 3) float64
        The profiles, from ``rail0[..., 0, :]`` to ``rail1[..., 0, :]`` and from
        ``rail0[..., -1, :]`` to ``rail1[..., -1, :]``, sampled at the same parameters
        (any leading batch shape, the same for all four).
    rail0, rail1 : (..., n, 3) float64
        The rails, sampled at ``u_i = i / (n - 1)``.

    Returns
    -------
    (..., n, m, 3) float64
        Row ``i``: the profile at ``u_i``, its ends on ``rail0[..., i, :]`` and
        ``rail1[..., i, :]``; row 0 is ``A`` and row ``n - 1`` is ``B``.
    """
    A, B, rail0, rail1 = (np.asarray(x, np.float64) for x in (A, B, rail0, rail1))
    n, m = rail0.shape[-2], A.shape[-2]
    u = np.linspace(0.0, 1.0, n)
    s, R = similarity_fit(A, B)
    axis, angle = _axis_angle(R)
    angle = _turn_with_the_rails(A, axis, angle, rail0, rail1, u)[..., None]  # (..., 1)
    a = A - A.mean(axis=-2, keepdims=True)
    b = B - B.mean(axis=-2, keepdims=True)
    fwd = rotations(axis, u * angle)                                       # (..., n, 3, 3)
    # the common shape, each profile's own part left absolute (see the module's notes),
    # under the turn the rails chose (R itself, or none: then B is still reached at u = 1)
    turn = fwd[..., -1, :, :]
    sc = s[..., None, None]
    common = (a + sc * np.einsum("...ji,...mj->...mi", turn, b)) / (1.0 + sc * sc)
    own_a = a - common
    own_b = b - sc * np.einsum("...ij,...mj->...mi", turn, common)
    w = u[:, None, None]
    X = (s[..., None, None, None] ** w * np.einsum("...kij,...mj->...kmi", fwd, common)
         + (1.0 - w) * np.einsum("...kij,...mj->...kmi", fwd, own_a)
         + w * np.einsum("...kij,...mj->...kmi", rotations(axis, (u - 1.0) * angle), own_b))
    da = X[..., -1, :] - X[..., 0, :]
    db = rail1 - rail0
    la = np.linalg.norm(da, axis=-1)
    lb = np.linalg.norm(db, axis=-1)
    ua = da / np.maximum(la, DIVISION_GUARD)[..., None]
    ub = db / np.maximum(lb, DIVISION_GUARD)[..., None]
    ok = (la > _CHORD_MIN * lb) & (lb > DIVISION_GUARD) & ((ua * ub).sum(-1) > -1.0 + 1e-9)
    scale = np.where(ok, lb / np.maximum(la, DIVISION_GUARD), 1.0)
    placed = rail0[..., None, :] + scale[..., None, None] * np.einsum(
        "...kij,...kmj->...kmi", _chord_rotations(ua, ub), X - X[..., :1, :])
    # degenerate chords: the blended profile moved by the offsets of its ends instead
    t = np.linspace(0.0, 1.0, m)[:, None]
    moved = (X + (1.0 - t) * (rail0 - X[..., 0, :])[..., None, :]
             + t * (rail1 - X[..., -1, :])[..., None, :])
    out = np.where(ok[..., None, None], placed, moved)
    out[..., 0, :, :], out[..., -1, :, :] = A, B
    return out


def sweep_grid(bottom, right, top, left, *, spread: bool = False):
    """The swept patch of four sides on the grid of their samples.

    Parameters
    ----------
    bottom, top : (..., p + 1, 3) float64
        ``c0`` from P00 to P10 and ``c2`` from P01 to P11 (:mod:`.coons`'s numbering);
        any leading batch shape (several patches of the same size at once).
    right, left : (..., q + 1, 3) float64
        ``c1`` from P10 to P11 and ``c3`` from P00 to P01.
    spread : bool
        Also return the distance between the two sweeps.

    Returns
    -------
    grid : (..., p + 1, q + 1, 3) float64
        ``grid[..., i, j, :]`` at ``(i / p, j / q)``; its border rows and columns are
        the given sides exactly (bottom and top win at the corners).
    gap : (..., p + 1, q + 1) float64
        Only with ``spread``: the distance between the surface swept along ``u`` and
        the one swept along ``v`` at each grid point (0 on the border). Each predicts
        the inside from a different pair of sides; where the sides are sections of one
        surface of revolution they agree exactly, and where the sides imply no
        consistent sweep they part.

    Examples
    --------
    Four sides of a quarter of a cylinder's wall give that wall:

    >>> a = np.linspace(0, np.pi / 2, 9)
    >>> arc = np.stack([np.cos(a), np.sin(a), 0 * a], 1)
    >>> up = np.linspace(0, 1, 5)[:, None] * [0, 0, 1]
    >>> g = sweep_grid(arc, arc[-1] + up, arc + [0, 0, 1], arc[0] + up)
    >>> bool(np.allclose(np.hypot(g[..., 0], g[..., 1]), 1))
    True
    >>> g, gap = sweep_grid(arc, arc[-1] + up, arc + [0, 0, 1], arc[0] + up, spread=True)
    >>> float(gap.max()) < 1e-12                  # both sweeps are the wall
    True
    """
    b, r, t, lf = (np.asarray(c, dtype=np.float64) for c in (bottom, right, top, left))
    along_u = transport(lf, r, b, t)                                 # (..., p+1, q+1, 3)
    along_v = np.swapaxes(transport(b, t, lf, r), -3, -2)            # (..., p+1, q+1, 3)
    g = 0.5 * (along_u + along_v)
    g[..., 0, :, :], g[..., -1, :, :] = lf, r
    g[..., :, 0, :], g[..., :, -1, :] = b, t
    if not spread:
        return g
    gap = np.linalg.norm(along_u - along_v, axis=-1)
    gap[..., [0, -1], :] = 0.0
    gap[..., :, [0, -1]] = 0.0
    return g, gap
