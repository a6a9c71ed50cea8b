"""Surface patches as a minimum-weight GF(2) cycle basis of the curve network.

Implements the automatic phase of Abbasinejad, Joshi, Amenta 2011 (Sec. 3-4,
Algorithm 1) and the closing-patch suggestions of its Sec. 5. This module is
the driver, :func:`find_patches`; the topics live in their own modules and
their public names are re-exported here:

* :mod:`curvenet.cycles.candidates`: candidate cycles of length ``i`` through every
  vertex, enumerated by a depth-bounded search (Algorithm 1, line 6) and
  weighed (Sec. 4.2): ``k = #edges + (2 + eps) s`` with ``s = 1`` for
  separating cycles, ties broken by a bounding-volume measure;
* :mod:`curvenet.cycles.basis`: the greedy matroid algorithm (Theorem 1) in the order
  ``N_1, N_2, N_3, S_1, N_4, S_2, ...``;
* :mod:`curvenet.cycles.loops`: walking a cycle as a closed loop, orienting patches;
* :mod:`curvenet.cycles.closing`: closing patches (Sec. 5) ranked by ``Ws = 10 (a + b) + k``.

References
----------
F. Abbasinejad, P. Joshi, N. Amenta. Surface patches from unorganized space
curves. Computer Graphics Forum 30(5) (SGP 2011), Sec. 3-5.
J. D. Horton. A polynomial-time algorithm to find the shortest cycle basis of a
graph. SIAM J. Comput. 16(2), 1987 (fallback candidates, see Notes of
:func:`find_patches`).
"""

from __future__ import annotations

import time

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from .basis import greedy_basis
from .candidates import (DEFAULT_MAX_WORK, ENGINES, NUMBA_MIN_WORK, SEPARATING_EPS, TIE_BREAKS,
                         Candidate, CandidatePool)
from .closing import auto_close, closing_suggestions
from ..core.errors import InvalidParameterError
from .holes import hole_patches
from .loops import cycle_to_loop, orient_patches
from .rotation import embedded_faces
from .seams import seam_patches
from ..model.network import CurveNetwork
from ..model.patchset import Patch, PatchSet

__all__ = ["find_patches", "cycle_to_loop", "orient_patches", "closing_suggestions",
           "greedy_basis", "Candidate", "CandidatePool", "SEPARATING_EPS", "TIE_BREAKS",
           "ENGINES", "DEFAULT_MAX_WORK", "NUMBA_MIN_WORK", "MODES"]

#: Patch selection: ``"basis"`` (the greedy GF(2) basis, Abbasinejad et al. 2011),
#: ``"faces"`` (the faces of the rotation system the junctions imply, Zhuang et al.
#: 2013), ``"auto"`` (both; the one closer to a 2-manifold).
MODES = ("auto", "basis", "faces")


def _validate(network, mode, close, tie_break, max_cycle_length, max_work):
    if not isinstance(network, CurveNetwork):
        raise InvalidParameterError(f"network: expected a CurveNetwork, got {type(network)!r}")
    if mode not in MODES:
        raise InvalidParameterError(f"mode: expected one of {MODES}, got {mode!r}")
    if close not in ("auto", "none"):
        raise InvalidParameterError(f"close: expected 'auto' or 'none', got {close!r}")
    if tie_break not in TIE_BREAKS:
        raise InvalidParameterError(f"tie_break: expected one of {TIE_BREAKS}, got {tie_break!r}")
    if max_cycle_length is not None and (not isinstance(max_cycle_length, (int, np.integer))
                                         or max_cycle_length < 1):
        raise InvalidParameterError(
            f"max_cycle_length: expected a positive integer or None, got {max_cycle_length!r}")
    if not isinstance(max_work, (int, np.integer)) or max_work < 1:
        raise InvalidParameterError(f"max_work: expected a positive integer, got {max_work!r}")

