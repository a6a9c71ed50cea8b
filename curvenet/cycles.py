"""Surface patches as a minimum-weight GF(2) cycle basis of the curve network.

Implements the automatic phase of Abbasinejad, Joshi, Amenta 2011 (Sec. 3-4,
Algorithm 1) and the closing-patch suggestions of its Sec. 5:

* a cycle is a set of edges (a loop edge is a 1-cycle, two parallel curves a
  2-cycle); the cycle space over GF(2) has rank ``E - V + C``;
* candidate cycles of length ``i`` through every vertex are enumerated by a
  depth-bounded search (Algorithm 1, line 6), deduplicated, for ``i = 1, 2,
  ...`` until the basis is full;
* weights (Sec. 4.2): ``k = #edges + (2 + eps) s`` with ``s = 1`` for separating
  cycles, ties broken by a bounding-volume measure;
* the greedy matroid algorithm (Theorem 1) keeps every candidate independent of
  the ones already kept, in the order ``N_1, N_2, N_3, S_1, N_4, S_2, ...``
  (Algorithm 1 interleaves ``N_i`` and ``S_{i-2}``);
* closing patches (Sec. 5) are ranked by ``Ws = 10 (a + b) + k``.

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
from collections import deque

import numpy as np

from ._gf2 import GF2Eliminator, edge_mask, mask_edges, popcount
from .errors import InvalidParameterError, NetworkError
from .network import CurveNetwork
from .patchset import Patch, PatchSet

__all__ = ["find_patches", "cycle_to_loop", "orient_patches", "closing_suggestions",
           "greedy_basis", "Candidate", "CandidatePool", "SEPARATING_EPS", "TIE_BREAKS",
           "ENGINES", "DEFAULT_MAX_WORK", "NUMBA_MIN_WORK"]

#: ``eps`` of ``k = #edges + (2 + eps) s`` (Sec. 4.2). Any value in (0, 1) gives the
#: same order; it only places separating cycles of length ``i - 2`` after the
#: non-separating cycles of length ``i``.
SEPARATING_EPS = 0.5
#: Tie-break measures for cycles of equal ``k`` (see :func:`find_patches`).
TIE_BREAKS = ("pca", "aabb")
#: Enumeration kernels of :class:`CandidatePool`.
ENGINES = ("auto", "python", "numba")
#: ``engine="auto"`` switches from the Python search to the numba kernel once
#: this many search steps were spent (about half a second of Python): importing
#: numba (about a second) costs more than shallow searches do.
NUMBA_MIN_WORK = 500_000
#: Default bound on search steps of the candidate enumeration (one step = one
#: path extension): about 5 s of pure Python, a fraction of a second in numba.
DEFAULT_MAX_WORK = 5_000_000
#: Eigenvalues below this fraction of the largest are treated as zero, so planar
#: cycles get exactly zero PCA volume despite round-off.
_FLAT_RTOL = 1e-10
#: Tie-break keys are rounded to this many decimals (after scaling by the network
#: diagonal) so round-off cannot reorder geometrically equal cycles.
_KEY_DECIMALS = 9
#: Closing weight constant of Sec. 5: ``Ws = 10 (a + b) + k``.
_WS_FACTOR = 10.0
#: Two patches are "smoothly continued" across an edge when their normals near
#: the edge are within this angle (degrees); used by ``close="auto"`` walls.
_SMOOTH_DEG = 30.0
#: A cycle "cuts through" the surface (a handle ring of a torus, not a face) when
#: other curves leave its vertices on both sides of its plane, each steeper than
#: this elevation (degrees) above or below the plane; see CandidatePool.is_cutting.
_CUT_DEG = 45.0
#: A cycle passes straight through a vertex when its two curves there meet at
#: more than arccos(_STRAIGHT_COS) = 150 degrees; only such vertices are tested.
_STRAIGHT_COS = np.cos(np.deg2rad(30.0))
#: Tangent of a curve at an end: chord to the point at this fraction of its length.
_END_TANGENT_FRAC = 0.1
#: Largest null-space dimension searched exhaustively for the smallest solid.
_MAX_NULL_ENUM = 8


class Candidate:
    """One candidate cycle with its Sec. 4.2 weight.

    Attributes
    ----------
    edges : tuple of int
        Sorted edge ids.
    mask : int
        Bitset of ``edges`` (computed on first use).
    length : int
        Number of edges.
    vertices : tuple of int
        The cycle's vertices.
    volume : float
        Tie-break volume (scaled by ``diagonal**3``, rounded).
    area : float
        Area estimate (Sec. 5: largest side of the bounding box), scaled by ``diagonal**2``.
    geo : tuple
        Geometric order within one ``k``: ``(volume, arc length, centroid x, y, z, edges)``.
    separating : bool or None
        Whether removing its vertices (and their edges) splits the graph further;
        ``None`` until :meth:`CandidatePool.classify` computed it (the greedy
        pass only classifies cycles independent of the basis so far).
    cutting : bool
        Whether the cycle cuts through the surface like a handle ring
        (:meth:`CandidatePool.is_cutting`); examined after the other cycles of
        equal ``k`` (a tie-break that comes before the geometric one).
    """

    __slots__ = ("edges", "length", "vertices", "volume", "area", "geo", "separating",
                 "cutting", "_mask")

    def __init__(self, edges, length, vertices, volume, area, geo, separating=None):
        self.edges = edges
        self.length = length
        self.vertices = vertices
        self.volume = volume
        self.area = area
        self.geo = geo
        self.separating = separating
        self.cutting = False
        self._mask = None

    def __repr__(self) -> str:
        return (f"Candidate(edges={self.edges}, volume={self.volume:g}, "
                f"separating={self.separating})")

    @property
    def mask(self) -> int:
        if self._mask is None:
            self._mask = edge_mask(self.edges)
        return self._mask

    @property
    def k(self) -> float:
        """``#edges + (2 + eps) s`` (Sec. 4.2)."""
        if self.separating is None:
            raise RuntimeError("classify the candidate first (CandidatePool.classify)")
        return self.length + (2.0 + SEPARATING_EPS) * self.separating

    @property
    def key(self) -> tuple:
        """Sort key ``(length + 2 s, s, *geo)``: orders by ``k``, then geometry."""
        s = int(self.k > self.length)
        return (self.length + 2 * s, s, *self.geo)


