"""Every stage scales about linearly with the network size (issue 32).

Small-size counterpart of ``benchmarks/bench_scale.py``: the CPU seconds of reading,
snapping, patch finding and (grid boxes only) the classical surface on grid boxes and
dense curved networks of about 100 to 450 curves, with the exponent ``k`` of
``cpu ~ curves^k`` fitted on log-log axes. A stage with a pair loop over patches or
curves shows ``k`` near 2 already at these sizes (the hole search of issue 31 measures
1.5 here); linear stages with a fixed overhead measure under 1. The dense networks'
classical surface is left out for time: its analytic-face fit costs about 0.1 s a
patch (benchmarks/README.md).

Reading is fitted against the file's bytes instead of its curves: a grid box's
coordinates are multiples of ``1/n``, written out in full, so a box of thirds or sixths
takes half as many bytes again per curve as one of quarters, and parsing text costs by
the byte (that alone once bent the reading exponent to 1.35).
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from curvenet.cycles.find import find_patches
from curvenet.datasets.dense import dense_blob
from curvenet.datasets.shapes import grid_box
from curvenet.io.sketch import write_sketch
from curvenet.io.source import load_source
from curvenet.pipeline import surface
from curvenet.snap.graph import snap

#: Largest exponent a stage may show: linear work plus noise, below quadratic.
MAX_EXPONENT = 1.3
SIZES = (3, 4, 6)                  # 108, 192, 432 curves (12 n^2)


#: Rounds over all sizes; each stage's time is its least over the rounds. Taking the
#: sizes in turn within a round spreads a slow spell of a shared machine over all of
#: them instead of one size's repeats (which once bent the fitted exponent to 1.4).
ROUNDS = 4


def _cpu(fn):
    """CPU seconds of one call, and its result."""
    t = time.process_time()
    out = fn()
    return time.process_time() - t, out


def _stages(path, with_surface) -> dict:
    out = {}
    out["read"], sk = _cpu(lambda: load_source(path)[0])
    out["snap"], net = _cpu(lambda: snap(sk, snap_tol="auto"))
    out["patches"], _ = _cpu(lambda: find_patches(net, close="auto"))
    if with_surface:
        out["surface"], _ = _cpu(lambda: surface(net, method="classical"))
    return out


def _exponents(make, tmp_path, with_surface) -> dict:
    paths, size = [], {"curves": [], "bytes": []}
    for n in (2,) + SIZES:
        sketch = make(n)
        paths.append(tmp_path / f"n{n}.obj")
        write_sketch(paths[-1], sketch)
        size["curves"].append(len(sketch.strokes))
        size["bytes"].append(paths[-1].stat().st_size)
    _stages(paths[0], with_surface)                          # imports, caches
    best = [{} for _ in paths[1:]]                           # stage -> least seconds
    for r in range(ROUNDS):
        for b, path in zip(best, paths[1:]):
            # the classical surface (grid boxes), the slowest stage, in the first round only
            for stage, t in _stages(path, with_surface and r == 0).items():
                b[stage] = min(b.get(stage, np.inf), t)
    def exponent(stage):
        logn = np.log(size["bytes" if stage == "read" else "curves"][1:])
        return float(np.polyfit(logn, np.log([max(b[stage], 1e-4) for b in best]), 1)[0])

    return {s: exponent(s) for s in best[0]}


@pytest.mark.parametrize("family", ["grid", "dense"])
def test_no_stage_grows_faster_than_curves_to_the_1_3(tmp_path, family):
    make = (lambda n: grid_box(n).sketch()) if family == "grid" else dense_blob
    k = _exponents(make, tmp_path, with_surface=family == "grid")
    print(family, {s: round(v, 2) for s, v in k.items()})
    assert set(k) == {"read", "snap", "patches"} | ({"surface"} if family == "grid" else set())
    worst = {s: round(v, 2) for s, v in k.items() if v > MAX_EXPONENT}
    assert not worst, f"{family}: stages growing faster than curves^{MAX_EXPONENT}: {worst} ({k})"

