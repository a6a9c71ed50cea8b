"""One pipeline from a sketch file to a surface: snap, find patches, surface.

``surface(...)`` decides by itself (``method="auto"``) whether the classical
patch route (Coons -> Catmull-Clark limit fit, :mod:`surfacing`) or the neural
route (flow-aligned implicit, :mod:`neural`) serves the sketch better, and says
why in ``SurfaceResult.diagnostics["decision"]``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ._atomic import atomic_path
from .errors import CurvenetError, InvalidParameterError, SketchFormatError
from .network import CurveNetwork
from .patchset import PatchSet, load_network_file
from .sketch import Sketch

__all__ = ["SurfaceResult", "surface", "patches", "load_source", "MESH_FORMATS",
           "AUTO_MIN_COVERAGE", "write_mesh"]

MESH_FORMATS = (".obj", ".ply", ".stl", ".off", ".glb")
METHODS = ("auto", "classical", "neural")
QUALITIES = ("draft", "default", "paper")

#: auto mode takes the classical route when at least this fraction of the
#: network's curve length lies on curves used by some patch.
AUTO_MIN_COVERAGE = 0.8


@dataclass
class SurfaceResult:
    """What :func:`surface` produced.

    Attributes
    ----------
    mesh : trimesh.Trimesh
        The surface, in the sketch's coordinates.
    method : str
        ``"classical"``, ``"soapfilm"`` or ``"neural"``; with ``refine``, the
        classical name plus ``"+refine"`` (e.g. ``"classical+refine"``).
    sketch : Sketch or None
    network : CurveNetwork or None
    patchset : PatchSet or None
    timings : dict
        Seconds per stage (``snap``, ``patches``, ``classical``, ``neural`` ...).
    diagnostics : dict
        ``decision`` (why this route), ``coverage``, ``unused_edges`` (curves no
        patch uses: dangling details, reported not lost), backend reports.
    """

    mesh: object
    method: str
    sketch: Sketch | None = None
    network: CurveNetwork | None = None
    patchset: PatchSet | None = None
    timings: dict = field(default_factory=dict)
    diagnostics: dict = field(default_factory=dict)

    @property
    def interrupted(self) -> bool:
        """True when a fit was stopped with Ctrl-C: the mesh is the best surface so far."""
        neural = self.diagnostics.get("neural", {})
        return bool(neural.get("interrupted")
                    or neural.get("creases", {}).get("interrupted"))

    def save(self, path) -> Path:
        """Write the mesh atomically; the format follows the extension."""
        return write_mesh(path, self.mesh)


def write_mesh(path, mesh) -> Path:
    """Write a ``trimesh.Trimesh`` to ``path`` (OBJ / PLY / STL / OFF / GLB) atomically."""
    path = Path(path)
    if path.suffix.lower() not in MESH_FORMATS:
        raise InvalidParameterError(
            f"output {path}: unknown mesh format {path.suffix!r}; use one of {MESH_FORMATS}")
    with atomic_path(path) as tmp:
        mesh.export(tmp, file_type=path.suffix.lower()[1:])
    return path


def _is_network_json(path: Path) -> bool:
    if path.suffix.lower() != ".json":
        return False
    with open(path, "rb") as fh:
        head = fh.read(4096)
    return b'"curvenet.network"' in head or b'"curvenet.patches"' in head


def load_source(source, *, points="auto"):
    """Turn what the user gave into ``(sketch, patchset)``; one of them may be None.

    Parameters
    ----------
    source : Sketch, CurveNetwork, PatchSet, str or os.PathLike
        A sketch, or a file: any sketch format, ``NETWORK.json`` or ``PATCHES.json``.
    points : {"auto", True, False}
        Reading of unordered point samples in a sketch file (see
        :func:`curvenet.io.read_sketch`); ``True`` also recovers the curves of
        every stroke of a :class:`Sketch` given directly.
    """
    if isinstance(source, Sketch):
        if points is True:
            from .pointcurves import read_point_blocks
            return read_point_blocks(source, True), None
        return source, None
    if isinstance(source, PatchSet):
        return None, source
    if isinstance(source, CurveNetwork):
        return None, PatchSet(source)
    path = Path(source)
    if not path.is_file():
        raise SketchFormatError("no such file", path=path)
    if _is_network_json(path):
        return None, load_network_file(path)
    from .io import read_sketch
    return read_sketch(path, points=points), None


def _network(sketch, patchset, *, snap_tol, timings):
    if patchset is not None:
        return patchset.network
    from .snap import snap
    t = time.perf_counter()
    kwargs = {} if snap_tol is None else {"snap_tol": snap_tol}
    net = snap(sketch, **kwargs)
    timings["snap"] = time.perf_counter() - t
    if "reading" in sketch.metadata:
        net.report["reading"] = sketch.metadata["reading"]
    return net


def patches(source, *, snap_tol: float | None = None, close: str = "auto", points="auto",
            **options) -> PatchSet:
    """Snap (when given a sketch) and find patches.

    Parameters
    ----------
    source : Sketch, CurveNetwork, str or os.PathLike
        A sketch or a ``NETWORK.json`` / ``PATCHES.json`` file (its patches are
        recomputed).
    snap_tol : float, optional
        Snapping tolerance as a fraction of the bounding-box diagonal.
    close : {"auto", "none"}
        Accept closing patches automatically (see :func:`curvenet.cycles.find_patches`).
    points : {"auto", True, False}
        Reading of unordered point samples (see :func:`load_source`).
    **options
        Passed to :func:`curvenet.cycles.find_patches`.

    Returns
    -------
    PatchSet
        ``report["timings"]`` has the snapping and patch-finding seconds.

    Examples
    --------
    >>> from curvenet import shapes
    >>> ps = patches(shapes.box().sketch())
    >>> len(ps.patches)
    6
    """
    from .cycles import find_patches
    sketch, given = load_source(source, points=points)
    timings: dict = {}
    net = _network(sketch, given, snap_tol=snap_tol, timings=timings)
    t = time.perf_counter()
    ps = find_patches(net, close=close, **options)
    timings["patches"] = time.perf_counter() - t
    ps.report.setdefault("timings", {}).update(timings)
    return ps


#: A patch set matches a sketch when nearly all stroke points and curve points lie within
#: this fraction of the sketch's diagonal of the other (snapping moves points far less)...
PATCHES_MATCH_TOL = 0.1
#: ...all but this share of them (trimmed overshoots and dropped strokes lie farther).
PATCHES_MATCH_OUTLIERS = 0.1


def _check_patches_match(sketch: Sketch, ps: PatchSet) -> None:
    """Refuse a patch set whose network was not made from ``sketch``."""
    from scipy.spatial import cKDTree
    net = ps.network
    strokes = np.concatenate(sketch.select(("boundary", "crease")).strokes or sketch.strokes)
    curves = (np.concatenate([e.curve for e in net.edges]) if net.edges
              else np.asarray(net.vertices, np.float64).reshape(-1, 3))
    diag = float(np.linalg.norm(strokes.max(axis=0) - strokes.min(axis=0)))
    if len(curves) == 0 or not diag > 0:
        return
    far = max(float(np.mean(cKDTree(curves).query(strokes)[0] > PATCHES_MATCH_TOL * diag)),
              float(np.mean(cKDTree(strokes).query(curves)[0] > PATCHES_MATCH_TOL * diag)))
    if far > PATCHES_MATCH_OUTLIERS:
        raise InvalidParameterError(
            f"the patch set's network does not match the sketch {sketch.source or ''}: "
            f"{far:.0%} of the points lie farther than {PATCHES_MATCH_TOL:.0%} of the diagonal "
            "from the other (were the patches made from another sketch?)")


def _coverage(ps: PatchSet) -> tuple[float, list]:
    """Fraction of curve length on edges used by a patch, and the unused edge ids."""
    net = ps.network
    if not net.edges:
        return 0.0, []
    lengths = np.array([e.length() for e in net.edges])
    used = np.zeros(len(lengths), bool)
    for p in ps.patches:
        used[list(p.edges)] = True
    total = lengths.sum()
    cov = float(lengths[used].sum() / total) if total > 0 else 0.0
    return cov, [int(i) for i in np.flatnonzero(~used)]


def _mesh(vertices, faces):
    import trimesh
    return trimesh.Trimesh(np.asarray(vertices, np.float64), np.asarray(faces, np.int64),
                           process=False)


def _classical(ps: PatchSet, *, surfacer, subdiv, resolution, crease_angle, options):
    from curvenet import surfacing

    from .cycles import orient_patches
    net = ps.network
    loops = orient_patches(net, ps.patches)
    curves = [e.curve for e in net.edges]
    creases = [i for i, e in enumerate(net.edges) if e.label == "crease"]
    kw = dict(options)
    if surfacer == "soapfilm":
        res = surfacing.soapfilm_loops(curves, loops, **kw)
    else:
        if subdiv is not None:
            kw["subdiv"] = subdiv
        if resolution is not None:
            kw["resolution"] = resolution
        res = surfacing.surface_loops(curves, loops, crease_curves=creases,
                                      crease_angle=crease_angle, **kw)
    return _mesh(res.vertices, res.faces), dict(res.report)


def _strokes_for_neural(sketch: Sketch | None, net: CurveNetwork | None):
    if sketch is not None:
        sub = sketch.select(("boundary", "crease"))
        return sub.strokes, sub.labels
    return [e.curve for e in net.edges], [e.label for e in net.edges]


def _neural(strokes, labels, *, quality, device, seed, progress, init_mesh, options,
            crease_options):
    from curvenet.neural.flow import fit_flow_surface
    res = fit_flow_surface(strokes, labels=labels, quality=quality, device=device, seed=seed,
                           init_mesh=init_mesh, progress=progress, **options)
    verts, faces, report = res.vertices, res.faces, dict(res.report)
    if "crease" in labels and not report.get("interrupted"):
        from curvenet.neural.creases import crease_refine
        cres = crease_refine(verts, faces, strokes, labels, quality=quality, device=device,
                             seed=seed, progress=progress, **crease_options)
        verts, faces = cres.vertices, cres.faces
        report["creases"] = dict(cres.report)
    return _mesh(verts, faces), report


def surface(source, *, method: str = "auto", patchset: PatchSet | None = None,
            snap_tol: float | None = None, close: str = "auto", surfacer: str = "catmull-clark",
            subdiv: int | None = None, resolution: int | None = None,
            crease_angle: float = 30.0, refine: bool = False, quality: str = "draft",
            device: str = "cpu", seed: int = 0, progress: bool = False,
            classical_options: dict | None = None,
            neural_options: dict | None = None,
            crease_options: dict | None = None, points="auto") -> SurfaceResult:
    """Sketch (or network, or patch set) to surface.

    Parameters
    ----------
    source : Sketch, CurveNetwork, PatchSet, str or os.PathLike
        The input: a sketch, a sketch file in any supported format, or a
        ``NETWORK.json`` / ``PATCHES.json`` file.
    method : {"auto", "classical", "neural"}
        ``auto`` snaps, finds patches and takes the classical route when the
        patches cover at least :data:`AUTO_MIN_COVERAGE` of the curve length,
        else the neural route.
    patchset : PatchSet, optional
        Use these patches (e.g. an edited ``PATCHES.json``) instead of finding them.
    snap_tol : float, optional
        Snapping tolerance (fraction of the bounding-box diagonal).
    close : {"auto", "none"}
        Closing-patch policy of the patch finder.
    surfacer : {"catmull-clark", "soapfilm"}
        Classical surfacer: Orbay-Kara limit fitting or the soap-film baseline.
    subdiv, resolution : int, optional
        Classical settings (Catmull-Clark levels, samples per side); backend defaults.
    crease_angle : float
        Dihedral angle (degrees) above which a curve becomes a crease.
    refine : bool
        Continue the classical result with the neural flow-alignment fit.
    quality : {"draft", "default", "paper"}
        Neural preset.
    device : str
        ``"cpu"`` or ``"cuda"`` for the neural route.
    seed : int
        Seed of every random choice.
    progress : bool
        Show progress bars.
    classical_options, neural_options : dict, optional
        Extra keyword arguments for :func:`surfacing.surface_loops` /
        :func:`neural.flow.fit_flow_surface`.
    crease_options : dict, optional
        Settings of the crease refit (:class:`neural.creases.CreaseConfig`, e.g.
        ``{"use_features": False}``), used when the neural route meets strokes labelled
        ``crease``; checked before any fit.
    points : {"auto", True, False}
        Reading of unordered point samples (see :func:`load_source`); the
        reading taken is in ``diagnostics["reading"]``.

    Returns
    -------
    SurfaceResult

    Examples
    --------
    >>> from curvenet import shapes
    >>> res = surface(shapes.box().sketch(), method="classical")
    >>> res.method, res.mesh.is_watertight
    ('classical', True)
    """
    if method not in METHODS:
        raise InvalidParameterError(f"method: {method!r} is not one of {METHODS}")
    if quality not in QUALITIES:
        raise InvalidParameterError(f"quality: {quality!r} is not one of {QUALITIES}")
    if surfacer not in ("catmull-clark", "soapfilm"):
        raise InvalidParameterError(f"surfacer: {surfacer!r} is not catmull-clark or soapfilm")
    if not (0.0 < crease_angle < 180.0):
        raise InvalidParameterError(f"crease_angle: {crease_angle!r} is not in (0, 180)")
    if device not in ("cpu", "cuda") and not str(device).startswith("cuda:"):
        raise InvalidParameterError(f"device: {device!r} is not cpu or cuda")
    if neural_options:
        from curvenet.neural.presets import get_config
        try:
            get_config(quality, **neural_options)
        except ValueError as err:
            raise InvalidParameterError(f"neural_options: {err}") from err
    if crease_options:
        from curvenet.neural.creases import crease_config
        try:
            crease_config(quality, crease_options)
        except ValueError as err:
            raise InvalidParameterError(f"crease_options: {err}") from err
    timings: dict = {}
    diag: dict = {}
    sketch, given = load_source(source, points=points)
    if sketch is not None:
        diag["reading"] = sketch.metadata.get("reading", "polylines: no stroke is a block of "
                                              "unordered points" if points is not False else
                                              "polylines: point reading off")
    if patchset is not None:
        given = patchset
        if sketch is not None:
            _check_patches_match(sketch, patchset)
    if sketch is not None and len(sketch.select(("boundary", "crease"))) == 0:
        raise InvalidParameterError(f"{sketch.source or 'sketch'}: no boundary or crease strokes")

    ps = None
    net = given.network if given is not None else None
    if method in ("auto", "classical"):
        from .cycles import find_patches
        net = _network(sketch, given, snap_tol=snap_tol, timings=timings)
        diag["snap"] = dict(net.report)
        if given is not None and given.patches:
            ps = given
        else:
            t = time.perf_counter()
            ps = find_patches(net, close=close)
            timings["patches"] = time.perf_counter() - t
        cov, unused = _coverage(ps)
        diag.update(coverage=cov, unused_edges=unused, patches=len(ps.patches))
        if method == "auto":
            if not ps.patches:
                reason = "neural: the strokes form no cycles that can be patches"
            elif cov < AUTO_MIN_COVERAGE:
                reason = (f"neural: patches cover only {cov:.0%} of the curve length "
                          f"(< {AUTO_MIN_COVERAGE:.0%})")
            else:
                reason = (f"classical: {len(ps.patches)} patches cover {cov:.0%} of the curve "
                          f"length (>= {AUTO_MIN_COVERAGE:.0%})")
            diag["decision"] = reason
            method = reason.split(":")[0]
        else:
            diag["decision"] = "classical: requested"
        if method == "classical" and not ps.patches:
            raise CurvenetError("no patches found: the curves form no cycles; "
                                "try --method neural")
    else:
        diag["decision"] = "neural: requested"

    mesh = None
    name = method
    try:
        if method == "classical":
            t = time.perf_counter()
            mesh, rep = _classical(ps, surfacer=surfacer, subdiv=subdiv, resolution=resolution,
                                   crease_angle=crease_angle, options=classical_options or {})
            timings["classical"] = time.perf_counter() - t
            diag["classical"] = rep
            name = "soapfilm" if surfacer == "soapfilm" else "classical"
        if method == "neural" or refine:
            strokes, labels = _strokes_for_neural(sketch, net)
            init = (np.asarray(mesh.vertices), np.asarray(mesh.faces)) if mesh is not None else None
            t = time.perf_counter()
            mesh, rep = _neural(strokes, labels, quality=quality, device=device, seed=seed,
                                progress=progress, init_mesh=init, options=neural_options or {},
                                crease_options=crease_options or {})
            timings["neural"] = time.perf_counter() - t
            diag["neural"] = rep
            name = name + "+refine" if init is not None else "neural"
    except ValueError as err:
        raise InvalidParameterError(str(err)) from err
    if mesh is None or len(mesh.faces) == 0:
        raise CurvenetError(f"the {name} route produced an empty surface")
    return SurfaceResult(mesh, name, sketch, net, ps, timings, diag)
