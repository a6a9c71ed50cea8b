"""``curvenet review`` in a real browser: headless Chromium driven by Playwright.

The command runs as a user runs it (a subprocess on a rough sketch file); the page is
loaded, looked at (screenshots of the 3D view, read as pixels) and used through the
accessibility tree (checkboxes ``patch 1`` ..., buttons by name) and the keyboard.
Skipped cleanly where Playwright's Python client, Debian's ``chromium`` (or the
browser named by ``CURVENET_CHROMIUM``) or the ``[view]`` extra is missing.
"""

from __future__ import annotations

import io
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("viser")
sync_api = pytest.importorskip("playwright.sync_api")
CHROMIUM = os.environ.get("CURVENET_CHROMIUM") or shutil.which("chromium")
if not CHROMIUM:
    pytest.skip("no chromium browser installed (apt-get install chromium)",
                allow_module_level=True)

#: Chromium switches for a headless run on a machine without a GPU or network.
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update",
                 "--disable-sync"]
#: Seconds to wait for the page (software WebGL on two busy cores is slow to start).
WAIT = 60


@pytest.fixture(scope="module")
def browser():
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        yield b
        b.close()


@pytest.fixture(scope="module")
def sketch(tmp_path_factory):
    """A rough L-prism sketch (wobbly, overshooting strokes) and its ``curvenet patches``."""
    from curvenet.datasets import shapes
    from curvenet.datasets.redraw import rough_sketch
    from curvenet.io.sketch import write_sketch

    folder = tmp_path_factory.mktemp("ref")
    path = folder / "l_prism.obj"
    write_sketch(path, rough_sketch(shapes.l_prism().network, seed=0))
    _cli(["patches", str(path), "-o", str(folder / "ref.json")], folder)
    return path, json.loads((folder / "ref.json").read_text())["patches"]


def _cli(args, cwd):
    proc = subprocess.run([sys.executable, "-m", "curvenet.cli", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return proc


class _Review:
    """``curvenet review`` running in a folder of its own, and its address."""

    def __init__(self, sketch: Path, folder: Path):
        self.folder = folder
        shutil.copy(sketch, folder / sketch.name)
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "curvenet.cli", "review", sketch.name, "-o", "out.json",
             "--no-browser", "--port", "0"], cwd=folder, text=True, stdout=subprocess.PIPE,
            stderr=subprocess.PIPE)
        deadline, line = time.monotonic() + WAIT, ""
        while time.monotonic() < deadline and "review: http" not in line:
            line = self.proc.stdout.readline()
        match = re.search(r"http://127\.0\.0\.1:\d+", line)
        assert match, line
        self.url = match.group(0)

    def stop(self) -> int:
        self.proc.send_signal(signal.SIGINT)
        self.proc.communicate(timeout=30)
        return self.proc.returncode


@pytest.fixture
def review(sketch, tmp_path):
    r = _Review(sketch[0], tmp_path)
    yield r
    if r.proc.poll() is None:
        r.stop()


def _view(page) -> np.ndarray:
    """The 3D view left of the panel, ``(H, W, 3) float`` RGB in [0, 1].

    The page's canvas fills the window; the panel floats over its right side.
    """
    from PIL import Image

    box = page.locator("canvas").first.bounding_box()
    panel = page.get_by_role("button", name="Save", exact=True).bounding_box()
    width = panel["x"] - box["x"] - 20
    png = page.screenshot(clip={"x": box["x"], "y": box["y"], "width": width,
                                "height": box["height"]})
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.float64) / 255.0


def _drawn(img) -> bool:
    """Not blank: 3% of the view is not background (the axes gizmo alone is 0.2%, the
    L-prism about 10%), in several distinct hues (the patch colours)."""
    from matplotlib.colors import rgb_to_hsv

    ink = np.abs(img - img[2, 2]).max(axis=-1) > 0.1
    hsv = rgb_to_hsv(img[ink])
    hues = np.unique(np.round(hsv[hsv[:, 1] > 0.2, 0] * 12) % 12)
    return ink.mean() > 0.03 and len(hues) >= 3


def _open(browser, url):
    page = browser.new_page(viewport={"width": 1200, "height": 800})
    page.goto(url)
    page.get_by_role("checkbox", name="patch 1", exact=True).wait_for(timeout=WAIT * 1000)
    for close in page.locator(".mantine-Notification-closeButton").all():
        close.click()                    # "software WebGL" notices: no GPU in a test run
    deadline = time.monotonic() + WAIT
    while not _drawn(_view(page)):
        assert time.monotonic() < deadline, "the 3D view stayed blank"
        time.sleep(0.5)
    return page


