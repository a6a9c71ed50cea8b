"""Benchmark: stroke fidelity of ``curvenet surface`` defaults on every real rough sketch.

Run from the repository root::

    nice -n 10 python benchmarks/bench_hybrid.py --out hybrid.tsv [--sets cassie,vns]

Inputs: every sketch in ``$CURVENET_DATA/sketches/cassie/curves`` and
``$CURVENET_DATA/sketches/vns`` (default ``../shared/data``). Each is surfaced with
``curvenet.surface(path)`` (the CLI defaults: ``method="auto"``). One row per sketch is
appended to ``--out`` as soon as it is done (a run stopped early keeps its rows): the
route, the seconds, and the share of stroke length within 1% of the sketch's diagonal
of the surface alone and of the surface and the wires kept beside it (when the result
has any), with the median and 95th percentile of the stroke-to-surface distance.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

import curvenet
from curvenet.evaluate import stroke_distance

DATA = Path(os.environ.get("CURVENET_DATA",
                           Path(__file__).resolve().parents[1].parent / "shared" / "data"))
SETS = {"cassie": ("sketches/cassie/curves", "*.curves"),
        "vns": ("sketches/vns", "*.obj")}
COLUMNS = ("set", "sketch", "route", "seconds", "surface_1pct", "with_wires_1pct",
           "wire_share", "median", "p95")


def _row(set_name: str, path: Path) -> dict:
    t = time.perf_counter()
    res = curvenet.surface(path)
    seconds = time.perf_counter() - t
    fid = res.diagnostics.get("fidelity")
    if fid is None:  # a version without the built-in measure: the surface alone
        d = stroke_distance(res.mesh, res.sketch)
        fid = {"surface": d["stroke_within_1pct"], "with_wires": d["stroke_within_1pct"],
               "wire_share": 0.0, "median": float("nan"), "p95": d["stroke_p95"]}
    route = res.method
    if res.decision is not None and res.decision.regions:
        route += " (" + ", ".join(sorted({r["route"] for r in res.decision.regions})) + ")"
    return {"set": set_name, "sketch": path.name, "route": route, "seconds": f"{seconds:.1f}",
            "surface_1pct": f"{fid['surface']:.3f}", "with_wires_1pct": f"{fid['with_wires']:.3f}",
            "wire_share": f"{fid['wire_share']:.3f}", "median": f"{fid['median']:.2e}",
            "p95": f"{fid['p95']:.2e}"}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="TSV table, one row per sketch")
    ap.add_argument("--sets", default="cassie,vns")
    args = ap.parse_args()
    out = Path(args.out)
    with open(out, "w") as fh:
        fh.write("\t".join(COLUMNS) + "\n")
    for set_name in args.sets.split(","):
        folder, pattern = SETS[set_name]
        for path in sorted((DATA / folder).glob(pattern)):
            try:
                row = _row(set_name, path)
            except Exception as err:  # noqa: BLE001 - a failed sketch is a row, not the end
                row = dict.fromkeys(COLUMNS, "-") | {"set": set_name, "sketch": path.name,
                                                    "route": f"error: {err}"[:80]}
            with open(out, "a") as fh:
                fh.write("\t".join(str(row[c]) for c in COLUMNS) + "\n")
            print("\t".join(str(row[c]) for c in COLUMNS), flush=True)
    rows = [line.split("\t") for line in out.read_text().splitlines()[1:]]
    ok = [r for r in rows if r[5] != "-"]
    if ok:
        both, wires = (np.array([float(r[k]) for r in ok]) for k in (5, 6))
        surf = np.array([float(r[4]) for r in ok])
        print(f"# {len(ok)} sketches ({len(rows) - len(ok)} errors): with wires >= 85% on "
              f"{np.sum(both >= 0.85)}, median {np.median(both):.1%}, min {both.min():.1%}; "
              f"surface alone median {np.median(surf):.1%}, min {surf.min():.1%}; "
              f"wires carry at most {wires.max():.1%}; "
              f"{sum(float(r[3]) for r in ok):.1f} s in all")


if __name__ == "__main__":
    main()
