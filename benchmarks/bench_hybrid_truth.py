"""Hybrid results against the true surface: ellipsoids half drawn as a network, half loose.

The hybrid route's fills were judged by stroke fidelity and roughness only; here each
case has a known surface. An ellipsoid (radii ``(1, a, b)``, ``a, b`` in [0.6, 1]) is
drawn as a curve network on its upper half (the equator, 8, 10 or 12 meridians from
the pole, rings at 30 or at 30 and 60 degrees: patches) and as 5 or 6 open arcs of
horizontal sections on its lower half (each 70-85% of its section, from a random
start: no cycles), so that ``auto`` surfaces the top with patches and the bottom with a neural
fill. Input ``clean`` (the curves as strokes) or ``wobble`` (each stroke moved by a
smooth wobble of 0.2% of the diagonal per axis); every case turned, scaled and moved at
random. Drawn from a seeded generator, never picked one by one.

Scores (against a dense mesh of the true ellipsoid): the route, the F-score at 1% of
the longest side and the Chamfer distance of the whole result
(:func:`curvenet.evaluate.evaluate_mesh`); for the fill's faces alone, the median and
90th percentile of their vertices' distance to the true surface and their roughness
(:func:`curvenet.evaluate.roughness`, ball radius 2% of the sketch's diagonal), both
as fractions of the diagonal and thousandths; the seam of the fill
(:func:`curvenet.route.hybrid.fill_seam`, as ``--explain`` prints it).

Run ``python benchmarks/bench_hybrid_truth.py [--cases 8] [--inputs clean wobble]
[--pictures DIR]``; one row per case, then the medians.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import curvenet
from curvenet.core.distance import point_surface_distance
from curvenet.core.geometry import bbox_diagonal
from curvenet.datasets.shapes import random_motion
from curvenet.evaluate import evaluate_mesh, roughness
from curvenet.model.sketch import Sketch

SAMPLES = 80


def _point(radii, lat, lon):
    """Points of the ellipsoid at latitudes and longitudes (radians): (n, 3)."""
    return np.c_[np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)] * radii


def case(seed: int):
    """``(name, strokes, truth (V, F), move)`` of one case: strokes in the ellipsoid's
    own frame and the random motion ``move`` applied to strokes and truth alike."""
    import trimesh
    rng = np.random.default_rng(seed)
    radii = np.r_[1.0, np.round(rng.uniform(0.6, 1.0, 2), 2)]
    n_mer = int(rng.choice([8, 10, 12]))
    rings = np.radians([30.0, 60.0][:int(rng.integers(1, 3))])
    n_arc = int(rng.integers(5, 7))
    t = np.linspace(0.0, 1.0, SAMPLES)
    strokes = [_point(radii, 0 * t + lat, 2 * np.pi * t) for lat in np.r_[0.0, rings]]
    strokes += [_point(radii, np.pi / 2 * t, 0 * t + a)
                for a in 2 * np.pi * np.arange(n_mer) / n_mer + rng.uniform(0, np.pi)]
    for k in range(1, n_arc + 1):
        span, start = rng.uniform(0.7, 0.85), rng.uniform(0, 2 * np.pi)
        strokes.append(_point(radii, 0 * t - np.pi / 2 * k / (n_arc + 1),
                              start + 2 * np.pi * span * t))
    move = random_motion(rng)
    sphere = trimesh.creation.icosphere(6)
    truth = (move(sphere.vertices * radii), np.asarray(sphere.faces))
    name = f"ellipsoid {radii[1]:.2f},{radii[2]:.2f} {n_mer}m{len(rings)}r{n_arc}a"
    return name, strokes, truth, move


def sketch(strokes, move, kind: str, seed: int) -> Sketch:
    """The case's strokes as drawn (``clean`` or ``wobble``), moved."""
    strokes = [move(s) for s in strokes]
    if kind == "wobble":
        rng = np.random.default_rng(seed + 1000)
        diag = bbox_diagonal(strokes)
        t = np.linspace(0.0, 1.0, SAMPLES)[:, None]
        strokes = [s + 0.002 * diag * np.sin(2 * np.pi * rng.uniform(1, 3, (1, 3)) * t
                                             + rng.uniform(0, 2 * np.pi, (1, 3)))
                   for s in strokes]
    return Sketch(strokes, ["boundary"] * len(strokes))


def run(seed: int, kind: str, pictures: Path | None = None) -> dict:
    name, strokes, truth, move = case(seed)
    sk = sketch(strokes, move, kind, seed)
    t0 = time.perf_counter()
    res = curvenet.surface(sk)
    sec = time.perf_counter() - t0
    diag = bbox_diagonal(sk.strokes)
    m = evaluate_mesh(res.mesh, truth, n_samples=30_000)
    row = {"case": name, "input": kind, "route": res.method, "F": m["fscore"],
           "chamfer": m["chamfer"], "s": sec}
    fill = res.face_route == 1 if res.face_route is not None and res.method == "hybrid" else None
    if fill is not None and fill.any():
        faces = np.asarray(res.mesh.faces)[fill]
        kept, inverse = np.unique(faces, return_inverse=True)
        V, F = np.asarray(res.mesh.vertices)[kept], inverse.reshape(-1, 3)
        d = point_surface_distance(V, *truth)[0] / diag
        own = bbox_diagonal([V])
        r = roughness((V, F), radius=min(0.5, 0.02 * diag / own))
        seams = [g.seam for g in res.decision.regions if g.route == "neural"]
        row.update(fill_d50=float(np.median(d)), fill_d90=float(np.percentile(d, 90)),
                   fill_rough=1000 * r["median"], seam=float(np.mean(seams)))
    if pictures is not None:
        from curvenet.view import render_preview
        render_preview(Path(pictures) / f"{seed}_{kind}.png", strokes=sk, mesh=res.mesh,
                       face_route=res.face_route, routes=res.routes,
                       title=f"{name} ({kind}): {res.method}, F {m['fscore']:.3f}")
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", type=int, default=8, help="seeds 0 .. cases - 1")
    ap.add_argument("--inputs", nargs="*", default=["clean", "wobble"])
    ap.add_argument("--pictures", type=Path, help="folder for one preview per case")
    args = ap.parse_args(argv)
    if args.pictures:
        args.pictures.mkdir(parents=True, exist_ok=True)
    cols = ("F", "chamfer", "fill_d50", "fill_d90", "fill_rough", "seam")
    print(f"{'case':<30}{'input':<8}{'route':<10}{'F':>7}{'Chamfer':>10}{'fill d50':>10}"
          f"{'fill d90':>10}{'rough':>7}{'seam':>6}{'s':>6}")
    rows = []
    for seed in range(args.cases):
        for kind in args.inputs:
            r = run(seed, kind, args.pictures)
            rows.append(r)
            fill = (f"{r['fill_d50']:>10.2e}{r['fill_d90']:>10.2e}{r['fill_rough']:>7.2f}"
                    f"{r['seam']:>6.2f}" if "fill_d50" in r
                    else f"{'-':>10}{'-':>10}{'-':>7}{'-':>6}")
            print(f"{r['case']:<30}{kind:<8}{r['route']:<10}{r['F']:>7.3f}{r['chamfer']:>10.2e}"
                  f"{fill}{r['s']:>6.1f}", flush=True)
    hybrid = [r for r in rows if "fill_d50" in r]
    print(f"\n{len(hybrid)} of {len(rows)} hybrid; medians over them: "
          + ", ".join(f"{c} {np.median([r[c] for r in hybrid]):.4g}" for c in cols))


if __name__ == "__main__":
    sys.exit(main())
