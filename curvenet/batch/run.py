"""Batch surfacing over many files: one engine, a local or a Dask executor.

:func:`run_batch` plans the outputs (unique names, nothing the user gave overwritten),
skips files already done (``skip_existing``), sends one task per file to an executor and
writes what comes back. The per-file task, :func:`surface_task`, is the same for both
executors; it never raises for a file (every failure becomes a row with a status) and
returns the mesh as bytes, so the *client* writes every output, atomically.

Executors
---------
:class:`LocalExecutor`
    In this process (``jobs=1``) or in a process pool (``jobs > 1``). Tasks carry
    *paths*: the workers share this machine's files.
:class:`DaskExecutor`
    A ``dask.distributed`` cluster (optional extra ``curvenet[cluster]``). Tasks carry
    the input file's *contents* (inside the task), so workers need no shared
    file system; results come back to the client. A worker that dies is handled by Dask
    (its tasks are re-run elsewhere, up to the scheduler's ``allowed-failures``); a task
    that still fails is reported as ``internal`` and the batch goes on.

Manifest and resuming
---------------------
Each finished file appends one JSON line to ``OUT_DIR/curvenet-manifest.jsonl`` (input
and output SHA-256, settings hash, the report row). With ``skip_existing`` a file is
skipped when its last manifest line says ``ok`` for the same input hash and settings and
the output file still has the recorded hash; an interrupted batch so restarts where it
stopped. A torn last line (a run killed while appending) is ignored.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import os
import signal
import sys
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..core.atomic import atomic_path
from ..cad.export import CAD_FORMATS
from ..core.errors import CurvenetError, InvalidParameterError, MissingDependencyError

__all__ = ["BatchOptions", "BatchResult", "LocalExecutor", "DaskExecutor", "run_batch",
           "surface_task", "plan_outputs", "MANIFEST_NAME", "STATUSES"]

#: File in the output folder that records every finished file (JSON lines).
MANIFEST_NAME = "curvenet-manifest.jsonl"

#: Row statuses: ``ok``; ``skipped`` (done before, ``skip_existing``); ``error`` (bad
#: input or impossible request: a CurvenetError); ``internal`` (any other exception, or a
#: worker that died).
STATUSES = ("ok", "skipped", "error", "internal")

#: What the report's measured columns mean (lines of its header).
COLUMN_NOTES = ("fidelity: share of stroke length within 1% of the surface's bbox diagonal; "
                "fidelity_median / fidelity_p95: stroke-to-surface distance / that diagonal",
                "pieces, closed, boundary_loops, genus, nonmanifold_edges: the surface's "
                "topology (genus of its closed pieces; edges in three or more faces, such as "
                "walls inside a solid or fins; curvenet.evaluate.topology)",
                "t_*: seconds per stage on the worker")

#: Tile size (pixels) of the per-file pictures of a contact sheet.
TILE_SIZE = (360, 300)

#: Seconds between two looks of a pool worker at its parent process (the fallback of
#: :func:`_exit_with_parent` where the kernel cannot signal a parent's death).
PARENT_POLL = 0.5

#: ``prctl`` option asking the kernel for a signal when the parent dies (linux/prctl.h).
_PR_SET_PDEATHSIG = 1


@dataclass(frozen=True)
class BatchOptions:
    """Settings of every file's surfacing (the arguments of :func:`curvenet.pipeline.surface`).

    ``format`` is the output format (a mesh, or ``step`` / ``3dm`` B-spline faces);
    ``neural_options`` a tuple of ``(name, value)`` pairs; ``points`` forces the
    point-sample reading (``--points``). Two batches with equal options give equal
    outputs for equal inputs; their hash
    (:meth:`digest`) is recorded in the manifest.
    """

    method: str = "auto"
    snap_tol: float | None = None
    close: str = "auto"
    surfacer: str = "catmull-clark"
    subdiv: int | None = None
    resolution: int | None = None
    crease_angle: float = 30.0
    edge_length: float | None = None
    refine: bool = False
    quality: str = "draft"
    device: str = "cpu"
    seed: int = 0
    neural_options: tuple = ()
    format: str = "obj"
    points: bool = False

    def digest(self) -> str:
        """SHA-256 of the settings (hex)."""
        text = json.dumps(dataclasses.asdict(self), sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()

    @property
    def may_be_neural(self) -> bool:
        """Whether a file's route may be neural (such tasks ask Dask for a ``neural`` unit)."""
        return self.method in ("auto", "neural", "hybrid") or self.refine


