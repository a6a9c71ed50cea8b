"""Scaling of every stage with the network size (issue 32): 1k to 20k curves.

Two families of networks, each at five sizes from about 1,000 to 20,000 curves:

* ``grid``: :func:`curvenet.datasets.shapes.grid_box` ``(n)``, a box whose six sides are
  ``n x n`` grids (``12 n^2`` curves of 33 points, ``6 n^2`` flat quad faces);
* ``dense``: :func:`curvenet.datasets.dense.dense_blob` ``(n)``, the same layout warped
  onto a bumpy ellipsoid with grid lines moved apart unevenly, every curve redrawn with
  12 to 60 unevenly spaced points and a small wobble: curved quads of unequal sizes.

Each network is written as an OBJ sketch, then per stage: ``read``
(:func:`curvenet.io.source.load_source`), ``snap`` (:func:`curvenet.snap.snap`,
``snap_tol="auto"``), ``patches`` (:func:`curvenet.cycles.find_patches`, ``close="auto"``),
``surface`` (the classical route of :func:`curvenet.pipeline.surface`, its default
density) and ``step`` (:meth:`SurfaceResult.save` to STEP; needs ``curvenet[cad]``,
skipped above ``--step-max`` patches). Printed per stage and size: wall seconds, CPU
seconds, peak resident memory during the stage (MB, the process's RSS sampled every
5 ms); then per stage and family the exponent ``k`` of ``cpu ~ curves^k`` fitted by
least squares on log-log axes.

Run: ``python benchmarks/bench_scale.py [--family grid,dense] [--max-curves 20000]
[--stages read,snap,patches,surface,step] [--step-max 2500]``.
``tests/curvenet/test_scaling.py`` checks the exponents at small sizes.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from curvenet.datasets import shapes  # noqa: E402
from curvenet.datasets.dense import dense_blob  # noqa: E402
from curvenet.io.sketch import write_sketch  # noqa: E402
from curvenet.model.sketch import Sketch  # noqa: E402

STAGES = ("read", "snap", "patches", "surface", "step")
GRID_SIZES = (9, 13, 19, 29, 41)          # 972 .. 20,172 curves
DENSE_SIZES = GRID_SIZES


def network_sketch(family: str, size: int) -> Sketch:
    """The sketch of one benchmark network (``family`` ``grid`` or ``dense``)."""
    if family == "grid":
        return shapes.grid_box(size).sketch()
    return dense_blob(size)


class PeakRSS:
    """Largest resident set size (bytes) of this process while the ``with`` block runs."""

    def __enter__(self):
        self.peak, self._stop = _rss(), threading.Event()
        self._thread = threading.Thread(target=self._sample, daemon=True)
        self._thread.start()
        return self

    def _sample(self):
        while not self._stop.wait(0.005):
            self.peak = max(self.peak, _rss())

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()
        self.peak = max(self.peak, _rss())


def _rss() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def run_stages(sketch: Sketch, folder, stages=STAGES, *, step_max: int = 2500) -> dict:
    """Run the stages on one sketch; ``{stage: (wall s, cpu s, peak RSS bytes)}``, and
    ``"found"``: the number of patches found.

    The sketch is written to ``folder/net.obj`` first (not timed). Stages after a
    skipped one that they need are skipped too; ``step`` is skipped without
    ``curvenet[cad]`` or above ``step_max`` patches.
    """
    from curvenet.cycles.find import find_patches
    from curvenet.io.source import load_source
    from curvenet.pipeline import surface
    from curvenet.snap.graph import snap
    path = Path(folder) / "net.obj"
    write_sketch(path, sketch)
    out, state = {}, {}

    def timed(name, fn):
        t, c = time.perf_counter(), time.process_time()
        with PeakRSS() as mem:
            state[name] = fn()
        out[name] = (time.perf_counter() - t, time.process_time() - c, mem.peak)

    need = set(stages)
    timed("read", lambda: load_source(path)[0])
    if need & {"snap", "patches", "surface", "step"}:
        timed("snap", lambda: snap(state["read"], snap_tol="auto"))
    if need & {"patches"}:
        timed("patches", lambda: find_patches(state["snap"], close="auto"))
    if need & {"surface", "step"}:
        timed("surface", lambda: surface(state["snap"], method="classical"))
    if "step" in need and len(state["surface"].patchset.patches) <= step_max:
        try:
            import OCP  # noqa: F401
        except ImportError:
            pass
        else:
            timed("step", lambda: state["surface"].save(Path(folder) / "net.step"))
    found = state.get("patches") or getattr(state.get("surface"), "patchset", None)
    out["found"] = len(found.patches) if found is not None else 0
    return {k: v for k, v in out.items() if k in need or k == "found"}


def exponent(curves, seconds) -> float:
    """Slope of ``log(seconds)`` against ``log(curves)`` (least squares)."""
    x, y = np.log(np.asarray(curves, float)), np.log(np.maximum(seconds, 1e-6))
    return float(np.polyfit(x, y, 1)[0])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--family", default="grid,dense")
    ap.add_argument("--max-curves", type=int, default=20_000)
    ap.add_argument("--stages", default=",".join(STAGES))
    ap.add_argument("--step-max", type=int, default=2500,
                    help="skip the STEP export above this many patches")
    args = ap.parse_args(argv)
    stages = tuple(s for s in STAGES if s in args.stages.split(","))
    print(f"{'network':<18}{'curves':>7}{'patches':>8}  " +
          "".join(f"{s + ' wall/cpu s, MB':>28}" for s in stages), flush=True)
    for family in args.family.split(","):
        sizes = GRID_SIZES if family == "grid" else DENSE_SIZES
        table = []
        for size in sizes:
            sk = network_sketch(family, size)
            if len(sk.strokes) > args.max_curves * 1.05:
                break
            with tempfile.TemporaryDirectory() as tmp:
                res = run_stages(sk, tmp, stages, step_max=args.step_max)
            cells = "".join(f"{'%.2f / %.2f, %d' % (w, c, m / 2 ** 20):>28}"
                            if (s in res and (w, c, m) == res[s]) else f"{'-':>28}"
                            for s in stages for (w, c, m) in [res.get(s, (0, 0, 0))])
            print(f"{family + '(' + str(size) + ')':<18}{len(sk.strokes):>7}"
                  f"{res['found']:>8}  {cells}", flush=True)
            table.append((len(sk.strokes), res))
        fits = []
        for s in stages:
            pts = [(n, r[s][1]) for n, r in table if s in r]
            if len(pts) >= 2:
                fits.append(f"{s} {exponent(*zip(*pts)):.2f}")
        print(f"{family}: fitted exponent of cpu ~ curves^k: " + ", ".join(fits), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
