"""Benchmark: stroke fidelity of ``curvenet surface`` defaults on every real rough sketch.

Run from the repository root::

    nice -n 10 python benchmarks/bench_hybrid.py --out hybrid.tsv [--sets cassie,vns]
        [--sketches 01-1-1,guitar] [--hybrid-only]

Inputs: every sketch in ``$CURVENET_DATA/sketches/cassie/curves`` and
``$CURVENET_DATA/sketches/vns`` (default ``../shared/data``). Each is surfaced with
``curvenet.surface(path)`` (the CLI defaults: ``method="auto"``). One row per sketch is
appended to ``--out`` as soon as it is done (a run stopped early keeps its rows): the
route, the seconds, and the share of stroke length within 1% of the sketch's diagonal
of the surface alone and of the surface and the wires kept beside it (when the result
has any), with the median and 95th percentile of the stroke-to-surface distance. For the
neural fills of hybrid results, the seam figures of :func:`curvenet.route.hybrid.fill_seam`
(one value per fill, comma-separated): ``seam_fit`` and ``seam`` (share of the reached
patch-shared curve length where the fill's boundary lies within 1% of the diagonal, as
fitted and after :func:`curvenet.route.hybrid.close_seam`), ``seam_p95`` (95th percentile of
that distance, fraction of the diagonal). ``--sketches`` runs only the sketches of those
names (file stems, or ``SET/STEM``); ``--hybrid-only`` only those that :data:`HYBRID`
lists (the sketches ``auto`` surfaces with a neural fill).
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
           "wire_share", "median", "p95", "seam_fit", "seam", "seam_p95")
#: the sketches ``auto`` surfaces with a neural fill (benchmarks/README.md)
HYBRID = tuple(f"cassie/{n}" for n in ("01-0-1", "01-1-1", "05-0-1", "05-0-2", "06-1-2",
                                        "guitar", "shield", "vintage_car")) \
    + ("vns/bulbasaur", "vns/ok_hand")


def _seams(res, key: str, fmt: str) -> str:
    """One value per neural fill of ``res`` ("-" when there is none)."""
    regions = res.decision.regions if res.decision is not None else []
    vals = [getattr(r, key) for r in regions if r.route == "neural"]
    return ",".join("-" if v is None else format(v, fmt) for v in vals) or "-"


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
        route += " (" + ", ".join(sorted({r.route for r in res.decision.regions})) + ")"
    return {"set": set_name, "sketch": path.name, "route": route, "seconds": f"{seconds:.1f}",
            "surface_1pct": f"{fid['surface']:.3f}", "with_wires_1pct": f"{fid['with_wires']:.3f}",
            "wire_share": f"{fid['wire_share']:.3f}", "median": f"{fid['median']:.2e}",
            "p95": f"{fid['p95']:.2e}", "seam_fit": _seams(res, "seam_fit", ".3f"),
            "seam": _seams(res, "seam", ".3f"), "seam_p95": _seams(res, "seam_p95", ".4f")}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="TSV table, one row per sketch")
    ap.add_argument("--sets", default="cassie,vns")
    ap.add_argument("--sketches", default="",
                    help="comma-separated names: file stems or SET/STEM")
    ap.add_argument("--hybrid-only", action="store_true", help="only the sketches of HYBRID")
    args = ap.parse_args()
    names = set(filter(None, args.sketches.split(","))) | (set(HYBRID) if args.hybrid_only
                                                           else set())
    out = Path(args.out)
    with open(out, "w") as fh:
        fh.write("\t".join(COLUMNS) + "\n")
    for set_name in args.sets.split(","):
        folder, pattern = SETS[set_name]
        for path in sorted((DATA / folder).glob(pattern)):
            if names and not {path.stem, f"{set_name}/{path.stem}"} & names:
                continue
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