@dataclass
class BatchResult:
    """What :func:`run_batch` did: one row per input (input order) and the totals.

    ``rows[i]`` has ``input``, ``output``, ``status`` (one of :data:`STATUSES`) and, when
    surfaced, ``input_sha256``, ``output_sha256``, ``route``, ``decision``, ``patches``,
    ``coverage``, ``faces``, ``fidelity``, ``fidelity_median``, ``fidelity_p95``,
    ``pieces``, ``closed``, ``boundary_loops``, ``genus``, ``nonmanifold_edges`` (the
    surface's topology),
    ``t_<stage>`` seconds and ``t_total``; failed rows carry ``error``.
    """

    rows: list
    seconds: float
    counts: dict = field(default_factory=dict)

    @property
    def exit_code(self) -> int:
        """0: all ok or skipped; 1: some internal failure; 2: some bad input, none internal."""
        if self.counts.get("internal"):
            return 1
        return 2 if self.counts.get("error") else 0

    def summary(self) -> str:
        done = self.counts.get("ok", 0) + self.counts.get("skipped", 0)
        return (f"{done} of {len(self.rows)} surfaced ({self.counts.get('skipped', 0)} "
                f"skipped), {self.counts.get('error', 0)} failed on bad input, "
                f"{self.counts.get('internal', 0)} internal failures, {self.seconds:.1f} s")


# --------------------------------------------------------------------------- the task
def surface_task(path: str, data: bytes | None, options: BatchOptions, *,
                 preview: bool = False, tile: bool = False, up: str = "z",
                 scratch: str | None = None) -> dict:
    """Surface one input file; never raises for the file (only KeyboardInterrupt).

    Parameters
    ----------
    path : str
        The input as the user named it (used in messages and, when ``data`` is None,
        read from).
    data : bytes or None
        The file's contents (tasks sent to another machine), or None to read ``path``.
    options : BatchOptions
    preview, tile : bool
        Also render a full preview PNG / a small one-view tile for a contact sheet.
    up : {"z", "y", "x"}
        Up axis of the pictures.
    scratch : str or None
        Folder in which the task makes its private working folder (default: the
        system's temporary folder).

    Returns
    -------
    dict
        A report row (see :class:`BatchResult`) plus ``mesh_bytes`` (the output file's
        contents) and ``preview_png`` / ``tile_png`` (bytes) when asked for.
    """
    t0 = time.perf_counter()
    row: dict = {"input": path, "worker": _worker_name()}
    with tempfile.TemporaryDirectory(prefix="curvenet-batch-", dir=scratch) as tmp:
        local = path
        if data is not None:  # contents sent to this worker: same name, private folder
            local = os.path.join(tmp, os.path.basename(path))
            Path(local).write_bytes(data)
        try:
            row.update(_surface_file(local, options, tmp, preview=preview, tile=tile, up=up))
            row["status"] = "ok"
        except CurvenetError as err:
            row.update(status="error", error=str(err).replace(local, path))
        except Exception as err:  # any other failure is this file's, the batch goes on
            row.update(status="internal",
                       error=f"{type(err).__name__}: {err}".replace(local, path))
    row["t_total"] = time.perf_counter() - t0
    return row