class CandidatePool:
    """Candidate cycles of a network, enumerated length by length (Algorithm 1).

    Precomputes adjacency, per-vertex search distances and per-edge geometric
    moments once; :meth:`cycles_of_length` then enumerates and weighs all simple
    cycles of one length, each exactly once.

    Parameters
    ----------
    network : CurveNetwork
    tie_break : {"pca", "aabb"}
    max_work : int
        Budget of search steps over the pool's lifetime; once spent,
        ``work_bound_hit`` is set and enumeration stops.
    genus_aware : bool
        Examine cycles that cut through the surface (:meth:`is_cutting`) after
        the others of equal ``k`` (ours); ``False``: the paper's order exactly.
    engine : {"auto", "python", "numba"}
        Enumeration kernel: pure Python, or the same search compiled with numba
        (cached on disk after the first compilation). ``"auto"`` starts in Python
        and moves to numba (when it imports) after :data:`NUMBA_MIN_WORK` steps.

    Notes
    -----
    A cycle of length ``L >= 2`` is found from its smallest vertex ``s`` by a
    depth-first search through vertices ``> s`` and kept only when its first
    edge id is smaller than its last (each undirected cycle has two directions).
    Paths are pruned when ``depth + dist_s(x) > L``, with ``dist_s`` the
    breadth-first distance to ``s`` inside the vertices ``>= s``.
    """

    def __init__(self, network: CurveNetwork, *, tie_break: str = "pca",
                 max_work: int = DEFAULT_MAX_WORK, engine: str = "auto",
                 genus_aware: bool = True):
        if engine not in ENGINES:
            raise InvalidParameterError(f"engine: expected one of {ENGINES}, got {engine!r}")
        self.network = network
        self.tie_break = tie_break
        self.genus_aware = bool(genus_aware)
        self.engine = engine
        self.max_work = int(max_work)
        self.work = 0
        self.work_bound_hit = False
        nv, ne = network.number_of_vertices, network.number_of_edges
        self.n_vertices, self.n_edges = nv, ne
        ends = network.endpoints
        self._ends = ends
        self.adj = [[] for _ in range(nv)]
        for e, (u, v) in enumerate(ends.tolist()):
            if u != v:
                self.adj[u].append((v, e))
                self.adj[v].append((u, e))
        for lst in self.adj:
            lst.sort()
        self.nbrs = [sorted({y for y, _ in lst}) for lst in self.adj]
        self.loops = [e for e, (u, v) in enumerate(ends.tolist()) if u == v]
        self._dist = [None] * nv
        #: Candidates offered to closing / replacement suggestions (set by the caller).
        self.all_candidates: list = []
        self._csr = None
        #: "numba" once the numba kernel enumerated some length, else "python".
        self.engine_used = "python"
        self._sep_cache: dict = {}
        self._tangents = None
        self._incident = None
        #: Candidates :meth:`classify` found cutting (0 when not ``genus_aware``).
        self.n_cutting = 0
        self._comp = self._components()
        self.cycle_rank = ne - nv + int(self._comp.max() + 1 if nv else 0)
        self._edge_geometry()

    # --- graph helpers --------------------------------------------------------
    def _components(self) -> np.ndarray:
        comp = -np.ones(self.n_vertices, dtype=np.int64)
        c = 0
        for s in range(self.n_vertices):
            if comp[s] >= 0:
                continue
            comp[s] = c
            stack = [s]
            while stack:
                x = stack.pop()
                for y in self.nbrs[x]:
                    if comp[y] < 0:
                        comp[y] = c
                        stack.append(y)
            c += 1
        return comp

    def _dist_from(self, s: int) -> dict:
        d = self._dist[s]
        if d is None:
            d = {s: 0}
            q = deque([s])
            while q:
                x = q.popleft()
                dx = d[x] + 1
                for y in self.nbrs[x]:
                    if y > s and y not in d:
                        d[y] = dx
                        q.append(y)
            self._dist[s] = d
        return d

    def is_separating(self, vertices) -> bool:
        """Sec. 4.2: removing ``vertices`` and their edges increases the component count.

        The outside neighbours of the vertex set all lie in one component of the
        graph; the removal splits it iff they are not all connected in the rest.
        A breadth-first search from one neighbour stops once all are reached.
        """
        vs = frozenset(vertices)
        hit = self._sep_cache.get(vs)
        if hit is not None:
            return hit
        targets = {y for x in vs for y in self.nbrs[x] if y not in vs}
        sep = False
        if len(targets) > 1:
            start = next(iter(targets))
            seen = {start}
            remaining = len(targets) - 1
            q = deque([start])
            while q and remaining:
                x = q.popleft()
                for y in self.nbrs[x]:
                    if y in vs or y in seen:
                        continue
                    seen.add(y)
                    if y in targets:
                        remaining -= 1
                    q.append(y)
            sep = remaining > 0
        self._sep_cache[vs] = sep
        return sep

    # --- geometry -------------------------------------------------------------
    def _edge_geometry(self):
        """Per-edge AABB and arc-length moments (uniform density along each curve)."""
        ne = self.n_edges
        self._emin = np.zeros((ne, 3))
        self._emax = np.zeros((ne, 3))
        self._m0 = np.zeros(ne)
        self._m1 = np.zeros((ne, 3))
        self._m2 = np.zeros((ne, 3, 3))
        for i, e in enumerate(self.network.edges):
            c = e.curve
            self._emin[i] = c.min(axis=0)
            self._emax[i] = c.max(axis=0)
            a, b = c[:-1], c[1:]
            seg = np.linalg.norm(b - a, axis=1)  # (m-1,)
            self._m0[i] = seg.sum()
            self._m1[i] = (seg[:, None] * (a + b)).sum(axis=0) / 2.0
            # exact second moment of a uniform segment: l (aa' + bb' + (ab' + ba')/2) / 3
            self._m2[i] = np.einsum("s,si,sj->ij", seg / 3.0, a, a) \
                + np.einsum("s,si,sj->ij", seg / 3.0, b, b) \
                + np.einsum("s,si,sj->ij", seg / 6.0, a, b) \
                + np.einsum("s,si,sj->ij", seg / 6.0, b, a)
        self.diagonal = max(self.network.diagonal, 1e-300)

    def measures(self, edge_lists):
        """Tie-break volume, area estimate, arc length and centroid of cycles.

        Parameters
        ----------
        edge_lists : sequence of sequences of int, all of the same length L

        Returns
        -------
        volume, area, arclen : (n,) float64
            Scaled by ``diagonal**3``, ``diagonal**2`` and ``diagonal``.
        centroid : (n, 3) float64
            Arc-length centroid divided by the diagonal.

        Notes
        -----
        ``aabb`` (the paper's choice, Sec. 4.2): volume of the axis-aligned
        bounding box; area = its largest side (Sec. 5).
        ``pca``: volume of the PCA ellipsoid of the curve points (the
        alternative the paper mentions in Sec. 4.2), ``sqrt(l1 l2 l3)`` of the
        arc-length covariance eigenvalues; area ``6 sqrt(l1 l2)`` (exact for a
        square's boundary). Both are zero for planar cycles.
        """
        idx = np.asarray(edge_lists, dtype=np.int64)
        if idx.ndim == 1:
            idx = idx[:, None]
        n = len(idx)
        d = self.diagonal
        m0 = self._m0[idx].sum(axis=1)  # (n,)
        m0s = np.maximum(m0, 1e-300)
        cen = self._m1[idx].sum(axis=1) / m0s[:, None]  # (n, 3)
        if self.tie_break == "aabb":
            ext = self._emax[idx].max(axis=1) - self._emin[idx].min(axis=1)  # (n, 3)
            vol = ext.prod(axis=1)
            area = np.max(ext[:, [0, 1, 2]] * ext[:, [1, 2, 0]], axis=1)
        else:
            cov = self._m2[idx].sum(axis=1) / m0s[:, None, None] \
                - cen[:, :, None] * cen[:, None, :]  # (n, 3, 3)
            lam = np.linalg.eigvalsh(cov)  # ascending, (n, 3)
            lam = np.where(lam < _FLAT_RTOL * np.maximum(lam[:, 2:], 1e-300), 0.0, lam)
            vol = np.sqrt(lam.prod(axis=1))
            area = 6.0 * np.sqrt(lam[:, 1] * lam[:, 2])
        if n == 0:
            z = np.zeros(0)
            return z, z, z, np.zeros((0, 3))
        return (np.round(vol / d**3, _KEY_DECIMALS), np.round(area / d**2, _KEY_DECIMALS),
                np.round(m0 / d, _KEY_DECIMALS), np.round(cen / d, _KEY_DECIMALS))

    def make_candidates(self, edges, vertices) -> list:
        """Weigh cycles of one length.

        Parameters
        ----------
        edges, vertices : (n, L) int64 arrays
            Edge ids and vertices of each cycle (any order within a row).
        """
        if len(edges) == 0:
            return []
        E = np.sort(np.asarray(edges, dtype=np.int64), axis=1)  # (n, L)
        vol, area, arclen, cen = self.measures(E)
        L = E.shape[1]
        out = []
        for es, vs, v, a, ln, c in zip(map(tuple, E.tolist()), map(tuple, np.asarray(vertices)
                                                                    .tolist()),
                                       vol.tolist(), area.tolist(), arclen.tolist(),
                                       cen.tolist()):
            out.append(Candidate(es, L, vs, v, a, (v, ln, c[0], c[1], c[2], es)))
        return out

    def classify(self, candidates) -> None:
        """Set ``separating`` and ``cutting`` on candidates that do not have them yet."""
        for c in candidates:
            if c.separating is None:
                c.separating = self.is_separating(c.vertices)
                c.cutting = (self.genus_aware and not c.separating
                             and self.is_cutting(c.edges))
                self.n_cutting += c.cutting

    def _end_tangents(self):
        """Unit tangents ``(E, 2, 3)`` pointing into each curve from its u and v ends."""
        t = np.zeros((self.n_edges, 2, 3))
        for i, e in enumerate(self.network.edges):
            c = e.curve
            seg = np.linalg.norm(np.diff(c, axis=0), axis=1)
            s = np.concatenate([[0.0], np.cumsum(seg)])
            if s[-1] <= 0:
                continue
            d = _END_TANGENT_FRAC * s[-1]
            t[i, 0] = np.array([np.interp(d, s, c[:, k]) for k in range(3)]) - c[0]
            t[i, 1] = np.array([np.interp(s[-1] - d, s, c[:, k]) for k in range(3)]) - c[-1]
        n = np.linalg.norm(t, axis=2, keepdims=True)
        return t / np.maximum(n, 1e-300)

    def is_cutting(self, edges) -> bool:
        """Whether a cycle cuts through the surface instead of bounding a face (ours).

        A face's neighbouring curves leave its vertices away from it: along the
        surface outside the face, or off to one side (the rest of a solid). Two
        kinds of cycle break this where they pass straight through a vertex
        (handle rings are smooth loops; the test skips the cycle's corners,
        where thin curved faces have ill-defined planes), and are flagged:

        * a ring around a handle (the meridian of a torus) is crossed by curves
          going both ways: at one of its vertices a curve not in the cycle
          leaves above its Newell plane and another below, both steeper than
          ``_CUT_DEG`` degrees (across *different* vertices both sides are
          normal: the faces at a concave edge of an L-shaped solid);
        * a ring along a handle (a parallel of a torus) has curves leaving
          into the disk it spans: some vertex has a curve flatter than
          ``_CUT_DEG`` whose direction, projected on the plane, lies inside the
          cycle's interior angle there (more than ``_CUT_DEG / 2`` degrees from
          both cycle curves).

        Notes
        -----
        Abbasinejad et al. weigh only separating cycles (Sec. 4.2); on a surface
        of genus ``g`` the ``2 g`` handle rings are non-separating and, planar,
        win the volume tie-break against curved faces. Examining them after the
        other cycles of the same ``k`` lets the faces come first; the weights
        ``k`` themselves are the paper's.
        """
        if self._tangents is None:
            self._tangents = self._end_tangents()
            self._incident = [[] for _ in range(self.n_vertices)]
            for e, (u, v) in enumerate(self._ends.tolist()):
                self._incident[u].append((e, 0))
                self._incident[v].append((e, 1))
        es = set(edges)
        try:
            loop = cycle_to_loop(self.network, sorted(es))
        except NetworkError:
            return False
        n = _newell_normal(self.network, loop)
        if not np.isfinite(n).all() or np.linalg.norm(n) < 0.5:
            return False
        lim = np.sin(np.deg2rad(_CUT_DEG))
        margin = np.deg2rad(_CUT_DEG / 2)
        # frame of the plane
        x = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
        x /= np.linalg.norm(x)
        y = np.cross(n, x)

        def angle(t):
            return np.arctan2(t @ y, t @ x)

        for i, (e_out, fwd_out) in enumerate(loop):
            e_in, fwd_in = loop[i - 1]
            v = self._ends[e_out, 0 if fwd_out else 1]
            a = self._tangents[e_out, 0 if fwd_out else 1]   # leaving v along the loop
            p = self._tangents[e_in, 1 if fwd_in else 0]     # leaving v back along the loop
            out = np.array([self._tangents[e, side] for e, side in self._incident[int(v)]
                            if e not in es]).reshape(-1, 3)
            if len(out) == 0 or a @ p > -_STRAIGHT_COS:
                continue  # a corner of the cycle: faces have corners, handle rings do not
            elev = out @ n
            if elev.max() > lim and elev.min() < -lim:
                return True
            # interior sector: counter-clockwise (about n) from a to p
            span = (angle(p) - angle(a)) % (2 * np.pi)
            for w in out[np.abs(elev) < lim]:
                rel = (angle(w) - angle(a)) % (2 * np.pi)
                if margin < rel < span - margin:
                    return True
        return False

    # --- enumeration ------------------------------------------------------------
    def _use_numba(self) -> bool:
        if self.engine == "python":
            return False
        if self.engine == "auto" and self.work < NUMBA_MIN_WORK:
            return False
        return _numba_kernel(required=self.engine == "numba") is not None

    def raw_cycles_of_length(self, L: int):
        """All simple cycles with ``L`` edges, each once.

        Returns
        -------
        edges, vertices : (n, L) int64 arrays, or None
            ``None`` when the work bound is hit.
        """
        if L == 1:
            lp = np.array(self.loops, dtype=np.int64).reshape(-1, 1)
            return lp, self._ends[lp[:, 0], :1].reshape(-1, 1)
        if self._use_numba():
            self.engine_used = "numba"
            return self._raw_cycles_numba(L)
        return self._raw_cycles_python(L)

    def _raw_cycles_numba(self, L: int):
        if self._csr is None:
            nbr = [(x, y, e) for x in range(self.n_vertices) for y, e in self.adj[x]]
            arr = np.array(nbr, dtype=np.int64).reshape(-1, 3)
            indptr = np.searchsorted(arr[:, 0], np.arange(self.n_vertices + 1)).astype(np.int64)
            self._csr = (indptr, np.ascontiguousarray(arr[:, 1]), np.ascontiguousarray(arr[:, 2]))
        indptr, nbrs, eids = self._csr
        kernel = _numba_kernel(required=True)
        edges, verts, work, hit = kernel(L, indptr, nbrs, eids, self.n_vertices,
                                         self.max_work, self.work)
        self.work = int(work)
        if hit:
            self.work_bound_hit = True
            return None
        return edges, verts

    def _raw_cycles_python(self, L: int):
        out = []
        adj = self.adj
        work = self.work
        budget = self.max_work
        for s in range(self.n_vertices):
            if not adj[s]:
                continue
            dist = self._dist_from(s)
            # stack of (vertex, depth, edge path, vertex path)
            for y, e in adj[s]:
                if y < s:
                    continue
                if L == 2:
                    if y == s:
                        continue
                    for y2, e2 in adj[y]:
                        if y2 == s and e2 > e:
                            out.append(((e, e2), (s, y)))
                    continue
                if y == s or dist.get(y, L + 1) + 1 > L:
                    continue
                stack = [(y, 1, (e,), (s, y))]
                while stack:
                    x, depth, ep, vp = stack.pop()
                    work += 1
                    if depth == L - 1:
                        for z, ez in adj[x]:
                            if z == s and ez > ep[0]:
                                out.append((ep + (ez,), vp))
                        continue
                    for z, ez in adj[x]:
                        if z <= s or z in vp:
                            continue
                        dz = dist.get(z)
                        if dz is None or depth + 1 + dz > L:
                            continue
                        stack.append((z, depth + 1, ep + (ez,), vp + (z,)))
                if work > budget:
                    self.work = work
                    self.work_bound_hit = True
                    return None
        self.work = work
        return (np.array([o[0] for o in out], dtype=np.int64).reshape(-1, L),
                np.array([o[1] for o in out], dtype=np.int64).reshape(-1, L))

    def cycles_of_length(self, L: int):
        """Weighted candidates of length ``L``, or ``None`` when the work bound is hit."""
        raw = self.raw_cycles_of_length(L)
        if raw is None:
            return None
        return self.make_candidates(*raw)

    def horton_candidates(self, min_length: int = 1) -> list:
        """Horton (1987) cycles ``P(s, x) + (x, y) + P(y, s)`` from shortest-path trees.

        They span the cycle space (they contain a minimum-length basis), so a
        greedy pass over them always completes the basis. Used only when the
        exhaustive enumeration hits its work bound.
        """
        seen = set()
        by_len: dict = {}
        for s in range(self.n_vertices):
            if not self.adj[s]:
                continue
            par = {s: (-1, -1)}  # vertex -> (parent, edge)
            branch = {s: -1}
            q = deque([s])
            while q:
                x = q.popleft()
                for y, e in self.adj[x]:
                    if y not in par:
                        par[y] = (x, e)
                        branch[y] = y if x == s else branch[x]
                        q.append(y)
            tree_edges = {pe for _, pe in par.values()}
            for x in par:
                for y, e in self.adj[x]:
                    if e in tree_edges or y < x:
                        continue
                    if x != s and y != s and branch[x] == branch[y]:
                        continue
                    edges, verts = [e], [x, y]
                    for w in (x, y):
                        while w != s:
                            p, pe = par[w]
                            edges.append(pe)
                            if p != s:
                                verts.append(p)
                            w = p
                    verts.append(s)
                    fe = frozenset(edges)
                    if len(fe) != len(edges) or len(fe) < min_length or fe in seen:
                        continue
                    if len(set(verts)) != len(edges):
                        continue
                    seen.add(fe)
                    by_len.setdefault(len(edges), []).append((tuple(edges), tuple(set(verts))))
        out = []
        for L in sorted(by_len):
            out.extend(self.make_candidates(np.array([c[0] for c in by_len[L]]),
                                            np.array([c[1] for c in by_len[L]])))
        return out