def find_patches(network: CurveNetwork, *, mode: str = "auto", close: str = "auto",
                 tie_break: str = "pca",
                 max_cycle_length=None, max_work: int = DEFAULT_MAX_WORK,
                 engine: str = "auto", genus_aware: bool = True, holes: bool = True,
                 seams: bool = True) -> PatchSet:
    """Find surface patches: the faces of the surface the curves imply.

    Parameters
    ----------
    network : CurveNetwork
    mode : {"auto", "basis", "faces"}
        ``"basis"``: the minimum-weight GF(2) cycle basis plus closing patches
        (Abbasinejad et al. 2011). ``"faces"``: the faces of the rotation system the
        junctions' tangents imply (:func:`curvenet.cycles.rotation.embedded_faces`,
        after Zhuang et al. 2013), as many as are independent, in the basis's weight
        order, plus closing patches. ``"auto"`` (default): both, and the one with the
        smaller manifold defect (see Notes); the basis on ties.
    close : {"auto", "none"}
        ``"none"``: the paper's solid-free basis. ``"auto"`` (default): also
        accept closing patches (Sec. 5) that fill a hole bounded by edges used
        by one patch, or an unexplained crease (see Notes).
    tie_break : {"pca", "aabb"}
        Order of cycles of equal ``k``: ``"aabb"`` is the paper's axis-aligned
        bounding-box volume; ``"pca"`` (default) the volume of the PCA ellipsoid
        of the cycle's curves, which Sec. 4.2 names as the natural alternative.
        PCA is the default because real sketches are not drawn aligned with the
        coordinate axes, and an AABB volume changes under rotation (a tilted
        planar face gets a positive AABB volume); PCA volume is rotation
        invariant and zero for every planar cycle. On the 29 public networks a
        random rotation changed 29 patches with ``"aabb"`` and 4 with ``"pca"``
        (exact geometric ties in symmetric models).
    max_cycle_length : int, optional
        Longest candidate cycle; the basis may stay incomplete (reported).
    max_work : int
        Bound on enumeration steps (default ``DEFAULT_MAX_WORK``). When hit, the
        remaining candidates are Horton cycles (shortest-path cycles, which span
        the cycle space), and ``report["work_bound_hit"]`` is True.
    engine : {"auto", "python", "numba"}
        Cycle enumeration kernel (see :class:`CandidatePool`); same results.
    genus_aware : bool
        Also run the finder with handle rings examined after the faces of equal
        ``k`` (and, with ``close="auto"``, left out of the patches), and keep
        that result when it is closer to a 2-manifold (see Notes). ``False``:
        the paper's order only.
    holes : bool
        Make nested coplanar patches holes of the face around them
        (:func:`curvenet.cycles.holes.hole_patches`; beyond the paper, whose basis
        holds only simple cycles). ``False``: every patch is a disc.
    seams : bool
        Add the periodic faces bounded by two loops and a seam curve walked twice (a
        bore wall drawn with one seam line; :func:`curvenet.cycles.seams.seam_patches`).
        ``False``: seams stay unused curves.

    Returns
    -------
    PatchSet
        Patches in acceptance order (basis cycles first, ``source="auto"``, then
        closing patches, ``source="closing"``). ``report`` holds ``rank``
        (``E - V + C``), ``basis_size``, ``full_rank``, ``candidates`` (per
        length: ``total`` enumerated, ``separating_examined``: separating ones
        that were independent when their turn came), ``max_length``, ``work``,
        ``work_bound_hit``, ``horton_candidates``, ``closing_added`` (edge
        lists), ``tie_break``, ``close``, ``timings`` (``{"patches": seconds}``) and
        ``patch_stages`` (seconds for ``setup``, ``basis``, ``closing``) and
        ``holes`` (which loops became holes of which patch, see
        :func:`curvenet.cycles.holes.hole_patches`) and ``seams`` (the periodic faces
        added, see :func:`curvenet.cycles.seams.seam_patches`).

    Raises
    ------
    InvalidParameterError
        Unknown ``close`` / ``tie_break`` or a bad bound.

    Notes
    -----
    Algorithm 1: for ``i = 1, 2, ...`` the cycles of length ``i`` are split
    into non-separating ``N_i`` and separating ``S_i``; ``N_i`` is examined in
    tie-break order, then ``S_{i-2}``, which realises the order of
    ``k = #edges + (2 + eps) s``. We start at ``i = 1`` (loop edges) where the
    paper starts at 2, and stop as soon as the basis is full. Cycles equal in
    ``k`` and volume are further ordered by arc length and centroid, then edge
    ids, so the result does not depend on vertex numbering except for exact
    geometric ties.

    ``close="auto"`` considers closing candidates no longer than the longest
    length the automatic phase enumerated, so an open sheet's long boundary is
    never taken as a hole. Besides holes it accepts "walls" (our addition): a
    closing cycle whose edges are all labelled ``"crease"`` and each shared by
    two patches that continue smoothly (Newell normals within 30 degrees), so
    the crease is explained only by a third patch (the face shared by two
    stacked boxes). Unlabelled sketches never get walls.

    Genus (beyond the paper): on a surface of genus ``g`` every cycle basis
    holds ``2 g`` cycles that bound no face, and planar handle rings beat
    curved faces on the paper's volume tie-break. Cycles that cut through the
    surface (:meth:`CandidatePool.is_cutting`) are examined after the other
    cycles of equal ``k``, so faces come first; the handle rings that still complete the basis
    are left out of the patches (``report["handle_cycles"]``) where the faces
    around them use each of their curves twice, and the face the basis could
    not hold (the faces of a closed surface sum to zero) comes back as a
    closing patch. A lat-long torus comes out as exactly its faces. The
    handle test is geometric and can misfire on coarse curved faces, so when
    it flags any cycle the paper's order is run too and the one with the
    smaller manifold defect (curves used by one patch plus curves used by three
    or more; ``report["manifold_defect"]``) is kept, the paper's on ties
    (``report["order"]``).

    References
    ----------
    Abbasinejad, Joshi, Amenta 2011, Sec. 4.1 (Theorem 1, greedy matroid),
    Sec. 4.2 (weights), Algorithm 1, Sec. 5 (closing patches).

    Examples
    --------
    >>> from curvenet.datasets.shapes import box
    >>> ps = find_patches(box().network)
    >>> len(ps.patches), ps.report["rank"], [p.source for p in ps.patches].count("closing")
    (6, 5, 1)
    """
    _validate(network, mode, close, tie_break, max_cycle_length, max_work)
    t0 = time.perf_counter()
    kw = dict(close=close, tie_break=tie_break, max_cycle_length=max_cycle_length,
              max_work=max_work, engine=engine)
    ps, pool = _find_patches(network, genus_aware=genus_aware, **kw)
    if genus_aware:
        ps, pool = _keep_closer_to_manifold(network, ps, pool, kw)
    else:
        ps.report["manifold_defect"] = {"paper": _manifold_defect(network, ps.patches)}
        ps.report["order"] = "paper"
    ps.report["mode"] = "basis"
    if mode != "basis":
        ps = _choose_faces(network, ps, pool, close, mode, max_cycle_length)
    ps.report["holes"] = []
    if holes:
        ps.patches, ps.report["holes"] = hole_patches(network, ps.patches)
    ps.report["seams"] = []
    if seams:
        ps.patches, ps.report["seams"], ps.report["holes"] = seam_patches(
            network, ps.patches, ps.report["holes"])
    ps.report["timings"] = {"patches": time.perf_counter() - t0}
    return ps


