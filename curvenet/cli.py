"""The ``curvenet`` command: a thin layer over the library.

Parses arguments, calls :mod:`curvenet.pipeline` and friends, and turns a
:class:`~curvenet.core.errors.CurvenetError` into one line on stderr and exit code 2
(1 for an internal failure, 130 for Ctrl-C); ``--debug`` shows tracebacks.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import time
from pathlib import Path

from .core.atomic import check_output_path
from .core.tolerances import check_snap_tol
from .core.errors import CurvenetError, InvalidParameterError, OutputError

__all__ = ["main", "build_parser"]


def _snap_tol(text: str) -> float | str:
    """``--snap-tol``: ``auto`` (choose from the sketch) or a fraction of the diagonal."""
    return "auto" if text.strip().lower() == "auto" else _fraction(text)


def _fraction(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    try:
        return check_snap_tol(value)
    except InvalidParameterError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def _neural_setting(text: str) -> tuple[str, object]:
    from curvenet.neural.presets import parse_setting
    try:
        return parse_setting(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text} is not a positive integer")
    return value


def _port(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"{text} is not a port (0..65535)")
    return value


def _edge_length(text: str) -> float:
    """``--edge-length``: a fraction of the diagonal in (0, 1]."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not 0.0 < value <= 1.0:
        raise argparse.ArgumentTypeError(f"{text} is not a fraction in (0, 1]")
    return value


def _classical_options(args) -> dict | None:
    """Options of the classical surfacer from the command line."""
    return None if args.edge_length is None else {"edge_length": args.edge_length}


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {text!r}") from None
    if not (0 <= value < 2**63):
        raise argparse.ArgumentTypeError(f"{text} is not in [0, 2**63)")
    return value