def _numba_kernel(required: bool = False):
    """The numba enumeration kernel, or None when numba is missing (and not required)."""
    try:
        from ._cycle_kernel import enumerate_cycles
    except ImportError:
        if required:
            from .errors import MissingDependencyError
            raise MissingDependencyError("engine='numba' needs numba: pip install numba") \
                from None
        return None
    return enumerate_cycles


def _validate(network, close, tie_break, max_cycle_length, max_work):
    if not isinstance(network, CurveNetwork):
        raise InvalidParameterError(f"network: expected a CurveNetwork, got {type(network)!r}")
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


def greedy_basis(pool: CandidatePool, *, max_cycle_length=None):
    """Algorithm 1 with the greedy matroid test on bitsets.

    Returns
    -------
    basis : list of Candidate
        In acceptance order.
    pool_candidates : list of Candidate
        Every candidate enumerated (for closing suggestions), by length then ``geo``.
    info : dict
        ``candidates`` per length, ``max_length`` reached, ``horton`` count.
    """
    el = GF2Eliminator()
    basis, allc = [], []
    counts = {}
    r_full = pool.cycle_rank
    pending_sep: dict = {}
    limit = pool.n_vertices if max_cycle_length is None else min(max_cycle_length,
                                                                 max(pool.n_vertices, 1))
    limit = max(limit, 1)

    def consume(cands):
        """Greedy matroid step over cycles already in ``k`` order."""
        for c in cands:
            if el.rank >= r_full:
                return
            if el.add(c.mask):
                basis.append(c)

    L = 0
    n_horton = 0
    while el.rank < r_full and L < limit:
        L += 1
        cands = pool.cycles_of_length(L)
        if cands is None:
            break
        allc.extend(cands)
        cands.sort(key=lambda c: c.geo)
        # N_L pass (k = L). A cycle dependent on the basis now stays dependent, so
        # it is dropped unclassified; independent separating ones wait for S_L.
        sep, cut = [], []
        for c in cands:
            if el.rank >= r_full:
                break
            if not el.is_independent(c.mask):
                continue
            pool.classify([c])
            if c.separating:
                sep.append(c)
            elif c.cutting:
                cut.append(c)        # same k, examined after the faces of length L
            else:
                el.add(c.mask)
                basis.append(c)
        consume(cut)
        pending_sep[L] = sep
        counts[L] = {"total": len(cands), "separating_examined": len(sep)}
        consume(pending_sep.pop(L - 2, []))       # S_{L-2} (k = L + eps)
    if el.rank < r_full:
        # flush separating cycles not yet examined, in k order
        consume([c for Ls in sorted(pending_sep) for c in pending_sep[Ls]])
    if el.rank < r_full and pool.work_bound_hit and max_cycle_length is None:
        known = {c.mask for c in allc}
        extra = [c for c in pool.horton_candidates(min_length=L) if c.mask not in known]
        pool.classify(extra)
        n_horton = len(extra)
        allc.extend(extra)
        consume(sorted(extra, key=lambda c: c.key))
    allc.sort(key=lambda c: (c.length, c.geo))
    return basis, allc, {"candidates": counts, "max_length": L, "horton_candidates": n_horton}