def _keep_closer_to_manifold(network, genus_aware: PatchSet, pool, kw: dict):
    """The genus-aware run, or the paper's order when that has no larger manifold defect.

    Sets ``report["manifold_defect"]`` and ``report["order"]`` of the one kept; returns
    it and its candidate pool.
    """
    score = _manifold_defect(network, genus_aware.patches)
    defect = {"paper": score, "genus_aware": score}
    ps, order = genus_aware, "paper"
    # with no cycle found cutting, the genus-aware run took the paper's order
    if genus_aware.report["cutting_flagged"]:
        paper, paper_pool = _find_patches(network, genus_aware=False, **kw)
        defect["paper"] = _manifold_defect(network, paper.patches)
        if score < defect["paper"]:
            order = "genus_aware"
        else:
            ps, pool = paper, paper_pool
    ps.report["manifold_defect"] = defect
    ps.report["order"] = order
    return ps, pool


def _choose_faces(network, basis: PatchSet, pool, close: str, mode: str,
                  max_cycle_length=None) -> PatchSet:
    """The embedded faces' patch set instead of ``basis`` when it is closer to a manifold.

    ``mode="faces"`` takes it whenever the faces give any patch. The one returned holds
    ``report["mode"]`` and ``report["embedding"]``: the :class:`EmbeddedFaces` figures
    and ``defect``, the :func:`_surface_defect` of both patch sets.
    """
    faces = embedded_faces(network)
    patches = _face_patches(pool, faces, close, max_cycle_length)
    defect = {"basis": _surface_defect(network, basis.patches, faces.core),
              "faces": _surface_defect(network, patches, faces.core)}
    embedding = dict(faces.report, faces=len(faces.loops),
                     simple=int(np.count_nonzero(faces.simple)), genus=faces.genus,
                     defect=defect)
    clean = bool(faces.simple.all()) and not faces.report["conflicts"]
    if patches and (mode == "faces" or clean and defect["faces"] <= defect["basis"]
                    and _covers(patches, basis.patches)):
        report = dict(basis.report, mode="faces",
                      closing_added=[list(p.edges) for p in patches if p.source == "closing"],
                      handle_cycles=[])
        basis = PatchSet(network, patches, report)
    basis.report["embedding"] = embedding
    return basis


