"""Benchmark of the CAD output (issue 21): B-spline faces in STEP, read back and checked.

For every analytic shape of ``curvenet.datasets.shapes`` and every public network in
``$CURVENET_DATA/networks`` (default ``../shared/data``): surface it on the classical
route, export STEP, read it back with OpenCascade and print

* patches, B-spline faces (pieces) and how many are exact, the most pieces of one
  patch (patches split around a centre), the largest knot grading used;
* validity (``BRepCheck_Analyzer``), free edges of the read-back shape and whether
  every one lies on the classical mesh's open boundary or on its curves of three
  or more patches (a shell per manifold piece), solids;
* the largest deviation of the B-spline faces from the limit surface (fraction of the
  diagonal; exact limit points one level finer than the fit), the largest seam gap
  (G0) and the largest normal angle across non-crease seams (G1, degrees), along
  the seams and at the faces' corners;
* export seconds (B-spline extraction + sewing + writing).

Then the export time of a 100-patch network (a 10 x 10 saddle grid; target < 10 s).

Run: ``python benchmarks/bench_cad.py [--quick]`` (needs ``pip install 'curvenet[cad]'``).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from curvenet import cad  # noqa: E402
from curvenet.datasets import shapes  # noqa: E402
from curvenet.core.errors import CurvenetError  # noqa: E402
from curvenet.pipeline import surface  # noqa: E402

HEADER = (f"{'input':<28s} {'patches':>7s} {'faces':>5s} {'exact':>5s} {'/patch':>6s} "
          f"{'grade':>5s} {'valid':>5s} {'free':>5s} {'on bdry':>7s} {'solid':>5s} "
          f"{'deviation':>9s} {'gap':>8s} {'G1 deg':>7s} {'corner':>7s} {'export s':>8s}")


def _mesh_borders(mesh):
    """Points along the classical mesh's edges of one face (open boundary) or of three
    or more (curves shared by three patches: a shell per manifold piece), and the
    mesh's mean edge length."""
    e = np.sort(mesh.edges, axis=1)
    uniq, count = np.unique(e, axis=0, return_counts=True)
    border = uniq[count != 2]
    V = mesh.vertices
    pts = np.linspace(V[border[:, 0]], V[border[:, 1]], 9).reshape(-1, 3)
    return pts, float(np.linalg.norm(V[e[:, 0]] - V[e[:, 1]], axis=1).mean())


def _free_on_border(shape, mesh) -> bool:
    """Whether every free edge of ``shape`` runs along the classical mesh's open
    boundary or non-manifold curves (its points within a quarter of the mean mesh
    edge length of them)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    from scipy.spatial import cKDTree
    fb = ShapeAnalysis_FreeBounds(shape, 1e-7)
    pts = []
    for wires in (fb.GetOpenWires(), fb.GetClosedWires()):
        exp = TopExp_Explorer(wires, TopAbs_EDGE)
        while exp.More():
            c = BRepAdaptor_Curve(TopoDS.Edge(exp.Current()))
            ts = np.linspace(c.FirstParameter(), c.LastParameter(), 5)
            pts += [[p.X(), p.Y(), p.Z()] for p in (c.Value(t) for t in ts)]
            exp.Next()
    if not pts:
        return True
    border, spacing = _mesh_borders(mesh)
    if not len(border):
        return False
    return bool(cKDTree(border).query(np.array(pts))[0].max() < 0.25 * spacing)


def run_one(name, source, tmp) -> str:
    try:
        res = surface(source, method="classical", subdiv=1)
    except CurvenetError as err:
        return f"{name:<28s} not surfaced: {err}"
    path = Path(tmp, "out.step")
    t = time.perf_counter()
    res.save(path)
    dt = time.perf_counter() - t
    rep = res.diagnostics["cad"]
    shape = cad.read_step(path)
    back = cad.shape_report(shape)
    pr, seams = rep["pieces"], rep["seams"]
    smooth = [s["angle"] for s in seams if not s["crease"]]
    corners = [s["corner_angle"] for s in seams if not s["crease"]]
    gap = max((s["gap"] for s in seams), default=0.0)
    on_open = _free_on_border(shape, res.mesh)
    split = max(pr["pieces_per_patch"].values(), default=1)
    return (f"{name:<28s} {len(res.patchset.patches):>7d} {back['faces']:>5d} "
            f"{pr['n_exact']:>5d} {split:>6d} {max(pr['grades_used'], default=0):>5d} "
            f"{str(back['valid']):>5s} {back['free_edges']:>5d} {str(on_open):>7s} "
            f"{back['solids']:>5d} {pr['max_deviation']:>9.1e} {gap:>8.1e} "
            f"{max(smooth, default=0.0):>7.2f} {max(corners, default=0.0):>7.2f} {dt:>8.2f}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="analytic shapes and 100 patches only")
    args = ap.parse_args(argv)
    root = Path(os.environ.get("CURVENET_DATA", Path(__file__).resolve().parents[2] /
                               "shared" / "data")) / "networks"
    inputs = [(f"shapes.{f.__name__}", f().sketch()) for f in (
        shapes.box, shapes.l_prism, shapes.house, shapes.two_boxes, shapes.grid_box,
        shapes.grid_sheet, shapes.saddle_grid, shapes.latlong_sphere, shapes.ellipsoid,
        shapes.capped_cylinder, shapes.torus)]
    if not args.quick and root.is_dir():
        inputs += [(f"{p.parent.name}/{p.name}", p) for p in sorted(root.glob("*/*.obj"))]
    print(HEADER)
    with tempfile.TemporaryDirectory() as tmp:
        for name, src in inputs:
            print(run_one(name, src, tmp), flush=True)
        res = surface(shapes.saddle_grid(10).sketch(), method="classical", subdiv=1)
        t = time.perf_counter()
        res.save(Path(tmp, "grid100.step"))
        print(f"\n100-patch export (saddle_grid(10), {len(res.patchset.patches)} patches): "
              f"{time.perf_counter() - t:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