def cycle_to_loop(network: CurveNetwork, edge_ids) -> list:
    """Order a cycle's edges into one closed, oriented loop.

    Parameters
    ----------
    network : CurveNetwork
    edge_ids : iterable of int
        The cycle's edges, in any order.

    Returns
    -------
    loop : list of (int, bool)
        ``(edge_id, forward)`` in walking order; ``forward`` means the edge is
        walked ``u -> v``. The walk starts with the smallest edge id, forward.

    Raises
    ------
    NetworkError
        Empty, repeated or out-of-range ids, or edges that are not one simple
        closed loop (a vertex of degree other than 2, or several loops).

    Examples
    --------
    >>> from curvenet.shapes import box
    >>> net = box().network
    >>> loop = cycle_to_loop(net, [2, 0, 1, 3])
    >>> sorted(e for e, _ in loop)
    [0, 1, 2, 3]
    """
    ids = [int(e) for e in edge_ids]
    ne = network.number_of_edges
    if not ids:
        raise NetworkError("cycle_to_loop: empty edge list")
    if len(set(ids)) != len(ids):
        raise NetworkError(f"cycle_to_loop: repeated edge ids in {ids}")
    bad = [e for e in ids if not 0 <= e < ne]
    if bad:
        raise NetworkError(f"cycle_to_loop: edge ids {bad} out of range 0..{ne - 1}")
    ends = {e: (network.edges[e].u, network.edges[e].v) for e in ids}
    if len(ids) == 1:
        u, v = ends[ids[0]]
        if u != v:
            raise NetworkError(f"cycle_to_loop: edge {ids[0]} alone is not closed")
        return [(ids[0], True)]
    inc: dict = {}
    for e, (u, v) in ends.items():
        if u == v:
            raise NetworkError(f"cycle_to_loop: loop edge {e} inside a longer cycle")
        inc.setdefault(u, []).append(e)
        inc.setdefault(v, []).append(e)
    odd = {x: len(es) for x, es in inc.items() if len(es) != 2}
    if odd:
        raise NetworkError(f"cycle_to_loop: edges {sorted(ids)} are not a simple loop "
                           f"(vertex degrees {odd})")
    start = min(ids)
    loop = [(start, True)]
    used = {start}
    x = ends[start][1]
    while len(loop) < len(ids):
        nxt = [e for e in inc[x] if e not in used]
        if not nxt:
            raise NetworkError(f"cycle_to_loop: edges {sorted(ids)} form several loops")
        e = nxt[0]
        u, v = ends[e]
        fwd = u == x
        loop.append((e, fwd))
        used.add(e)
        x = v if fwd else u
    if x != ends[start][0]:
        raise NetworkError(f"cycle_to_loop: edges {sorted(ids)} do not close")
    return loop


