"""Patch finding speed: grid boxes against networkx, and every public curve network.

Run ``python benchmarks/bench_patches.py [--quick] [--no-data]``. Prints two tables:

1. grid boxes (box whose six sides are n x n grids: 12 n^2 curves, 6 n^2 faces):
   ``find_patches`` time (median of repeats), whether it returned the true
   faces, and ``networkx.minimum_cycle_basis`` on the same graph in the same
   run (simple graph: grid boxes have no parallel curves), with the ratio;
2. sketch file (OBJ, one stroke per curve) to ``PATCHES.json`` in process:
   read, snap, find patches, write;
3. the networks in ``../shared/data/networks/*/*.obj`` (or ``$CURVENET_DATA``):
   curves, rank, patches found (auto + closing), longest candidate length,
   whether the work bound was hit, and time.

The OBJ networks are read with :func:`curvenet.io.read_network_obj`.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import networkx as nx

from curvenet.cycles.find import find_patches
from curvenet.datasets.shapes import grid_box

DATA = Path(os.environ.get("CURVENET_DATA",
                           Path(__file__).resolve().parents[2] / "shared" / "data"))


def _time(fn, repeats):
    ts, out = [], None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        ts.append(time.perf_counter() - t)
    return statistics.median(ts), out


def bench_grid_boxes(sizes, repeats, nx_limit):
    print(f"{'shape':<12}{'curves':>7}{'faces':>7}{'ours s':>9}{'exact':>7}"
          f"{'nx mcb s':>10}{'nx/ours':>9}")
    for n in sizes:
        shape = grid_box(n)
        net = shape.network
        truth = {tuple(sorted(e for e, _ in f)) for f in shape.faces}
        t_ours, ps = _time(lambda: find_patches(net), repeats)  # noqa: B023
        exact = {p.edges for p in ps.patches} == truth
        t_nx, ratio = float("nan"), float("nan")
        if net.number_of_edges <= nx_limit:
            g = nx.Graph(net.graph())
            t_nx, _ = _time(lambda: nx.minimum_cycle_basis(g), 1)  # noqa: B023
            ratio = t_nx / t_ours
        print(f"grid_box({n}){'':<{max(0, 2 - len(str(n)))}}{net.number_of_edges:>7}"
              f"{len(shape.faces):>7}{t_ours:>9.3f}{str(exact):>7}{t_nx:>10.2f}{ratio:>9.0f}")


def bench_sketch_to_file(sizes, repeats):
    """Sketch OBJ -> PATCHES.json in process (read, snap, find patches, write)."""
    import tempfile

    from curvenet.io.sketch import write_sketch
    from curvenet.io.network import write_patches
    from curvenet.pipeline import patches

    print(f"\n{'sketch -> PATCHES.json':<24}{'curves':>7}{'patches':>8}{'total s':>9}"
          f"{'find s':>8}")
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            shape = grid_box(n)
            src, dst = Path(tmp) / f"gb{n}.obj", Path(tmp) / f"gb{n}.json"
            write_sketch(src, shape.sketch())

            def run(src=src, dst=dst):
                ps = patches(src)
                write_patches(dst, ps)
                return ps

            t, ps = _time(run, repeats)
            print(f"{'grid_box(' + str(n) + ')':<24}{ps.network.number_of_edges:>7}"
                  f"{len(ps.patches):>8}{t:>9.3f}{ps.report['timings']['patches']:>8.3f}")


def bench_data(repeats):
    from curvenet.io.sketch import read_network_obj

    files = sorted((DATA / "networks").glob("*/*.obj"))
    if not files:
        print(f"(no networks under {DATA / 'networks'})")
        return
    print(f"\n{'network':<28}{'curves':>7}{'rank':>6}{'patches':>8}{'closing':>8}"
          f"{'maxlen':>7}{'bound':>6}{'s':>8}")
    total = 0.0
    for f in files:
        net = read_network_obj(f)
        t, ps = _time(lambda: find_patches(net), repeats)  # noqa: B023
        total += t
        r = ps.report
        print(f"{f.parent.name + '/' + f.stem:<28}{net.number_of_edges:>7}{r['rank']:>6}"
              f"{len(ps.patches):>8}{len(r['closing_added']):>8}{r['max_length']:>7}"
              f"{'yes' if r['work_bound_hit'] else 'no':>6}{t:>8.3f}")
    print(f"{'total':<28}{'':>42}{total:>8.3f}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small sizes, one repeat")
    ap.add_argument("--no-data", action="store_true", help="skip the public networks")
    args = ap.parse_args(argv)
    if args.quick:
        bench_grid_boxes([2, 4], 1, nx_limit=200)
        bench_sketch_to_file([4], 1)
    else:
        bench_grid_boxes([2, 4, 6, 9], 5, nx_limit=450)
        bench_sketch_to_file([4, 9], 3)
    if not args.no_data:
        bench_data(1 if args.quick else 3)
    return 0


if __name__ == "__main__":
    sys.exit(main())