def _surface_file(local: str, options: BatchOptions, tmp: str, *, preview, tile, up) -> dict:
    from ..core.fidelity import stroke_fidelity
    from ..pipeline import surface
    res = surface(local, method=options.method, snap_tol=options.snap_tol,
                  close=options.close, surfacer=options.surfacer, subdiv=options.subdiv,
                  resolution=options.resolution, crease_angle=options.crease_angle,
                  refine=options.refine, quality=options.quality, device=options.device,
                  seed=options.seed, progress=False,
                  classical_options=(None if options.edge_length is None
                                     else {"edge_length": options.edge_length}),
                  neural_options=dict(options.neural_options) or None,
                  points=True if options.points else "auto")
    out: dict = {f"t_{k}": float(v) for k, v in res.timings.items()}
    t = time.perf_counter()
    fid = stroke_fidelity(res.mesh, res.sketch if res.sketch is not None else res.network)
    out["t_fidelity"] = time.perf_counter() - t
    if "." + options.format in CAD_FORMATS:
        data = _cad_bytes(res, Path(tmp, f"out.{options.format}"), out)
    else:   # OBJ keeps the route groups and the wires (``SurfaceResult.save``)
        data = res.save(Path(tmp, f"out.{options.format}")).read_bytes()
    cov = res.diagnostics.get("coverage")
    out.update(route=res.method, decision=res.diagnostics.get("decision", ""),
               patches=res.diagnostics.get("patches"),
               coverage=None if cov is None else float(cov), faces=len(res.mesh.faces),
               fidelity=fid["fidelity"], fidelity_median=fid["median"],
               fidelity_p95=fid["p95"],
               **{k: res.diagnostics["topology"][k]
                  for k in ("pieces", "closed", "boundary_loops", "genus",
                            "nonmanifold_edges")},
               mesh_bytes=data.encode() if isinstance(data, str) else bytes(data))
    name = Path(local).name
    strokes = res.sketch if res.sketch is not None else None
    routed = dict(face_route=res.face_route, routes=res.routes, wires=res.wires)
    t = time.perf_counter()
    if preview:
        from ..view.preview import render_preview
        png = Path(tmp, "preview.png")
        render_preview(png, strokes=strokes, network=res.network, mesh=res.mesh,
                       title=f"{name}: {res.method}", up=up, **routed)
        out["preview_png"] = png.read_bytes()
    if tile:
        from ..view.preview import render_preview
        png = Path(tmp, "tile.png")
        render_preview(png, mesh=res.mesh, network=res.network, view=(20.0, -60.0),
                       size=TILE_SIZE, up=up, **routed)
        out["tile_png"] = png.read_bytes()
    if preview or tile:
        out["t_preview"] = time.perf_counter() - t
    return out


def _cad_bytes(res, path: Path, out: dict) -> bytes:
    """Write the B-spline CAD file (STEP AP214 / 3DM) and add its figures to the row."""
    res.save(path)
    cad = res.diagnostics["cad"]
    smooth = [s["angle"] for s in cad["seams"] if not s["crease"]]
    out.update(cad_faces=len(cad["faces"]), cad_exact=cad["pieces"]["n_exact"],
               cad_deviation=cad["pieces"]["max_deviation"],
               cad_gap=max((s["gap"] for s in cad["seams"]), default=0.0),
               cad_g1=max(smooth, default=0.0))
    return path.read_bytes()


def _worker_name() -> str:
    """The Dask worker's address inside a Dask worker, else ``pid N``."""
    distributed = sys.modules.get("distributed")  # not imported in local processes
    if distributed is not None:
        with contextlib.suppress(ValueError):
            return distributed.get_worker().address
    return f"pid {os.getpid()}"


# --------------------------------------------------------------------------- executors
def _set_death_signal() -> bool:
    """Ask the Linux kernel to SIGKILL this process when its parent dies; False elsewhere."""
    if not sys.platform.startswith("linux"):
        return False
    import ctypes
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch_parent(parent: int) -> None:
    """Exit this process at once when ``parent`` is no longer its parent (it died)."""
    while True:
        if os.getppid() != parent:
            os._exit(1)
        time.sleep(PARENT_POLL)