def _face_patches(pool, faces, close: str, max_cycle_length=None) -> list:
    """Patches from the simple faces of an embedding.

    The faces are taken greedily in the basis's weight order (length, then the
    tie-break volume: faces of an embedding are not tested for separating) as long as
    they are independent over GF(2); with ``close="auto"`` the closing rules of
    :func:`~curvenet.cycles.closing.auto_close` then consider the other faces and the
    cycles the basis run enumerated (walls are no faces), up to the longest face kept.
    A face left out of a closed group counts as long as its sides (:func:`_sides`)
    allow: where junctions of two curves split its sides, it is the heaviest face but
    no longer than the others (a torus's face of four sides and six curves, where a
    closed stroke's ends met on two of them), while the rim of an open sheet or a
    cup's opening has more sides than any face, and stays open.
    """
    loops = [lp for lp, ok in zip(faces.loops, faces.simple)
             if ok and (max_cycle_length is None or len(lp) <= max_cycle_length)]
    ends = [(e.u, e.v) for e in pool.network.edges]
    by_len: dict = {}
    for lp in loops:
        by_len.setdefault(len(lp), []).append(lp)
    cands = []
    for _, group in sorted(by_len.items()):
        edges = np.array([[i for i, _ in lp] for lp in group], np.int64)
        verts = np.array([[ends[i][0] if f else ends[i][1] for i, f in lp] for lp in group],
                         np.int64)
        cands += pool.make_candidates(edges, verts)
    for c in cands:
        c.separating = False
    seen, unique = set(), []
    for c in sorted(cands, key=lambda c: c.key):
        if c.edges not in seen:
            seen.add(c.edges)
            unique.append(c)
    kept, dropped = _independent_faces(unique, pool.n_edges)
    added = []
    if close == "auto" and kept:
        taken = {id(c) for c in kept}
        rest = [c for c in unique if id(c) not in taken] + pool.all_candidates
        degree = np.bincount(np.ravel(ends), minlength=pool.network.number_of_vertices)
        most = max(_sides(c, degree) for c in kept)
        longest = max([c.length for c in kept]
                      + [c.length for c in dropped if _sides(c, degree) <= most])
        added = auto_close(pool, [c.edges for c in kept], longest, candidates=rest,
                           faces=seen)
    return [Patch(c.edges, "auto") for c in kept] + [Patch(e, "closing") for e in added]


def _sides(candidate, degree) -> int:
    """Sides of a cycle: its junctions of three or more curves (1 where it has none)."""
    return max(1, int(np.count_nonzero(degree[list(candidate.vertices)] >= 3)))


