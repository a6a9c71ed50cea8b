"""Coarse Catmull-Clark control mesh from curve loops (Orbay & Kara 2011, Sec. 4.2).

Every network curve is resampled into ``N`` equal-arc-length segments (``2 N`` for a
closed curve, one whose two ends are the same junction; with ``adaptive`` a multiple
of ``N`` for long or winding curves, see :func:`.pieces.piece_counts`), and the samples become
control vertices shared by every patch that uses the curve. Each loop is then filled
with quads:

* four sides (after grouping curves that meet nearly straight, :mod:`.sides`) whose
  opposite sides have equal segment counts: one ``p x q`` grid sampled from the
  bicubically blended Coons patch of the four sides (the paper's case);
* otherwise the loop is cut into *pieces* of ``N`` segments (one per curve, two for
  a closed curve). Four pieces: an ``N x N`` Coons grid. Two pieces (a double edge or
  a closed stroke): four half-pieces, an ``N/2 x N/2`` Coons grid. Three or five and
  more pieces: split around a centre point into one ``N/2 x N/2`` quad grid per
  piece corner, as one Catmull-Clark step splits an n-gon::

        v2 ------ m1 ------ v1          centre C joined by spokes to the piece
         \\         |        /          midpoints m_i; sub-quad i is bounded by
          \\  Q1    |  Q0   /           m_i -> v_{i+1} -> m_{i+1} -> C -> m_i
           m2 ----- C ---- m0
                    ...

  Geometry of a split loop: if its curves still form four geometric sides, the quad
  vertices are placed by a uniform (Tutte) embedding into the unit square and the
  Coons patch of the four sides is evaluated there; otherwise the interior is the
  uniform harmonic interpolant of the border (each inner vertex the mean of its
  neighbours), which does not fold in concave loops as straight spokes would.

No face is degenerate: every quad has four distinct vertices when ``N >= 2``
(``N`` even). Quads run counter-clockwise along the loop's traversal, so loops that
traverse shared curves in opposite directions give a consistently oriented mesh.

Notes
-----
The paper treats four-sided loops only; the piece split and the Tutte placement are
our extension (docs/methods.md, "Where we differ from the papers, and why": loops with
other than four sides are split into quads around a centre).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .coons import coons_eval, coons_grid
from curvenet.core.geometry import resample_polyline
from curvenet.core.tolerances import DIVISION_GUARD
from .pieces import equalise_pieces, piece_counts
from .sides import DEFAULT_STRAIGHT_ANGLE, group_sides
from .sweep import sweep_grid

__all__ = ["ControlMesh", "build_control_mesh", "orient_loops", "JUNCTION_TOL"]

#: Curve ends closer than this fraction of the bounding-box diagonal are one junction.
JUNCTION_TOL = 1e-6
@dataclass
class ControlMesh:
    """A stitched quad control mesh.

    Attributes
    ----------
    vertices : (n, 3) float64
        Initial control points (curve samples, then Coons-sampled interiors).
    quads : (f, 4) int64
    face_patch : (f,) int64
        Loop index of each quad.
    curve_vids : list of (k_c + 1,) int64
        Control vertices along each curve, from its first to its last sample.
    curve_targets : (n,) bool / (n, 3) float64
        ``on_curve[v]`` and ``target[v]``: the curve sample a vertex must interpolate.
    junction_of_end : (C, 2) int64
        Junction vertex id at the start and end of each curve.
    n_junctions : int
    loops : list of list of (int, bool)
        The loops after orientation repair (see :func:`orient_loops`).
    patch_kind : list of str
        ``"grid"``, ``"pieces4"``, ``"halves"``, ``"split-coons4"`` or ``"split"``.
    diagonal : float
        Bounding-box diagonal of all curve points.
    rest : (n, 3) float64
        The swept shape (:func:`.sweep.sweep_grid`) of the ``"grid"`` loops' vertices,
        ``vertices`` elsewhere: the rest shape of the ``sweep`` fit.
    swept : (L,) bool
        Loops whose inside ``rest`` sweeps (the ``"grid"`` ones).
    spread : (n,) float64
        At the vertices inside the swept loops, the distance between the two sweeps of
        ``rest`` (along ``u`` and along ``v``: ``sweep_grid``'s ``gap``); NaN elsewhere.
    """

    vertices: np.ndarray
    quads: np.ndarray
    face_patch: np.ndarray
    curve_vids: list
    on_curve: np.ndarray
    target: np.ndarray
    junction_of_end: np.ndarray
    n_junctions: int
    loops: list
    patch_kind: list = field(default_factory=list)
    diagonal: float = 1.0
    rest: np.ndarray | None = None
    swept: np.ndarray | None = None
    spread: np.ndarray | None = None


def _validate(curves, loops):
    cs = []
    for i, c in enumerate(curves):
        a = np.asarray(c, dtype=np.float64)
        if a.ndim != 2 or a.shape[1] != 3 or len(a) < 2:
            raise ValueError(f"curves[{i}]: expected an (m, 3) array with m >= 2, got {a.shape}")
        if not np.isfinite(a).all():
            raise ValueError(f"curves[{i}]: contains non-finite coordinates")
        cs.append(a)
    ls = []
    for j, lp in enumerate(loops):
        if len(lp) == 0:
            raise ValueError(f"loops[{j}]: empty loop")
        out = []
        for item in lp:
            try:
                ci, fwd = item
            except (TypeError, ValueError):
                raise ValueError(f"loops[{j}]: items must be (curve_index, forward), "
                                 f"got {item!r}") from None
            ci = int(ci)
            if not 0 <= ci < len(cs):
                raise ValueError(f"loops[{j}]: curve index {ci} out of range [0, {len(cs)})")
            out.append((ci, bool(fwd)))
        ls.append(out)
    return cs, ls


def _junctions(curves, loops, diag):
    """Cluster curve ends into junctions; returns (junction_of_end (C, 2), positions (J, 3))."""
    C = len(curves)
    ends = np.concatenate([np.stack([c[0], c[-1]]) for c in curves])   # (2C, 3): 2i start
    tree = cKDTree(ends)
    pairs = tree.query_pairs(JUNCTION_TOL * max(diag, DIVISION_GUARD), output_type="ndarray")
    extra = []
    for lp in loops:              # consecutive curves in a loop share the junction between them
        n = len(lp)
        for k in range(n):
            (a, fa), (b, fb) = lp[k], lp[(k + 1) % n]
            extra.append((2 * a + (1 if fa else 0), 2 * b + (0 if fb else 1)))
    if extra:
        pairs = np.concatenate([pairs.reshape(-1, 2), np.array(extra, dtype=np.int64)])
    g = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(2 * C, 2 * C))
    n_j, lab = connected_components(g, directed=False)
    pos = np.zeros((n_j, 3))
    np.add.at(pos, lab, ends)
    pos /= np.bincount(lab, minlength=n_j)[:, None]
    return lab.reshape(C, 2), pos


def orient_loops(loops: list, n_curves: int) -> list:
    """Flip loops so that loops sharing a curve traverse it in opposite directions.

    Breadth-first over loops joined by curves used exactly twice (by two different
    loops); a loop is reversed when it traverses a shared curve in the same direction
    as an already-placed neighbour. Non-orientable conflicts are left as they are.

    Parameters
    ----------
    loops : list of list of (int, bool)
    n_curves : int

    Returns
    -------
    list of list of (int, bool)
    """
    uses: list = [[] for _ in range(n_curves)]
    for j, lp in enumerate(loops):
        for ci, fwd in lp:
            uses[ci].append((j, fwd))
    adj: list = [[] for _ in loops]
    for u in uses:
        if len(u) == 2 and u[0][0] != u[1][0]:
            (a, fa), (b, fb) = u
            same = fa == fb
            adj[a].append((b, same))
            adj[b].append((a, same))
    flip = np.full(len(loops), -1, dtype=np.int64)
    for s in range(len(loops)):
        if flip[s] >= 0:
            continue
        flip[s] = 0
        stack = [s]
        while stack:
            a = stack.pop()
            for b, same in adj[a]:
                if flip[b] < 0:
                    flip[b] = flip[a] ^ int(same)
                    stack.append(b)
    out = []
    for j, lp in enumerate(loops):
        out.append([(ci, not fwd) for ci, fwd in reversed(lp)] if flip[j] else list(lp))
    return out


def _grid_ids(boundary, p, q, next_id):
    """Id grid (p+1, q+1) whose border is the cyclic ``boundary`` (length 2p+2q)."""
    L = len(boundary)
    G = np.full((p + 1, q + 1), -1, dtype=np.int64)
    a = np.arange(p + 1)
    b = np.arange(q + 1)
    G[:, 0] = boundary[a]
    G[p, :] = boundary[p + b]
    G[:, q] = boundary[p + q + (p - a)]
    G[0, :] = boundary[(2 * p + q + (q - b)) % L]
    n_int = (p - 1) * (q - 1)
    if n_int > 0:
        G[1:p, 1:q] = (next_id + np.arange(n_int)).reshape(p - 1, q - 1)
    return G, next_id + max(n_int, 0)


def _grid_quads(G):
    a, b = G[:-1, :-1], G[1:, :-1]
    c, d = G[1:, 1:], G[:-1, 1:]
    return np.stack([a.ravel(), b.ravel(), c.ravel(), d.ravel()], axis=1)


def _local_quads(subs, B, new_lo, n_new):
    """Quads of a split loop in local numbering: border ``B`` first, then the new ids."""
    quads = np.concatenate([_grid_quads(G) for G in subs])
    ids_all = np.concatenate([B, new_lo + np.arange(n_new)])
    lut = np.full(int(ids_all.max()) + 1, -1, dtype=np.int64)
    lut[ids_all] = np.arange(len(ids_all))
    return ids_all, lut[quads]


def _tutte_square(quads_local, n_local, bnd_local, bnd_uv):
    """Uniform harmonic map of a local quad mesh with the border pinned to ``bnd_uv (b, d)``."""
    e = np.concatenate([quads_local[:, [0, 1]], quads_local[:, [1, 2]],
                        quads_local[:, [2, 3]], quads_local[:, [3, 0]]])
    A = sp.coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n_local, n_local))
    A = ((A + A.T) > 0).astype(np.float64)
    deg = np.asarray(A.sum(axis=1)).ravel()
    Lap = sp.diags(deg) - A
    uv = np.zeros((n_local, bnd_uv.shape[1]))
    uv[bnd_local] = bnd_uv
    free = np.ones(n_local, bool)
    free[bnd_local] = False
    fi = np.flatnonzero(free)
    if len(fi):
        Lff = Lap[fi][:, fi].tocsc()
        rhs = -Lap[fi][:, bnd_local] @ bnd_uv
        uv[fi] = spla.splu(Lff).solve(np.asarray(rhs))
    return uv


def build_control_mesh(curves, loops, resolution: int = 4, *,
                       straight_angle: float = DEFAULT_STRAIGHT_ANGLE,
                       orient: bool = True, adaptive: bool = True) -> ControlMesh:
    """Stitch the loops' Coons patches into one quad control mesh.

    Parameters
    ----------
    curves : list of (m_i, 3) float64
        Network curves; curves that meet share end points (within
        ``JUNCTION_TOL`` of the diagonal, or by following each other in a loop).
    loops : list of list of (int, bool)
        Each loop: (curve index, traversed forward) in traversal order.
    resolution : int
        ``N``, control-polygon segments per curve (per piece), >= 2; an odd value is
        rounded up to the next even one (the centre split halves pieces).
    straight_angle : float
        Degrees; curves turning less at a junction belong to one side.
    orient : bool
        Repair loop orientation first (:func:`orient_loops`).
    adaptive : bool
        Give long or winding curves several pieces of ``N`` segments
        (:func:`.pieces.piece_counts`), equalised along the quad strips of four-curve loops and
        between curves that continue each other (:func:`.pieces.equalise_pieces`);
        False: ``N`` per curve (``2 N`` if closed), as in the paper.

    Returns
    -------
    ControlMesh

    References
    ----------
    Orbay & Kara 2011, Sec. 4.2 (Fig. 6).
    """
    if isinstance(resolution, bool) or int(resolution) != resolution or resolution < 2:
        raise ValueError(f"resolution: expected an integer >= 2, got {resolution!r}")
    N = int(resolution) + int(resolution) % 2       # the centre split halves pieces
    curves, loops = _validate(curves, loops)
    if not curves:
        raise ValueError("curves: empty")
    if not loops:
        raise ValueError("loops: empty (nothing to surface)")
    allpts = np.concatenate(curves)
    diag = float(np.linalg.norm(allpts.max(0) - allpts.min(0)))
    if orient:
        loops = orient_loops(loops, len(curves))
    jend, jpos = _junctions(curves, loops, diag)
    closed = jend[:, 0] == jend[:, 1]
    sides = [group_sides([curves[ci] if fwd else curves[ci][::-1] for ci, fwd in lp],
                         straight_angle) if len(lp) >= 2 else [] for lp in loops]
    if adaptive:
        m, most, lengths = piece_counts(curves, closed)
        k_c = N * equalise_pieces(m, loops, lengths, jend, most, sides=sides)
    else:
        k_c = N * np.where(closed, 2, 1)
    curve_pos, curve_vids, samples = _sample_curves(curves, jend, jpos, k_c)
    nid = n_curve_v = len(curve_pos)
    positions, quads_all, fpatch, kinds = [curve_pos], [], [], []
    swept: dict = {}                # (p, q) -> [(block in positions, its four sides)]
    for j, lp in enumerate(loops):
        B, BP, starts = _loop_boundary(lp, curve_vids, samples)
        kind, p, q, roll = _patch_layout(lp, sides[j], starts, k_c, N, len(B))
        kinds.append(kind)
        if kind in ("grid", "pieces4", "halves"):
            newpos, grid_sides, quads, nid = _grid_patch(np.roll(B, -roll),
                                                         np.roll(BP, -roll, axis=0), p, q, nid)
            if kind == "grid" and p > 1 and q > 1:
                swept.setdefault((p, q), []).append((len(positions), grid_sides))
        else:
            corners = [starts[s[0]] for s in sides[j]] if kind == "split-coons4" else None
            newpos, quads, nid = _split_patch(B, BP, N, nid, corners)
        positions.append(newpos)
        quads_all.append(quads)
        fpatch.append(np.full(len(quads), j))

    V = np.concatenate(positions)
    on_curve = np.zeros(len(V), bool)
    on_curve[:n_curve_v] = True
    target = V.copy()
    rest, spread = _swept_rest(positions, swept)
    return ControlMesh(V, np.concatenate(quads_all).astype(np.int64),
                       np.concatenate(fpatch).astype(np.int64), curve_vids, on_curve, target,
                       jend, len(jpos), loops, kinds, diag, rest=rest,
                       swept=np.array([k == "grid" for k in kinds], bool), spread=spread)


def _swept_rest(positions, swept):
    """The control vertices with the insides of the grid loops swept
    (:func:`.sweep.sweep_grid`), loops of one size at once: ``(n, 3) float64``, and the
    two sweeps' distance there (``(n,) float64``, NaN outside the swept insides)."""
    rest = list(positions)
    spread = [np.full(len(block), np.nan) for block in positions]
    for (p, q), items in swept.items():
        grids, gaps = sweep_grid(*(np.stack(side) for side in zip(*(sides for _, sides in items))),
                                 spread=True)
        for (block, _), grid, gap in zip(items, grids, gaps):
            rest[block] = grid[1:p, 1:q].reshape(-1, 3)
            spread[block] = gap[1:p, 1:q].reshape(-1)
    return np.concatenate(rest), np.concatenate(spread)


def _sample_curves(curves, jend, jpos, k_c):
    """Shared control vertices along the curves: junctions first, then each curve's inside.

    Returns
    -------
    positions : (n, 3) float64
        Junction positions ``jpos``, then the inner samples of each curve in order.
    curve_vids : list of (k_c + 1,) int64
        Vertex ids along each curve, junction to junction.
    samples : list of (k_c + 1, 3) float64
        Each curve resampled to ``k_c`` equal-arc segments, ends on its junctions.
    """
    pos_blocks = [jpos]
    curve_vids = []
    samples = []
    nid = len(jpos)
    for i, c in enumerate(curves):
        s = resample_polyline(c, int(k_c[i]))
        s[0], s[-1] = jpos[jend[i, 0]], jpos[jend[i, 1]]
        ids = np.concatenate([[jend[i, 0]], nid + np.arange(k_c[i] - 1), [jend[i, 1]]])
        nid += k_c[i] - 1
        pos_blocks.append(s[1:-1])
        curve_vids.append(ids.astype(np.int64))
        samples.append(s)
    return np.concatenate(pos_blocks), curve_vids, samples


def _loop_boundary(lp, curve_vids, samples):
    """A loop's border in traversal order.

    Returns
    -------
    B : (Lb,) int64
        Control vertex ids around the loop (each shared end once).
    BP : (Lb, 3) float64
        Their positions.
    starts : list of int
        Index in ``B`` where each of the loop's curves starts.
    """
    bids, bpos, starts = [], [], []
    off = 0
    for ci, fwd in lp:
        ids = curve_vids[ci] if fwd else curve_vids[ci][::-1]
        ps = samples[ci] if fwd else samples[ci][::-1]
        starts.append(off)
        bids.append(ids[:-1])
        bpos.append(ps[:-1])
        off += len(ids) - 1
    return np.concatenate(bids), np.concatenate(bpos), starts


def _patch_layout(lp, sides, starts, k_c, N, Lb):
    """How a loop is meshed: ``(kind, p, q, roll)``.

    A grid of ``p x q`` quads when the loop has four sides (``sides``: the groups of
    loop positions per side, :func:`.sides.group_sides`) with opposite sides of equal
    sample counts (``"grid"``, border rolled by ``roll`` to start at a corner), four
    pieces (``"pieces4"``) or at most two (``"halves"``); otherwise a centre split
    (``"split-coons4"`` for four sides, else ``"split"``; ``p``, ``q`` unused).
    """
    T = Lb // N
    side_len = [sum(int(k_c[lp[i][0]]) for i in s) for s in sides]
    if len(sides) == 4 and side_len[0] == side_len[2] and side_len[1] == side_len[3]:
        return "grid", side_len[0], side_len[1], starts[sides[0][0]]
    if T == 4:
        return "pieces4", N, N, 0
    if T <= 2:
        return "halves", Lb // 4, Lb // 4, 0
    return ("split-coons4" if len(sides) == 4 else "split"), 0, 0, 0


def _grid_patch(Br, BPr, p, q, nid):
    """Coons grid of ``p x q`` quads inside the border ``Br`` (ids) / ``BPr`` (positions).

    Returns the new interior positions ``((p-1)(q-1), 3)``, the four sides (bottom,
    right, top, left, as :func:`.coons.coons_grid` takes them), the quads ``(p q, 4)``
    and the next free vertex id.
    """
    Lb = len(Br)
    G, nid = _grid_ids(Br, p, q, nid)
    idx = np.arange(Lb)
    sides = (BPr[idx[:p + 1]], BPr[idx[p:p + q + 1]],
             BPr[(p + q + (p - np.arange(p + 1))) % Lb],
             BPr[(2 * p + q + (q - np.arange(q + 1))) % Lb])
    newpos = coons_grid(*sides)[1:p, 1:q].reshape(-1, 3) if p > 1 and q > 1 else np.zeros((0, 3))
    return newpos, sides, _grid_quads(G), nid


def _split_patch(B, BP, N, nid, corners):
    """Centre split of a loop into ``T = len(B) / N`` sub-quads of ``h x h``, ``h = N / 2``.

    Interior positions: with four side ``corners`` (indices into ``B``), a Tutte
    embedding in the unit square mapped by the 4-sided Coons patch; without, the
    harmonic (uniform-weight) interior: the 3D image of a Tutte embedding into a
    convex polygon, so it cannot fold the way straight spokes do in a concave
    loop (the L of an L-prism).

    Returns the new positions, the quads and the next free vertex id.
    """
    Lb = len(B)
    T = Lb // N
    h = N // 2
    centre = nid
    nid += 1
    spokes = []
    for i in range(T):
        spokes.append(np.concatenate([[centre], nid + np.arange(h - 1),
                                      [B[(i * N + h) % Lb]]]).astype(np.int64))
        nid += h - 1
    subs = []
    for i in range(T):
        G = np.full((h + 1, h + 1), -1, dtype=np.int64)
        G[:, 0] = spokes[i]
        G[:, h] = B[((i + 1) * N + h - np.arange(h + 1)) % Lb]
        G[h, :] = B[(i * N + h + np.arange(h + 1)) % Lb]
        G[0, :] = spokes[(i + 1) % T]
        if h > 1:
            G[1:h, 1:h] = (nid + np.arange((h - 1) ** 2)).reshape(h - 1, h - 1)
            nid += (h - 1) ** 2
        subs.append(G)
    ids_all, ql = _local_quads(subs, B, centre, nid - centre)
    if corners is not None:
        uvb, side_pts = _square_border(BP, corners)
        uv = _tutte_square(ql, len(ids_all), np.arange(Lb), uvb)
        newpos = coons_eval(side_pts[0], side_pts[1], side_pts[2][::-1], side_pts[3][::-1],
                            uv[Lb:])
    else:
        newpos = _tutte_square(ql, len(ids_all), np.arange(Lb), BP)[Lb:]
    return newpos, np.concatenate([_grid_quads(G) for G in subs]), nid


def _square_border(BP, corners):
    """Unit-square parameters ``(Lb, 2)`` of a four-sided border and its four side polylines."""
    Lb = len(BP)
    uvb = np.zeros((Lb, 2))
    side_pts = []
    for s in range(4):
        a0, a1 = corners[s], corners[(s + 1) % 4]
        n_s = (a1 - a0) % Lb
        t = np.arange(n_s) / n_s
        sel = (a0 + np.arange(n_s)) % Lb
        uvb[sel] = [np.stack([t, 0 * t], 1), np.stack([1 + 0 * t, t], 1),
                    np.stack([1 - t, 1 + 0 * t], 1), np.stack([0 * t, 1 - t], 1)][s]
        side_pts.append(BP[(a0 + np.arange(n_s + 1)) % Lb])
    return uvb, side_pts