def _exit_with_parent(parent: int) -> None:
    """Pool initializer: the worker ends when the batch process ``parent`` dies.

    A pool worker whose parent is killed (SIGKILL, the out-of-memory killer) would
    otherwise sleep on for ever, holding its memory. The kernel's parent-death signal
    (``prctl(PR_SET_PDEATHSIG, SIGKILL)``, Linux) ends it at once; a daemon thread that
    looks at ``os.getppid()`` every :data:`PARENT_POLL` seconds covers other systems and
    a parent that died before the signal was set up.
    """
    _set_death_signal()
    if os.getppid() != parent:
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent,), name="curvenet-parent-watch",
                     daemon=True).start()


def _pool(workers: int):
    """A process pool whose workers exit when this process dies (:func:`_exit_with_parent`)."""
    from concurrent.futures import ProcessPoolExecutor
    return ProcessPoolExecutor(max_workers=workers, initializer=_exit_with_parent,
                               initargs=(os.getpid(),))


class LocalExecutor:
    """Run tasks in this process (``jobs=1``) or a pool of ``jobs`` processes.

    Tasks carry paths. When a pool process dies (a crash in native code, the kernel's
    out-of-memory killer), the whole pool breaks; the unfinished tasks then run one per
    fresh process (``jobs`` at a time), so a crash costs only its own file, which is
    reported as ``internal``. Workers exit when this process dies. The pool's tasks
    make their working folders in one that this process removes when the batch ends,
    so a worker that dies leaves none behind.
    """

    def __init__(self, jobs: int = 1):
        if not isinstance(jobs, int) or jobs < 1:
            raise InvalidParameterError(f"jobs must be a positive integer, got {jobs!r}")
        self.jobs = jobs
        self.carries = "paths"

    def run(self, tasks, options, render):
        """Yield ``(index, row)`` as tasks finish; ``tasks`` is a list of input paths."""
        if self.jobs == 1:
            for i, path in enumerate(tasks):
                yield i, surface_task(path, None, options, **render)
            return
        from concurrent.futures import ThreadPoolExecutor, as_completed
        from concurrent.futures.process import BrokenProcessPool
        broken = []
        with tempfile.TemporaryDirectory(prefix="curvenet-batch-") as scratch:
            render = dict(render, scratch=scratch)
            with _pool(self.jobs) as pool:
                futures = {pool.submit(surface_task, path, None, options, **render): i
                           for i, path in enumerate(tasks)}
                for fut in as_completed(futures):
                    try:
                        yield futures[fut], fut.result()
                    except BrokenProcessPool:
                        broken.append(futures[fut])
            with ThreadPoolExecutor(self.jobs) as threads:
                futures = {threads.submit(_isolated, tasks[i], options, render): i
                           for i in sorted(broken)}
                for fut in as_completed(futures):
                    yield futures[fut], fut.result()


def _isolated(path: str, options: BatchOptions, render: dict) -> dict:
    """Run one task in a process of its own; its death is this file's failure alone."""
    from concurrent.futures.process import BrokenProcessPool
    with _pool(1) as pool:
        try:
            return pool.submit(surface_task, path, None, options, **render).result()
        except BrokenProcessPool:
            return _lost_row(path, "its worker process died")


class DaskExecutor:
    """Send tasks to a ``dask.distributed`` scheduler; tasks carry the files' contents.

    Parameters
    ----------
    address : str or distributed.Client
        Scheduler address (``tcp://host:8786``) or a connected client.

    Notes
    -----
    When some worker declares a ``neural`` resource (``dask worker ... --resources
    neural=1``), tasks whose route may be neural (method ``auto`` or ``neural``, or
    ``refine``) ask for one unit of it, so they run only there and one at a time per
    unit; without such a worker no resource is asked for (a task asking for a resource
    no worker has would wait forever).
    """

    def __init__(self, address):
        try:
            import distributed  # noqa: F401
        except ImportError:
            raise MissingDependencyError(
                "--scheduler needs dask.distributed: pip install 'curvenet[cluster]'") from None
        self.address = address
        self.carries = "contents"

    def run(self, tasks, options, render):
        """Yield ``(index, row)`` as tasks finish; ``tasks`` is a list of input paths."""
        from distributed import Client, as_completed
        own = not hasattr(self.address, "submit")
        try:
            client = Client(self.address, timeout="30s") if own else self.address
        except OSError as err:
            raise InvalidParameterError(
                f"--scheduler {self.address}: cannot connect ({err})") from None
        try:
            resources = None
            if options.may_be_neural and any(
                    "neural" in w.get("resources", {})
                    for w in client.scheduler_info()["workers"].values()):
                resources = {"neural": 1}
            futures = {}
            for i, path in enumerate(tasks):
                # the contents travel inside the task (not scattered): the scheduler keeps
                # them, so a task whose worker dies can be re-run elsewhere
                data = _read_or_none(path)
                fut = client.submit(surface_task, path, data, options, **render,
                                    pure=False, resources=resources)
                futures[fut] = i
            # the client's own loop: as_completed would otherwise take the process's
            # default client, which need not be this one (a notebook's, a test's), and a
            # result re-run after a lost worker would wait on an event of another loop
            for fut in as_completed(futures, loop=client.loop):
                try:
                    row = fut.result()
                except Exception as err:  # KilledWorker, a lost connection ...
                    row = _lost_row(tasks[futures[fut]], f"{type(err).__name__}: {err}")
                yield futures[fut], row
        finally:
            if own:
                client.close()


