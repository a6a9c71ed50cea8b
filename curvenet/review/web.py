"""Patch review in the browser: the patches in 3D, accepted and rejected with a click.

:class:`ReviewPage` serves one patch set on a local web page built with viser (the
``[view]`` extra: ``pip install 'curvenet[view]'``; its page is one self-contained file,
so it works offline): the strokes, the snapped network and the patches each in its
colour (:func:`curvenet.view.patch_colours`, as in the ``--preview`` pictures), and the
surface when asked. A panel lists the patches as checkboxes ``patch 1``, ``patch 2``,
... in the order of ``curvenet patches`` (ticked = accepted); clicking a patch in the
view selects it and the panel offers its alternatives, the next cycles through the
same curves (:meth:`curvenet.cycles.PatchSession.alternatives_to`). ``Save`` writes
``PATCHES.json`` atomically; ``Surface`` shows the result of the surfacer the caller
passed in (the review layer sits below the pipeline).

References
----------
Abbasinejad, Joshi, Amenta 2011, Sec. 5: "point at the patch, and click to delete it";
suggested patches "accepted or rejected with a single click".
"""

from __future__ import annotations

import threading
import time
import webbrowser
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.atomic import check_output_path
from ..core.errors import CurvenetError, InvalidParameterError, MissingDependencyError
from ..core.tolerances import DIVISION_GUARD
from ..cycles.session import PatchSession
from ..io.network import write_patches
from ..model.patchset import PatchSet
from ..view.colours import CURVE_COLOURS, HIGHLIGHT_COLOUR, patch_colours
from .scene import camera_pose, patch_mesh, polyline_segments

__all__ = ["ReviewPage", "serve_review", "require_viser", "SHORTCUTS", "DEFAULT_HOST",
           "DEFAULT_PORT"]

#: Bound unless told otherwise: the page edits files, so it is not offered to the network.
DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 8080
#: Keyboard shortcuts: (key, modifier or None, command label); also in the command
#: palette (Ctrl+K) and the panel's "Shortcuts" folder.
SHORTCUTS = (("A", None, "accept the selected patch"),
             ("R", None, "reject the selected patch"),
             ("N", None, "select the next patch"),
             ("P", None, "select the previous patch"),
             ("L", None, "show the next alternative"),
             ("U", None, "use the alternative shown"),
             ("escape", None, "clear the selection"),
             ("Z", "cmd/ctrl", "undo"),
             ("S", "cmd/ctrl", "save"),
             ("F", None, "surface"))
#: A rejected patch: grey and faint, still there to click and accept again.
REJECTED_COLOUR, REJECTED_OPACITY = (0.62, 0.62, 0.62), 0.2
#: The alternative shown for the selected patch, lifted this share of the camera
#: distance off the surface it may share with patches.
ALTERNATIVE_COLOUR, ALTERNATIVE_OPACITY, ALTERNATIVE_LIFT = (0.0, 0.62, 0.55), 0.65, 0.002
#: Hemisphere fill (white sky along the up axis) and a key light above the first camera.
FILL_LIGHT, KEY_LIGHT = 1.6, 1.4
_STROKE_COLOUR = (0.25, 0.25, 0.25)
_SURFACE_COLOUR = (0.72, 0.76, 0.82)


def require_viser():
    """The ``viser`` module, or MissingDependencyError naming the extra."""
    try:
        import viser
    except ImportError:
        raise MissingDependencyError("the patch review page (curvenet review) needs viser: "
                                     "pip install 'curvenet[view]'") from None
    return viser


def _rgb(colour) -> tuple:
    """RGB in [0, 1] -> the 0..255 ints viser takes."""
    return tuple(int(round(255 * float(c))) for c in colour)


@dataclass
class _Entry:
    """One row of the panel: a cycle, its checkbox and its mesh."""

    edges: tuple
    patch: object           # the Patch written on save (source and holes kept)
    label: str
    colour: tuple
    mesh: object = None
    checkbox: object = None