def _loop_points(network, loop) -> np.ndarray:
    pts = [network.edges[e].curve if f else network.edges[e].curve[::-1] for e, f in loop]
    return np.concatenate([p[:-1] for p in pts])


def _signed_volume(network, loops) -> float:
    """Signed volume of the fan-triangulated loops (divergence theorem)."""
    total = 0.0
    for loop in loops:
        p = _loop_points(network, loop)
        c = p.mean(axis=0)
        a, b = p, np.roll(p, -1, axis=0)
        total += float(np.einsum("ij,ij->", np.cross(a, b), np.broadcast_to(c, a.shape)))
    return total / 6.0


def orient_patches(network: CurveNetwork, patches) -> list:
    """Oriented loops of the patches, consistent across shared edges.

    Parameters
    ----------
    network : CurveNetwork
    patches : sequence of Patch or of edge-id sequences

    Returns
    -------
    loops : list of list of (int, bool)
        One loop per patch, same order.

    Notes
    -----
    Patches are visited breadth-first across edges shared by exactly two
    patches; a neighbour is reversed when it walks the shared edge in the same
    direction, so adjacent patches traverse it in opposite directions where the
    surface is orientable (non-manifold edges, used by three or more patches,
    impose nothing; on a non-orientable surface the first orientation found
    wins). Each group of patches connected this way that is closed (every edge
    used twice within it) is then flipped as a whole if its fan-triangulated
    signed volume is negative, so closed surfaces come out with outward normals
    (right-hand rule); open ones keep the orientation of their first patch as
    :func:`cycle_to_loop` walks it.
    """
    edge_sets = [p.edges if isinstance(p, Patch) else tuple(p) for p in patches]
    loops = [cycle_to_loop(network, es) for es in edge_sets]
    by_edge: dict = {}
    for i, es in enumerate(edge_sets):
        for e in es:
            by_edge.setdefault(int(e), []).append(i)
    dirs = [{e: f for e, f in lp} for lp in loops]
    done = [False] * len(loops)
    for root in range(len(loops)):
        if done[root]:
            continue
        done[root] = True
        group = [root]
        q = deque([root])
        while q:
            i = q.popleft()
            for e in edge_sets[i]:
                users = by_edge[int(e)]
                if len(users) != 2:
                    continue
                j = users[0] if users[1] == i else users[1]
                if done[j]:
                    continue
                if dirs[j][e] == dirs[i][e]:
                    loops[j] = [(x, not f) for x, f in reversed(loops[j])]
                    dirs[j] = {x: f for x, f in loops[j]}
                done[j] = True
                group.append(j)
                q.append(j)
        uses: dict = {}
        for i in group:
            for e in edge_sets[i]:
                uses[e] = uses.get(e, 0) + 1
        closed = all(n == 2 for n in uses.values())
        if closed and _signed_volume(network, [loops[i] for i in group]) < 0:
            for i in group:
                loops[i] = [(x, not f) for x, f in reversed(loops[i])]
    return loops