class _Parser(argparse.ArgumentParser):
    """An option error is one line and a hint, not the usage block."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


_POINTS_HELP = ("read every block of points as unordered samples of curves and recover the "
                "curves (default: detected block by block)")


def _points(args):
    return True if args.points else "auto"


def build_parser() -> argparse.ArgumentParser:
    from .pipeline import METHODS
    from .route.registry import get_surfacer, surfacer_names
    p = _Parser(prog="curvenet", description="3D sketches and curve networks to surfaces.")
    p.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    sub = p.add_subparsers(dest="command", required=True)

    s = sub.add_parser("snap", help="snap rough strokes into a curve network (NETWORK.json)")
    s.add_argument("input")
    s.add_argument("-o", "--output", required=True, help="NETWORK.json (or .obj polylines)")
    s.add_argument("--snap-tol", type=_snap_tol, default="auto",
                   help="fraction of the bbox diagonal, or auto (default: chosen from the "
                        "sketch, the choice and why printed)")
    s.add_argument("--points", action="store_true", help=_POINTS_HELP)

    s = sub.add_parser("patches", help="find surface patches (PATCHES.json)")
    s.add_argument("input", help="sketch file or NETWORK.json")
    s.add_argument("-o", "--output", required=True, help="PATCHES.json")
    s.add_argument("--snap-tol", type=_snap_tol, default="auto",
                   help="fraction of the bbox diagonal, or auto (default)")
    s.add_argument("--close", choices=("auto", "none"), default="auto",
                   help="accept solid-closing patches automatically (default auto)")
    s.add_argument("--points", action="store_true", help=_POINTS_HELP)
    s.add_argument("--interactive", action="store_true",
                   help="review patches: delete, accept/reject suggestions, undo, save")
    s.add_argument("--preview", metavar="PNG", help="write a picture of the patches")
    s.add_argument("--up", choices=("x", "y", "z"), default="z", help="up axis of the preview")

    s = sub.add_parser("review", help="review the patches in the browser: click to accept or "
                                      "reject, Save writes PATCHES.json (needs curvenet[view])")
    s.add_argument("input", help="sketch file, NETWORK.json or PATCHES.json (reviewed as saved)")
    s.add_argument("-o", "--output", metavar="PATCHES.json",
                   help="the file Save writes (default: INPUT-stem.patches.json beside the "
                        "input); nothing else is written")
    s.add_argument("--port", type=_port, default=8080,
                   help="port to serve on (default 8080; the next free one if taken; 0: any)")
    s.add_argument("--host", default="127.0.0.1",
                   help="address to bind (default 127.0.0.1: this machine only)")
    s.add_argument("--no-browser", action="store_true", help="do not open a browser")
    s.add_argument("--snap-tol", type=_snap_tol, default="auto",
                   help="fraction of the bbox diagonal, or auto (default)")
    s.add_argument("--close", choices=("auto", "none"), default="auto",
                   help="accept solid-closing patches automatically (default auto)")
    s.add_argument("--points", action="store_true", help=_POINTS_HELP)
    s.add_argument("--up", choices=("x", "y", "z"), default="z", help="up axis of the view")

    s = sub.add_parser("surface", help="surface a sketch, network or patch set")
    s.add_argument("inputs", nargs="+", metavar="INPUT")
    s.add_argument("-o", "--output", help="mesh file (.obj .ply .stl .off .glb) or B-spline "
                                          "CAD file (.step .stp .3dm, needs curvenet[cad])")
    s.add_argument("--out-dir", help="batch mode: write INPUT-stem.<--format> here")
    s.add_argument("--format", default="obj",
                   choices=("obj", "ply", "stl", "off", "glb", "step", "3dm"),
                   help="output format in batch mode (default obj)")
    s.add_argument("--step-schema", choices=("AP214", "AP242"), default="AP214",
                   help="STEP application protocol (default AP214)")
    s.add_argument("--jobs", type=_positive_int, default=1, help="batch: parallel processes")
    s.add_argument("--scheduler", metavar="ADDRESS",
                   help="batch: send the files to this Dask scheduler (tcp://host:8786) "
                        "instead of local processes; needs curvenet[cluster]")
    s.add_argument("--skip-existing", action="store_true",
                   help="batch: skip files already surfaced with the same input and "
                        "settings (from OUT_DIR/curvenet-manifest.jsonl); resumes a batch")
    s.add_argument("--report", metavar="REPORT.csv|json",
                   help="batch: per-file report (hash, route, times, patches, coverage, "
                        "stroke fidelity, output, status)")
    s.add_argument("--preview-dir", metavar="DIR",
                   help="batch: a picture per file and contact_sheet.png of the batch")
    s.add_argument("--method", choices=METHODS + surfacer_names(), default="auto",
                   help="auto: classical when the patches cover the curves, else neural; "
                        "classical: the --surfacer on the patches; or a surfacer: "
                        + "; ".join(f"{n}: {get_surfacer(n).summary}" for n in surfacer_names()))
    s.add_argument("--patches", metavar="PATCHES.json", help="use this (edited) patch set")
    s.add_argument("--snap-tol", type=_snap_tol, default="auto",
                   help="fraction of the bbox diagonal, or auto (default)")
    s.add_argument("--close", choices=("auto", "none"), default="auto")
    s.add_argument("--points", action="store_true", help=_POINTS_HELP)
    s.add_argument("--surfacer", choices=surfacer_names("patches"), default="catmull-clark",
                   help="surfacer of the classical route (default catmull-clark)")
    density = s.add_mutually_exclusive_group()
    density.add_argument("--subdiv", type=_positive_int, help="Catmull-Clark levels")
    density.add_argument("--edge-length", type=_edge_length, metavar="F",
                         help="classical: target output edge length, fraction of the bbox "
                              "diagonal (default 0.005; at most 200k triangles)")
    s.add_argument("--resolution", type=_positive_int, help="Coons samples per side segment")
    s.add_argument("--crease-angle", type=float, default=30.0, metavar="DEG")
    s.add_argument("--refine", action="store_true",
                   help="continue the classical result with the neural flow-alignment fit "
                        "(closer to the strokes as drawn, not to the true shape)")
    s.add_argument("--quality", choices=("draft", "default", "paper"), default="draft")
    s.add_argument("--device", default="cpu", help="cpu or cuda (neural route)")
    s.add_argument("--closed-box", action="store_true",
                   help="neural: f = outside on the box walls, so the surface closes "
                        "inside the box (default: the paper's periodic box)")
    s.add_argument("--neural-set", type=_neural_setting, action="append", default=[],
                   metavar="NAME=VALUE",
                   help="override one neural setting (neural.presets.FlowConfig), repeatable: "
                        "--neural-set res=96 --neural-set w_smooth=0.01")
    s.add_argument("--seed", type=_seed, default=0)
    s.add_argument("--preview", metavar="PNG", help="write a picture of the result")
    s.add_argument("--up", choices=("x", "y", "z"), default="z", help="up axis of the preview")
    s.add_argument("--explain", action="store_true", help="say which route was taken and why")
    s.add_argument("--no-progress", action="store_true", help="hide progress bars")

    s = sub.add_parser("eval", help="compare a mesh with a reference mesh or the sketch")
    s.add_argument("mesh", nargs="?")
    s.add_argument("reference", nargs="?",
                   help="reference mesh, or a sketch file for stroke distance")
    s.add_argument("--pairs", nargs="+", metavar="DIR_OUT DIR_REF | PAIRS.csv",
                   help="batch: every mesh in DIR_OUT against the file of the same stem in "
                        "DIR_REF, or the mesh,reference rows of a CSV")
    s.add_argument("--report", metavar="REPORT.csv|json",
                   help="batch: write the table with the metric definitions in its header")
    s.add_argument("--json", action="store_true", help="print JSON")
    s.add_argument("--samples", type=_positive_int, default=100_000)
    s.add_argument("--threshold", type=float, default=0.01, help="F-score threshold")
    s.add_argument("--seed", type=int, default=0, help="seed of the surface sampling")
    return p


# --------------------------------------------------------------------------- commands
def _cmd_snap(args) -> int:
    from .io.sketch import read_sketch, write_network_obj
    from .io.network import write_network
    from .snap.graph import snap
    check_output_path(args.output, inputs=[args.input], what="-o")
    sketch = read_sketch(args.input, points=_points(args))
    net = snap(sketch, snap_tol=args.snap_tol)
    if net.number_of_edges == 0:
        raise CurvenetError(f"{args.input}: snapping left no curves (every stroke collapsed "
                            "to a point)")
    if args.output.lower().endswith(".obj"):
        write_network_obj(args.output, net)
    else:
        write_network(args.output, net)
    print(f"{args.output}: {net.number_of_vertices} vertices, {net.number_of_edges} curves")
    print(net.report["summary"])
    if sketch.metadata.get("point_blocks"):
        print(f"reading: {sketch.metadata['reading']}")
    return 0


def _cmd_patches(args) -> int:
    from .io.network import write_patches
    from .pipeline import patches
    check_output_path(args.output, inputs=[args.input], what="-o")
    if args.preview:
        check_output_path(args.preview, inputs=[args.input, args.output], what="--preview")
    ps = patches(args.input, snap_tol=args.snap_tol, close=args.close, points=_points(args))
    if args.interactive:
        from .review import run_interactive
        ps = run_interactive(ps, input=sys.stdin, output=sys.stdout, preview=args.preview)
    write_patches(args.output, ps)
    t = ps.report.get("timings", {})
    print(f"{args.output}: {len(ps.patches)} patches on {ps.network.number_of_edges} curves "
          f"({sum(t.values()):.2f} s)")
    if args.preview:
        from .view.preview import render_preview
        render_preview(args.preview, network=ps.network, patches=ps, title=Path(args.input).name,
                       up=args.up)
    return 0


def _cmd_review(args) -> int:
    from .pipeline import load_source, patches, surface
    from .review.web import require_viser, serve_review
    require_viser()                               # before any work: say which extra
    stem = Path(args.input)
    output = args.output or str(stem.with_name(stem.stem + ".patches.json"))
    check_output_path(output, inputs=[args.input], what="-o")
    sketch, given = load_source(args.input, points=_points(args))
    ps = given if given is not None and given.patches else patches(
        sketch if sketch is not None else given, snap_tol=args.snap_tol, close=args.close)
    if not ps.patches:
        raise CurvenetError(f"{args.input}: no patches found, nothing to review")

    def surface_fn(patchset):
        return surface(sketch if sketch is not None else patchset, patchset=patchset,
                       method="classical").mesh

    serve_review(dict(patchset=ps, output=output, inputs=[args.input],
                      strokes=[] if sketch is None else sketch.strokes, surface=surface_fn,
                      host=args.host, port=args.port, title=Path(args.input).name,
                      up=args.up), open_browser=not args.no_browser)
    return 0


def _neural_options(args) -> dict | None:
    """``--neural-set`` overrides, with ``--closed-box`` as ``boundary="dirichlet"``."""
    options = dict(args.neural_set)
    if args.closed_box:
        options["boundary"] = "dirichlet"
    return options or None


def _surface_one(inp: str, out: str, args) -> dict:
    """Surface one input; returns a status row (never raises CurvenetError)."""
    from .io.network import read_patches
    from .pipeline import surface
    from .surfacing.sectors import explain_boundaries
    t0 = time.perf_counter()
    try:
        ps = read_patches(args.patches) if args.patches else None
        res = surface(inp, method=args.method, patchset=ps, snap_tol=args.snap_tol,
                      close=args.close, surfacer=args.surfacer, subdiv=args.subdiv,
                      resolution=args.resolution, crease_angle=args.crease_angle,
                      refine=args.refine, quality=args.quality, device=args.device,
                      seed=args.seed, progress=not args.no_progress,
                      classical_options=_classical_options(args),
                      neural_options=_neural_options(args), points=_points(args))
        _save(res, out, args, inputs=[inp, args.patches])
        if args.preview:
            from .view.preview import render_preview
            prev = args.preview if args.output else str(Path(out).with_suffix(".png"))
            render_preview(prev, strokes=res.sketch, network=res.network, mesh=res.mesh,
                           title=f"{Path(inp).name}: {res.method}", up=args.up,
                           face_route=res.face_route, routes=res.routes, wires=res.wires)
        return {"input": inp, "output": out, "status": "ok", "method": res.method,
                "faces": len(res.mesh.faces), "seconds": time.perf_counter() - t0,
                "why": res.decision.explain(), "interrupted": res.interrupted,
                "reading": res.diagnostics.get("reading", ""),
                "snap": res.diagnostics.get("snap", {}).get("summary", ""),
                "regions": res.decision.explain_regions(),
                "check": res.decision.explain_check(),
                "classical": explain_boundaries(res.diagnostics.get("classical")),
                "fidelity": res.diagnostics.get("fidelity"),
                "topology": res.diagnostics.get("topology"),
                "cad": res.diagnostics.get("cad")}
    except CurvenetError as err:
        return {"input": inp, "output": out, "status": "error", "error": _naming(err, inp),
                "seconds": time.perf_counter() - t0}


def _save(res, out: str, args, *, inputs) -> None:
    """Write the result; when only a CAD export fails, the mesh still goes beside it
    (``OUT`` with ``.obj``, ``-mesh.obj`` where that is an input) and the failure names
    where it is."""
    from .pipeline import CAD_FORMATS
    if Path(out).suffix.lower() not in CAD_FORMATS:
        res.save(out, schema=args.step_schema)
        return
    try:
        res.save(out, schema=args.step_schema)
    except Exception as err:
        mesh = Path(out).with_suffix(".obj")
        given = {Path(i).resolve() for i in inputs if i}
        if mesh.resolve() in given:
            mesh = mesh.with_name(mesh.stem + "-mesh.obj")
        res.save(mesh)
        note = f"; no {Path(out).suffix.lower()} written, the mesh is in {mesh}"
        if isinstance(err, CurvenetError):
            raise CurvenetError(f"{err}{note}") from None
        raise RuntimeError(f"CAD export: {type(err).__name__}: {err}{note}") from err


def _cmd_surface(args) -> int:
    from .cad.export import require_cad
    from .pipeline import CAD_FORMATS, MESH_FORMATS
    suffix = (Path(args.output).suffix.lower() if args.out_dir is None and args.output
              else "." + args.format)
    if suffix in CAD_FORMATS:
        require_cad(suffix)                       # before any work: say which extra
    if args.out_dir is not None:
        return _cmd_surface_batch(args)
    for flag in ("scheduler", "report", "preview_dir", "skip_existing"):
        if getattr(args, flag) not in (None, False):
            raise InvalidParameterError(f"surface: --{flag.replace('_', '-')} needs --out-dir")
    if args.output is None:
        raise InvalidParameterError("surface: give -o MESH (one input) or --out-dir DIR")
    if len(args.inputs) > 1:
        raise InvalidParameterError("surface: several inputs need --out-dir DIR, not -o")
    if suffix not in MESH_FORMATS + CAD_FORMATS:
        raise InvalidParameterError(f"output {args.output}: unknown format; use one "
                                    f"of {', '.join(MESH_FORMATS + CAD_FORMATS)}")
    given = [*args.inputs, args.patches]
    check_output_path(args.output, inputs=given, what="-o")
    if args.preview:
        check_output_path(args.preview, inputs=[*given, args.output], what="--preview")
    row = _surface_one(args.inputs[0], args.output, args)
    if row["status"] != "ok":
        raise CurvenetError(row["error"])
    partial = " (partial: interrupted, the best surface so far)" if row["interrupted"] else ""
    print(f"{row['output']}: {row['faces']} faces, {row['method']}, "
          f"{row['seconds']:.1f} s{partial}")
    if args.explain:
        reading = row.get("reading") and f"reading: {row['reading']}"
        for line in [reading, row["snap"], f"route: {row['why']}",
                     *(f"  region {r}" for r in row.get("regions", [])),
                     row.get("check"), *row.get("classical", [])]:
            if line:
                print(line)
        from .evaluate import format_fidelity, format_topology
        for key, fmt in (("fidelity", format_fidelity), ("topology", format_topology)):
            if row.get(key):
                print(fmt(row[key]))
        if row.get("cad"):
            from .cad.report import cad_report_lines
            print("\n".join(cad_report_lines(row["cad"])))
    return 130 if row["interrupted"] else 0


def _batch_options(args):
    from .batch.run import BatchOptions
    return BatchOptions(method=args.method, snap_tol=args.snap_tol, close=args.close,
                        surfacer=args.surfacer, subdiv=args.subdiv, resolution=args.resolution,
                        crease_angle=args.crease_angle, edge_length=args.edge_length,
                        refine=args.refine, quality=args.quality, device=args.device,
                        seed=args.seed,
                        neural_options=tuple(sorted((_neural_options(args) or {}).items())),
                        format=args.format, points=args.points)


def _progress(total: int, quiet: bool):
    """A tqdm bar across files on a terminal (None elsewhere: the per-file lines suffice)."""
    if quiet or not sys.stderr.isatty():
        return None
    from tqdm import tqdm
    return tqdm(total=total, unit="file", file=sys.stderr, leave=False)


def _cmd_surface_batch(args) -> int:
    """``--out-dir``: the batch engine (:mod:`curvenet.batch`), one line per file."""
    from .batch.run import COLUMN_NOTES, DaskExecutor, LocalExecutor, run_batch
    from .io.tables import check_report_path, write_table
    if args.output is not None:
        raise InvalidParameterError("surface: give -o MESH or --out-dir DIR, not both")
    if args.patches is not None:
        raise InvalidParameterError("surface: --patches applies to one input with -o, "
                                    "not to a batch")
    report = None if args.report is None else check_report_path(
        args.report, inputs=args.inputs, out_dir=args.out_dir)
    executor = DaskExecutor(args.scheduler) if args.scheduler else LocalExecutor(args.jobs)
    options = _batch_options(args)
    bar = _progress(len(args.inputs), args.no_progress)
    say = print if bar is None else bar.write

    def on_row(row, done, total):
        if bar is not None:
            bar.update(1)
        say(_batch_line(row, done, total, args.explain))

    try:
        result = run_batch(args.inputs, args.out_dir, options, executor=executor,
                           skip_existing=args.skip_existing, preview=args.preview is not None,
                           preview_dir=args.preview_dir, up=args.up, on_row=on_row)
    finally:
        if bar is not None:
            bar.close()
    summary = result.summary()
    if report is not None:
        header = [f"curvenet surface batch: {len(result.rows)} files, executor "
                  f"{'dask ' + args.scheduler if args.scheduler else f'local, {args.jobs} jobs'}",
                  f"settings: {options}", *COLUMN_NOTES]
        write_table(report, result.rows, header=header, summary=summary,
                    first=("input", "status", "route", "output", "input_sha256"))
    print(summary)
    return result.exit_code


def _batch_line(row: dict, done: int, total: int, explain: bool) -> str:
    head = f"[{done}/{total}] "
    if row["status"] in ("ok", "skipped"):
        fid = row.get("fidelity")
        line = (f"{head}{row['status']:<7s} {row['input']} -> {row['output']}  "
                f"{row.get('route', ''):<10s} {row.get('faces', 0):>8d} faces"
                + ("" if fid is None else f"  fidelity {fid:.1%}")
                + f" {row.get('t_total', 0.0):7.1f} s")
        return line + (f"  ({row.get('decision', '')})" if explain else "")
    return f"{head}FAILED  {row['input']}: {row.get('error', '')}"


def _cmd_eval_pairs(args) -> int:
    """``eval --pairs``: a table over many pairs, metric definitions in the report header."""
    from .evaluate import pairs as be
    from .io.tables import check_report_path, write_table
    if args.mesh is not None:
        raise InvalidParameterError("eval: give MESH REFERENCE or --pairs, not both")
    report = None if args.report is None else check_report_path(args.report,
                                                                 inputs=args.pairs)
    if len(args.pairs) == 1:
        pairs = be.pairs_from_csv(args.pairs[0])
    elif len(args.pairs) == 2:
        pairs = be.pairs_from_dirs(*args.pairs)
    else:
        raise InvalidParameterError("eval: --pairs takes DIR_OUT DIR_REF or one PAIRS.csv")
    header = be.metric_definitions(args.samples, args.threshold, args.seed)
    bar = _progress(len(pairs), False)
    rows = be.evaluate_pairs(pairs, n_samples=args.samples, threshold=args.threshold,
                             seed=args.seed,
                             on_row=None if bar is None else lambda *_: bar.update(1))
    if bar is not None:
        bar.close()
    summary = be.summary_line(rows)
    if report is not None:
        write_table(report, rows, header=header, summary=summary,
                    first=("mesh", "reference", "status", "kind"))
    if args.json:
        print(json.dumps({"header": header, "rows": rows, "summary": summary}, indent=1))
    else:
        print("\n".join(f"# {line}" for line in header))
        print(be.format_table(rows))
        print(summary)
    return 1 if any(r["status"] == "internal" for r in rows) else (
        2 if any(r["status"] != "ok" for r in rows) else 0)


def _cmd_eval(args) -> int:
    from .evaluate.pairs import is_mesh_file
    from .evaluate.metrics import evaluate_mesh, format_report, stroke_distance
    if args.pairs is not None:
        return _cmd_eval_pairs(args)
    if args.mesh is None or args.reference is None:
        raise InvalidParameterError("eval: give MESH REFERENCE, or --pairs")
    ref = Path(args.reference)
    if is_mesh_file(ref):
        metrics = evaluate_mesh(args.mesh, args.reference, n_samples=args.samples,
                                threshold=args.threshold, seed=args.seed)
    else:
        from .core.fidelity import sketch_fidelity
        from .io.sketch import read_sketch
        from .io.meshes import read_obj_wires
        sketch = read_sketch(ref)
        metrics = stroke_distance(args.mesh, sketch)
        wires = read_obj_wires(args.mesh) if str(args.mesh).lower().endswith(".obj") else []
        fid = sketch_fidelity(args.mesh, sketch, wires=wires)
        metrics.update({f"fidelity_{k}": fid[k] for k in ("surface", "with_wires", "wire_share",
                                                          "median", "p95")})
    for warning in metrics.get("warnings", []):
        print(f"curvenet eval: warning: {warning}", file=sys.stderr)
    print(json.dumps(metrics, indent=2) if args.json else format_report(metrics))
    return 0


def _naming(err: CurvenetError, path) -> str:
    """The error's message, prefixed with the input file when it does not name it yet."""
    text = str(err)
    return text if str(path) in text else f"{path}: {text}"