class ReviewPage:
    """A patch set served on a local page for review; the server runs from construction.

    Parameters
    ----------
    patchset : PatchSet
        The suggested patches (e.g. :func:`curvenet.pipeline.patches`); not modified.
    output : str or os.PathLike
        ``PATCHES.json`` that ``Save`` writes (atomically); checked now, never one
        of ``inputs``.
    inputs : sequence of str or os.PathLike
        The files the patch set came from.
    strokes : list of (n, 3) array_like
        The sketch's strokes, drawn thin and grey (none for a network file).
    surface : callable, optional
        ``surface(patchset) -> mesh`` with ``vertices (V, 3)`` and ``faces (F, 3)``
        (a ``trimesh.Trimesh``); raises CurvenetError on failure. Without it the
        ``Surface`` button is disabled.
    host : str
        Address to bind, default :data:`DEFAULT_HOST`.
    port : int
        Port to bind (0: any free one); when taken, the next free one is used.
    title : str, optional
        Shown at the top of the panel (the input file's name, say).
    up : {"z", "y", "x"}
        The data's up axis.
    backend : {"bitset", "galois"}
        GF(2) solver of the session: ``bitset`` (default) gives the same answers as
        ``galois`` without importing it (1.3 s of the page's start on two cores).

    Notes
    -----
    The state is a :class:`~curvenet.cycles.session.PatchSession`: unticking a patch
    deletes it, ticking accepts it, ``Use alternative`` deletes the selected patch and
    accepts the alternative (one undo step), and the page repaints from the session
    after every action, so undo restores both. Every action updates the view first
    and computes suggestions after. Callbacks run on viser's threads, one at a time.
    ``Save`` writes the ticked rows in panel order, the original patches with their
    ``source`` and holes, alternatives as ``"user"``.
    """

    def __init__(self, patchset: PatchSet, *, output, inputs=(), strokes=(), surface=None,
                 host: str = DEFAULT_HOST, port: int = DEFAULT_PORT, title=None,
                 up: str = "z", backend: str = "bitset"):
        if not isinstance(patchset, PatchSet):
            raise InvalidParameterError(f"patchset: expected a PatchSet, got {type(patchset)!r}")
        if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
            raise InvalidParameterError(f"port: expected 0..65535, got {port!r}")
        if surface is not None and not callable(surface):
            raise InvalidParameterError(f"surface: expected a callable, got {type(surface)!r}")
        self.output = check_output_path(output, inputs=inputs, what="output")
        viser = require_viser()
        self.session = PatchSession(patchset, backend=backend)
        self.network = patchset.network
        net = self.network
        colours = patch_colours(len(patchset.patches))
        self._entries = [_Entry(p.edges, p, f"patch {i + 1}", tuple(c))
                         for i, (p, c) in enumerate(zip(patchset.patches, colours))]
        if not net.edges:
            raise InvalidParameterError("patchset: its network has no curves to review")
        meshes = [patch_mesh(net, e.edges) for e in self._entries]
        strokes = polyline_segments(list(strokes))
        curves = polyline_segments([e.curve for e in net.edges])
        labels = np.repeat([e.label for e in net.edges], [len(e.curve) - 1 for e in net.edges])
        curve_rgb = np.array([CURVE_COLOURS.get(lab, CURVE_COLOURS["boundary"]) for lab in labels]
                             ).reshape(-1, 1, 3).repeat(2, axis=1)
        junctions = np.asarray(net.positions, np.float32).reshape(-1, 3)
        points = np.concatenate([strokes.reshape(-1, 3), curves.reshape(-1, 3)])
        position, look_at, up_dir = camera_pose(points, up)
        self._surface_fn = surface
        self._lock = threading.RLock()
        self._steps: list = []          # session actions per page action, for undo
        self._selected: int | None = None
        self._alternatives: list = []
        self._shown = 0                 # index of the alternative drawn
        self._baseline = frozenset(e.edges for e in self._entries)  # ticked at the last save
        self.saved = None               # path of the last save
        self.server = viser.ViserServer(host=host, port=port, verbose=False)
        try:
            self._build(strokes, curves, curve_rgb, junctions, meshes, (position, look_at, up_dir),
                        title)
        except BaseException:
            self.server.stop()
            raise

    # ------------------------------------------------------------------ building
    def _build(self, strokes, curves, curve_rgb, junctions, meshes, camera, title):
        s, gui = self.server, self.server.gui
        position, look_at, up_dir = camera
        gui.configure_theme(control_width="medium", show_share_button=False)
        s.scene.set_up_direction(tuple(up_dir))
        # Plain lights, no image-based light and no shadows: each of those doubles the
        # time of a frame where WebGL runs on the CPU (11 -> 44 frames/s, 216 patches).
        s.scene.configure_environment_map(None)
        s.scene.configure_default_lights(False)
        s.scene.add_light_hemisphere("/lights/fill", sky_color=(255, 255, 255),
                                     ground_color=(120, 120, 130), intensity=FILL_LIGHT,
                                     position=tuple(up_dir))
        key = position - look_at + np.linalg.norm(position - look_at) * up_dir
        s.scene.add_light_directional("/lights/key", intensity=KEY_LIGHT,
                                      position=tuple(look_at + key))
        s.initial_camera.position = tuple(position)
        s.initial_camera.look_at = tuple(look_at)
        s.initial_camera.up = tuple(up_dir)
        scale = float(np.linalg.norm(position - look_at))
        self._lift = ALTERNATIVE_LIFT * scale
        self._layers = {}
        if len(strokes):
            self._layers["show strokes"] = [s.scene.add_line_segments(
                "/strokes", strokes, colors=_rgb(_STROKE_COLOUR), thickness=1.0,
                thickness_units="screen")]
        net_nodes = [s.scene.add_line_segments("/network/curves", curves,
                                               colors=(255 * curve_rgb).astype(np.uint8),
                                               thickness=2.5, thickness_units="screen")]
        if len(junctions):
            net_nodes.append(s.scene.add_point_cloud(
                "/network/junctions", junctions, colors=(20, 20, 20),
                point_size=0.004 * scale, point_shape="circle"))
        self._layers["show network"] = net_nodes
        for i, (entry, (v, f)) in enumerate(zip(self._entries, meshes)):
            self._add_mesh(i, entry, v, f)
        self._layers["show patches"] = [e.mesh for e in self._entries]
        self._alt_nodes: list = []
        self._surface_node = None

        if title:
            gui.add_markdown(f"**{title}**")
        self._status = gui.add_markdown("")
        self._buttons = {name: gui.add_button(name) for name in ("Save", "Surface", "Undo")}
        self._buttons["Save"].on_click(lambda _: self.save())
        self._buttons["Surface"].on_click(lambda _: self.show_surface())
        self._buttons["Undo"].on_click(lambda _: self.undo())
        self._buttons["Surface"].disabled = self._surface_fn is None
        with gui.add_folder("Selected"):
            self._selection_text = gui.add_markdown("Click a patch in the view to select it.")
            self._alt_buttons = {name: gui.add_button(name, disabled=True)
                                 for name in ("Next alternative", "Use alternative")}
        self._alt_buttons["Next alternative"].on_click(lambda _: self.next_alternative())
        self._alt_buttons["Use alternative"].on_click(lambda _: self.use_alternative())
        with gui.add_folder("Show"):
            self._layer_boxes = {}
            for name in ("show strokes", "show network", "show patches", "show surface"):
                box = gui.add_checkbox(name, name != "show surface",
                                       disabled=name not in self._layers and name != "show surface")
                box.on_update(lambda _, name=name: self._show_layer(name))
                self._layer_boxes[name] = box
        with gui.add_folder("Shortcuts", expand_by_default=False):
            gui.add_markdown("\n".join(f"- `{(m + '+') if m else ''}{k}`: {text}"
                                       for k, m, text in SHORTCUTS))
        self._folder = gui.add_folder("Patches")
        with self._folder:
            for i, entry in enumerate(self._entries):
                self._add_checkbox(i, entry)
        actions = {"accept the selected patch": lambda: self._tick_selected(True),
                   "reject the selected patch": lambda: self._tick_selected(False),
                   "select the next patch": lambda: self._step_selection(1),
                   "select the previous patch": lambda: self._step_selection(-1),
                   "show the next alternative": self.next_alternative,
                   "use the alternative shown": self.use_alternative,
                   "clear the selection": lambda: self.select(None),
                   "undo": self.undo, "save": self.save, "surface": self.show_surface}
        for key, modifier, label in SHORTCUTS:
            cmd = gui.add_command(label, hotkey=key, modifier=modifier)
            cmd.on_trigger(lambda _, act=actions[label]: act())
        self._refresh_panel()

    def _add_mesh(self, i: int, entry: _Entry, vertices, faces) -> None:
        entry.mesh = self.server.scene.add_mesh_simple(
            f"/patches/{i + 1}", vertices, faces, color=_rgb(entry.colour), side="double",
            flat_shading=False, cast_shadow=False, receive_shadow=False)
        entry.mesh.on_click(lambda _, i=i: self.select(i))

    def _add_checkbox(self, i: int, entry: _Entry) -> None:
        entry.checkbox = self.server.gui.add_checkbox(entry.label, True)
        entry.checkbox.on_update(lambda _, i=i: self.set_accepted(i, entry.checkbox.value))

    # ------------------------------------------------------------------ state
    @property
    def url(self) -> str:
        """The page's address (with the port actually bound)."""
        host = self.server.get_host()
        return f"http://{'127.0.0.1' if host in ('0.0.0.0', '') else host}:{self.server.get_port()}"

    @property
    def labels(self) -> list:
        """The panel's rows, ``["patch 1", ...]``."""
        return [e.label for e in self._entries]

    def accepted(self) -> list:
        """``[bool]`` per row: is it a current patch of the session."""
        current = {p.edges for p in self.session.patches}
        return [e.edges in current for e in self._entries]

    @property
    def selected(self) -> int | None:
        """The selected row, or None."""
        return self._selected

    @property
    def alternatives(self) -> list:
        """The selected row's alternatives (Suggestion), best first; the drawn one is
        ``alternatives[shown]``."""
        return list(self._alternatives)

    @property
    def shown(self) -> int:
        """Index of the alternative drawn."""
        return self._shown

    @property
    def status(self) -> str:
        """The panel's status text (Markdown)."""
        return self._status.content

    @property
    def patchset(self) -> PatchSet:
        """The ticked rows in panel order, as ``Save`` writes them."""
        report = self.session.patchset.report
        return PatchSet(self.network, [e.patch for e, ok in zip(self._entries, self.accepted())
                                       if ok], report)

    @property
    def unsaved(self) -> bool:
        """True when the ticked rows differ from the last save (or from the start)."""
        return frozenset(p.edges for p in self.patchset.patches) != self._baseline

    # ------------------------------------------------------------------ actions
    def set_accepted(self, index: int, accepted: bool) -> None:
        """Tick (accept) or untick (reject) row ``index``; unticking also selects it."""
        with self._lock:
            entry = self._entry(index)
            if accepted == self.accepted()[index]:
                self._paint(index)          # our own repaint of the checkbox, or a repeat
                return
            self._paint_mesh(index, accepted)           # the view first, sent now
            self.server.flush()
            if accepted:
                self.session.accept(entry.edges)
            else:
                self.session.delete(entry.edges, top=0)
            self._steps.append(1)
            self._paint(index)
            if not accepted or self._selected == index:
                self.select(index)
            self._refresh_panel()

    def select(self, index: int | None) -> None:
        """Select row ``index`` (None: nothing) and list its alternatives."""
        with self._lock:
            old, self._selected = self._selected, (None if index is None
                                                   else self._index(index))
            if old is not None:
                self._paint(old)
            self._alternatives, self._shown = [], 0
            if self._selected is not None:
                self._paint(self._selected)
                self._alternatives = self.session.alternatives_to(
                    self._entries[self._selected].edges)
            self._draw_alternative()
            self._refresh_panel()

    def next_alternative(self) -> None:
        """Draw the selected patch's next alternative (wrapping round)."""
        with self._lock:
            if self._alternatives:
                self._shown = (self._shown + 1) % len(self._alternatives)
                self._draw_alternative()
                self._refresh_panel()

    def use_alternative(self) -> None:
        """Replace the selected patch by the alternative drawn (a new ticked row)."""
        with self._lock:
            if self._selected is None or not self._alternatives:
                return
            alt = self._alternatives[self._shown]
            old = self._entries[self._selected]
            steps = 0
            if old.edges in {p.edges for p in self.session.patches}:
                self.session.delete(old.edges, top=0)
                steps += 1
            patch = self.session.accept(alt)
            self._steps.append(steps + 1)
            i = len(self._entries)
            entry = _Entry(patch.edges, patch, f"patch {i + 1}", tuple(patch_colours(i + 1)[i]))
            self._entries.append(entry)
            self._add_mesh(i, entry, *patch_mesh(self.network, entry.edges))
            self._layers["show patches"].append(entry.mesh)
            with self._folder:
                self._add_checkbox(i, entry)
            self._paint(self._entries.index(old))
            self.select(i)

    def undo(self) -> bool:
        """Undo the last page action; False when there is none."""
        with self._lock:
            if not self._steps:
                return False
            for _ in range(self._steps.pop()):
                self.session.undo()
            for i in range(len(self._entries)):
                self._paint(i)
            self.select(self._selected)
            return True

    def save(self) -> Path:
        """Write the ticked rows to :attr:`output` (atomically); returns the path."""
        with self._lock:
            try:
                write_patches(self.output, self.patchset)
            except CurvenetError as err:
                self._status_line(f"not saved: {err}")
                raise
            self._baseline = frozenset(p.edges for p in self.patchset.patches)
            self.saved = self.output
            self._refresh_panel()
            return self.output

    def show_surface(self) -> None:
        """Surface the ticked patches with the ``surface`` callable and show the result."""
        with self._lock:
            if self._surface_fn is None:
                return
            button = self._buttons["Surface"]
            button.disabled = True
            self._status_line("surfacing ...")
            try:
                mesh = self._surface_fn(self.patchset)
            except CurvenetError as err:
                self._status_line(f"no surface: {err}")
                return
            except Exception as err:  # an internal failure: said on the page, not raised
                self._status_line(f"no surface: internal error: {type(err).__name__}: {err}")
                return
            finally:
                button.disabled = False
            if self._surface_node is not None:
                self._surface_node.remove()
            self._surface_node = self.server.scene.add_mesh_simple(
                "/surface", np.asarray(mesh.vertices, np.float32),
                np.asarray(mesh.faces, np.uint32), color=_rgb(_SURFACE_COLOUR), side="double",
                cast_shadow=False, receive_shadow=False)
            self._layers["show surface"] = [self._surface_node]
            self._layer_boxes["show surface"].disabled = False
            self._layer_boxes["show surface"].value = True
            self._layer_boxes["show patches"].value = False
            self._show_layer("show surface")
            self._refresh_panel(f"surface: {len(mesh.faces)} triangles")

    def close(self) -> None:
        """Stop the server."""
        self.server.stop()

    # ------------------------------------------------------------------ helpers
    def _index(self, index) -> int:
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)) \
                or not 0 <= index < len(self._entries):
            raise InvalidParameterError(f"index: expected a row 0..{len(self._entries) - 1}, "
                                        f"got {index!r}")
        return int(index)

    def _entry(self, index) -> _Entry:
        return self._entries[self._index(index)]

    def _tick_selected(self, accepted: bool) -> None:
        if self._selected is not None:
            self._entries[self._selected].checkbox.value = accepted

    def _step_selection(self, step: int) -> None:
        with self._lock:
            n = len(self._entries)
            self.select(0 if self._selected is None and step > 0 else
                        n - 1 if self._selected is None else (self._selected + step) % n)

    def _paint(self, index: int) -> None:
        """Row ``index``'s mesh and checkbox as the session has it."""
        entry = self._entries[index]
        accepted = entry.edges in {p.edges for p in self.session.patches}
        self._paint_mesh(index, accepted)
        entry.checkbox.value = accepted   # its callback sees the session agree: no action

    def _paint_mesh(self, index: int, accepted: bool) -> None:
        entry = self._entries[index]
        colour = (HIGHLIGHT_COLOUR if index == self._selected else
                  entry.colour if accepted else REJECTED_COLOUR)
        with self.server.atomic():
            entry.mesh.color = _rgb(colour)
            entry.mesh.opacity = None if accepted else REJECTED_OPACITY + 0.3 * (
                index == self._selected)

    def _draw_alternative(self) -> None:
        for node in self._alt_nodes:
            node.remove()
        self._alt_nodes = []
        if not self._alternatives:
            return
        edges = self._alternatives[self._shown].edges
        v, f = patch_mesh(self.network, edges)
        # An alternative shares its curves, often its plane, with patches: drawn where
        # they are it would flicker through them (z-fighting). Two copies lifted off
        # each side along the fan's normals: one of them is always in front.
        normals = np.zeros_like(v)
        tri = v[f]
        np.add.at(normals, f, np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])[:, None])
        normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), DIVISION_GUARD)
        seg = polyline_segments([self.network.edges[e].curve for e in edges])
        with self.server.atomic():
            self._alt_nodes = [
                self.server.scene.add_mesh_simple(f"/alternative/{side}",
                                                  v + sign * self._lift * normals, f,
                                                  color=_rgb(ALTERNATIVE_COLOUR),
                                                  opacity=ALTERNATIVE_OPACITY, side="double",
                                                  cast_shadow=False, receive_shadow=False)
                for side, sign in (("front", 1.0), ("back", -1.0))]
            self._alt_nodes.append(self.server.scene.add_line_segments(
                "/alternative/curves", seg, colors=_rgb(ALTERNATIVE_COLOUR), thickness=5.0,
                thickness_units="screen"))

    def _show_layer(self, name: str) -> None:
        visible = self._layer_boxes[name].value
        for node in self._layers.get(name, ()):
            node.visible = visible

    def _status_line(self, text: str) -> None:
        self._status.content = f"{self._head()}  \n{text}"

    def _head(self) -> str:
        ok = self.accepted()
        return (f"**{len(ok)} patches, {sum(ok)} accepted**; rank {self.session.rank()} of "
                f"{self.session.full_rank}")

    def _refresh_panel(self, note: str | None = None) -> None:
        saved = (f"saved to `{self.saved}`" if self.saved and not self.unsaved
                 else f"unsaved changes: Save writes `{self.output}`" if self.unsaved
                 else f"Save writes `{self.output}`")
        self._status_line(saved + (f"  \n{note}" if note else ""))
        sel = self._selected
        if sel is None:
            text = "Click a patch in the view to select it."
        else:
            e = self._entries[sel]
            state = "accepted" if self.accepted()[sel] else "rejected"
            text = f"**{e.label}**: {len(e.edges)} curves ({e.patch.source}), {state}.  \n"
            if self._alternatives:
                a = self._alternatives[self._shown]
                text += (f"alternative {self._shown + 1} of {len(self._alternatives)} "
                         f"(drawn): {a.describe()}")
            else:
                text += "no alternative through its curves."
        self._selection_text.content = text
        for button in self._alt_buttons.values():
            button.disabled = not self._alternatives


