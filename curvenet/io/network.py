"""Curve networks and patch sets as JSON files: ``NETWORK.json`` and ``PATCHES.json``.

File layout (``PATCHES.json``, format version 1; ``NETWORK.json`` is the same
without ``patches`` and with ``"format": "curvenet.network"``)::

    {"format": "curvenet.patches", "version": 1,
     "vertices": [[x, y, z], ...],
     "edges":    [{"u": 0, "v": 3, "curve": [[x, y, z], ...]}, ...],
     "patches":  [{"edges": [0, 4, 7, 2], "source": "auto" | "closing" | "user",
                   "holes": [[9, 10, 11], ...]}, ...]}

``holes`` is optional (absent: a patch bounded by one loop): the edge cycles of
the inner boundary loops of a face with holes, ``edges`` being its outer loop.
Readers that ignore ``holes`` see the outer loop as a filled patch. Files are written
atomically.
"""

from __future__ import annotations

import json
from pathlib import Path

from ..core.atomic import atomic_write_text
from ..core.errors import SketchFormatError
from ..model.network import CurveNetwork
from ..model.patchset import PatchSet

__all__ = ["read_patches", "write_patches", "read_network", "write_network"]


def write_network(path, network: CurveNetwork) -> None:
    """Write ``NETWORK.json`` atomically."""
    atomic_write_text(path, json.dumps(network.to_dict(), check_circular=False))


def write_patches(path, patchset: PatchSet) -> None:
    """Write ``PATCHES.json`` atomically."""
    atomic_write_text(path, json.dumps(patchset.to_dict(), check_circular=False))


def read_patches(path) -> PatchSet:
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


def read_network(path) -> CurveNetwork:
    """The network of a ``NETWORK.json`` or ``PATCHES.json`` file (see :func:`read_patches`)."""
    return read_patches(path).network