def _newell_normal(network, loop) -> np.ndarray:
    p = _loop_points(network, loop)
    n = np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0)
    return n / max(np.linalg.norm(n), 1e-300)


def _smallest_in_coset(x: int, null: list) -> int:
    """Smallest-popcount element of ``x + span(null)``: exhaustive for small spans, else greedy."""
    if not null:
        return x
    if len(null) <= _MAX_NULL_ENUM:
        best, bc = x, popcount(x)
        sums = [0]
        for v in null:
            sums += [s ^ v for s in sums]
        for s in sums:
            c = popcount(x ^ s)
            if c < bc:
                best, bc = x ^ s, c
        return best
    improved = True
    while improved:
        improved = False
        for v in null:
            if popcount(x ^ v) < popcount(x):
                x ^= v
                improved = True
    return x


def closing_suggestions(pool: CandidatePool, patch_edges, *, exclude=(), max_length=None,
                        backend: str = "bitset", candidates=None):
    """Closing patches for a patch set (Sec. 5), best first.

    Parameters
    ----------
    pool : CandidatePool
        Its ``all_candidates`` are the cycles considered.
    patch_edges : list of tuple of int
        Current patches.
    exclude : iterable of tuple of int
        Edge sets not to suggest (rejected ones).
    max_length : int, optional
        Longest candidate considered (default: every enumerated candidate).
    backend : {"bitset", "galois"}
        GF(2) solver: Python-int elimination, or ``galois`` row reduction (same answers).
    candidates : list of Candidate, optional
        Cycles to consider instead of ``pool.all_candidates``.

    Returns
    -------
    list of dict
        Keys ``edges``, ``size`` (k = number of edges), ``score`` (``Ws``),
        ``a``, ``b``, ``solid`` (indices of current patches closing the solid
        with the suggestion), ``candidate``.

    Notes
    -----
    ``Ws = 10 (a + b) + k`` (Sec. 5), larger is better; ``a`` = area estimate of
    the solid (sum over its cycles, the suggestion included) / area estimate
    of the suggestion, ``b`` = edges of the suggestion used by exactly one
    current patch. The paper's text says short cycles are preferred while its
    formula adds ``k``; we implement the formula. The solid is found by rank
    (Sec. 5): the suggestion ``c`` is the GF(2) sum of a subset ``J`` of the
    patches; the solid is ``J + c``. When the patches are dependent (solids
    already closed) ``J`` is not unique: we take the smallest one in its coset
    (exhaustive when the null space has dimension <= 8, else greedy). Only
    candidates in the span of the patches close a solid; independent ones are
    not closing patches.

    Our addition: a candidate sharing two or more edges and at least half of
    the edges of some current patch ``p`` is not suggested. Then ``c + p`` is a
    cycle no longer than ``c``, and ``c`` is bent around ``p`` (two faces of a
    box merged across an edge, a skew hexagon through half of a face); with the
    paper's ``Ws`` such cycles outrank true faces because they inherit large
    solids and open edges. Faces of a curve network normally share one curve.
    """
    from ._gf2 import bitset_solve, gf2_solve

    current = {tuple(sorted(p)) for p in patch_edges}
    excl = {tuple(sorted(p)) for p in exclude}
    cands = [c for c in (pool.all_candidates if candidates is None else candidates)
             if c.edges not in current and c.edges not in excl
             and (max_length is None or c.length <= max_length)]
    if not cands or not patch_edges:
        return []
    # Overlap filter (our addition): drop c when it shares two or more edges and at
    # least half of some patch p (then c + p is no longer than c): c folds onto p.
    users: dict = {}
    for i, p in enumerate(patch_edges):
        for e in p:
            users.setdefault(e, []).append(i)
    plen = [len(p) for p in patch_edges]
    kept = []
    for c in cands:
        shared: dict = {}
        for e in c.edges:
            for i in users.get(e, ()):
                shared[i] = shared.get(i, 0) + 1
        if all(n < 2 or 2 * n < plen[i] for i, n in shared.items()):
            kept.append(c)
    cands = kept
    if not cands:
        return []
    pmasks = [edge_mask(p) for p in patch_edges]
    if backend == "galois":
        sols, null = gf2_solve(pmasks, [c.mask for c in cands], pool.n_edges)
    else:
        sols, null = bitset_solve(pmasks, [c.mask for c in cands])
    parea = _patch_areas(pool, patch_edges)
    degree = np.zeros(pool.n_edges, dtype=np.int64)
    for p in patch_edges:
        degree[list(p)] += 1
    out = []
    for c, x in zip(cands, sols):
        if x is None:
            continue
        J = mask_edges(_smallest_in_coset(x, null))
        ca = max(c.area, 1e-300)
        a = (float(parea[list(J)].sum()) + c.area) / ca
        b = int((degree[list(c.edges)] == 1).sum())
        ws = _WS_FACTOR * (a + b) + c.length
        out.append({"edges": c.edges, "size": c.length, "score": float(ws), "a": float(a),
                    "b": b, "solid": J, "candidate": c})
    out.sort(key=lambda s: (-s["score"], s["candidate"].length, s["candidate"].geo))
    return out


