"""Benchmark: smoothness beside stroke fidelity, classical against neural, on real sketches.

Run from the repository root::

    nice -n 5 python benchmarks/bench_smoothness.py --out smooth.tsv
        [--sketches vns/torus,cassie/01-0-1] [--quality draft] [--threads 2] [--meshes DIR]
        [--seed 0] [--set lowpass=0 ...]

Each sketch (default: the 22 of ``$CURVENET_DATA/sketches/vns``, ``input/`` included;
``--sketches`` takes ``SET/STEM`` names of ``vns``, ``cassie`` and ``networks``, the
public clean curve networks: ``networks/haopan/loftbug``; a set's name alone takes all
of it) is surfaced twice:
``curvenet.surface(path, method="classical")`` and ``method="neural"`` at ``--quality``
(with the :class:`neural.presets.FlowConfig` fields of ``--set`` over the preset).
One row per sketch (appended as soon as it is done): for each surface the seconds, the
stroke fidelity of the surface alone (share of stroke length within 1% of the sketch's
diagonal, :func:`curvenet.evaluate.sketch_fidelity`) and the roughness
(:func:`curvenet.evaluate.smoothness.roughness`: RMS residual of a local quadric within
2% of the diagonal, divided by that radius; median and 90th percentile over 4,000
centres, in thousandths; ``_away``: the median over the centres farther than the
ball's radius from every stroke, where a crease or a pull at a stroke is not in the
ball); then the neural surface against the classical one as the
reference (:func:`curvenet.evaluate.evaluate_mesh`, F-score at 1% and 2% of the
reference's longest side, and ``f2_diag``: at 2% of its bounding-box diagonal, the
scale issue 36 states its agreement target in), and the Euler characteristic
``V - E + F`` of each surface (its vertices merged where they coincide: 2 for a closed
genus-0 surface, 2 less for each handle, 2 more for each extra piece). The classical
route is the reference only where it holds its strokes (``classical_fid`` near 1) and
covers the shape; the table says which.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

import curvenet
from curvenet.evaluate import evaluate_mesh, roughness, sketch_fidelity
from curvenet.neural.presets import parse_setting

DATA = Path(os.environ.get("CURVENET_DATA",
                           Path(__file__).resolve().parents[1].parent / "shared" / "data"))
SETS = {"cassie": ("sketches/cassie/curves", ".curves"), "networks": ("networks", ".obj"),
        "vns": ("sketches/vns", ".obj")}
ROUTE_COLUMNS = ("fid", "rough", "rough90", "rough_away", "rough_near", "euler")
COLUMNS = ("sketch", "classical_s", *(f"classical_{c}" for c in ROUTE_COLUMNS[:-1]),
           "neural_s", *(f"neural_{c}" for c in ROUTE_COLUMNS[:-1]), "f1_vs_classical",
           "f2_vs_classical", "f2_diag_vs_classical", "classical_euler", "neural_euler")


def _measure(res):
    from scipy.spatial import cKDTree

    from curvenet.core.geometry import densify_polylines
    fid = sketch_fidelity(res.mesh, res.sketch)["surface"]
    r = roughness(res.mesh)
    samples = densify_polylines(res.sketch.strokes, r["radius"] / 4)[0]
    away = cKDTree(samples).query(r["points"])[0] > r["radius"]
    import trimesh
    euler = trimesh.Trimesh(res.mesh.vertices, res.mesh.faces).euler_number
    per_mille = [1000 * np.median(r["values"][k]) if k.any() else float("nan")
                 for k in (away, ~away)]
    return dict(zip(ROUTE_COLUMNS, (f"{fid:.3f}", f"{1000 * r['median']:.2f}",
                                    f"{1000 * r['p90']:.2f}", f"{per_mille[0]:.2f}",
                                    f"{per_mille[1]:.2f}", str(euler))))


def _row(name: str, path: Path, quality: str, meshes: Path | None = None,
         settings: dict | None = None, seed: int = 0) -> dict:
    t = time.perf_counter()
    cla = curvenet.surface(path, method="classical")
    t_c = time.perf_counter() - t
    t = time.perf_counter()
    neu = curvenet.surface(path, method="neural", quality=quality, neural_options=settings,
                           seed=seed)
    t_n = time.perf_counter() - t
    if meshes is not None:
        for route, res in (("classical", cla), ("neural", neu)):
            res.mesh.export(meshes / f"{name.replace('/', '_')}_{route}.ply")
    c, n = _measure(cla), _measure(neu)
    extent = np.ptp(np.asarray(cla.mesh.vertices), axis=0)
    diag = float(np.linalg.norm(extent) / extent.max())       # diagonal in longest sides
    f1, f2, f2d = (evaluate_mesh(neu.mesh, cla.mesh, n_samples=30_000, threshold=th)["fscore"]
                   for th in (0.01, 0.02, 0.02 * diag))
    return {"sketch": name, "classical_s": f"{t_c:.1f}", "neural_s": f"{t_n:.1f}",
            **{f"classical_{k}": v for k, v in c.items()},
            **{f"neural_{k}": v for k, v in n.items()},
            "f1_vs_classical": f"{f1:.3f}", "f2_vs_classical": f"{f2:.3f}",
            "f2_diag_vs_classical": f"{f2d:.3f}"}


def _paths(names):
    out = []
    for name in names:
        set_name, _, stem = name.partition("/")
        folder, suffix = SETS[set_name]
        root = DATA / folder
        paths = [root / f"{stem}{suffix}"] if stem else sorted(root.rglob(f"*{suffix}"))
        out += [(f"{set_name}/{p.relative_to(root).with_suffix('').as_posix()}", p)
                for p in paths]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="TSV table, one row per sketch")
    ap.add_argument("--sketches", default="", help="comma-separated SET/STEM names")
    ap.add_argument("--quality", default="default", choices=("draft", "default", "paper"))
    ap.add_argument("--threads", type=int, default=0, help="torch threads (0: torch's)")
    ap.add_argument("--meshes", type=Path, default=None,
                    help="folder for both surfaces of each sketch (SET_STEM_ROUTE.ply)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the neural fit")
    ap.add_argument("--set", nargs="*", default=[], metavar="NAME=VALUE",
                    help="FlowConfig fields over the preset, e.g. lowpass=0")
    args = ap.parse_args()
    settings = dict(parse_setting(t) for t in args.set)
    if args.threads:
        import torch
        torch.set_num_threads(args.threads)
    if args.meshes is not None:
        args.meshes.mkdir(parents=True, exist_ok=True)
    out = Path(args.out)
    with open(out, "w") as fh:
        fh.write("\t".join(COLUMNS) + "\n")
    rows = []
    for name, path in _paths(list(filter(None, args.sketches.split(","))) or ["vns"]):
        try:
            row = _row(name, path, args.quality, args.meshes, settings, args.seed)
        except Exception as err:  # noqa: BLE001 - a failed sketch is a row, not the end
            row = dict.fromkeys(COLUMNS, "-") | {"sketch": f"{name}: {err}"[:80]}
        rows.append(row)
        with open(out, "a") as fh:
            fh.write("\t".join(row[c] for c in COLUMNS) + "\n")
        print("\t".join(row[c] for c in COLUMNS), flush=True)
    ok = [r for r in rows if r["neural_s"] != "-"]
    if ok:
        col = {c: np.array([float(r[c]) for r in ok]) for c in COLUMNS[1:]}
        print(f"# {len(ok)} sketches: roughness median classical "
              f"{np.median(col['classical_rough']):.2f}, neural "
              f"{np.median(col['neural_rough']):.2f} (away from the strokes "
              f"{np.nanmedian(col['classical_rough_away']):.2f} and "
              f"{np.nanmedian(col['neural_rough_away']):.2f}, near them "
              f"{np.nanmedian(col['classical_rough_near']):.2f} and "
              f"{np.nanmedian(col['neural_rough_near']):.2f}); neural fidelity median "
              f"{np.median(col['neural_fid']):.1%}, min {col['neural_fid'].min():.1%}; "
              f"F against classical median {np.median(col['f2_vs_classical']):.3f} at 2% of "
              f"its longest side, {np.median(col['f2_diag_vs_classical']):.3f} of its diagonal")


if __name__ == "__main__":
    main()
