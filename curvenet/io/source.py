"""What the user gave, turned into a sketch or a patch set: a sketch in any format, a
``NETWORK.json`` / ``PATCHES.json``, or the objects themselves; and the check that a
given patch set was made from a given sketch."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from ..core.errors import InvalidParameterError
from ..model.network import CurveNetwork
from ..model.patchset import PatchSet
from ..model.sketch import Sketch
from .common import require_file
from .network import read_patches
from .points import read_point_blocks
from .sketch import read_sketch

__all__ = ["load_source", "check_patches_match", "PATCHES_MATCH_TOL", "PATCHES_MATCH_OUTLIERS"]


def _is_network_json(path: Path) -> bool:
    if path.suffix.lower() != ".json":
        return False
    with open(path, "rb") as fh:
        head = fh.read(4096)
    return b'"curvenet.network"' in head or b'"curvenet.patches"' in head


def load_source(source, *, points="auto"):
    """Turn what the user gave into ``(sketch, patchset)``; one of them may be None.

    Parameters
    ----------
    source : Sketch, CurveNetwork, PatchSet, str or os.PathLike
        A sketch, or a file: any sketch format, ``NETWORK.json`` or ``PATCHES.json``.
    points : {"auto", True, False}
        Reading of unordered point samples in a sketch file (see
        :func:`curvenet.io.read_sketch`); ``True`` also recovers the curves of
        every stroke of a :class:`Sketch` given directly.
    """
    if isinstance(source, Sketch):
        if points is True:
            return read_point_blocks(source, True), None
        return source, None
    if isinstance(source, PatchSet):
        return None, source
    if isinstance(source, CurveNetwork):
        return None, PatchSet(source)
    path = require_file(source)
    if _is_network_json(path):
        return None, read_patches(path)
    return read_sketch(path, points=points), None


#: A patch set matches a sketch when nearly all stroke points and curve points lie within
#: this fraction of the sketch's diagonal of the other (snapping moves points far less)...
PATCHES_MATCH_TOL = 0.1
#: ...all but this share of them (trimmed overshoots and dropped strokes lie farther).
PATCHES_MATCH_OUTLIERS = 0.1


def check_patches_match(sketch: Sketch, ps: PatchSet) -> None:
    """Refuse a patch set whose network was not made from ``sketch``."""
    net = ps.network
    drawn = sketch.select(("boundary", "crease"))
    drawn = drawn if len(drawn) else sketch
    strokes = np.concatenate(drawn.strokes)
    curves = (np.concatenate([e.curve for e in net.edges]) if net.edges
              else np.asarray(net.positions, np.float64).reshape(-1, 3))
    diag = drawn.diagonal
    if len(curves) == 0 or not diag > 0:
        return
    far = max(float(np.mean(cKDTree(curves).query(strokes)[0] > PATCHES_MATCH_TOL * diag)),
              float(np.mean(cKDTree(strokes).query(curves)[0] > PATCHES_MATCH_TOL * diag)))
    if far > PATCHES_MATCH_OUTLIERS:
        raise InvalidParameterError(
            f"the patch set's network does not match the sketch {sketch.source or ''}: "
            f"{far:.0%} of the points lie farther than {PATCHES_MATCH_TOL:.0%} of the diagonal "
            "from the other (were the patches made from another sketch?)")