def _patch_areas(pool, patch_edges) -> np.ndarray:
    out = np.zeros(len(patch_edges))
    by_len: dict = {}
    for i, p in enumerate(patch_edges):
        by_len.setdefault(len(p), []).append(i)
    for _, idx in by_len.items():
        _, area, _, _ = pool.measures([sorted(patch_edges[i]) for i in idx])
        out[idx] = area
    return out


def _auto_close(pool, patch_edges, max_length):
    """``close="auto"``: accept closing patches that fill holes or unexplained creases.

    Repeatedly takes the best closing suggestion (up to ``max_length`` edges,
    the longest cycle the automatic phase needed) that either (i) uses only
    edges currently used by exactly one patch (a hole bounded by open edges,
    like the missing face of a box), or (ii) uses only edges labelled
    ``"crease"`` that are each used by exactly two patches continuing smoothly
    across it (normals within 30 degrees): a crease that no current patch
    explains, like the wall shared by two stacked boxes. Rule (ii) is our
    addition to the paper (Sec. 5 leaves closing to the user).
    """
    added = []
    patch_edges = list(patch_edges)
    normals: dict = {}
    cos_smooth = np.cos(np.deg2rad(_SMOOTH_DEG))
    net = pool.network
    crease = np.array([e.label == "crease" for e in net.edges], dtype=bool)
    pool_short = [c for c in pool.all_candidates if c.length <= max_length]
    if not pool_short:
        return added
    ne = pool.n_edges
    width = max(c.length for c in pool_short)
    idx = np.full((len(pool_short), width), ne, dtype=np.int64)  # padded with sentinel ne
    for j, c in enumerate(pool_short):
        idx[j, :c.length] = c.edges
    pad = idx == ne
    crease_ok = (np.append(crease, True)[idx]).all(axis=1)

    def normal(i):
        if i not in normals:
            normals[i] = _newell_normal(net, cycle_to_loop(net, patch_edges[i]))
        return normals[i]

    while True:
        users: dict = {}
        deg = np.zeros(ne + 1, dtype=np.int64)
        for i, p in enumerate(patch_edges):
            deg[list(p)] += 1
            for e in p:
                users.setdefault(e, []).append(i)
        dc = deg[idx]
        hole = ((dc == 1) | pad).all(axis=1)
        wall = ((dc == 2) | pad).all(axis=1) & crease_ok
        current = set(map(tuple, patch_edges))
        eligible = []
        for j in np.flatnonzero(hole | wall):
            c = pool_short[j]
            if c.edges in current:
                continue
            if hole[j] or all(abs(float(normal(users[e][0]) @ normal(users[e][1])))
                              >= cos_smooth for e in c.edges):
                eligible.append(c)
        sugg = closing_suggestions(pool, patch_edges, candidates=eligible)
        if not sugg:
            break
        patch_edges.append(sugg[0]["edges"])
        added.append(sugg[0]["edges"])
    return added