def _wait_for(predicate, what: str, timeout: float = WAIT):
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, what
        time.sleep(0.2)


def test_untick_patch_1_save_and_surface_the_file(browser, sketch, review, tmp_path_factory):
    path, ref = sketch
    page = _open(browser, review.url)
    boxes = [page.get_by_role("checkbox", name=f"patch {i + 1}", exact=True)
             for i in range(len(ref))]
    assert all(b.is_checked() for b in boxes)             # ticked = accepted
    boxes[0].uncheck()
    _wait_for(lambda: not boxes[0].is_checked(), "patch 1 stays ticked")
    page.get_by_role("button", name="Save", exact=True).click()
    out = review.folder / "out.json"
    _wait_for(out.is_file, "Save wrote nothing")
    saved = json.loads(out.read_text())["patches"]
    assert len(saved) == len(ref) - 1
    assert [p["edges"] for p in saved] == [p["edges"] for p in ref[1:]]
    page.close()
    assert review.stop() == 0                              # Ctrl-C: a clean stop
    assert sorted(p.name for p in review.folder.iterdir()) == [path.name, "out.json"]
    elsewhere = tmp_path_factory.mktemp("surface")
    _cli(["surface", str(path), "--patches", str(out), "-o", str(elsewhere / "mesh.obj")],
         elsewhere)
    import trimesh

    assert len(trimesh.load(elsewhere / "mesh.obj").faces) > 100


def _orange(img) -> np.ndarray:
    """Pixels of the highlight colour in the view: orange hues, saturated.

    Light keeps the hue and at most whitens a lit face to a saturation near 0.5; the
    patch colours have saturation 0.45 (curvenet.view.patch_colours).
    """
    from matplotlib.colors import rgb_to_hsv

    hsv = rgb_to_hsv(img)
    return (hsv[..., 0] > 0.02) & (hsv[..., 0] < 0.13) & (hsv[..., 1] > 0.5)


def test_click_a_patch_in_the_view_shortcuts_and_surface(browser, sketch, review):
    page = _open(browser, review.url)
    img = _view(page)
    plain = _orange(img).sum()                             # the axes gizmo has some
    ink = np.argwhere(np.abs(img - img[2, 2]).max(axis=-1) > 0.1)
    y, x = np.median(ink, axis=0)                          # inside the shape's picture
    box = page.locator("canvas").first.bounding_box()      # _view starts at its corner
    page.mouse.click(box["x"] + x, box["y"] + y)
    selected = page.get_by_text(re.compile(r"^patch \d+: \d+ curves"))
    selected.wait_for(timeout=WAIT * 1000)
    label = re.match(r"patch \d+", selected.inner_text()).group(0)
    _wait_for(lambda: _orange(_view(page)).sum() > plain + 1000,
              "the selection is not highlighted")
    check = page.get_by_role("checkbox", name=label, exact=True)
    page.keyboard.press("r")                               # reject the selected patch
    _wait_for(lambda: not check.is_checked(), "r did not reject it")
    page.keyboard.press("Control+z")                       # undo
    _wait_for(check.is_checked, "ctrl+z did not undo")
    nxt = f"patch {int(label.split()[1]) % len(sketch[1]) + 1}:"
    page.keyboard.press("n")                               # next patch
    page.get_by_text(nxt).wait_for(timeout=WAIT * 1000)
    page.keyboard.press("Escape")
    page.get_by_text("Click a patch in the view").wait_for(timeout=WAIT * 1000)
    page.get_by_role("button", name="Surface", exact=True).click()
    page.get_by_text(re.compile(r"surface: \d+ triangles")).wait_for(timeout=300_000)
    assert not page.get_by_role("checkbox", name="show patches", exact=True).is_checked()
    _wait_for(lambda: _grey_shape(_view(page)), "the surface is not drawn")
    page.close()


def _grey_shape(img) -> bool:
    """The shape drawn (3% of the view) in grey: the surface, the coloured patches hidden
    (only the thin curves keep colour)."""
    from matplotlib.colors import rgb_to_hsv

    ink = np.abs(img - img[2, 2]).max(axis=-1) > 0.1
    return ink.mean() > 0.03 and np.mean(rgb_to_hsv(img[ink])[:, 1] > 0.2) < 0.2
