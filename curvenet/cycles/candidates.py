"""Candidate cycles of a curve network and their Sec. 4.2 weights.

Part of the automatic phase of Abbasinejad, Joshi, Amenta 2011 (Sec. 3-4,
Algorithm 1): a cycle is a set of edges (a loop edge is a 1-cycle, two parallel
curves a 2-cycle). :class:`CandidatePool` enumerates the simple cycles of length
``i`` by a depth-bounded search (Algorithm 1, line 6), each exactly once, and
weighs them: ``k = #edges + (2 + eps) s`` with ``s = 1`` for separating cycles,
ties broken by a bounding-volume measure (Sec. 4.2). When the search exceeds
its work bound, Horton's shortest-path cycles stand in for the rest.

References
----------
F. Abbasinejad, P. Joshi, N. Amenta. Surface patches from unorganized space
curves. Computer Graphics Forum 30(5) (SGP 2011), Sec. 3-4.
J. D. Horton. A polynomial-time algorithm to find the shortest cycle basis of a
graph. SIAM J. Comput. 16(2), 1987.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from .gf2 import edge_mask
from ..core.polylines import Polylines, row_dots
from ..core.tolerances import DIVISION_GUARD
from ..core.errors import InvalidParameterError, NetworkError
from .loops import cycle_to_loop, newell_normal
from .search import horton_cycles, simple_cycles
from ..model.network import CurveNetwork

__all__ = ["Candidate", "CandidatePool", "SEPARATING_EPS", "TIE_BREAKS", "ENGINES",
           "DEFAULT_MAX_WORK", "NUMBA_MIN_WORK"]

#: ``eps`` of ``k = #edges + (2 + eps) s`` (Sec. 4.2). Any value in (0, 1) gives the
#: same order; it only places separating cycles of length ``i - 2`` after the
#: non-separating cycles of length ``i``.
SEPARATING_EPS = 0.5
#: Tie-break measures for cycles of equal ``k`` (see :func:`curvenet.cycles.find_patches`).
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
#: A cycle "cuts through" the surface (a handle ring of a torus, not a face) when
#: other curves leave its vertices on both sides of its plane, each steeper than
#: this elevation (degrees) above or below the plane; see CandidatePool.is_cutting.
_CUT_DEG = 45.0
#: A cycle passes straight through a vertex when its two curves there meet at
#: more than arccos(_STRAIGHT_COS) = 150 degrees; only such vertices are tested.
_STRAIGHT_COS = np.cos(np.deg2rad(30.0))
#: Tangent of a curve at an end: chord to the point at this fraction of its length.
_END_TANGENT_FRAC = 0.1

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

    Precomputes adjacency and per-edge geometric moments once;
    :meth:`cycles_of_length` then enumerates and weighs all simple cycles of one
    length, each exactly once.

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
    breadth-first distance to ``s`` inside the vertices ``>= s``, searched up to
    ``L // 2`` hops (as the numba kernel does: no vertex of such a cycle lies farther).
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
        self._by_length: dict = {}        # L -> candidates of cycles_of_length(L)
        self._candidates: list = []       # every candidate handed out, in enumeration order
        self._sorted = None               # cache of all_candidates
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

    @property
    def all_candidates(self) -> list:
        """Every candidate enumerated so far, by length then ``geo`` (a new list).

        :meth:`cycles_of_length` and :meth:`horton_candidates` add to it; closing
        and replacement suggestions choose from it.
        """
        if self._sorted is None:
            self._sorted = sorted(self._candidates, key=lambda c: (c.length, c.geo))
        return list(self._sorted)

    def _record(self, candidates: list) -> list:
        self._candidates.extend(candidates)
        self._sorted = None
        return candidates

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

    def _dist_from(self, s: int, reach: int) -> dict:
        """Hop distances from ``s`` inside the vertices ``>= s``, up to ``reach`` hops.

        Every vertex of a cycle of ``L`` edges through its smallest vertex ``s`` lies
        within ``L // 2`` hops of ``s``, so that reach prunes the search exactly as the
        whole breadth-first tree would, at a cost bounded by the ball, not the graph.
        """
        d = {s: 0}
        q = deque([s])
        while q:
            x = q.popleft()
            dx = d[x] + 1
            if dx > reach:
                continue
            for y in self.nbrs[x]:
                if y > s and y not in d:
                    d[y] = dx
                    q.append(y)
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
        """Per-edge AABB and arc-length moments (uniform density along each curve), for
        all curves of one point count at once."""
        ne = self.n_edges
        self._lines = Polylines([e.curve for e in self.network.edges])
        self._emin = np.zeros((ne, 3))
        self._emax = np.zeros((ne, 3))
        self._m0 = np.zeros(ne)
        self._m1 = np.zeros((ne, 3))
        self._m2 = np.zeros((ne, 3, 3))
        for ids, c, _ in self._lines.groups:
            self._emin[ids] = c.min(axis=1)
            self._emax[ids] = c.max(axis=1)
            a, b = c[:, :-1], c[:, 1:]
            seg = np.linalg.norm(b - a, axis=2)  # (g, m-1)
            self._m0[ids] = seg.sum(axis=1)
            self._m1[ids] = (seg[:, :, None] * (a + b)).sum(axis=1) / 2.0
            # exact second moment of a uniform segment: l (aa' + bb' + (ab' + ba')/2) / 3
            self._m2[ids] = np.einsum("gs,gsi,gsj->gij", seg / 3.0, a, a) \
                + np.einsum("gs,gsi,gsj->gij", seg / 3.0, b, b) \
                + np.einsum("gs,gsi,gsj->gij", seg / 6.0, a, b) \
                + np.einsum("gs,gsi,gsj->gij", seg / 6.0, b, a)
        self.diagonal = max(self.network.diagonal, DIVISION_GUARD)

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
        m0s = np.maximum(m0, DIVISION_GUARD)
        cen = self._m1[idx].sum(axis=1) / m0s[:, None]  # (n, 3)
        if self.tie_break == "aabb":
            ext = self._emax[idx].max(axis=1) - self._emin[idx].min(axis=1)  # (n, 3)
            vol = ext.prod(axis=1)
            area = np.max(ext[:, [0, 1, 2]] * ext[:, [1, 2, 0]], axis=1)
        else:
            cov = self._m2[idx].sum(axis=1) / m0s[:, None, None] \
                - cen[:, :, None] * cen[:, None, :]  # (n, 3, 3)
            lam = np.linalg.eigvalsh(cov)  # ascending, (n, 3)
            lam = np.where(lam < _FLAT_RTOL * np.maximum(lam[:, 2:], DIVISION_GUARD), 0.0, lam)
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
        total = self._lines.length
        d = _END_TANGENT_FRAC * total
        ends = np.array([(e.curve[0], e.curve[-1]) for e in self.network.edges]).reshape(-1, 2, 3)
        t = self._lines.interp(np.stack([d, total - d], axis=1)) - ends
        t[total <= 0] = 0.0
        n = np.linalg.norm(t, axis=2, keepdims=True)
        return t / np.maximum(n, DIVISION_GUARD)

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
        e_out = np.array([e for e, _ in loop], np.int64)
        s_out = np.array([0 if f else 1 for _, f in loop], np.int64)
        e_in = np.concatenate([e_out[-1:], e_out[:-1]])
        s_in = 1 - np.concatenate([s_out[-1:], s_out[:-1]])
        a_all = self._tangents[e_out, s_out]     # leaving each vertex along the loop
        p_all = self._tangents[e_in, s_in]       # leaving it back along the loop
        # a corner of the cycle (a @ p > -cos): faces have corners, handle rings do not
        straight = np.flatnonzero(~(row_dots(a_all, p_all) > -_STRAIGHT_COS))
        if len(straight) == 0:
            return False
        n = newell_normal(self.network, loop)
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

        for i in straight.tolist():
            a, p = a_all[i], p_all[i]
            v = self._ends[e_out[i], s_out[i]]
            out = np.array([self._tangents[e, side] for e, side in self._incident[int(v)]
                            if e not in es]).reshape(-1, 3)
            if len(out) == 0:
                continue
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
        found = simple_cycles(self.adj, L, lambda s: self._dist_from(s, L // 2), self.work,
                              self.max_work)
        self.work = found[2]
        if found[0] is None:
            self.work_bound_hit = True
            return None
        return found[0], found[1]

    def cycles_of_length(self, L: int):
        """Weighted candidates of length ``L``, or ``None`` when the work bound is hit.

        Enumerated once per length (later calls return the same candidates in a
        new list); they are also added to :attr:`all_candidates`.
        """
        if L not in self._by_length:
            raw = self.raw_cycles_of_length(L)
            if raw is None:
                return None
            self._by_length[L] = self._record(self.make_candidates(*raw))
        return list(self._by_length[L])

    def horton_candidates(self, min_length: int = 1) -> list:
        """Horton (1987) cycles ``P(s, x) + (x, y) + P(y, s)`` from shortest-path trees.

        They span the cycle space (they contain a minimum-length basis), so a
        greedy pass over them always completes the basis. Used only when the
        exhaustive enumeration hits its work bound.

        Returns
        -------
        list of Candidate
            The Horton cycles of at least ``min_length`` edges that are not in
            :attr:`all_candidates` yet, by length; they are added to it.
        """
        seen = {frozenset(c.edges) for c in self._candidates}
        by_len = horton_cycles(self.adj, seen, min_length)
        out = []
        for L in sorted(by_len):
            out.extend(self.make_candidates(np.array([c[0] for c in by_len[L]]),
                                            np.array([c[1] for c in by_len[L]])))
        return self._record(out)


def _numba_kernel(required: bool = False):
    """The numba enumeration kernel, or None when numba is missing (and not required)."""
    try:
        from .kernel import enumerate_cycles
    except ImportError:
        if required:
            from ..core.errors import MissingDependencyError
            raise MissingDependencyError("engine='numba' needs numba: pip install numba") \
                from None
        return None
    return enumerate_cycles
