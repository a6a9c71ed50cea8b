"""Benchmark: curves given as unordered point samples.

``python benchmarks/bench_points.py large`` writes a file of about 1,000,000
shuffled samples of the torus network (``x y z`` lines, density varying 1:3
along each curve, RMS noise 0.25% of the diagonal), then times
``read_sketch`` on it (parsing, detection, curve recovery) and the snapping
that follows; prints seconds, peak RSS and whether the recovered network is
isomorphic to the true one. Target: under 60 s and 4 GB.

``python benchmarks/bench_points.py rates --seeds 10`` prints, per analytic
shape and sampling case, how many seeded trials recover a network isomorphic
to the true one (the figures behind the ``slow`` test), and
``python benchmarks/bench_points.py fscore`` the F-score of the classical
surface from recovered curves against the one from the true curves.
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
import time
from pathlib import Path

import networkx as nx
import numpy as np

from curvenet.datasets import shapes
from curvenet.io.points import recover_curves
from curvenet.datasets.shapes import sample_curves
from curvenet.model.sketch import Sketch
from curvenet.snap.graph import snap

#: (spacing, RMS noise, density ratio); lengths are fractions of the diagonal.
CASES = {"uniform": (0.002, 0.0, 1.0), "uneven": (0.004, 0.0025, 3.0),
         "noisy": (0.002, 0.005, 1.0), "noisy-uneven": (0.003, 0.005, 3.0)}


def samples(shape, case, seed):
    sp, noise, uneven = CASES[case]
    d = shape.network.diagonal
    return sample_curves([e.curve for e in shape.network.edges], sp * d, noise=noise * d,
                         uneven=uneven, rng=seed)


def recovered(pts):
    return snap(Sketch(recover_curves(pts).strokes))


def large(n_points: int) -> None:
    from curvenet.io.sketch import read_sketch
    shape = shapes.torus()
    net = shape.network
    length = sum(e.length() for e in net.edges)
    pts = sample_curves([e.curve for e in net.edges], length / n_points,
                        noise=0.0025 * net.diagonal, uneven=3.0, rng=0)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "torus_1m.xyz"
        np.savetxt(path, pts, fmt="%.7g")
        del pts
        size = path.stat().st_size
        t0 = time.perf_counter()
        sk = read_sketch(path)
        t1 = time.perf_counter()
        out = snap(sk)
        t2 = time.perf_counter()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024 ** 2
    print("| points | file MB | read+recover s | snap s | total s | peak RSS GB | isomorphic |")
    print("|---|---|---|---|---|---|---|")
    print(f"| {sk.metadata['point_blocks'][0]['points']:,} | {size / 1e6:.0f} | {t1 - t0:.1f} "
          f"| {t2 - t1:.2f} | {t2 - t0:.1f} | {peak:.2f} | "
          f"{nx.is_isomorphic(out.graph(), net.graph())} |")
    print(sk.metadata["reading"])


def rates(seeds: int, names) -> None:
    print("| shape | " + " | ".join(CASES) + " | all |")
    print("|---" * (len(CASES) + 2) + "|")
    for name in names:
        shape = shapes.SHAPES[name]()
        row, total = [], 0
        for case in CASES:
            ok = 0
            for seed in range(seeds):
                try:
                    ok += nx.is_isomorphic(recovered(samples(shape, case, seed)).graph(),
                                           shape.network.graph())
                except Exception as err:  # a refusal counts as a failure
                    print(f"  {name} {case} {seed}: {err}", file=sys.stderr)
            row.append(f"{ok}/{seeds}")
            total += ok
        print(f"| {name} | " + " | ".join(row) + f" | {total / (seeds * len(CASES)):.0%} |",
              flush=True)


def fscore(names, cases) -> None:
    import curvenet
    from curvenet.evaluate import evaluate_mesh
    print("| shape | case | F true curves | F recovered | difference (points) |")
    print("|---|---|---|---|---|")
    for name in names:
        shape = shapes.SHAPES[name]()
        ref = shape.reference_mesh(4)
        f_true = evaluate_mesh(curvenet.surface(shape.sketch(), method="classical").mesh, ref,
                               n_samples=50_000)["fscore"]
        for case in cases:
            res = curvenet.surface(Sketch([samples(shape, case, 0)]), method="classical",
                                   points=True)
            f = evaluate_mesh(res.mesh, ref, n_samples=50_000)["fscore"]
            print(f"| {name} | {case} | {f_true:.2%} | {f:.2%} | {100 * (f - f_true):+.2f} |",
                  flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=("large", "rates", "fscore"))
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--shapes", default=",".join(shapes.SHAPES))
    ap.add_argument("--cases", default=",".join(CASES))
    args = ap.parse_args()
    names = args.shapes.split(",")
    if args.what == "large":
        large(args.points)
    elif args.what == "rates":
        rates(args.seeds, names)
    else:
        fscore(names, args.cases.split(","))


if __name__ == "__main__":
    main()
