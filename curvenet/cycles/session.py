"""Interactive patch editing: delete, replacement and closing suggestions, accept / reject.

The topology-aware interface of Abbasinejad, Joshi, Amenta 2011, Sec. 5, as a
Python API (:class:`PatchSession`); :mod:`curvenet.review` puts it in front of a
user (the terminal loop :func:`curvenet.review.run_interactive`).

* Deleting a patch that was part of the basis drops the rank: the session
  suggests replacements that restore it, next-best first by the automatic
  phase's weight (Sec. 4.2: ``k``, then the tie-break volume).
* Closing patches add a solid: they are ranked by ``Ws = 10 (a + b) + k``
  (Sec. 5); each suggestion names the patches that close the solid with it.

The GF(2) algebra (which candidates are independent of the current patches,
which patches sum to a candidate) is done with ``galois`` by default
(``backend="bitset"`` gives the same answers with Python-int elimination).

References
----------
Abbasinejad, Joshi, Amenta 2011, Sec. 5 (replacement and closing suggestions).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .gf2 import bitset_solve, edge_mask, gf2_rank, gf2_solve
from .candidates import DEFAULT_MAX_WORK, TIE_BREAKS, CandidatePool
from .closing import closing_suggestions
from ..core.errors import InvalidParameterError
from .loops import cycle_to_loop
from ..io.network import write_patches
from ..model.patchset import Patch, PatchSet

__all__ = ["Suggestion", "PatchSession"]

#: Candidate cycles are enumerated up to the longest patch plus this many edges.
EXTRA_LENGTH = 2
#: Suggestions returned per request by default.
DEFAULT_TOP = 10
_BACKENDS = ("galois", "bitset")


@dataclass(frozen=True)
class Suggestion:
    """A patch the session proposes.

    Attributes
    ----------
    edges : tuple of int
        Sorted edge ids of the cycle.
    kind : {"replacement", "closing"}
    score : float
        ``k`` (Sec. 4.2, smaller is better) for replacements, ``Ws`` (Sec. 5,
        larger is better) for closing patches.
    size : int
        Number of edges.
    details : dict
        Replacements: ``k``, ``volume``. Closing: ``a``, ``b``, ``solid``
        (indices of current patches that close the solid with this one).
    """

    edges: tuple
    kind: str
    score: float
    size: int
    details: dict = field(default_factory=dict, compare=False, hash=False)

    def describe(self) -> str:
        """One line: kind, size, score, edges (and the solid for closing patches)."""
        head = (f"{self.kind} patch: {self.size} edges, "
                + (f"k = {self.score:g}" if self.kind == "replacement"
                   else f"Ws = {self.score:.1f} (a = {self.details['a']:.2f}, "
                        f"b = {self.details['b']})"))
        tail = f"; edges {list(self.edges)}"
        if self.kind == "closing":
            tail += f"; closes a solid with patches {list(self.details['solid'])}"
        return head + tail


class PatchSession:
    """Editable patch set with ranked suggestions, accept / reject and undo.

    Parameters
    ----------
    patchset : PatchSet
        Starting patches (e.g. from :func:`curvenet.cycles.find_patches`);
        not modified.
    tie_break : {"pca", "aabb"}, optional
        Default: the one recorded in ``patchset.report``, else ``"pca"``.
    backend : {"galois", "bitset"}
        GF(2) solver for the suggestions.
    max_work : int
        Enumeration budget for candidate cycles (see
        :class:`~curvenet.cycles.candidates.CandidatePool`).

    Notes
    -----
    Candidates are all cycles up to the longest current patch (or the length
    the automatic phase reached) plus :data:`EXTRA_LENGTH` edges, within the
    work budget. Rejected suggestions are not proposed again (until undone).
    Every action (delete, accept, reject) can be undone, last first.

    Examples
    --------
    >>> from curvenet.datasets.shapes import box
    >>> from curvenet.cycles import find_patches
    >>> s = PatchSession(find_patches(box().network))
    >>> face = s.patches[0].edges
    >>> s.delete(0)[0].edges == face
    True
    """

    def __init__(self, patchset: PatchSet, *, tie_break=None, backend: str = "galois",
                 max_work: int = DEFAULT_MAX_WORK):
        if not isinstance(patchset, PatchSet):
            raise InvalidParameterError(f"patchset: expected a PatchSet, got {type(patchset)!r}")
        tie_break = tie_break or patchset.report.get("tie_break", "pca")
        if tie_break not in TIE_BREAKS:
            raise InvalidParameterError(f"tie_break: expected one of {TIE_BREAKS}, "
                                        f"got {tie_break!r}")
        if backend not in _BACKENDS:
            raise InvalidParameterError(f"backend: expected one of {_BACKENDS}, got {backend!r}")
        self.network = patchset.network
        self.report = dict(patchset.report)
        self.backend = backend
        self._patches = [Patch(p.edges, p.source) for p in patchset.patches]
        self._rejected: set = set()
        self._history: list = []
        self.pool = CandidatePool(self.network, tie_break=tie_break, max_work=max_work)
        longest = max([len(p.edges) for p in self._patches]
                      + [int(self.report.get("max_length", 0)), 1])
        cands = []
        for L in range(1, longest + EXTRA_LENGTH + 1):
            found = self.pool.cycles_of_length(L)
            if found is None:
                break
            cands.extend(found)
        self._by_edges = {c.edges: c for c in cands}

    # --- state ----------------------------------------------------------------
    @property
    def patches(self) -> list:
        """Current patches (copies)."""
        return [Patch(p.edges, p.source) for p in self._patches]

    @property
    def patchset(self) -> PatchSet:
        """The current patch set (network shared, report copied with a ``session`` entry)."""
        rep = dict(self.report)
        rep["session"] = {"rejected": [list(e) for e in sorted(self._rejected)]}
        return PatchSet(self.network, self.patches, rep)

    @property
    def full_rank(self) -> int:
        """Rank of the cycle space, ``E - V + C``."""
        return self.pool.cycle_rank

    def rank(self) -> int:
        """GF(2) rank of the current patches, by the session's ``backend``."""
        masks = [edge_mask(p.edges) for p in self._patches]
        if self.backend == "galois":
            return gf2_rank(masks, self.network.number_of_edges)
        return len(masks) - len(bitset_solve(masks, [])[1])   # minus the dependencies

    def _solve(self, targets):
        pm = [edge_mask(p.edges) for p in self._patches]
        tm = [c.mask for c in targets]
        if self.backend == "galois":
            return gf2_solve(pm, tm, self.network.number_of_edges)
        return bitset_solve(pm, tm)

    def _index(self, patch) -> int:
        if isinstance(patch, (int,)) and not isinstance(patch, bool):
            if not 0 <= patch < len(self._patches):
                raise InvalidParameterError(f"patch: index {patch} out of range "
                                            f"0..{len(self._patches) - 1}")
            return patch
        edges = tuple(sorted(patch.edges if isinstance(patch, Patch) else map(int, patch)))
        for i, p in enumerate(self._patches):
            if p.edges == edges:
                return i
        raise InvalidParameterError(f"patch: {list(edges)} is not a current patch")

    def _push(self):
        self._history.append(([Patch(p.edges, p.source) for p in self._patches],
                              set(self._rejected)))

    # --- suggestions ----------------------------------------------------------------
    def replacement_suggestions(self, *, top: int = DEFAULT_TOP, exclude=()) -> list:
        """Cycles independent of the current patches, best first by Sec. 4.2 weight.

        Each one raises the rank by one (towards :attr:`full_rank`); empty when the
        patches already have full rank.
        """
        current = {p.edges for p in self._patches}
        skip = current | self._rejected | {tuple(sorted(e)) for e in exclude}
        cands = [c for c in self.pool.all_candidates if c.edges not in skip]
        if not cands:
            return []
        sols, _ = self._solve(cands)
        return self._replacements([c for c, x in zip(cands, sols) if x is None], top)

    def _replacements(self, free, top: int) -> list:
        """Candidates outside the span as replacement suggestions, by Sec. 4.2 weight."""
        self.pool.classify(free)
        free.sort(key=lambda c: c.key)
        return [Suggestion(c.edges, "replacement", float(c.k), c.length,
                           {"k": float(c.k), "volume": c.volume, "separating": c.separating})
                for c in free[:top]]

    def closing_suggestions(self, *, top: int = DEFAULT_TOP) -> list:
        """Closing patches (Sec. 5) ranked by ``Ws = 10 (a + b) + k``, best first."""
        out = closing_suggestions(self.pool, [p.edges for p in self._patches],
                                  exclude=self._rejected, backend=self.backend)
        return [Suggestion(s["edges"], "closing", s["score"], s["size"],
                           {"a": s["a"], "b": s["b"], "solid": s["solid"]})
                for s in out[:top]]

    def alternatives_to(self, cycle, *, top: int = DEFAULT_TOP) -> list:
        """Cycles through the same curves that could take a cycle's place, best first.

        Parameters
        ----------
        cycle : int, Patch or sequence of int
            An index into :attr:`patches`, or a cycle's edge ids (a current patch or
            not, e.g. one the user took out).
        top : int
            Most suggestions returned.

        Returns
        -------
        list of Suggestion
            Candidates sharing at least one curve with ``cycle`` (never ``cycle``
            itself, a current patch or a rejected one). Let ``R`` be the current
            patches other than ``cycle``. When ``cycle`` is independent of ``R`` (a
            basis patch), the replacements: candidates outside the span of ``R``, so
            that ``R`` plus any one of them has the rank ``R`` plus ``cycle`` has, ranked
            by the Sec. 4.2 weight (:meth:`replacement_suggestions`). When ``cycle``
            is a sum of patches of ``R`` (it closes a solid), the closing patches of
            ``R``, ranked by ``Ws`` (:meth:`closing_suggestions`); their ``solid`` indexes
            :attr:`patches`.

        Notes
        -----
        This is what :meth:`delete` would suggest after taking ``cycle`` out, kept to
        "the next cycle through the same curves" (Sec. 5: the replacement is the
        next-best patch), and it changes nothing: no history entry, nothing to undo.
        """
        if isinstance(cycle, (int, Patch)) and not isinstance(cycle, bool):
            edges = self._patches[self._index(cycle)].edges
        else:
            edges = tuple(sorted(map(int, cycle)))
        rest = [p for p in self._patches if p.edges != edges]
        masks = [edge_mask(p.edges) for p in rest]
        skip = {p.edges for p in self._patches} | self._rejected | {edges}
        near = [c for c in self.pool.all_candidates
                if c.edges not in skip and not set(c.edges).isdisjoint(edges)]
        if bitset_solve(masks, [edge_mask(edges)])[0][0] is not None:
            out = closing_suggestions(self.pool, [p.edges for p in rest], exclude=skip,
                                      backend=self.backend, candidates=near)
            where = [i for i, p in enumerate(self._patches) if p.edges != edges]
            return [Suggestion(s["edges"], "closing", s["score"], s["size"],
                               {"a": s["a"], "b": s["b"],
                                "solid": [where[j] for j in s["solid"]]})
                    for s in out[:top]]
        sols = (gf2_solve(masks, [c.mask for c in near], self.network.number_of_edges)[0]
                if self.backend == "galois" else bitset_solve(masks, [c.mask for c in near])[0])
        return self._replacements([c for c, x in zip(near, sols) if x is None], top)

    # --- actions ------------------------------------------------------------------
    def delete(self, patch, *, top: int = DEFAULT_TOP) -> list:
        """Remove a patch; returns ranked suggestions to put in its place.

        Parameters
        ----------
        patch : int, Patch or sequence of int
            Index into :attr:`patches`, or the patch / its edge ids.

        Returns
        -------
        list of Suggestion
            If the deletion lowered the rank (a basis patch), the replacements
            restoring it, the deleted cycle excluded (Sec. 5: "the next-best
            patch"). If the rank is unchanged (the patch closed a solid), the
            closing suggestions, where the deleted cycle competes like any other.
        """
        i = self._index(patch)
        self._push()
        gone = self._patches.pop(i)
        masks = [edge_mask(p.edges) for p in self._patches]
        sols, _ = bitset_solve(masks, [edge_mask(gone.edges)])
        if sols[0] is None:
            return self.replacement_suggestions(top=top, exclude=[gone.edges])
        return self.closing_suggestions(top=top)

    def accept(self, suggestion) -> Patch:
        """Add a suggested (or any) cycle as a patch (``source`` "closing" or "user")."""
        edges = tuple(sorted(suggestion.edges if isinstance(suggestion, Suggestion)
                             else map(int, suggestion)))
        if edges in {p.edges for p in self._patches}:
            raise InvalidParameterError(f"suggestion: {list(edges)} is already a patch")
        cycle_to_loop(self.network, edges)  # raises NetworkError if not a simple loop
        kind = suggestion.kind if isinstance(suggestion, Suggestion) else "user"
        self._push()
        patch = Patch(edges, "closing" if kind == "closing" else "user")
        self._patches.append(patch)
        self._rejected.discard(edges)
        return patch

    def reject(self, suggestion) -> None:
        """Never suggest this cycle again (until undone)."""
        edges = tuple(sorted(suggestion.edges if isinstance(suggestion, Suggestion)
                             else map(int, suggestion)))
        self._push()
        self._rejected.add(edges)

    def undo(self) -> bool:
        """Revert the last delete / accept / reject; False when there is nothing to undo."""
        if not self._history:
            return False
        self._patches, self._rejected = self._history.pop()
        return True

    def save(self, path) -> None:
        """Write the current patch set as ``PATCHES.json`` (atomically)."""
        write_patches(path, self.patchset)
