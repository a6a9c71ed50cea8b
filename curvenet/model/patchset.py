"""Patch sets: cycles of a curve network chosen as surface patches, and their JSON files.

File layout (``PATCHES.json``, format version 1; ``NETWORK.json`` is the same
without ``patches`` and with ``"format": "curvenet.network"``)::

    {"format": "curvenet.patches", "version": 1,
     "vertices": [[x, y, z], ...],
     "edges":    [{"u": 0, "v": 3, "curve": [[x, y, z], ...]}, ...],
     "patches":  [{"edges": [0, 4, 7, 2], "source": "auto" | "closing" | "user",
                   "holes": [[9, 10, 11], ...]}, ...]}

``holes`` is optional (absent: a patch bounded by one loop): the edge cycles of
the inner boundary loops of a face with holes, ``edges`` being its outer loop;
in the cycle space the face is the sum of all of them. Readers that ignore
``holes`` see the outer loop as a filled patch.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

from ..core.atomic import atomic_write_text
from ..core.errors import SketchFormatError
from .network import CurveNetwork

__all__ = ["Patch", "PatchSet", "PATCH_SOURCES", "save_patchset", "save_network",
           "load_network_file"]

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


def save_network(path, network: CurveNetwork) -> None:
    """Write ``NETWORK.json`` atomically."""
    atomic_write_text(path, json.dumps(network.to_dict()))


def save_patchset(path, patchset: PatchSet) -> None:
    """Write ``PATCHES.json`` atomically."""
    atomic_write_text(path, json.dumps(patchset.to_dict()))


def load_network_file(path) -> PatchSet:
    """Read a ``NETWORK.json`` or ``PATCHES.json`` file as a :class:`PatchSet`.

    A network file gives a patch set with no patches.

    Raises
    ------
    SketchFormatError
        Not JSON, or not one of the two curvenet formats / versions.
    """
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as err:
        raise SketchFormatError(f"invalid JSON: {err.msg}", path=path, line=err.lineno) from None
    except (OSError, UnicodeDecodeError) as err:
        raise SketchFormatError(f"cannot read: {err}", path=path) from None
    if not isinstance(data, dict) or data.get("format") not in ("curvenet.network",
                                                                 "curvenet.patches"):
        raise SketchFormatError("not a curvenet network or patch file (missing 'format')",
                                path=path)
    if data.get("version") != 1:
        raise SketchFormatError(f"unsupported version {data.get('version')!r} (expected 1)",
                                path=path)
    return PatchSet.from_dict(data, path=path)