def _read_or_none(path: str) -> bytes | None:
    """The file's bytes, or None when it cannot be read here (the task then says why)."""
    try:
        return Path(path).read_bytes()
    except OSError:
        return None


def _lost_row(path: str, why: str) -> dict:
    return {"input": path, "status": "internal", "error": f"task lost: {why}"}


# --------------------------------------------------------------------------- the engine
def plan_outputs(inputs, out_dir, fmt: str) -> list:
    """Output path ``OUT_DIR/STEM.FMT`` of each input; refuses clashes before any work.

    Raises
    ------
    InvalidParameterError
        Two inputs with the same stem (one output would overwrite the other), an input
        given twice, an output that would overwrite an input, or ``out_dir`` a file.
    """
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise InvalidParameterError(f"--out-dir {out_dir}: is a file, not a folder")
    outputs, seen = [], {}
    given = {os.path.realpath(p) for p in inputs}
    for inp in inputs:
        out = out_dir / f"{Path(inp).stem}.{fmt}"
        key = os.path.normcase(str(out))
        if key in seen:
            raise InvalidParameterError(
                f"inputs {seen[key]} and {inp} would both write {out}; rename one or "
                f"surface them in separate batches")
        if os.path.realpath(out) in given:
            raise InvalidParameterError(f"output {out} would overwrite the input {out}")
        seen[key] = inp
        outputs.append(str(out))
    return outputs


