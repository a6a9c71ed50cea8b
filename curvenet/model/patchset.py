"""Patch sets: cycles of a curve network chosen as surface patches.

A :class:`Patch` is an edge cycle (its outer loop) and, for a face with holes, the
edge cycles of its inner loops; in the cycle space the face is the sum of all of
them. ``PatchSet.to_dict`` / ``from_dict`` are the ``PATCHES.json`` layout, which
:mod:`curvenet.io.network` reads and writes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..core.errors import SketchFormatError
from .network import CurveNetwork

__all__ = ["Patch", "PatchSet", "PATCH_SOURCES"]

PATCH_SOURCES = ("auto", "closing", "user")


@dataclass
class Patch:
    """One patch: a cycle given as a sorted tuple of edge ids, with optional holes.

    ``holes`` holds one sorted tuple of edge ids per inner boundary loop (empty
    for a disc); ``edges`` is the outer loop.
    """

    edges: tuple
    source: str = "auto"
    holes: tuple = ()

    def __post_init__(self):
        self.edges = tuple(sorted(int(e) for e in self.edges))
        self.holes = tuple(tuple(sorted(int(e) for e in h)) for h in self.holes)

    @property
    def all_edges(self) -> tuple:
        """Every boundary edge id, outer loop and holes (sorted)."""
        return tuple(sorted(self.edges + tuple(e for h in self.holes for e in h)))

    def to_dict(self) -> dict:
        d = {"edges": list(self.edges), "source": self.source}
        if self.holes:
            d["holes"] = [list(h) for h in self.holes]
        return d


@dataclass
class PatchSet:
    """A network and the patches chosen on it.

    Attributes
    ----------
    network : CurveNetwork
    patches : list of Patch
    report : dict
        Diagnostics from the patch finder (timings, candidate counts, bounds hit).
    """

    network: CurveNetwork
    patches: list = field(default_factory=list)
    report: dict = field(default_factory=dict)

    def __repr__(self) -> str:
        sources = [p.source for p in self.patches]
        counts = {src: sources.count(src) for src in PATCH_SOURCES if src in sources}
        return (f"<PatchSet(patches={len(self.patches)}, sources={counts}, "
                f"network={self.network!r})>")

    def to_dict(self) -> dict:
        d = self.network.to_dict()
        d["format"] = "curvenet.patches"
        d["patches"] = [p.to_dict() for p in self.patches]
        return d

    @classmethod
    def from_dict(cls, data: dict, *, path=None) -> "PatchSet":
        net = CurveNetwork.from_dict(data, path=path)
        patches = []
        for i, p in enumerate(data.get("patches", [])):
            try:
                edges = [int(e) for e in p["edges"]]
                source = str(p.get("source", "user"))
                holes = [[int(e) for e in h] for h in p.get("holes", [])]
            except (KeyError, TypeError, ValueError):
                raise SketchFormatError(f"patches[{i}]: expected {{'edges': [...]}}",
                                        path=path) from None
            every = edges + [e for h in holes for e in h]
            bad = [e for e in every if not 0 <= e < net.number_of_edges]
            if not all(holes):
                raise SketchFormatError(f"patches[{i}]: empty hole", path=path)
            if bad or not edges:
                raise SketchFormatError(f"patches[{i}]: edge ids {bad or edges} out of range "
                                        f"0..{net.number_of_edges - 1}", path=path)
            if source not in PATCH_SOURCES:
                raise SketchFormatError(f"patches[{i}]: unknown source {source!r}", path=path)
            patches.append(Patch(tuple(edges), source, tuple(map(tuple, holes))))
        return cls(net, patches)
