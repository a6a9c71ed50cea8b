"""One command that runs the surfacing methods over test shapes and public data and prints a table.

Usage::

    python benchmarks/run.py                          # analytic shapes, all methods
    python benchmarks/run.py --set networks --methods auto,classical
    python benchmarks/run.py --set vns --methods auto --limit 5
    python benchmarks/run.py --rough --methods classical,refine     # classical, then the flow fit
    python benchmarks/run.py --set all --markdown > table.md

Columns: seconds, Chamfer, Hausdorff, F-score at 0.01 and normal error (degrees)
against the true surface where one exists (analytic shapes, longest side scaled
to 1), and the stroke-to-surface distance (mean and max, fraction of the
sketch's bounding-box diagonal) everywhere.

Sets: ``analytic`` (clean networks of :mod:`curvenet.datasets.shapes`, re-drawn rough with
:func:`curvenet.datasets.redraw.rough_sketch`), ``networks`` (``shared/data/networks``),
``vns`` (``shared/data/sketches/vns``). Data is read in place from
``$CURVENET_DATA`` (default ``../shared/data``).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

from curvenet.datasets import shapes
from curvenet.core.errors import CurvenetError
from curvenet.evaluate import evaluate_mesh, stroke_distance
from curvenet.pipeline import SurfaceResult, surface

DATA = Path(os.environ.get("CURVENET_DATA", Path(__file__).resolve().parents[2] / "shared/data"))
ANALYTIC = ("sphere", "ellipsoid", "capped_cylinder", "saddle", "torus", "box", "l_prism")
METHODS = {
    "classical": dict(method="classical"),
    "soapfilm": dict(method="classical", surfacer="soapfilm"),
    "neural": dict(method="neural"),
    "auto": dict(method="auto"),
    "refine": dict(method="classical", refine=True),
    "poisson": None,  # point-cloud baseline, see poisson_baseline()
}


def poisson_baseline(source):
    """Screened Poisson reconstruction (open3d) of stroke samples with PCA normals.

    The point-cloud baseline: stroke points only, normals estimated from 16
    neighbours and oriented by a tangent-plane propagation, octree depth 8,
    cropped to the strokes' bounding box. Needs ``pip install open3d`` (not a
    dependency of curvenet); raises ``CurvenetError`` when it is missing.
    """
    try:
        import open3d as o3d
    except ImportError as err:
        raise CurvenetError(f"poisson baseline needs open3d ({err})") from None
    import trimesh

    from curvenet.pipeline import load_source
    sketch, ps = load_source(source)
    strokes = sketch.select(("boundary", "crease")).strokes if sketch is not None else \
        [e.curve for e in ps.network.edges]
    pts = np.concatenate(strokes)
    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(pts))
    pcd.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(16))
    pcd.orient_normals_consistent_tangent_plane(16)
    mesh, _ = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pcd, depth=8)
    mesh = mesh.crop(pcd.get_axis_aligned_bounding_box())

    return SurfaceResult(trimesh.Trimesh(np.asarray(mesh.vertices), np.asarray(mesh.triangles)),
                         "poisson", sketch, ps.network if ps else None)


def inputs(which: str, rough: bool, limit: int | None):
    """Yield ``(name, source, reference_mesh_or_None)``."""
    if which in ("analytic", "all"):
        from curvenet.datasets.redraw import rough_sketch
        for name in ANALYTIC:
            s = shapes.SHAPES[name]()
            sk = rough_sketch(s.network, seed=0) if rough else s.sketch()
            yield f"{name}{' (rough)' if rough else ''}", sk, s.reference_mesh(5)
    folders = {"networks": sorted((DATA / "networks").glob("*/*.obj")),
               "vns": sorted((DATA / "sketches/vns").glob("*.obj"))}
    for key, files in folders.items():
        if which in (key, "all"):
            for f in files[:limit]:
                yield f"{f.parent.name}/{f.stem}", f, None


def run(args) -> list[dict]:
    rows = []
    for name, source, ref in inputs(args.set, args.rough, args.limit):
        for meth in args.methods.split(","):
            row = {"input": name, "method": meth}
            t = time.perf_counter()
            try:
                res = poisson_baseline(source) if meth == "poisson" else \
                    surface(source, quality=args.quality, device=args.device, **METHODS[meth])
            except CurvenetError as err:
                row.update(status=f"error: {err}"[:60], seconds=time.perf_counter() - t)
                rows.append(row)
                print(_fmt(row), flush=True, file=sys.stderr)
                continue
            row["seconds"] = time.perf_counter() - t
            row["route"] = res.method
            if ref is not None:
                m = evaluate_mesh(res.mesh, ref, n_samples=args.samples)
                row.update(chamfer=m["chamfer"], hausdorff=m["hausdorff"], fscore=m["fscore"],
                           normal=m["normal_error_deg"])
            strokes = res.sketch.select(("boundary", "crease")).strokes if res.sketch else \
                [e.curve for e in res.network.edges]
            sd = stroke_distance(res.mesh, strokes)
            row.update(stroke_mean=sd["stroke_mean"], stroke_max=sd["stroke_max"], status="ok")
            rows.append(row)
            print(_fmt(row), flush=True, file=sys.stderr)
    return rows


COLS = [("input", "{:<26s}"), ("method", "{:<9s}"), ("route", "{:<16s}"), ("seconds", "{:8.2f}"),
        ("chamfer", "{:9.2e}"), ("hausdorff", "{:9.2e}"), ("fscore", "{:7.2%}"),
        ("normal", "{:7.2f}"), ("stroke_mean", "{:9.2e}"), ("stroke_max", "{:9.2e}"),
        ("status", "{:<8s}")]


def _fmt(row: dict, sep: str = " ") -> str:
    cells = []
    for key, f in COLS:
        v = row.get(key)
        cells.append("-" if v is None else f.format(v).strip() if sep != " " else f.format(v))
    return sep.join(cells)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--set", default="analytic", choices=("analytic", "networks", "vns", "all"))
    p.add_argument("--methods", default="classical,soapfilm,neural,auto,poisson")
    p.add_argument("--rough", action="store_true", help="re-draw analytic shapes rough")
    p.add_argument("--limit", type=int, help="at most this many files per data folder")
    p.add_argument("--quality", default="draft")
    p.add_argument("--device", default="cpu")
    p.add_argument("--samples", type=int, default=100_000)
    p.add_argument("--markdown", action="store_true")
    args = p.parse_args(argv)
    rows = run(args)
    print(f"# {platform.node()} {platform.processor() or platform.machine()}, "
          f"{os.cpu_count()} cores, quality {args.quality}, device {args.device}")
    if args.markdown:
        print("| " + " | ".join(k for k, _ in COLS) + " |")
        print("|" + "---|" * len(COLS))
        for r in rows:
            print("| " + _fmt(r, " | ") + " |")
    else:
        print(" ".join(k for k, _ in COLS))
        for r in rows:
            print(_fmt(r))
    ok = [r for r in rows if "fscore" in r]
    if ok:
        print(f"mean F-score {np.mean([r['fscore'] for r in ok]):.2%} over {len(ok)} runs")


if __name__ == "__main__":
    main()
