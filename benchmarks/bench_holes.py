"""Faces with holes and flat faces: the CAD shapes against their true surfaces, and the
public clean networks (patch counts, holes, stroke distance, output size, time).

Run ``CURVENET_DATA=/work/shared/data python benchmarks/bench_holes.py [--no-data]``.
Prints two tables:

1. every :data:`curvenet.datasets.shapes.CAD_SHAPES` network through
   ``surface(method="classical")``:
   patches, holes, seconds, triangles, F-score at 0.01 against the true surface
   (30k samples), and the flatness of the flat faces (largest distance of an
   output vertex of a face whose boundary is planar to that plane, fraction of
   the diagonal);
2. every ``networks/*/*.obj`` of ``$CURVENET_DATA``: patches (auto + closing),
   holes, seconds, triangles, and the stroke-to-surface distance (mean and max,
   fraction of the diagonal) of the classical surface.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from curvenet.datasets import shapes
from curvenet.cycles.find import find_patches
from curvenet.core.errors import CurvenetError
from curvenet.evaluate import evaluate_mesh, stroke_distance
from curvenet.cycles.loops import orient_boundaries
from curvenet.pipeline import surface
from curvenet.surfacing.sectors import surface_boundaries

DATA = Path(os.environ.get("CURVENET_DATA",
                           Path(__file__).resolve().parents[2] / "shared" / "data"))


def flatness(net) -> float:
    """Largest distance of a flat face's output vertex to its plane (fraction of the diagonal)."""
    ps = find_patches(net)
    curves = [e.curve for e in net.edges]
    res = surface_boundaries(curves, orient_boundaries(net, ps.patches),
                             crease_curves=[i for i, e in enumerate(net.edges)
                                            if e.label == "crease"])
    worst = 0.0
    for k, p in enumerate(ps.patches):
        pts = np.concatenate([net.edges[e].curve for e in p.all_edges])
        c = pts.mean(axis=0)
        normal = np.linalg.svd(pts - c)[2][2]
        if np.abs((pts - c) @ normal).max() > 1e-9 * net.diagonal:
            continue
        v = res.vertices[np.unique(res.faces[res.face_patch == k])]
        worst = max(worst, float(np.abs((v - c) @ normal).max()) / net.diagonal)
    return worst


def bench_cad():
    print(f"{'shape':<12}{'patches':>8}{'holes':>6}{'s':>7}{'faces':>8}{'F@0.01':>8}"
          f"{'flat':>10}")
    for name, make in shapes.CAD_SHAPES.items():
        s = make()
        t = time.perf_counter()
        res = surface(s.network, method="classical")
        dt = time.perf_counter() - t
        f = evaluate_mesh(res.mesh, s.reference_mesh(4), n_samples=30_000)["fscore"]
        print(f"{name:<12}{len(res.patchset.patches):>8}{len(res.patchset.report['holes']):>6}"
              f"{dt:>7.2f}{len(res.mesh.faces):>8}{100 * f:>8.2f}{flatness(s.network):>10.1e}",
              flush=True)


def bench_networks():
    print(f"{'network':<28}{'patches':>8}{'holes':>6}{'s':>7}{'faces':>8}{'mean':>10}"
          f"{'max':>10}")
    for f in sorted((DATA / "networks").glob("*/*.obj")):
        name = f"{f.parent.name}/{f.stem}"
        t = time.perf_counter()
        try:
            res = surface(f, method="classical")
        except CurvenetError as err:
            print(f"{name:<28} error: {err}", flush=True)
            continue
        dt = time.perf_counter() - t
        sd = stroke_distance(res.mesh, [e.curve for e in res.network.edges])
        print(f"{name:<28}{len(res.patchset.patches):>8}{len(res.patchset.report['holes']):>6}"
              f"{dt:>7.2f}{len(res.mesh.faces):>8}{sd['stroke_mean']:>10.2e}"
              f"{sd['stroke_max']:>10.2e}", flush=True)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--no-data", action="store_true", help="CAD shapes only")
    args = p.parse_args(argv)
    bench_cad()
    if not args.no_data:
        if not (DATA / "networks").is_dir():
            print(f"no networks under {DATA}", file=sys.stderr)
            return
        bench_networks()


if __name__ == "__main__":
    main()
