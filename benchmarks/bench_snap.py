"""Benchmark: snapping rough sketches (target: 1,000 strokes x 100 points in < 2 s).

Run ``python benchmarks/bench_snap.py`` (``--data ../shared/data`` prints one line
of snapping statistics per public data file instead; ``--recovery --seeds 200 --gap
0.04`` the graph-recovery rate per shape on the independent redraws of issue 16, with
``--generator loop_sketch`` on rings drawn past or short of their start, issue 33).
Prints one row per case: strokes, points, seconds (best of ``--repeat``), and
whether the snapped graph matches the clean network it was re-drawn from
(:func:`curvenet.datasets.redraw.match_networks`).

The large case is a saddle grid re-drawn rough with every redraw amplitude and
the snapping tolerance scaled by ``4 / n`` (so each grid cell looks like the
n = 4 test case), trimmed to 1,000 strokes resampled to 100 points each.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from curvenet.datasets import shapes
from curvenet.datasets.redraw import match_networks, rough_sketch
from curvenet.datasets.redraw_loops import loop_sketch
from curvenet.model.sketch import Sketch
from curvenet.snap.graph import DEFAULT_SNAP_TOL, snap


def _resample(stroke, n):
    cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(stroke, axis=0), axis=1))])
    s = np.linspace(0.0, cum[-1], n)
    return np.stack([np.interp(s, cum, stroke[:, k]) for k in range(3)], axis=1)


def grid_case(n: int, seed: int, *, points: int = 100, max_strokes: int | None = None):
    """(sketch, reference network, snap_tol) for a rough saddle grid of size n."""
    ref = shapes.saddle_grid(n).network
    f = 4.0 / n
    sk = rough_sketch(ref, seed=seed, wobble=0.003 * f, overshoot=0.015 * f, gap=0.01 * f)
    strokes = [_resample(s, points) for s in sk.strokes]
    labels = list(sk.labels)
    if max_strokes is not None:
        strokes, labels = strokes[:max_strokes], labels[:max_strokes]
    return Sketch(strokes, labels), ref, DEFAULT_SNAP_TOL * f


def _time(fn, repeat):
    """Best wall-clock and best CPU (process) seconds over ``repeat`` runs, and the result.

    On a shared machine the CPU time is the better estimate of an unloaded run.
    """
    best, best_cpu = np.inf, np.inf
    out = None
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        out = fn()
        best = min(best, time.perf_counter() - t)
        best_cpu = min(best_cpu, time.process_time() - c)
    return (best, best_cpu), out


def data_table(root):
    """One line of snapping statistics per public data file (networks, vns, cassie, stability)."""
    import warnings

    from curvenet.io.sketch import read_network_obj, read_sketch

    root = Path(root)
    print(f"{'file':44s} {'mode':5s} {'str':>4s} {'V':>5s} {'E':>5s} {'ref V,E':>9s} {'jun':>4s} "
          f"{'T':>3s} {'gap':>3s} {'trim':>4s} {'odr':>3s} {'cor':>3s} {'dang':>4s} {'drop':>4s} "
          f"{'sec':>5s}")
    groups = [sorted((root / "networks").glob("*/*.obj")),
              sorted((root / "sketches" / "vns").rglob("*.obj")),
              sorted((root / "sketches" / "cassie" / "curves").glob("*.curves")),
              sorted((root / "surfaces" / "stability" / "input" / "curves").glob("*.txt"))]
    for f in [f for g in groups for f in g]:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sk = read_sketch(f)
        t = time.perf_counter()
        net = snap(sk)
        dt = time.perf_counter() - t
        r = net.report
        ref = "-"
        if f.parent.parent.name == "networks":
            rn = read_network_obj(f)
            ok = (rn.number_of_vertices, rn.number_of_edges) == (net.number_of_vertices,
                                                                  net.number_of_edges)
            ref = f"{rn.number_of_vertices},{rn.number_of_edges}" + ("" if ok else "!")
        name = str(f.relative_to(root))
        print(f"{name:44s} {r['mode']:5s} {len(sk):4d} {net.number_of_vertices:5d} "
              f"{net.number_of_edges:5d} {ref:>9s} {r['junctions']:4d} {r['t_junctions']:3d} "
              f"{r['gap_merges']:3d} {r['trimmed_overshoots']:4d} "
              f"{r['overdraw_consolidations']:3d} {r['corners']:3d} {r['dangling_ends']:4d} "
              f"{r['strokes_dropped_short']:4d} {dt:5.2f}")


def patch_table(root, snap_tol=None):
    """Patch count and coverage (curve length on patch edges) per public rough sketch."""
    import warnings

    from curvenet.io.sketch import read_sketch
    from curvenet.pipeline import patches
    from curvenet.route.decision import coverage

    root = Path(root) / "sketches"
    files = (sorted((root / "vns").rglob("*.obj"))
             + sorted((root / "cassie" / "curves").glob("*.curves")))
    print(f"{'file':44s} {'tol':>7s} {'V':>5s} {'E':>5s} {'patches':>7s} {'coverage':>8s}")
    tot_p, tot_c = 0, 0.0
    for f in files:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sk = read_sketch(f)
            ps = patches(sk, snap_tol=snap_tol)
        cov, _ = coverage(ps)
        net = ps.network
        tot_p += len(ps.patches)
        tot_c += cov
        print(f"{str(f.relative_to(root)):44s} {net.report.get('snap_tol', 0):7.4f} "
              f"{net.number_of_vertices:5d} {net.number_of_edges:5d} {len(ps.patches):7d} "
              f"{cov:8.3f}", flush=True)
    print(f"{'total / mean':44s} {'':7s} {'':5s} {'':5s} {tot_p:7d} {tot_c / len(files):8.3f}")


def big_inputs(folder):
    """Write the two big inputs of issue 20 into ``folder``; returns their paths.

    ``rings.json``: 4,000 latitude rings of 400 points on the unit sphere (about 62 MB of
    JSON; the rings are open by one sample spacing, so snapping takes the tolerance
    path). ``scribbles.txt``: 7,000 random smooth strokes of 1,000 points in the unit cube
    (7M points, about 200 MB of text).
    """
    from curvenet.io.sketch import write_sketch
    folder = Path(folder)
    rng = np.random.default_rng(0)
    lat = np.linspace(-1.55, 1.55, 4000)[:, None]
    t = np.linspace(0.0, 2 * np.pi, 400, endpoint=False)[None, :]  # not closed exactly
    rings = np.stack([np.cos(lat) * np.cos(t), np.cos(lat) * np.sin(t),
                      np.sin(lat) + 0 * t], axis=-1)
    write_sketch(folder / "rings.json", Sketch(list(np.round(rings, 6))))
    s = np.linspace(0.0, 1.0, 1000)[None, :, None]
    c, a, b = (rng.uniform(0, 1, (7000, 1, 3)), rng.normal(size=(7000, 1, 3)) * 0.3,
               rng.normal(size=(7000, 1, 3)) * 0.3)
    scribbles = c + a * np.sin(np.pi * s) + b * np.sin(2 * np.pi * s + 1.0) * s
    write_sketch(folder / "scribbles.txt", Sketch(list(np.round(scribbles, 5))))
    return [folder / "rings.json", folder / "scribbles.txt"]


_CHILD = """
import os, resource, sys, time
resource.setrlimit(resource.RLIMIT_AS, (int(sys.argv[2]) << 30, int(sys.argv[2]) << 30))
from curvenet.core.errors import CurvenetError
from curvenet.io import read_sketch
from curvenet.snap import snap
t, c = time.perf_counter(), time.process_time()
try:
    net = snap(read_sketch(sys.argv[1]))
    out = f"ok: {net.number_of_vertices} vertices, {net.number_of_edges} curves; " \
          + net.report["snap_tol_reason"][:90]
