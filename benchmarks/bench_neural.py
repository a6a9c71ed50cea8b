"""Benchmark of the flow-aligned neural surfacing (neural.flow, Zhang et al. 2025).

Run from the repository root::

    python benchmarks/bench_neural.py                 # everything (long on 2 cores)
    python benchmarks/bench_neural.py --only draft100 steps reference vns
    nice -n 5 python benchmarks/bench_neural.py --only spheres --seeds 0 1 2 3 4

Sections
--------
draft100   ``draft`` on a ~100-stroke sketch of ../shared/data/sketches/vns (target < 90 s)
steps      seconds per full-stage step of ``default`` and ``paper`` at 128^3 and 256^3
reference  ``default`` on an 18-stroke rough sphere: time, peak memory, F-score, Chamfer,
           next to the published code's figures on this CPU (128^3, 300 steps: ~22 min,
           13.8 GB, F 99.8 %, Chamfer 2.6e-3)
spheres    ``--reference-quality`` (default ``default``) on the rough spheres of sketch seeds
           ``--seeds`` (0-4): F-score at 0.01 and Chamfer against the true sphere, wall and
           CPU seconds of the fit, peak RSS; ``--set NAME=VALUE`` overrides settings
heldout    ``--reference-quality`` on smooth closed sketches the presets were not chosen on:
           ``rough_sketch`` of the ellipsoid and the torus with its default noise, and a
           second noise model of this file (:func:`_tremor_sketch`) on a sphere and an
           ellipsoid; each with ``polish=0`` (the last step) and as set: F-score, Chamfer,
           stroke fidelity
wireframes ``--reference-quality`` and ``draft`` on clean sparse wireframes whose true surface
           is known (the curves of the network, exact, no noise): tori of 4 meridians x 2
           rings (tube radius 0.25 and 0.4) and 3 x 2 (0.4), 3 great circles of a
           sphere, two such spheres 0.2 apart, and the edges alone of a box, an L-shaped
           prism and a gabled house (flat faces and a notch that no stroke crosses;
           fitted part by part,
           :mod:`neural.parts`, as the route does: ``--set split_parts=0`` for one
           field), and a capped cylinder drawn by its two rims and 4 rulings; each
           with the fit seeds ``--fit-seeds`` (default 0); F-score at 0.01 and Chamfer
           against the true surface; ``--wireframes NAME ...`` takes some of them
vns        time and stroke fidelity per sketch (``--vns-quality``, default draft) on
           several vns sketches (``--vns all``: every ``*.obj`` under sketches/vns), PNG
           previews under ``--png-dir`` (default /tmp); fidelity is the share of stroke
           length within 1 % of the sketch's diagonal of the surface, as ``curvenet eval``
           reports it (:func:`curvenet.core.fidelity.sketch_fidelity`)

Figures, with their dates and machines, are in benchmarks/README.md.

Each measurement runs in a fresh subprocess so that peak memory (ru_maxrss) is its own.
The machine is shared: note the load average printed with the table.
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from curvenet.neural.presets import parse_setting

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(os.environ.get("CURVENET_DATA", ROOT.parent / "shared" / "data"))
REFERENCE = {"time_s": 22 * 60, "peak_gb": 13.8, "fscore": 0.998, "chamfer": 2.6e-3}


def _worker(spec: dict) -> dict:
    """One measurement in this process (called through a subprocess)."""
    import resource

    import torch
    torch.set_num_threads(spec.get("threads", 2))
    sys.path.insert(0, str(ROOT))
    from curvenet.model.sketch import Sketch
    from curvenet.neural.parts import fit_parts
    out = {}
    if spec["kind"] == "sketch":
        from curvenet.io.sketch import read_sketch
        sk = read_sketch(spec["path"])
    elif spec["kind"] == "sphere":
        from curvenet.datasets.redraw import rough_sketch
        from curvenet.datasets.shapes import latlong_sphere
        shape = latlong_sphere(n_lat=2, n_lon=6)
        sk = rough_sketch(shape.network, seed=spec.get("sketch_seed", 0), split=0.0,
                          overdraw=0.0)
    elif spec["kind"] == "wireframe":
        curves, ref = _wireframe(spec["shape"])
        sk = Sketch(curves)
    else:
        shape, sk = _heldout_sketch(spec["shape"], spec["noise"], spec["sketch_seed"])
    if spec["kind"] in ("sphere", "shape"):
        ref = shape.reference_mesh(5)
    strokes, labels = sk.strokes, sk.labels
    out["strokes"] = len(strokes)
    t, cpu = time.perf_counter(), time.process_time()
    device = spec.get("device", "cpu")
    r = fit_parts(strokes, labels=labels, quality=spec["quality"], progress=False,
                  device=device, seed=spec.get("fit_seed", 0), **spec.get("overrides", {}))
    out["time_s"] = time.perf_counter() - t
    out["timings"] = getattr(r, "timings", {})        # one fit's (not parts fitted apart)
    out["steps"] = r.report["steps"]
    out["faces"] = len(r.faces)
    out["polish"] = _polish_column(r.report.get("polish"))
    out["cpu_s"] = time.process_time() - cpu
    out["peak_gb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6
    if device.startswith("cuda"):
        out["gpu_peak_gb"] = torch.cuda.max_memory_allocated() / 1e9
    if spec["kind"] != "sphere" and len(r.faces):
        from curvenet.core.fidelity import sketch_fidelity
        out["fidelity"] = sketch_fidelity((r.vertices, r.faces), sk)["surface"]
    if spec["kind"] != "sketch":
        from tests.neural._metrics import fscore
        out["fscore"], out["chamfer"] = fscore(r.vertices, r.faces, ref.vertices, ref.faces)
    if spec.get("png"):
        _render(r.vertices, r.faces, strokes, spec["png"])
        out["png"] = spec["png"]
    return out


WIREFRAMES = ["torus r0.25 4x2", "torus r0.4 4x2", "torus r0.4 3x2", "sphere 3 circles",
              "2 spheres gap0.2", "box edges", "l_prism edges", "house edges", "cylinder 4x1",
              "sphere 3 circles turned", "cylinder 4x1 turned"]
#: Euler angles (degrees, xyz) of a ``turned`` wireframe: the turn of three great circles
#: whose bounding box is smallest against the sphere's (its sides at 0.94 of the radius).
TURN = (45.0, 20.0, 45.0)


def _wireframe(name: str):
    """``(curves, true surface (trimesh.Trimesh))`` of a ``WIREFRAMES`` name; ``2 spheres
    gapG``: two unit spheres of 3 great circles each, ``G`` apart; ``NAME edges``: the
    crease curves alone of the polyhedron ``curvenet.datasets.shapes.SHAPES[NAME]``;
    ``cylinder AxH``: a capped cylinder (radius 0.5, height 1.5) of ``A`` rulings and
    ``H + 1`` circles, no stroke on its caps; ``NAME turned``: NAME turned by
    :data:`TURN` (its rims and poles no longer on the sides of the axis-aligned box)."""
    import trimesh
    if name.endswith(" turned"):
        from scipy.spatial.transform import Rotation
        R = Rotation.from_euler("xyz", TURN, degrees=True).as_matrix()
        curves, truth = _wireframe(name[:-len(" turned")])
        truth = truth.copy()
        truth.vertices = truth.vertices @ R.T
        return [c @ R.T for c in curves], truth

    from curvenet.datasets import sections, shapes
    if name.startswith("2 spheres"):
        ball = sections.great_circles(3)
        shift = [2.0 + float(name.split()[2][3:]), 0.0, 0.0]
        curves = [e.curve for e in ball.network.edges]
        sphere = ball.reference_mesh(5)
        return curves + [c + shift for c in curves], trimesh.util.concatenate(
            [sphere, sphere.copy().apply_translation(shift)])
    if name.endswith(" edges"):
        shape = shapes.SHAPES[name.split()[0]]()
    elif name.startswith("sphere"):
        shape = sections.great_circles(int(name.split()[1]))
    elif name.startswith("cylinder"):
        around, rows = (int(k) for k in name.split()[1].split("x"))
        shape = shapes.capped_cylinder(0.5, 1.5, n_around=around, n_height=rows)
    else:
        _, r, counts = name.split()
        meridians, rings = (int(k) for k in counts.split("x"))
        shape = shapes.torus(1.0, float(r[1:]), n_u=meridians, n_v=rings)
    return [e.curve for e in shape.network.edges], shape.reference_mesh(5)


HELDOUT = [("ellipsoid", "rough", 0), ("torus", "rough", 0), ("sphere", "tremor", 1),
           ("ellipsoid", "tremor", 2)]


def _heldout_sketch(name: str, noise: str, seed: int):
    """``(AnalyticShape, Sketch)`` of the heldout section (``noise``: rough or tremor)."""
    from curvenet.datasets.redraw import rough_sketch
    from curvenet.datasets.shapes import SHAPES, latlong_sphere
    if noise == "rough":
        shape = SHAPES[name]()
        return shape, rough_sketch(shape.network, seed=seed)
    shape = latlong_sphere(n_lat=3, n_lon=8) if name == "sphere" else SHAPES[name]()
    return shape, _tremor_sketch(shape, seed)


def _tremor_sketch(shape, seed: int):
    """A noise model unlike ``rough_sketch``'s, for checks the presets were not tuned on.

    Each curve of the shape's network is resampled at sorted uniform random arc lengths
    (0.6-1.5 times its point count, at least 12), moved along the true surface's normal
    by the mean of three sines of random phase and 1-4 half-waves per curve (amplitude
    0.6 % of the diagonal), jittered by isotropic Gaussian tremor (0.15 % of the
    diagonal) and cut into 1-3 strokes that overlap by two points.
    """
    import numpy as np

    from curvenet.core.geometry import arc_length, interpolate_polyline
    from curvenet.model.sketch import Sketch
    rng = np.random.default_rng(seed)
    ref = shape.reference_mesh(5)
    diag = float(np.linalg.norm(ref.vertices.max(0) - ref.vertices.min(0)))
    strokes = []
    for edge in shape.network.edges:
        length = arc_length(edge.curve)
        n = max(12, int(len(edge.curve) * rng.uniform(0.6, 1.5)))
        t = np.sort(rng.uniform(0.0, length, n))
        p = interpolate_polyline(edge.curve, t)
        _, _, tri = ref.nearest.on_surface(p)
        phase, waves = rng.uniform(0, 2 * np.pi, 3), rng.uniform(1, 4, 3)
        offset = np.sin(np.outer(t / length * np.pi, waves) + phase).mean(1) * 0.006 * diag
        p = p + offset[:, None] * ref.face_normals[tri] + rng.normal(scale=0.0015 * diag,
                                                                     size=p.shape)
        cuts = np.sort(rng.choice(np.arange(4, len(p) - 4), rng.integers(0, 3), replace=False))
        for a, b in zip(np.r_[0, cuts], np.r_[cuts, len(p)]):
            strokes.append(p[max(0, a - 2): b])
    return Sketch(strokes, ["crease"] * len(strokes))


def _polish_column(info) -> str:
    """The polish's choice: stroke fidelity of the last step and of the polished surface."""
    if info is None:
        return "polish=off"
    last, polished = info["fidelity"]
    return f"polish={'kept' if info['kept'] else 'dropped'} ({last:.3f}->{polished:.3f})"