def serve_review(page_args: dict, *, open_browser: bool = True, say=print,
                 poll: float = 0.2) -> PatchSet:
    """Run a :class:`ReviewPage` until Ctrl-C; returns the patch set as it was left.

    Parameters
    ----------
    page_args : dict
        Keyword arguments of :class:`ReviewPage` (``patchset``, ``output``, ...).
    open_browser : bool
        Open the page in the default browser.
    say : callable
        Where the address and the closing line go.
    poll : float
        Seconds between checks for Ctrl-C.

    Notes
    -----
    Ctrl-C (and SIGTERM, which the CLI turns into ``SystemExit``) stops the server
    and returns; unsaved changes are named, not written: only ``Save`` writes.
    """
    import signal
    import threading
    if threading.current_thread() is threading.main_thread():
        # started with SIGINT ignored (a background job of a script, which is how
        # Python then leaves it), Ctrl-C would never reach the loop below
        signal.signal(signal.SIGINT, signal.default_int_handler)
    page = ReviewPage(**page_args)
    try:
        say(f"review: {page.url}  ({len(page.labels)} patches; Save writes {page.output}; "
            "Ctrl-C stops)")
        if open_browser:
            webbrowser.open(page.url)
        while True:
            time.sleep(poll)
    except KeyboardInterrupt:
        pass
    finally:
        page.close()
        say("review: stopped" + (f"; unsaved changes not written to {page.output}"
                                 if page.unsaved else ""))
    return page.patchset
