"""Headless preview pictures: strokes, curve network, coloured patches and shaded surfaces.

Rendering uses matplotlib's Agg canvas directly (no pyplot, no display, no global
backend switch); matplotlib is imported inside :func:`render_preview`, so
``import curvenet`` stays light.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.atomic import atomic_path
from ..core.errors import InvalidParameterError
from ..core.geometry import as_polyline
from ..core.tolerances import DIVISION_GUARD, ZERO_LENGTH
from .decimate import decimate_clustering
from .colours import (CURVE_COLOURS, HIGHLIGHT_COLOUR, ROUTE_COLOURS, WIRE_COLOUR,
                      patch_colours)

__all__ = ["render_preview", "patch_polygons", "decimate_clustering", "DEFAULT_VIEWS",
           "MAX_PREVIEW_FACES"]

#: Default cameras: ``(elevation, azimuth)`` in degrees, one panel each: front and back.
#: The back camera is the front one's antipode (azimuth 180 degrees on, elevation
#: negated), so the two look along opposite directions: every face that a convex shape
#: turns away from one camera faces the other, and the pair shows each face once
#: (the bottom too, where a missing patch hides). Two cameras both above, 180 degrees
#: apart, see the same top twice and read as nearly the same picture.
DEFAULT_VIEWS = ((20.0, -60.0), (-20.0, 120.0))

#: Meshes with more faces are decimated (vertex clustering) before drawing.
MAX_PREVIEW_FACES = 60_000

#: Patch fans are cut into this many rings (smaller pieces sort better in depth).
FAN_RINGS = 4

#: Share of a panel's width and height that the shape's projected bounding box fills
#: (the rest is margin): the camera zoom is chosen per panel to fit it.
FILL = 0.92
#: Measure-and-correct passes of the fit (the second one only tidies rounding).
FIT_PASSES = 2

#: Lambert shading: ``AMBIENT + (1 - AMBIENT) * |n . l|`` (two-sided: orientation-agnostic);
#: highlighted patches use the larger HIGHLIGHT_AMBIENT so they stay bright.
AMBIENT, HIGHLIGHT_AMBIENT = 0.30, 0.75

#: Rotation taking the named up axis to z (rows: picture x, y, z in data coordinates);
#: proper rotations, so handedness and face orientation are kept.
_UP = {"z": ((1, 0, 0), (0, 1, 0), (0, 0, 1)),
       "y": ((1, 0, 0), (0, 0, -1), (0, 1, 0)),
       "x": ((0, 1, 0), (0, 0, 1), (1, 0, 0))}

_STROKE_COLOUR = (0.25, 0.25, 0.25)
_CONSTRUCTION_COLOUR = (0.65, 0.65, 0.65)
_MESH_COLOUR = np.array([0.72, 0.76, 0.82])


# ---------------------------------------------------------------------------
# geometry helpers
# ---------------------------------------------------------------------------
def patch_polygons(network, edge_ids) -> list:
    """Closed polygons traced by a set of network edges (one per connected component).

    Parameters
    ----------
    network : CurveNetwork
    edge_ids : iterable of int
        Ids into ``network.edges``, in any order (a :class:`~curvenet.model.patchset.Patch`'s
        ``edges`` are sorted, not in walking order).

    Returns
    -------
    list of (k, 3) float64 ndarray
        One polygon per component in which every vertex has even degree (an Eulerian
        circuit through the component's curves, each curve walked in the circuit's
        direction, the closing point not repeated). Components that are not closed
        (an odd-degree vertex) give no polygon.

    Raises
    ------
    InvalidParameterError
        An edge id out of range.
    """
    import networkx as nx

    ids = _edge_ids(network, edge_ids)
    g = nx.MultiGraph()
    for e in ids:
        g.add_edge(network.edges[e].u, network.edges[e].v, key=e)
    polygons = []
    for comp in nx.connected_components(g):
        sub = g.subgraph(comp)
        if any(d % 2 for _, d in sub.degree()):
            continue
        parts = []
        for u, v, key in nx.eulerian_circuit(sub, keys=True):
            edge = network.edges[key]
            curve = edge.curve if (edge.u, edge.v) == (u, v) else edge.curve[::-1]
            parts.append(curve[:-1])
        polygons.append(np.concatenate(parts))
    return polygons


def _edge_ids(network, edge_ids) -> list:
    """``edge_ids`` as a list of int, checked against ``network.edges``."""
    ids = [int(e) for e in edge_ids]
    n = len(network.edges)
    bad = [e for e in ids if not 0 <= e < n]
    if bad:
        raise InvalidParameterError(f"edge ids {bad} out of range 0..{n - 1}")
    return ids


def _fan(polygon, rings: int = 1):
    """Fan triangles ``(k (2 rings - 1), 3, 3)`` of a closed polygon around its centroid.

    With ``rings > 1`` each fan sector (centroid, p_i, p_i+1) is cut by ``rings - 1``
    scaled copies of the polygon into one triangle and ``rings - 1`` quads (two triangles
    each). The surface is the same (every piece lies in its sector's plane); the smaller
    pieces only help matplotlib's per-polygon depth sort.
    """
    c = polygon.mean(axis=0)
    k = len(polygon)
    t = np.arange(1, rings + 1) / rings  # ring scale factors, outermost = 1
    ring = c + t[:, None, None] * (polygon - c)[None]  # (rings, k, 3)
    nxt = np.roll(ring, -1, axis=1)
    inner = np.stack([np.broadcast_to(c, (k, 3)), ring[0], nxt[0]], axis=1)
    a, b = ring[:-1].reshape(-1, 3), nxt[:-1].reshape(-1, 3)  # inner ring edge a -> b
    a2, b2 = ring[1:].reshape(-1, 3), nxt[1:].reshape(-1, 3)  # outer ring edge a2 -> b2
    quads = np.concatenate([np.stack([a, a2, b2], axis=1), np.stack([a, b2, b], axis=1)])
    return np.concatenate([inner, quads])


def _light(elev, azim):
    """Unit key-light direction for a camera at ``(elev, azim)``: above-left of the eye."""
    e, a = np.radians(elev + 25.0), np.radians(azim - 30.0)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def _shade(triangles, base, light, ambient=AMBIENT):
    """Per-triangle RGB ``(n, 3)``: ``base * (ambient + (1 - ambient) * |n . l|)``.

    ``ambient`` is a scalar or one value per triangle.
    """
    n = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1), DIVISION_GUARD)[:, None]
    lam = ambient + (1.0 - ambient) * np.abs(n @ light)
    return np.clip(np.asarray(base, dtype=np.float64).reshape(-1, 3) * lam[:, None], 0, 1)


# ---------------------------------------------------------------------------
# argument handling
# ---------------------------------------------------------------------------
def _strokes_with_colours(strokes):
    if strokes is None:
        return [], []
    if isinstance(strokes, (str, os.PathLike)):
        from ..io.sketch import read_sketch

        strokes = read_sketch(strokes)
    labels = None
    if hasattr(strokes, "strokes") and hasattr(strokes, "labels"):
        strokes, labels = strokes.strokes, strokes.labels

    lines = [as_polyline(s, name=f"strokes[{i}]") for i, s in enumerate(strokes)]
    labels = labels or ["boundary"] * len(lines)
    colours = [_CONSTRUCTION_COLOUR if lab == "construction" else _STROKE_COLOUR
               for lab in labels]
    return lines, colours


def _patch_list(patches, network):
    if patches is None:
        return [], network
    if hasattr(patches, "patches") and hasattr(patches, "network"):  # PatchSet
        network = network if network is not None else patches.network
        patches = patches.patches
    edge_sets = [tuple(p.edges) if hasattr(p, "edges") else tuple(p) for p in patches]
    if edge_sets and network is None:
        raise InvalidParameterError("patches: a list of patches needs network= (or pass a "
                                    "PatchSet)")
    return edge_sets, network


def _views(view):
    if view is None:
        return list(DEFAULT_VIEWS)
    arr = np.asarray(view, dtype=np.float64)
    if arr.shape == (2,):
        arr = arr[None]
    if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) == 0 or not np.isfinite(arr).all():
        raise InvalidParameterError(
            f"view must be (elev, azim) or a list of them, got {view!r}")
    return [tuple(map(float, v)) for v in arr]


# ---------------------------------------------------------------------------
# public
# ---------------------------------------------------------------------------
def render_preview(path, *, strokes=None, network=None, patches=None, mesh=None,
                   highlight=None, title=None, view=None, size=(900, 700),
                   up: str = "z", face_route=None, routes=(), wires=()) -> Path:
    """Draw a PNG picture of a sketch, its network, its patches and/or a surface.

    Parameters
    ----------
    path : str or os.PathLike
        Output PNG file (written atomically; parent folders are created).
    strokes : Sketch, list of (n, 3) array_like, or path of a sketch file, optional
        Drawn as thin dark lines (``construction`` strokes light grey).
    network : CurveNetwork, optional
        Curves drawn blue (``boundary``) or red (``crease``), junctions as dots.
        Defaults to ``patches.network`` when ``patches`` is a PatchSet.
    patches : PatchSet or list of Patch (or of edge-id sequences), optional
        Each patch filled with its own colour: the cycle's curves chained into a polygon
        and fan-triangulated around its centroid, Lambert-shaded.
    mesh : trimesh.Trimesh, (vertices, faces) pair or path, optional
        Surface, Lambert-shaded per face; decimated by vertex clustering to at most
        :data:`MAX_PREVIEW_FACES` faces.
    highlight : list of int or of edge-id sequences, optional
        Drawn emphasised in :data:`HIGHLIGHT_COLOUR`: an ``int`` is an index into
        ``patches``, a sequence of edge ids a cycle of ``network`` (e.g. a suggested
        patch that is not in the set yet).
    title : str, optional
        Figure title.
    view : (elev, azim) or list of (elev, azim), optional
        Camera angles in degrees, one panel per view, side by side. Default
        :data:`DEFAULT_VIEWS` (front and back).
    size : (int, int), default (900, 700)
        Picture width and height in pixels.
    up : {"z", "y", "x"}, default "z"
        The data's up axis (many OBJ sketches are y-up); the picture is rotated so
        that it points up.
    face_route : (F,) int, optional
        Per face of ``mesh``, an index into ``routes``: faces are coloured by route
        (:data:`ROUTE_COLOURS`) and a legend names them.
    routes : sequence of str
        Route names of ``face_route`` (``("classical", "neural")``).
    wires : list of (m, 3) array_like
        Polylines kept beside the surface, drawn in :data:`WIRE_COLOUR`.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    InvalidParameterError
        Nothing to draw, bad ``size`` / ``view`` / ``highlight``, or patches without a
        network.
    SketchFormatError
        A mesh or sketch file that cannot be read.

    Notes
    -----
    matplotlib draws 3D collections with the painter's algorithm (no z-buffer): triangles
    are depth-sorted within the mesh and within the patches; curves and strokes are drawn
    on top of surfaces, so hidden curves stay visible. Axes are equal-scaled and hidden.
    Shading is two-sided, ``0.3 + 0.7 |n . l|`` with the light above-left of the camera
    (``0.75 + 0.25 |n . l|`` for highlighted patches).

    Examples
    --------
    >>> import tempfile, trimesh
    >>> out = render_preview(tempfile.mkdtemp() + "/sphere.png",
    ...                      mesh=trimesh.creation.icosphere(), view=(20, -60))
    >>> out.suffix
    '.png'
    """
    width, height = _size(size)
    views = _views(view)
    rot = _rotation(up)
    lines, line_colours = _strokes_with_colours(strokes)
    edge_sets, network = _patch_list(patches, network)
    hl_index, hl_extra, hl_edges = _highlights(highlight, edge_sets, network)
    fans = _patch_fans(network, edge_sets, hl_index, hl_extra)
    mesh_v, mesh_f, mesh_rgb = _preview_mesh(mesh, face_route, routes)
    wires = [as_polyline(w, name=f"wires[{i}]") for i, w in enumerate(wires)]
    scene = _Scene.build(rot, lines, line_colours, network, hl_edges, fans, mesh_v, mesh_f,
                         mesh_rgb, wires)
    fig = _figure(scene, views, width, height, title)
    _legend(fig, routes if face_route is not None else (), bool(wires))
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=100, facecolor="white")
    return path


def _size(size) -> tuple[int, int]:
    """``(width, height)`` in pixels, each 16..10000."""
    try:
        width, height = (int(s) for s in size)
    except (TypeError, ValueError):
        raise InvalidParameterError(f"size must be (width, height), got {size!r}") from None
    if not (16 <= width <= 10_000 and 16 <= height <= 10_000):
        raise InvalidParameterError(f"size must be 16..10000 pixels each, got {size!r}")
    return width, height


def _rotation(up) -> np.ndarray:
    """``(3, 3) float64`` taking data coordinates (row vectors) to picture coordinates."""
    if up not in _UP:
        raise InvalidParameterError(f"up must be one of {sorted(_UP)}, got {up!r}")
    return np.asarray(_UP[up], dtype=np.float64).T


def _highlights(highlight, edge_sets, network):
    """Split ``highlight`` into patch indices and extra cycles; collect their curves.

    Returns
    -------
    hl_index : set of int
        Patches recoloured in :data:`HIGHLIGHT_COLOUR`.
    hl_extra : list of tuple of int
        Edge-id cycles not in the patch list, drawn as extra polygons.
    hl_edges : list of (n, 3) float64
        Curves of every highlighted cycle, drawn emphasised.
    """
    hl_index, hl_extra, hl_edges = set(), [], []
    for item in highlight or []:
        if isinstance(item, (int, np.integer)):
            if not 0 <= item < len(edge_sets):
                raise InvalidParameterError(
                    f"highlight: patch index {item} out of range 0..{len(edge_sets) - 1}")
            hl_index.add(int(item))
            edges = edge_sets[item]
        else:
            edges = tuple(int(e) for e in item)
            if network is None:
                raise InvalidParameterError("highlight: edge ids need network= or patches=")
            hl_extra.append(edges)
        hl_edges += [network.edges[e].curve for e in _edge_ids(network, edges)]
    return hl_index, hl_extra, hl_edges


def _patch_fans(network, edge_sets, hl_index, hl_extra):
    """Fan triangles of the patch polygons, one palette colour per patch.

    Highlighted patches (indices ``hl_index``) and the extra cycles ``hl_extra``
    take :data:`HIGHLIGHT_COLOUR` and :data:`HIGHLIGHT_AMBIENT`.

    Returns
    -------
    tris : list of (t, 3, 3) float64
    rgb : list of (t, 3) float64
    ambient : list of (t,) float64
        One entry per polygon.
    """
    fill = [(edges, HIGHLIGHT_COLOUR if i in hl_index else colour)
            for i, (edges, colour) in enumerate(zip(edge_sets, patch_colours(len(edge_sets))))]
    fill += [(edges, HIGHLIGHT_COLOUR) for edges in hl_extra]
    tris, rgb, amb = [], [], []
    for edges, colour in fill:
        for poly in patch_polygons(network, edges):
            t = _fan(poly, rings=FAN_RINGS)
            tris.append(t)
            rgb.append(np.broadcast_to(colour, (len(t), 3)))
            a = HIGHLIGHT_AMBIENT if colour is HIGHLIGHT_COLOUR else AMBIENT
            amb.append(np.full(len(t), a))
    return tris, rgb, amb


def _preview_mesh(mesh, face_route, routes):
    """``(vertices, faces, rgb)`` of ``mesh`` decimated to :data:`MAX_PREVIEW_FACES`.

    ``rgb`` is (F', 3) per face by route (None without ``face_route``); all None
    without a mesh.
    """
    if mesh is None:
        return None, None, None
    from ..core.distance import load_mesh_arrays

    mesh_v, mesh_f = load_mesh_arrays(mesh, name="mesh")
    v, f, index = decimate_clustering(mesh_v, mesh_f, MAX_PREVIEW_FACES, return_index=True)
    if face_route is None:
        return v, f, None
    route = np.asarray(face_route, dtype=np.int64).ravel()
    if route.shape != (len(mesh_f),) or (len(route) and not 0 <= route.min() <= route.max()
                                         < len(routes)):
        raise InvalidParameterError(
            f"face_route must give each of the {len(mesh_f)} faces an index into routes "
            f"{tuple(routes)}")
    table = np.array([ROUTE_COLOURS.get(r, _MESH_COLOUR) for r in routes], dtype=np.float64)
    return v, f, table[route[index]].reshape(-1, 3)


def _legend(fig, routes, wires: bool):
    """Route names (and "wires") in their colours along the picture's bottom edge.

    One matplotlib legend, its entries in a row: matplotlib measures each label, so the
    swatches and names never overlap, at any picture width. Returns the Legend (None
    when there is nothing to name).
    """
    from matplotlib.patches import Patch as Swatch

    names = [(str(r), ROUTE_COLOURS.get(r, _MESH_COLOUR)) for r in routes]
    names += [("wires", WIRE_COLOUR)] if wires else []
    if not names:
        return None
    return fig.legend(handles=[Swatch(facecolor=c, label=n) for n, c in names],
                      loc="lower left", ncols=len(names), frameon=False,
                      labelcolor=[c for _, c in names], handlelength=1.0,
                      handleheight=1.0, handletextpad=0.4, columnspacing=1.2,
                      borderaxespad=0.3, prop={"weight": "bold", "size": 9})


@dataclass
class _Scene:
    """Everything a preview draws, rotated so that the data's up axis is z."""

    lines: list                 # strokes, (n, 3) each
    line_colours: list
    net_curves: list            # network curves, (n, 3) each
    net_colours: list
    net_pos: np.ndarray         # (V, 3) junctions
    hl_edges: list              # highlighted curves, (n, 3) each
    patch_tris: np.ndarray | None   # (T, 3, 3)
    patch_rgb: np.ndarray | None    # (T, 3)
    patch_amb: np.ndarray | None    # (T,)
    mesh_tris: np.ndarray | None    # (F, 3, 3)
    lo: np.ndarray              # (3,) bounding box of all of it
    hi: np.ndarray
    mesh_rgb: np.ndarray | None     # (F, 3) per-face colour (routes), else one colour
    wires: list                 # polylines beside the surface, (n, 3) each

    @classmethod
    def build(cls, rot, lines, line_colours, network, hl_edges, fans, mesh_v, mesh_f,
              mesh_rgb=None, wires=()):
        """Rotate by ``rot`` (3, 3) and bound; raises when there is nothing to draw."""
        net_curves = [] if network is None else [e.curve for e in network.edges]
        net_colours = [] if network is None else [
            CURVE_COLOURS.get(e.label, CURVE_COLOURS["boundary"]) for e in network.edges]
        net_pos = (np.zeros((0, 3)) if network is None or not net_curves
                   else network.positions)
        lines = [x @ rot for x in lines]
        hl_edges = [x @ rot for x in hl_edges]
        net_curves = [x @ rot for x in net_curves]
        net_pos = net_pos @ rot
        wires = [x @ rot for x in wires]
        tris, rgb, amb = fans
        tris = [t @ rot for t in tris]
        if mesh_v is not None:
            mesh_v = mesh_v @ rot
        pts = [np.zeros((0, 3)), net_pos] + lines + hl_edges + net_curves + wires
        if mesh_v is not None:
            pts.append(mesh_v[np.unique(mesh_f)])
        pts = np.concatenate(pts)
        if len(pts) == 0:
            raise InvalidParameterError(
                "render_preview: nothing to draw (give strokes, network, patches or mesh)")
        return cls(lines, line_colours, net_curves, net_colours, net_pos, hl_edges,
                   np.concatenate(tris) if tris else None,
                   np.concatenate(rgb) if rgb else None,
                   np.concatenate(amb) if amb else None,
                   None if mesh_v is None else mesh_v[mesh_f],
                   pts.min(axis=0), pts.max(axis=0), mesh_rgb, wires)


def _figure(scene: _Scene, views, width: int, height: int, title):
    """A matplotlib Figure (Agg canvas) with one 3D panel per ``(elev, azim)`` view."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width / 100.0, height / 100.0), dpi=100)
    FigureCanvasAgg(fig)
    fig.patch.set_facecolor("white")
    axes = []
    for i, (elev, azim) in enumerate(views):
        ax = fig.add_subplot(1, len(views), i + 1, projection="3d")
        ax.computed_zorder = False  # our zorder: surfaces, then curves on top
        _frame(ax, scene.lo, scene.hi, elev, azim)
        axes.append(ax)
    if title:
        fig.suptitle(str(title), fontsize=11)
    fig.subplots_adjust(left=0, right=1, bottom=0, top=0.94 if title else 1, wspace=0)
    _fit(fig, axes, scene.lo, scene.hi)     # on the empty panels: a cheap draw
    for ax, (elev, azim) in zip(axes, views):
        _draw_panel(ax, scene, _light(elev, azim))
    return fig


def _draw_panel(ax, scene: _Scene, light):
    """Shaded mesh and patches, then strokes, curves, junctions and highlights on top."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    if scene.mesh_tris is not None:
        ax.add_collection3d(Poly3DCollection(
            scene.mesh_tris,
            facecolors=_shade(scene.mesh_tris,
                              _MESH_COLOUR if scene.mesh_rgb is None else scene.mesh_rgb, light),
            edgecolors="none", linewidths=0, antialiased=False, zorder=1))
    if scene.patch_tris is not None:
        ax.add_collection3d(Poly3DCollection(
            scene.patch_tris,
            facecolors=_shade(scene.patch_tris, scene.patch_rgb, light, scene.patch_amb),
            edgecolors="none", linewidths=0, antialiased=False, zorder=2))
    if scene.lines:
        ax.add_collection3d(Line3DCollection(scene.lines, colors=scene.line_colours,
                                             linewidths=0.6, alpha=0.8, zorder=4))
    if scene.net_curves:
        ax.add_collection3d(Line3DCollection(scene.net_curves, colors=scene.net_colours,
                                             linewidths=1.2, zorder=5))
        pos = scene.net_pos
        ax.scatter(pos[:, 0], pos[:, 1], pos[:, 2], s=4, c="k", depthshade=False, zorder=6)
    if scene.wires:
        ax.add_collection3d(Line3DCollection(scene.wires, colors=[WIRE_COLOUR],
                                             linewidths=1.6, zorder=5))
    if scene.hl_edges:
        ax.add_collection3d(Line3DCollection(scene.hl_edges, colors=[HIGHLIGHT_COLOUR],
                                             linewidths=3.0, zorder=7))


def _box(lo, hi):
    """The drawn box ``(centre, extent)``: the bounds, a flat side kept 2% thick."""
    ext = hi - lo
    big = max(float(ext.max()), ZERO_LENGTH)
    return 0.5 * (lo + hi), np.maximum(ext, 0.02 * big)


def _frame(ax, lo, hi, elev, azim):
    """Equal aspect around the data's bounding box, axes hidden, orthographic camera set."""
    centre, ext = _box(lo, hi)
    ax.set_xlim(centre[0] - ext[0] / 2, centre[0] + ext[0] / 2)
    ax.set_ylim(centre[1] - ext[1] / 2, centre[1] + ext[1] / 2)
    ax.set_zlim(centre[2] - ext[2] / 2, centre[2] + ext[2] / 2)
    ax.set_box_aspect(tuple(ext))
    ax.set_proj_type("ortho")
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()


def _fit(fig, axes, lo, hi) -> None:
    """Zoom each panel so that the bounding box's projection fills :data:`FILL` of it.

    matplotlib sizes a 3D panel for its (hidden) axes box seen from any side, so a long
    shape seen along its diagonal overflows a narrow panel while a compact one floats
    small. Under the orthographic camera the projection scales linearly with the zoom:
    one measurement of the eight corners per panel gives the zoom exactly.
    """
    from mpl_toolkits.mplot3d import proj3d

    centre, ext = _box(lo, hi)
    corners = centre + ext * (np.indices((2, 2, 2)).reshape(3, -1).T - 0.5)  # (8, 3)
    fw, fh = fig.get_size_inches()
    panels = [ax.get_subplotspec().get_position(fig) for ax in axes]
    for ax, pb in zip(axes, panels):
        # a 3D panel draws in a square: make it the panel's longer side, centred on it
        side = max(pb.width * fw, pb.height * fh)
        ax.set_position([pb.x0 + pb.width / 2 - side / fw / 2,
                         pb.y0 + pb.height / 2 - side / fh / 2, side / fw, side / fh])
        ax.patch.set_visible(False)         # squares overlap: none may paint over another
    zoom = [1.0] * len(axes)
    for _ in range(FIT_PASSES):
        fig.draw_without_rendering()
        for i, (ax, pb) in enumerate(zip(axes, panels)):
            x, y, _ = proj3d.proj_transform(*corners.T, ax.get_proj())
            px = ax.transData.transform(np.column_stack([x, y]))       # (8, 2) pixels
            size = np.maximum(np.ptp(px, axis=0), 1.0)
            box = pb.transformed(fig.transFigure)
            scale = FILL * min(box.width / size[0], box.height / size[1])
            zoom[i] *= scale
            ax.set_box_aspect(tuple(ext), zoom=zoom[i])
            # the projection scales about the axes' centre: move the axes so that the
            # projection's centre lands on the panel's
            a = np.array([ax.bbox.x0 + ax.bbox.x1, ax.bbox.y0 + ax.bbox.y1]) / 2
            d = (px.min(axis=0) + px.max(axis=0)) / 2 - a
            shift = np.array([box.x0 + box.x1, box.y0 + box.y1]) / 2 - d * scale - a
            pos = ax.get_position()
            ax.set_position([pos.x0 + shift[0] / fig.bbox.width,
                             pos.y0 + shift[1] / fig.bbox.height, pos.width, pos.height])