def _render(V, F, strokes, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    fig = plt.figure(figsize=(10, 5))
    for i, (elev, azim) in enumerate([(20, 30), (20, 210)]):
        ax = fig.add_subplot(1, 2, i + 1, projection="3d")
        if len(F):
            ax.plot_trisurf(V[:, 0], V[:, 1], V[:, 2], triangles=F, color="0.8",
                            edgecolor="none", alpha=0.9, shade=True)
        for s in strokes:
            ax.plot(s[:, 0], s[:, 1], s[:, 2], "r-", lw=0.6)
        pts = np.vstack(strokes)
        c, r = pts.mean(0), (pts.max(0) - pts.min(0)).max() / 2
        ax.set_xlim(c[0] - r, c[0] + r)
        ax.set_ylim(c[1] - r, c[1] + r)
        ax.set_zlim(c[2] - r, c[2] + r)
        ax.view_init(elev, azim)
        ax.set_axis_off()
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def _run(spec: dict, timeout: float = 3600) -> dict:
    cmd = [sys.executable, __file__, "--worker", json.dumps(spec)]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=ROOT)
    if p.returncode != 0:
        return {"error": p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "failed"}
    return json.loads(p.stdout.strip().splitlines()[-1])


def _memory(r: dict) -> str:
    """Peak host memory, and peak GPU memory on CUDA runs."""
    text = f"peak={r.get('peak_gb', float('nan')):.2f}GB"
    if "gpu_peak_gb" in r:
        text += f" gpu={r['gpu_peak_gb']:.2f}GB"
    return text