def _terminate(signum, frame):
    """SIGTERM unwinds like Ctrl-C, so atomic writes remove their temporary files."""
    raise SystemExit(128 + signum)


def _on_sigterm(handler):
    """Install ``handler`` for SIGTERM; returns the previous one (None off the main thread)."""
    if handler is None:
        return None
    try:
        return signal.signal(signal.SIGTERM, handler)
    except ValueError:  # signal handlers can only be set from the main thread
        return None


COMMANDS = {"snap": _cmd_snap, "patches": _cmd_patches, "review": _cmd_review,
            "surface": _cmd_surface, "eval": _cmd_eval}


def main(argv=None) -> int:
    """Entry point of the ``curvenet`` command; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    previous = _on_sigterm(_terminate)
    try:
        return COMMANDS[args.command](args)
    except CurvenetError as err:
        if args.debug:
            raise
        inputs = getattr(args, "inputs", None) or [getattr(args, "input", None)
                                                   or getattr(args, "mesh", None)]
        named = len(inputs) == 1 and inputs[0] and not isinstance(err, OutputError)
        msg = _naming(err, inputs[0]) if named else str(err)
        print(f"curvenet {args.command}: error: {msg}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"curvenet {args.command}: interrupted", file=sys.stderr)
        return 130
    except Exception as err:  # an internal failure: one line unless --debug
        if args.debug:
            raise
        print(f"curvenet {args.command}: internal error: {type(err).__name__}: {err} "
              f"(run with --debug for the traceback)", file=sys.stderr)
        return 1
    finally:
        _on_sigterm(previous)


if __name__ == "__main__":
    sys.exit(main())