def _independent_faces(faces: list, n_edges: int) -> tuple:
    """The faces less the last of each closed group: a GF(2) independent set.

    Each curve bounds at most two faces of an embedding, so a set of them sums to zero
    only where every curve of it bounds two: a union of *closed* groups (faces joined
    by shared curves, every curve of the group used twice). Each closed group has that
    one relation; dropping its last face (``faces`` is in weight order) leaves the rest
    independent, as the greedy matroid pass would, without an elimination.

    Returns ``(kept, dropped)``: the faces kept and the faces left out.
    """
    if not faces:
        return [], []
    face = np.repeat(np.arange(len(faces)), [c.length for c in faces])
    edge = np.concatenate([c.edges for c in faces])
    uses = np.bincount(edge, minlength=n_edges)
    order = np.argsort(edge, kind="stable")
    e, f = edge[order], face[order]
    pair = np.flatnonzero(e[1:] == e[:-1])                  # the two faces of a curve
    graph = coo_matrix((np.ones(len(pair)), (f[pair], f[pair + 1])),
                       shape=(len(faces), len(faces)))
    _, group = connected_components(graph, directed=False)
    open_group = np.zeros(group.max() + 1, bool)
    open_group[group[face[uses[edge] != 2]]] = True
    last = {g: i for i, g in enumerate(group.tolist())}    # the heaviest face per group
    drop = {i for g, i in last.items() if not open_group[g]}
    return ([c for i, c in enumerate(faces) if i not in drop],
            [c for i, c in enumerate(faces) if i in drop])


def _covers(patches, others) -> bool:
    """Whether ``patches`` use every curve ``others`` use."""
    return {e for p in others for e in p.edges} <= {e for p in patches for e in p.edges}


def _surface_defect(network: CurveNetwork, patches, core) -> int:
    """Curves that can bound faces (``core``) but bound no patch, one, or three or more.

    0 for a closed 2-manifold through every curve; an open surface adds its boundary.
    """
    uses = np.zeros(network.number_of_edges, dtype=np.int64)
    for p in patches:
        uses[list(p.edges)] += 1
    return int(np.count_nonzero(core & (uses != 2)))


def _manifold_defect(network: CurveNetwork, patches) -> int:
    """Curves used by one patch plus curves used by three or more (0 for a closed 2-manifold)."""
    uses = np.zeros(network.number_of_edges, dtype=np.int64)
    for p in patches:
        uses[list(p.edges)] += 1
    return int(np.count_nonzero(uses == 1) + np.count_nonzero(uses >= 3))


def _find_patches(network, *, close, tie_break, max_cycle_length, max_work, engine,
                  genus_aware) -> PatchSet:
    """One run of the patch finder (see :func:`find_patches`) with a fixed cycle order."""
    t0 = time.perf_counter()
    pool = CandidatePool(network, tie_break=tie_break, max_work=max_work, engine=engine,
                         genus_aware=genus_aware)
    t1 = time.perf_counter()
    basis, allc, info = greedy_basis(pool, max_cycle_length=max_cycle_length)
    t2 = time.perf_counter()
    kept = [c for c in basis if not c.cutting]
    handles = [c for c in basis if c.cutting]
    added = []
    if close == "auto" and basis:
        max_len = max(c.length for c in basis)
        added = auto_close(pool, [c.edges for c in kept], max_len)
    # a handle ring is dropped only where the faces around it cover each of its
    # curves twice; otherwise it is the best patch there is and stays
    uses = np.zeros(pool.n_edges, dtype=np.int64)
    for es in [c.edges for c in kept] + added:
        uses[list(es)] += 1
    dropped = [c for c in handles if close == "auto" and (uses[list(c.edges)] >= 2).all()]
    dropped_ids = {id(c) for c in dropped}
    kept = [c for c in basis if id(c) not in dropped_ids]
    patches = [Patch(c.edges, "auto") for c in kept] + [Patch(e, "closing") for e in added]
    t3 = time.perf_counter()
    report = {
        "method": "abbasinejad2011",
        "tie_break": tie_break,
        "close": close,
        "rank": pool.cycle_rank,
        "basis_size": len(basis),
        "full_rank": len(basis) == pool.cycle_rank,
        "candidates": {str(k): v for k, v in info["candidates"].items()},
        "n_candidates": len(allc),
        "max_length": info["max_length"],
        "work": pool.work,
        "work_bound_hit": pool.work_bound_hit,
        "engine": pool.engine_used,
        "horton_candidates": info["horton_candidates"],
        "closing_added": [list(e) for e in added],
        "handle_cycles": [list(c.edges) for c in dropped],
        "cutting_flagged": pool.n_cutting,
        "timings": {"patches": t3 - t0},
        "patch_stages": {"setup": t1 - t0, "basis": t2 - t1, "closing": t3 - t2},
    }
    return PatchSet(network, patches, report), pool