def _row(*cols):
    print(" | ".join(str(c) for c in cols), flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", default=["draft100", "steps", "reference", "vns"])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--vns", nargs="*", default=["bulbasaur", "guitar", "phone_flowrep",
                                                  "trebol_flowrep", "torus"],
                    help="sketch names under sketches/vns (without .obj), or all")
    ap.add_argument("--device", default="cpu", help="cpu or cuda")
    ap.add_argument("--reference-quality", default="default",
                    help="preset of the rough-sphere comparison (default: default)")
    ap.add_argument("--seeds", type=int, nargs="*", default=[0, 1, 2, 3, 4],
                    help="rough-sphere sketch seeds of the spheres section")
    ap.add_argument("--fit-seeds", type=int, nargs="*", default=[0],
                    help="seeds of the fit itself in the wireframes section")
    ap.add_argument("--timeout", type=float, default=3600,
                    help="seconds per rough sphere of the spheres section (loaded machines: more)")
    ap.add_argument("--wireframes", nargs="*", default=WIREFRAMES, choices=WIREFRAMES,
                    metavar="NAME", help="shapes of the wireframes section (default: all)")
    ap.add_argument("--set", nargs="*", default=[], metavar="NAME=VALUE",
                    help="FlowConfig overrides (sections spheres, heldout, wireframes, vns)")
    ap.add_argument("--vns-quality", default="draft", help="preset of the vns section")
    ap.add_argument("--png-dir", default="/tmp", help="where the vns previews go")
    ap.add_argument("--worker", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.worker:
        print(json.dumps(_worker(json.loads(a.worker))))
        return
    print(f"# load average at start: {os.getloadavg()}; device {a.device}")
    base = {"threads": a.threads, "device": a.device}
    overrides = dict(parse_setting(t) for t in a.set)
    png = Path(a.png_dir)
    png.mkdir(parents=True, exist_ok=True)   # before any fit, not after each
    vns = DATA / "sketches" / "vns"
    if "draft100" in a.only:
        path = vns / "input" / "gamepad.obj"
        r = _run({**base, "kind": "sketch", "path": str(path), "quality": "draft",
                  "png": str(png / "neural_gamepad.png")})
        _row("draft100", path.name, f"strokes={r.get('strokes')}",
             f"time={r.get('time_s', float('nan')):.1f}s (target < 90 s)", _memory(r),
             r.get("error", ""))
    if "steps" in a.only:
        for quality in ("default", "paper"):
            for res in (128, 256):
                n = 2 if a.device == "cpu" else 20
                r = _run({**base, "kind": "sketch", "path": str(vns / "input" / "gamepad.obj"),
                          "quality": quality,
                          "overrides": {"res": res, "init_steps": 1, "steps": n}})
                per = r["timings"]["full"] / n if "timings" in r else float("nan")
                _row("steps", quality, f"{res}^3", f"{per:.3f} s/step (full stage, {n} steps)",
                     _memory(r), r.get("error", ""))
    if "reference" in a.only:
        r = _run({**base, "kind": "sphere", "quality": a.reference_quality})
        _row("reference", "method", "time", "peak memory", "F-score@0.01", "Chamfer")
        _row("reference", "published code, 128^3 x 300 steps", f"{REFERENCE['time_s']:.0f}s",
             f"{REFERENCE['peak_gb']:.1f}GB", f"{REFERENCE['fscore']:.3f}",
             f"{REFERENCE['chamfer']:.2e}")
        label = f"ours {a.reference_quality} on {a.device}"
        if "error" in r:
            _row("reference", label, r["error"])
        else:
            _row("reference", f"{label} ({r['strokes']} strokes)", f"{r['time_s']:.1f}s",
                 _memory(r), f"{r['fscore']:.3f}", f"{r['chamfer']:.2e}")
    if "spheres" in a.only:
        _row("spheres", "quality", "sketch seed", "F-score@0.01", "Chamfer", "wall", "CPU",
             "peak RSS", "polish (stroke fidelity)")
        for seed in a.seeds:
            r = _run({**base, "kind": "sphere", "quality": a.reference_quality,
                      "sketch_seed": seed, "overrides": overrides}, timeout=a.timeout)
            if "error" in r:
                _row("spheres", a.reference_quality, seed, r["error"])
                continue
            _row("spheres", a.reference_quality, seed, f"{r['fscore']:.4f}",
                 f"{r['chamfer']:.2e}", f"{r['time_s']:.1f}s", f"{r['cpu_s']:.1f}s",
                 _memory(r), r["polish"])
    if "heldout" in a.only:
        _row("heldout", "shape", "noise", "sketch seed", "polish", "F-score@0.01", "Chamfer",
             "stroke fidelity", "wall")
        for name, noise, seed in HELDOUT:
            for label, extra in (("off", {"polish": 0}), ("as set", {})):
                r = _run({**base, "kind": "shape", "shape": name, "noise": noise,
                          "sketch_seed": seed, "quality": a.reference_quality,
                          "overrides": {**overrides, **extra}}, timeout=a.timeout)
                if "error" in r:
                    _row("heldout", name, noise, seed, label, r["error"])
                    continue
                _row("heldout", name, noise, seed, f"{label}: {r['polish']}",
                     f"{r['fscore']:.4f}", f"{r['chamfer']:.2e}",
                     f"{r.get('fidelity', 0.0):.3f}", f"{r['time_s']:.1f}s")
    if "wireframes" in a.only:
        _row("wireframes", "shape", "quality", "fit seed", "F-score@0.01", "Chamfer", "wall")
        for name, seed in itertools.product(a.wireframes, a.fit_seeds):
            for quality in ("draft", a.reference_quality):
                r = _run({**base, "kind": "wireframe", "shape": name, "quality": quality,
                          "fit_seed": seed, "overrides": overrides}, timeout=a.timeout)
                if "error" in r:
                    _row("wireframes", name, quality, seed, r["error"])
                    continue
                _row("wireframes", name, quality, seed, f"{r['fscore']:.4f}",
                     f"{r['chamfer']:.2e}", f"{r['time_s']:.1f}s")
    if "vns" in a.only:
        names = a.vns
        if names == ["all"]:
            names = [p.relative_to(vns).with_suffix("").as_posix()
                     for p in sorted(vns.rglob("*.obj"))]
        for name in names:
            path = vns / f"{name}.obj"
            r = _run({**base, "kind": "sketch", "path": str(path), "quality": a.vns_quality,
                      "overrides": overrides,
                      "png": str(png / f"neural_{Path(name).name}.png")})
            _row("vns", a.vns_quality, name, f"strokes={r.get('strokes')}",
                 f"time={r.get('time_s', float('nan')):.1f}s",
                 f"cpu={r.get('cpu_s', float('nan')):.1f}s", f"faces={r.get('faces')}",
                 f"fidelity={r.get('fidelity', float('nan')):.3f}", _memory(r),
                 r.get("polish", ""), r.get("error", ""))
    print(f"# load average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
