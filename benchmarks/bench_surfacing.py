"""Benchmark of the classical surfacer (issue 4).

Prints two tables:

1. time against patch count (about 10 / 50 / 200 patches) on lat-long spheres and
   saddle grids at the default resolution and subdivision, for the direct
   least-squares fit (default), the published iteration (Eq. 3-4) and the soap-film
   baseline; target: 50 patches in under 2 s;
2. accuracy on the analytic networks of ``curvenet.datasets.shapes`` against their true
   surfaces (Chamfer, F-score at 0.01, after scaling the longest side to 1), classical
   against soap-film.

Run: ``python benchmarks/bench_surfacing.py [--quick]``. Timings are wall-clock
best-of-3 on whatever machine runs it (the project's reference is 2 shared cores).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from curvenet import surfacing  # noqa: E402
from curvenet.datasets import shapes  # noqa: E402
from tests.surfacing._metrics import compare  # noqa: E402


def _inputs(shape):
    curves = [e.curve for e in shape.network.edges]
    cr = [i for i, e in enumerate(shape.network.edges) if e.label == "crease"]
    return curves, cr


def _best(fn, repeat, *args, **kwargs):
    best, out = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn(*args, **kwargs)
        best = min(best, time.perf_counter() - t)
    return best, out


def timing_table(repeat: int) -> None:
    cases = [("sphere", shapes.latlong_sphere(n_lat=2, n_lon=5)),
             ("sphere", shapes.latlong_sphere(n_lat=5, n_lon=10)),
             ("sphere", shapes.latlong_sphere(n_lat=10, n_lon=20)),
             ("saddle", shapes.saddle_grid(3)),
             ("saddle", shapes.saddle_grid(7)),
             ("saddle", shapes.saddle_grid(14))]
    print(f"{'shape':8s} {'patches':>7s} {'lsq s':>8s} {'iter s':>8s} {'its':>4s} "
          f"{'soap s':>8s} {'faces':>8s} {'lsq dev':>8s}")
    for name, s in cases:
        curves, cr = _inputs(s)
        t_l, r_l = _best(surfacing.surface_loops, repeat, curves, s.faces, crease_curves=cr)
        t_i, r_i = _best(surfacing.surface_loops, repeat, curves, s.faces, crease_curves=cr,
                         fit="iterative")
        t_s, _ = _best(surfacing.soapfilm_loops, repeat, curves, s.faces)
        print(f"{name:8s} {len(s.faces):7d} {t_l:8.3f} {t_i:8.3f} "
              f"{r_i.report['iterations']:4d} {t_s:8.3f} {len(r_l.faces):8d} "
              f"{r_l.report['max_curve_deviation']:8.1e}")


def accuracy_table(n_samples: int) -> None:
    names = ["sphere", "ellipsoid", "capped_cylinder", "saddle", "torus", "box", "l_prism"]
    print(f"\n{'shape':16s} {'chamfer':>9s} {'F@0.01':>7s} {'iter ch':>9s} {'iter F':>7s} "
          f"{'soap ch':>9s} {'soap F':>7s} {'curve dev':>9s} {'creases':>7s}")
    for name in names:
        s = shapes.SHAPES[name]()
        curves, cr = _inputs(s)
        ref = s.reference_mesh()
        r = surfacing.surface_loops(curves, s.faces, crease_curves=cr)
        ri = surfacing.surface_loops(curves, s.faces, crease_curves=cr, fit="iterative")
        sf = surfacing.soapfilm_loops(curves, s.faces)
        m = compare(r.vertices, r.faces, ref.vertices, ref.faces, n=n_samples)
        mi = compare(ri.vertices, ri.faces, ref.vertices, ref.faces, n=n_samples)
        ms = compare(sf.vertices, sf.faces, ref.vertices, ref.faces, n=n_samples)
        print(f"{name:16s} {m['chamfer']:9.2e} {100 * m['fscore']:6.1f}% "
              f"{mi['chamfer']:9.2e} {100 * mi['fscore']:6.1f}% "
              f"{ms['chamfer']:9.2e} {100 * ms['fscore']:6.1f}% "
              f"{r.report['max_curve_deviation']:9.1e} {len(r.report['creases']):7d}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one repeat, fewer samples")
    a = ap.parse_args()
    print(f"defaults: resolution={surfacing.DEFAULT_RESOLUTION} "
          f"subdiv={surfacing.DEFAULT_SUBDIV}\n")
    timing_table(1 if a.quick else 3)
    accuracy_table(10000 if a.quick else 50000)


if __name__ == "__main__":
    main()