def find_patches(network: CurveNetwork, *, close: str = "auto", tie_break: str = "pca",
                 max_cycle_length=None, max_work: int = DEFAULT_MAX_WORK,
                 engine: str = "auto", genus_aware: bool = True) -> PatchSet:
    """Find surface patches: minimum-weight GF(2) cycle basis plus closing patches.

    Parameters
    ----------
    network : CurveNetwork
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
        ``patch_stages`` (seconds for ``setup``, ``basis``, ``closing``).

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
    smaller manifold defect (curves used
    by one patch plus curves used by three or more; ``report["manifold_defect"]``)
    is kept, the paper's on ties (``report["order"]``). On the 29 public
    networks this changes 4 models (torus_simple, mug, cup, beetle), each to a
    smaller defect.

    References
    ----------
    Abbasinejad, Joshi, Amenta 2011, Sec. 4.1 (Theorem 1, greedy matroid),
    Sec. 4.2 (weights), Algorithm 1, Sec. 5 (closing patches).

    Examples
    --------
    >>> from curvenet.shapes import box
    >>> ps = find_patches(box().network)
    >>> len(ps.patches), ps.report["rank"], [p.source for p in ps.patches].count("closing")
    (6, 5, 1)
    """
    _validate(network, close, tie_break, max_cycle_length, max_work)
    t0 = time.perf_counter()
    kw = dict(close=close, tie_break=tie_break, max_cycle_length=max_cycle_length,
              max_work=max_work, engine=engine)
    ps = _find_patches(network, genus_aware=genus_aware, **kw)
    score = _manifold_defect(network, ps.patches)
    defect = {"paper": score}
    order = "paper"
    if genus_aware:
        defect["genus_aware"] = score
        # with no cycle found cutting, the genus-aware run took the paper's order
        if ps.report["cutting_flagged"]:
            paper = _find_patches(network, genus_aware=False, **kw)
            defect["paper"] = _manifold_defect(network, paper.patches)
            if score < defect["paper"]:
                order = "genus_aware"
            else:
                ps = paper
    ps.report["manifold_defect"] = defect
    ps.report["order"] = order
    ps.report["timings"] = {"patches": time.perf_counter() - t0}
    return ps


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
    pool.all_candidates = allc
    t2 = time.perf_counter()
    kept = [c for c in basis if not c.cutting]
    handles = [c for c in basis if c.cutting]
    added = []
    if close == "auto" and basis:
        max_len = max(c.length for c in basis)
        added = _auto_close(pool, [c.edges for c in kept], max_len)
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
    return PatchSet(network, patches, report)