except CurvenetError as err:
    out = f"refused: {err}"[:160]
except MemoryError:
    out = "MemoryError"
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20
print(f"{time.perf_counter() - t:.1f}|{time.process_time() - c:.1f}|{os.getloadavg()[0]:.1f}|"
      f"{peak:.2f}|{out}")
"""


def big_table(folder, cap_gb=5):
    """Read and snap each big input in a child process; its peak memory (RSS) and seconds.

    Seconds: wall and CPU (the child's process time; on a shared machine the better
    estimate of an idle run), and the 1-minute load average at the end. The child's
    address space is capped at ``cap_gb`` GiB (``RLIMIT_AS``) so a run that would need
    more ends with MemoryError instead of swapping a shared machine.
    """
    import subprocess
    import sys

    print(f"{'input':16s} {'MB':>6s} {'peak GB':>8s} {'wall s':>7s} {'cpu s':>7s} {'load':>5s}  "
          "result")
    for f in big_inputs(folder):
        r = subprocess.run([sys.executable, "-c", _CHILD, str(f), str(cap_gb)],
                           capture_output=True, text=True)
        last = (r.stdout.strip().splitlines() or ["-|-|-|-|" + r.stderr.strip()[-120:]])[-1]
        sec, cpu, load, peak, out = last.split("|", 4)
        print(f"{f.name:16s} {f.stat().st_size / 1e6:6.0f} {peak:>8s} {sec:>7s} {cpu:>7s} "
              f"{load:>5s}  {out}", flush=True)


RECOVERY_SHAPES = ("sphere", "ellipsoid", "torus", "capped_cylinder", "box", "l_prism", "house",
                   "grid_box", "saddle", "two_boxes")


#: Redraw models of the library, by name (the others are ``tests/curvenet/_NAME.py``).
LIBRARY_GENERATORS = {"rough_sketch": rough_sketch, "loop_sketch": loop_sketch}


def _recovery_trial(job):
    """Snap one redraw; returns (shape, seed, ok, reason)."""
    name, seed, gap, generator, snap_tol = job
    import importlib
    from tests.curvenet import _redraw2
    ref = shapes.SHAPES[name]().network
    draw = LIBRARY_GENERATORS.get(generator) or getattr(
        importlib.import_module(f"tests.curvenet._{generator}"), generator)
    net = snap(draw(ref, seed=seed, gap=gap), snap_tol=snap_tol)
    if _redraw2.graph_recovered(ref, net):
        return name, seed, True, ""
    dv = net.number_of_vertices - ref.number_of_vertices
    de = net.number_of_edges - ref.number_of_edges
    deg = np.bincount(np.bincount(net.endpoints.ravel(), minlength=net.number_of_vertices))
    ref_deg = np.bincount(np.bincount(ref.endpoints.ravel(), minlength=ref.number_of_vertices))
    n = max(len(deg), len(ref_deg))
    ddeg = np.pad(deg, (0, n - len(deg))) - np.pad(ref_deg, (0, n - len(ref_deg)))
    diff = ",".join(f"deg{d}{c:+d}" for d, c in enumerate(ddeg) if c)
    why = f"V{dv:+d} E{de:+d} {diff}" if (dv or de or diff) else "same counts, not matched"
    return name, seed, False, f"{why}; tol {net.report['snap_tol']:.2%}"


def recovery_table(seeds, gap, shape_names=RECOVERY_SHAPES, jobs=1, generator="redraw2",
                   snap_tol="auto"):
    """Graph-recovery rate per shape on rough redraws (default ``tests/curvenet/_redraw2.py``).

    Each of ``seeds`` seeded redraws per shape (largest gap ``gap`` of the diagonal: split
    gaps, and for ``loop_sketch`` a ring's stop short of its start and its drift beside
    it) is snapped at ``snap_tol`` (default ``"auto"``) and checked with
    ``graph_recovered``. Prints one row per shape with its failing seeds and why
    (vertex, edge and per-degree count differences; the tolerance used).
    """
    import sys
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    work = [(name, s, gap, generator, snap_tol) for name in shape_names for s in seeds]
    if jobs > 1:
        from multiprocessing import Pool
        with Pool(jobs) as pool:
            res = pool.map(_recovery_trial, work, chunksize=4)
    else:
        res = [_recovery_trial(w) for w in work]
    tot = 0
    for name in shape_names:
        rows = [r for r in res if r[0] == name]
        ok = sum(r[2] for r in rows)
        tot += ok
        print(f"{name:16s} {ok:4d}/{len(rows)}", flush=True)
        for _, seed, _, why in (r for r in rows if not r[2]):
            print(f"    seed {seed}: {why}")
    print(f"{'all':16s} {tot:4d}/{len(res)} ({tot / len(res):.1%}) at gaps <= {gap:.1%}, "
          f"generator {generator}, snap_tol {snap_tol}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--data", metavar="DIR", help="print per-file statistics for the public "
                    "data folder (e.g. ../shared/data) instead of timing")
    ap.add_argument("--patches", metavar="DIR", help="print patch count and coverage per "
                    "public rough sketch under DIR/sketches instead of timing")
    ap.add_argument("--big", metavar="TMPDIR", help="write the two big inputs of issue 20 "
                    "into TMPDIR and print peak memory and time of snapping each")
    ap.add_argument("--recovery", action="store_true", help="print the graph-recovery rate "
                    "per shape on the independent redraws of issue 16 instead of timing")
    ap.add_argument("--seeds", type=int, default=50, help="--recovery: seeds 0..N-1 per shape")
    ap.add_argument("--first-seed", type=int, default=0, help="--recovery: first seed")
    ap.add_argument("--gap", type=float, default=0.015, help="--recovery: largest split gap, "
                    "fraction of the diagonal")
    ap.add_argument("--shapes", default=",".join(RECOVERY_SHAPES), help="--recovery: shapes")
    ap.add_argument("--generator", default="redraw2", help="--recovery: the generator: "
                    "redraw2 or redraw3 (function NAME in tests/curvenet/_NAME.py), "
                    "rough_sketch (curvenet.datasets.redraw) or loop_sketch (rings drawn "
                    "past or short of their start, curvenet.datasets.redraw_loops)")
    ap.add_argument("--snap-tol", default="auto", help="--recovery: snapping tolerance, "
                    "a fraction of the diagonal or auto (the default)")
    ap.add_argument("--jobs", type=int, default=1, help="--recovery: worker processes")
    args = ap.parse_args(argv)
    if args.recovery:
        recovery_table(range(args.first_seed, args.first_seed + args.seeds), args.gap,
                       args.shapes.split(","), args.jobs, args.generator,
                       args.snap_tol if args.snap_tol == "auto" else float(args.snap_tol))
        return
    if args.big:
        big_table(args.big)
        return
    if args.patches:
        patch_table(args.patches)
        return
    if args.data:
        data_table(args.data)
        return
    rows = []
    for name in ("box", "l_prism", "latlong_sphere", "saddle_grid"):
        ref = getattr(shapes, name)().network
        sk = rough_sketch(ref, seed=0)
        t, net = _time(lambda sk=sk: snap(sk), args.repeat)
        rows.append((f"{name} rough", len(sk), len(sk.points), t, match_networks(ref, net)["ok"]))
    for n in (10, 20):
        sk, ref, tol = grid_case(n, seed=0)
        t, net = _time(lambda sk=sk, tol=tol: snap(sk, snap_tol=tol), args.repeat)
        rows.append((f"saddle_grid({n}) rough", len(sk), len(sk.points), t,
                     match_networks(ref, net)["ok"]))
    sk, ref, tol = grid_case(20, seed=1, max_strokes=1000)
    t, net = _time(lambda: snap(sk, snap_tol=tol), args.repeat)
    rows.append(("1000 strokes x 100 pts", len(sk), len(sk.points), t, "-"))
    print(f"{'case':28s} {'strokes':>8s} {'points':>8s} {'wall s':>8s} {'cpu s':>8s}  graph ok")
    for name, ns, npt, (t, c), ok in rows:
        print(f"{name:28s} {ns:8d} {npt:8d} {t:8.3f} {c:8.3f}  {ok}")
    print("target: 1000 strokes x 100 points < 2 s")


if __name__ == "__main__":
    main()