def _sha256(path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def read_manifest(out_dir) -> dict:
    """Last manifest entry per output path (a torn or garbled line is ignored)."""
    entries = {}
    path = Path(out_dir) / MANIFEST_NAME
    if path.is_file():
        for line in path.read_text(encoding="utf-8", errors="replace").splitlines():
            with contextlib.suppress(ValueError, KeyError, TypeError):
                entry = json.loads(line)
                entries[entry["output"]] = entry
    return entries


def _done_before(entry, in_hash, digest, out) -> bool:
    return (entry is not None and entry.get("status") == "ok"
            and entry.get("input_sha256") == in_hash and entry.get("options_sha256") == digest
            and Path(out).is_file() and _sha256(out) == entry.get("output_sha256"))


def run_batch(inputs, out_dir, options: BatchOptions | None = None, *, executor=None,
              skip_existing: bool = False, preview: bool = False, preview_dir=None,
              up: str = "z", on_row=None) -> BatchResult:
    """Surface many files into ``out_dir``; every failure is a row, the batch goes on.

    Parameters
    ----------
    inputs : list of str or os.PathLike
        Sketch, ``NETWORK.json`` or ``PATCHES.json`` files.
    out_dir : str or os.PathLike
        Output folder (created); outputs are ``STEM.<options.format>``.
    options : BatchOptions, optional
    executor : LocalExecutor or DaskExecutor, optional
        Default ``LocalExecutor(1)``.
    skip_existing : bool
        Skip files the manifest records as done with the same input and settings and
        whose output is intact (see the module notes).
    preview : bool
        Also write ``STEM.png`` (the full preview) beside each output.
    preview_dir : str or os.PathLike, optional
        Write a small picture per file there and ``contact_sheet.png`` of the whole batch.
    up : {"z", "y", "x"}
        Up axis of the pictures.
    on_row : callable, optional
        Called as ``on_row(row, n_done, n_total)`` when each file is finished or skipped.

    Returns
    -------
    BatchResult
    """
    options = options or BatchOptions()
    executor = executor or LocalExecutor(1)
    inputs = [str(p) for p in inputs]
    if not inputs:
        raise InvalidParameterError("batch: no inputs")
    outputs = plan_outputs(inputs, out_dir, options.format)
    if preview_dir is not None and Path(preview_dir).exists() and not Path(preview_dir).is_dir():
        raise InvalidParameterError(f"--preview-dir {preview_dir}: is a file, not a folder")
    t0 = time.perf_counter()
    Path(out_dir).mkdir(parents=True, exist_ok=True)
    tiles_dir = None if preview_dir is None else Path(preview_dir)
    if tiles_dir is not None:
        tiles_dir.mkdir(parents=True, exist_ok=True)
    digest = options.digest()
    hashes = []
    for p in inputs:
        try:
            hashes.append(_sha256(p))
        except OSError:
            hashes.append(None)  # the task reports why it cannot be read
    manifest = read_manifest(out_dir) if skip_existing else {}
    rows: list = [None] * len(inputs)
    todo = []
    for i, out in enumerate(outputs):
        entry = manifest.get(out)
        if hashes[i] is not None and _done_before(entry, hashes[i], digest, out):
            rows[i] = {**entry["row"], "status": "skipped"}
            if on_row:
                on_row(rows[i], sum(r is not None for r in rows), len(inputs))
        else:
            todo.append(i)
    render = {"preview": preview, "tile": tiles_dir is not None, "up": up}
    try:
        for k, row in executor.run([inputs[i] for i in todo], options, render):
            i = todo[k]
            rows[i] = _finish_row(row, outputs[i], hashes[i], digest, out_dir, tiles_dir,
                                  preview)
            if on_row:
                on_row(rows[i], sum(r is not None for r in rows), len(inputs))
    finally:
        if tiles_dir is not None and any(r is not None for r in rows):
            from ..view.contact_sheet import contact_sheet
            contact_sheet(tiles_dir / "contact_sheet.png", [r for r in rows if r is not None],
                          tiles_dir)
    counts = {s: sum(r["status"] == s for r in rows) for s in STATUSES}
    return BatchResult(rows, time.perf_counter() - t0, counts)


def _finish_row(row, out, in_hash, digest, out_dir, tiles_dir, preview) -> dict:
    """Write what a task returned (client side, atomically); append the manifest line."""
    row = dict(row)
    mesh_bytes = row.pop("mesh_bytes", None)
    preview_png = row.pop("preview_png", None)
    tile_png = row.pop("tile_png", None)
    row.update(output=out, input_sha256=in_hash)
    if row["status"] == "ok":
        try:
            with atomic_path(out) as tmp:
                tmp.write_bytes(mesh_bytes)
            if preview and preview_png is not None:
                with atomic_path(Path(out).with_suffix(".png")) as tmp:
                    tmp.write_bytes(preview_png)
        except OSError as err:
            row.update(status="error", error=f"{out}: cannot write: {err.strerror or err}")
        else:
            row["output_sha256"] = hashlib.sha256(mesh_bytes).hexdigest()
    if tiles_dir is not None and tile_png is not None:
        with atomic_path(tiles_dir / f"{Path(out).stem}.png") as tmp:
            tmp.write_bytes(tile_png)
    entry = {"output": out, "input_sha256": in_hash, "options_sha256": digest,
             "output_sha256": row.get("output_sha256"), "status": row["status"], "row": row}
    with open(Path(out_dir) / MANIFEST_NAME, "a", encoding="utf-8") as fh:
        fh.write(json.dumps(entry, default=str) + "\n")
    return row
