"""Benchmark: `curvenet.evaluate.evaluate_mesh` speed and agreement, and preview speed.

Run from the repository root::

    python benchmarks/bench_eval.py

Prints, per mesh pair, the time of ``evaluate_mesh`` at 100k samples per mesh (best and
median of 3 runs), its metrics, and the relative difference to an independent
computation (trimesh sampling + scipy KD-tree on 1e6 samples of the other surface,
``tests/curvenet/test_evaluate.py::independent_metrics``), whose own bias is an
O(density^-1/2) over-estimate of the distances (see that docstring). Then the time of
``render_preview`` on a 100k-face mesh.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import trimesh

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from curvenet.evaluate import evaluate_mesh  # noqa: E402
from curvenet.view.preview import render_preview  # noqa: E402
from tests.curvenet.test_evaluate import independent_metrics  # noqa: E402

KEYS = ("chamfer", "hausdorff", "normal_error_deg", "fscore")


def bumpy(mesh, amplitude):
    """Displace vertices along the vertex normals by a smooth bump field."""
    v = mesh.vertices
    b = amplitude * np.sin(3 * v[:, 0]) * np.cos(2 * v[:, 1] + 1.0)
    return trimesh.Trimesh(v + b[:, None] * mesh.vertex_normals, mesh.faces, process=False)


def pairs():
    # 50,000 faces vs 51,200 faces of a differently tessellated torus
    ref = trimesh.creation.torus(1.0, 0.4, major_sections=256, minor_sections=100)
    mesh = bumpy(trimesh.creation.torus(1.0, 0.4, major_sections=250, minor_sections=100),
                 0.04)
    yield "torus 50k vs 51k", mesh, ref
    # 81,920 vs 20,480 faces (ellipsoids)
    ref = trimesh.creation.icosphere(subdivisions=5)
    ref.vertices *= [1.0, 0.8, 0.6]
    mesh = trimesh.creation.icosphere(subdivisions=6)
    mesh.vertices *= [1.0, 0.8, 0.6]
    yield "ellipsoid 82k vs 20k", bumpy(mesh, 0.06), ref


def timed(fn, repeats=3):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return out, min(times), float(np.median(times))


def main():
    print("evaluate_mesh, 100,000 samples per mesh; times in s (best / median of 3).")
    print("KD-tree rows: the independent computation with that many dense samples of the")
    print("other surface; 'diff' = ours / KD-tree - 1 (the KD-tree's floor shrinks as")
    print("density^-1/2, so the diff should roughly halve from 1e6 to 4e6).")
    print(f"{'pair':<22} {'method':<13} {'time':>11}" + "".join(f" {k:>16} {'diff':>7}"
                                                          for k in KEYS))
    for name, mesh, ref in pairs():
        ours, best, med = timed(lambda m=mesh, r=ref: evaluate_mesh(m, r))
        faces = f"{len(mesh.faces)}/{len(ref.faces)} faces"
        print(f"{name:<22} {'ours':<13} {best:5.2f}/{med:5.2f}"
              + "".join(f" {ours[k]:16.6g} {'':>7}" for k in KEYS) + f"  {faces}")
        for dense in (1_000_000, 4_000_000):
            theirs = independent_metrics(mesh, ref, dense=dense)
            row = f"{'':<22} {f'KD-tree {dense:.0e}':<13} {'':>11}"
            for k in KEYS:
                rel = ours[k] / theirs[k] - 1 if theirs[k] else float("nan")
                row += f" {theirs[k]:16.6g} {rel:+7.2%}"
            print(row)

    print()
    print("render_preview (two default views, 900x700)")
    big = trimesh.creation.torus(1.0, 0.4, major_sections=400, minor_sections=125)
    with tempfile.TemporaryDirectory() as tmp:
        _, best, med = timed(lambda: render_preview(Path(tmp) / "big.png", mesh=big))
        print(f"{'torus mesh':<22} {len(big.faces):>6} faces  best {best:.2f} s  "
              f"median {med:.2f} s")


if __name__ == "__main__":
    main()
