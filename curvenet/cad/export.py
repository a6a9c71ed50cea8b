"""CAD output of the classical surface: a B-rep in STEP (OpenCascade) and 3DM (rhino3dm).

The shape comes from :func:`curvenet.cad.brep.brep_shape`: elementary faces (planes,
cylinders, cones, spheres, tori) trimmed by the network's curves, B-spline faces
elsewhere (:func:`curvenet.surfacing.bspline.extract_bsplines`: one clamped bicubic
B-spline per quad-grid piece of the control mesh), sewn so faces meeting along a
curve share that edge, one shell per manifold piece, each closed shell a solid
oriented outward. This module writes it:

* STEP (AP214 or AP242) through OpenCascade's writer, the largest tolerance as the
  file's uncertainty;
* 3DM: the same shape as one Brep per shell, joined (:mod:`curvenet.cad.rhino`).

Both need the optional extra ``curvenet[cad]`` (``cadquery-ocp``, ``rhino3dm``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.atomic import atomic_path
from ..core.errors import InvalidParameterError
from .brep import CAD_KINDS, CadModel, brep_shape
from .occ import quiet_occ, require_cad, shape_report
from .rhino import write_3dm

__all__ = ["CAD_FORMATS", "STEP_SCHEMAS", "write_cad", "write_step", "read_step", "require_cad",
           "shape_report"]

CAD_FORMATS = (".step", ".stp", ".3dm")
#: STEP application protocols and the names OpenCascade's writer knows them by.
STEP_SCHEMAS = {"AP214": "AP214IS", "AP242": "AP242DIS"}


def write_step(path, shape, *, schema: str = "AP214", wires=()) -> dict:
    """Write a B-rep shape (and polylines beside it) as STEP.

    Parameters
    ----------
    path : str or os.PathLike
    shape : TopoDS_Shape
    schema : {"AP214", "AP242"}
    wires : list of (m, 3) float64
        Polylines written as edges beside the faces.

    Returns
    -------
    dict
        :func:`curvenet.cad.occ.shape_report` of the written shape, ``schema``,
        ``wires``.
    """
    require_cad(".step")
    quiet_occ()
    if schema not in STEP_SCHEMAS:
        raise InvalidParameterError(f"schema: {schema!r} is not one of {tuple(STEP_SCHEMAS)}")
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Controller, STEPControl_Writer

    rep = shape_report(shape)
    shape = _with_wires(shape, wires)
    STEPControl_Controller.Init_s()              # registers the parameter the schema sets
    Interface_Static.SetCVal_s("write.step.schema", STEP_SCHEMAS[schema])
    Interface_Static.SetIVal_s("write.precision.mode", 1)   # uncertainty: largest tolerance
    writer = STEPControl_Writer()
    writer.Transfer(shape, STEPControl_AsIs)
    path = Path(path)
    with atomic_path(path) as tmp:
        if writer.Write(str(tmp)) != IFSelect_RetDone:
            raise OSError(f"{path}: the STEP writer failed")
    rep.update(schema=schema, wires=len(wires))
    return rep


def _with_wires(shape, wires):
    """``shape`` and one polyline wire per ``(m, 3)`` array, in a compound."""
    if not len(wires):
        return shape
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakePolygon
    from OCP.gp import gp_Pnt
    from OCP.TopoDS import TopoDS_Compound
    comp, bld = TopoDS_Compound(), BRep_Builder()
    bld.MakeCompound(comp)
    bld.Add(comp, shape)
    for w in wires:
        poly = BRepBuilderAPI_MakePolygon()
        for x, y, z in np.asarray(w, np.float64).tolist():
            poly.Add(gp_Pnt(x, y, z))
        bld.Add(comp, poly.Wire())
    return comp


def read_step(path):
    """Read a STEP file back into one ``TopoDS_Shape``."""
    require_cad(".step")
    quiet_occ()
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader
    rd = STEPControl_Reader()
    if rd.ReadFile(str(path)) != IFSelect_RetDone:
        raise OSError(f"{path}: not readable as STEP")
    rd.TransferRoots()
    return rd.OneShape()


def write_cad(path, model: CadModel, *, schema: str = "AP214", wires=()) -> dict:
    """Build the B-rep of ``model`` and write it as STEP or 3DM by the extension.

    Parameters
    ----------
    path : str or os.PathLike
        ``.step`` / ``.stp`` or ``.3dm``.
    model : CadModel
    schema : {"AP214", "AP242"}
        STEP only.
    wires : list of (m, 3) float64
        Curves that bound no surface, written beside the faces as polyline edges
        (STEP) or polyline curves (3DM).

    Returns
    -------
    dict
        :func:`curvenet.cad.brep.brep_shape`'s report with the writer's
        (``faces``, ``shells``, ``solids``, ``free_edges``, ``valid`` of the written
        shape) under ``file``.

    Raises
    ------
    CadInputError
        A face with no valid B-rep (its loop crosses itself), named by its patch.
    """
    suffix = Path(path).suffix.lower()
    if suffix not in CAD_FORMATS:
        raise InvalidParameterError(f"output {path}: {suffix!r} is not one of {CAD_FORMATS}")
    require_cad(suffix)
    quiet_occ()
    shape, rep = brep_shape(model, nurbs=suffix == ".3dm")
    if suffix == ".3dm":
        rep["file"] = write_3dm(path, shape, wires=wires)
    else:
        rep["file"] = write_step(path, shape, schema=schema, wires=wires)
    return rep


def cad_model(network, patchset, control_net, surfaces, loop_patch, *, level: int,
              curve_deviation: float = 0.0):
    """The :class:`CadModel` of a classical surface, and the B-spline extraction it took.

    Parameters
    ----------
    network : CurveNetwork
    patchset : PatchSet
    control_net : surfacing.levels.ControlNet
        The fitted Catmull-Clark control net.
    surfaces : list of AnalyticSurface or None
        Per patch its analytic surface (None: a B-spline face).
    loop_patch : list of int
        The patch of each loop of the control net.
    level : int
        B-spline extraction level (:func:`surfacing.bspline.extract_bsplines`).
    curve_deviation : float
        The limit surface's largest deviation from the curves, fraction of the diagonal.

    Returns
    -------
    (CadModel, BSplineSet)
    """
    from curvenet.surfacing.bspline import extract_bsplines
    from ..cycles.loops import orient_boundaries
    # pieces of the faces not trimmed, and of spheres and tori (the B-rep may fall back
    # to them); without those where they cannot be extracted (a dome's polar patch)
    plain = [s is not None and s.kind in ("plane", "cylinder", "cone") for s in surfaces]
    trimmed = [s is not None and s.kind in CAD_KINDS for s in surfaces]
    try:
        bset = extract_bsplines(control_net, level,
                                skip=[i for i, k in enumerate(loop_patch) if plain[k]])
    except ValueError:
        bset = extract_bsplines(control_net, level,
                                skip=[i for i, k in enumerate(loop_patch) if trimmed[k]])
    free = bset.pieces
    diag = bset.report.get("diagonal", 1.0)
    gap = max([s["gap"] for s in bset.seams] + [curve_deviation]) * diag
    model = CadModel(
        curves=[e.curve for e in network.edges], ends=[(e.u, e.v) for e in network.edges],
        positions=np.asarray(network.positions, np.float64),
        boundaries=orient_boundaries(network, patchset.patches), surfaces=surfaces,
        pieces=free, piece_patch=[loop_patch[pc.patch] for pc in free], diagonal=diag,
        gap=gap)
    return model, bset
