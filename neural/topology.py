"""Small tunnels and thin bridges taken out of a grid function's zero set, geometry kept.

Not in the paper. The integrated f of the flow fit carries Monte-Carlo noise; where it
is near zero over a wide area (thin parts, the crossings of many strokes) its zero set
gets pierced by small holes and spanned by thin strands, each a handle of the surface:
a sketch of a genus-0 shape comes out of marching cubes with tens of handles. After the
fairing (:mod:`neural.attach`) a small handle is a pit or a see-through tear.

:func:`remove_small_handles` takes them out on the grid, before the extraction, in the
spirit of Wood et al. (2004): a handle is removed only if it is small, and the rest of
the zero set does not move. With the solid ``I = {f < 0}``:

0. **specks**: the pieces of ``I`` smaller than the largest closing cube (fewer voxels)
   that no stroke passes through (``keep``) are given to the air. They are noise of f,
   which :func:`neural.extract.keep_supported_components` would drop after the
   extraction anyway (or keep as specks beside the surface), and a speck inside a
   small hole makes its plug join two pieces of the solid, which step 1 refuses (below):
   where many strokes cross, f's crumpled sheet holds many such specks;
1. **plugs**: the closing of ``I`` by a cube of ``size`` cells fills every hole and gap
   narrower than the cube. It also fills wide gaps' narrow ends and fattens concave
   corners, so the filled voxels are then given back to the outside one at a time as
   long as each is a *simple point* (removing it changes no topology: Bertrand &
   Malandain 1994), in the eight parity classes of the grid in turn, so that no two
   voxels removed together are neighbours. What stays filled is a plug one voxel thick
   across each small hole: the least that closes it;
2. **cuts**: the same on the outside (the closing of ``{f > 0}``), which cuts each thin
   strand of solid that forms a loop at one voxel.

Pockets of one side that the closing would swallow whole (a cavity in the solid, a
speck of solid that step 0 keeps) are left alone: they are no handle, and a thin pocket may be
what holds a stroke. A plug that would join two pieces of the solid, and a cut that
would open a cavity or split a piece of the solid in two (a thin neck, a speck apart),
joins or parts what was not a handle, and is left out too. A plug may seal a pocket of
air off: the cavity it leaves is a bubble inside the solid, which
:func:`neural.extract.drop_redundant_bubbles` drops when it holds no stroke of its own.
Changed voxels get a value of their new side (a small one for a plug, so that marching
cubes joins it to the solid across faces only; a full one for a cut, so that it joins
the air across edges and corners too); every other value of ``f`` is kept.

Digital topology: the solid is 6-connected and the air 26-connected. Marching cubes
decides the ambiguous faces by the values and agrees with that pairing only mostly, so
some handles stay (``benchmarks/README.md`` counts them). The closing cubes grow from 3
to ``size`` cells (a large hole is closed best after the small ones around it), and no
step undoes a voxel an earlier one changed (a plug is a thin sheet, a cut a small hole:
the cut or plug steps after it would take it for noise).

References
----------
Bertrand, Malandain, "A new characterization of three-dimensional simple points",
Pattern Recognition Letters 15(2), 1994.
Wood, Hoppe, Desbrun, Schroeder, "Removing excess topology from isosurfaces", ACM TOG
23(2), 2004.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

__all__ = ["remove_small_handles", "simple_points"]

#: The 27 offsets of a voxel's 3 x 3 x 3 neighbourhood, row-major; index 13 is the voxel.
_OFFSETS = np.array([(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)])
_L1 = np.abs(_OFFSETS).sum(axis=1)
_N26 = np.flatnonzero(_L1 > 0)                          # the 26 neighbours
_N18 = np.flatnonzero((_L1 > 0) & (_L1 <= 2))          # the 18 sharing a face or an edge
#: Which of the 18 share a face with the voxel.
_FACE_OF_18 = _L1[_N18] == 1
#: The value of f given to a plugged voxel, as a fraction of the solid's median |f|: a
#: small one, so that marching cubes joins it to the solid only across faces.
PLUG_VALUE = 0.05
#: The value given to a cut voxel, as a fraction of the air's median |f|: a full one, so
#: that marching cubes joins it to the air across edges and corners too.
CUT_VALUE = 1.0


def _adjacency(pos: np.ndarray, faces_only: bool) -> np.ndarray:
    """(len(pos), k) indices into ``pos`` of each position's neighbours among them (26-
    adjacency, or 6 with ``faces_only``), padded with ``len(pos)``."""
    d = np.abs(_OFFSETS[pos][:, None, :] - _OFFSETS[pos][None, :, :])
    adj = d.sum(axis=2) == 1 if faces_only else d.max(axis=2) == 1
    out = np.full((len(pos), adj.sum(axis=1).max()), len(pos))
    for a, row in enumerate(adj):
        nb = np.flatnonzero(row)
        out[a, :len(nb)] = nb
    return out


_ADJ26 = _adjacency(_N26, faces_only=False)
_ADJ6_IN_18 = _adjacency(_N18, faces_only=True)


def _component_labels(member: np.ndarray, adjacency: np.ndarray) -> np.ndarray:
    """(c, m) labels of the connected components of each row's ``member`` positions
    (the least position index of the component; ``m`` for non-members)."""
    c, m = member.shape
    lab = np.where(member, np.arange(m), m)
    padded = np.full((c, m + 1), m)
    while True:
        padded[:, :m] = lab
        new = np.where(member, np.minimum(lab, padded[:, adjacency].min(axis=2)), m)
        if np.array_equal(new, lab):
            return lab
        lab = new


def simple_points(solid: np.ndarray, index: np.ndarray) -> np.ndarray:
    """Which voxels of ``solid`` are simple: removable without changing its topology.

    Parameters
    ----------
    solid : (a, b, c) bool
        The solid, 6-connected (its complement 26-connected).
    index : (k,) int64
        Flat indices of voxels of ``solid``, none on the array's border.

    Returns
    -------
    (k,) bool
        Bertrand and Malandain's (1994) test: a voxel is simple when the solid in its
        18-neighbourhood has one 6-connected component that touches one of its faces,
        and the outside in its 26-neighbourhood one 26-connected component.

    Examples
    --------
    >>> rod = np.zeros((5, 5, 5), bool); rod[2, 2, 1:4] = True
    >>> simple_points(rod, np.ravel_multi_index(([2, 2], [2, 2], [1, 2]), rod.shape)).tolist()
    [True, False]
    """
    strides = np.array(solid.strides) // solid.itemsize
    nb = solid.ravel()[np.asarray(index)[:, None] + (_OFFSETS @ strides)[None, :]]   # (k, 27)
    air = ~nb[:, _N26]
    lab = _component_labels(air, _ADJ26)
    n_air = (air & (lab == np.arange(26))).sum(axis=1)
    full = nb[:, _N18]
    none = len(_N18)                              # the label of a position off the solid
    lab = np.where(_FACE_OF_18, _component_labels(full, _ADJ6_IN_18), none)
    lab = np.sort(lab, axis=1)                    # the distinct labels at the six faces
    n_solid = (lab[:, 0] != none) + ((np.diff(lab, axis=1) != 0) & (lab[:, 1:] != none)).sum(axis=1)
    return (n_air == 1) & (n_solid == 1)


def _close_small(f: np.ndarray, size: int, kept: np.ndarray, may_split: bool) -> np.ndarray:
    """The voxels that plug the holes of ``{f < 0}`` narrower than ``size`` cells (step 1
    of the notes), none of them in ``kept`` (bool, f's shape); with ``may_split`` False,
    none that splits a piece of the air."""
    solid = f < 0
    closed = (ndimage.grey_opening(f, size=(size,) * 3) < 0) & ~kept
    closed[[0, -1]] = solid[[0, -1]]
    closed[:, [0, -1]] = solid[:, [0, -1]]
    closed[:, :, [0, -1]] = solid[:, :, [0, -1]]
    air, n_air = ndimage.label(~solid)
    if n_air:                     # pockets of air swallowed whole stay as they are
        whole = np.flatnonzero(ndimage.minimum(closed, air, np.arange(1, n_air + 1)) > 0) + 1
        closed &= ~np.isin(air, whole)
    closed |= solid
    if not (closed & ~solid).any():
        return np.zeros_like(solid)
    work = np.pad(closed, 1)                                  # every voxel has 26 neighbours
    flat = work.ravel()
    cand = np.flatnonzero(np.pad(closed & ~solid, 1))
    parity = (np.stack(np.unravel_index(cand, work.shape), axis=1) % 2) @ np.array([4, 2, 1])
    while True:
        removed = 0
        for p in range(8):          # no two voxels of one parity class are neighbours
            live = cand[(parity == p) & flat[cand]]
            if len(live):
                ok = simple_points(work, live)
                flat[live[ok]] = False
                removed += int(ok.sum())
        if not removed:
            break
    plug = work[1:-1, 1:-1, 1:-1] & ~solid
    plugs, n_plugs = ndimage.label(plug)
    if not n_plugs:
        return plug
    # a plug that touches two pieces of the solid joins them
    touch = ndimage.maximum_filter(plugs, footprint=ndimage.generate_binary_structure(3, 1))
    rim = ndimage.binary_dilation(plug)
    at = rim & solid
    pairs = np.unique(np.stack([touch[at], ndimage.label(solid)[0][at]], axis=1), axis=0)
    bad = np.bincount(pairs[:, 0], minlength=n_plugs + 1) > 1
    if not may_split:     # one that touches two pieces of the rest of the air that were one
        at = rim & ~solid & ~plug
        now = np.unique(np.stack([touch[at], ndimage.label(~solid & ~plug)[0][at], air[at]],
                                 axis=1), axis=0)
        was = np.unique(now[:, [0, 2]], axis=0)
        bad |= (np.bincount(now[:, 0], minlength=n_plugs + 1)
                > np.bincount(was[:, 0], minlength=n_plugs + 1))
    return plug & ~np.isin(plugs, np.flatnonzero(bad))


def remove_small_handles(f, size: int = 5, keep=None) -> tuple[np.ndarray, dict]:
    """``f`` with the small handles of its zero set plugged and cut (see the notes).

    Parameters
    ----------
    f : (a, b, c) float array
        Grid function, negative inside the solid and positive outside.
    size : int
        Odd width (cells) of the largest closing cube: holes and strands up to
        ``size - 1`` cells across are taken out; 0 or 1 changes nothing.
    keep : (a, b, c) bool array, optional
        The voxels a stroke passes through: a speck of solid that holds one stays
        (step 0 of the notes). None: no speck is dropped.

    Returns
    -------
    f : (a, b, c) float array, the same dtype
        A new array, equal to ``f`` except at the dropped, plugged and cut voxels.
    report : dict
        ``specks``: voxels of the dropped specks; ``plugged``, ``cut``: voxels moved
        into the solid and out of it by the plugs and cuts.

    Raises
    ------
    ValueError
        ``size`` negative or even (other than 0), or ``keep`` not of ``f``'s shape.
    """
    if int(size) != size or size < 0 or (size > 1 and size % 2 == 0):
        raise ValueError(f"size must be 0, 1 or an odd integer >= 3, got {size!r}")
    if keep is not None and np.shape(keep) != np.shape(f):
        raise ValueError(f"keep has shape {np.shape(keep)}, f {np.shape(f)}")
    out = np.array(f)
    count = {"specks": 0, "plugged": 0, "cut": 0}
    inside = out < 0
    if size < 3 or not inside.any() or inside.all():
        return out, count
    if keep is not None:
        count["specks"] = _drop_specks(out, int(size) ** 3, np.asarray(keep, bool))
        inside = out < 0
        if not inside.any():
            return out, count
    # nothing changes farther than the cube from the solid: work in its box, with air
    # all round it (one outside, as in the whole grid)
    solid = np.argwhere(inside)
    lo = np.maximum(solid.min(axis=0) - size - 1, 0)
    hi = np.minimum(solid.max(axis=0) + size + 2, out.shape)
    box = tuple(slice(a, b) for a, b in zip(lo, hi))
    f = out[box]
    moved = np.zeros(f.shape, bool)      # what no later step may undo
    for s in range(3, int(size) + 1, 2):
        for sign, what in ((1, "plugged"), (-1, "cut")):
            g = sign * f
            plug = _close_small(g, s, moved, may_split=sign > 0)
            if plug.any():
                value = PLUG_VALUE if sign > 0 else CUT_VALUE
                g[plug] = -value * float(np.median(np.abs(g[g < 0])))
                f = sign * g
                moved |= plug
                count[what] += int(plug.sum())
    out[box] = f
    return out, count


def _drop_specks(f: np.ndarray, most: int, keep: np.ndarray) -> int:
    """Give the air, in place, the pieces of the solid ``{f < 0}`` of fewer than ``most``
    voxels that hold no ``keep`` voxel (step 0 of the notes); returns the voxels moved."""
    pieces, n = ndimage.label(f < 0)
    held = np.bincount(pieces[keep], minlength=n + 1)
    speck = (np.bincount(pieces.ravel(), minlength=n + 1) < most) & (held == 0)
    speck[0] = False                                  # the air
    drop = speck[pieces]
    if drop.any():
        f[drop] = CUT_VALUE * float(np.median(f[f > 0]))
    return int(drop.sum())
