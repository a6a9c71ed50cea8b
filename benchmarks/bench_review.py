"""The review page with a 216-patch network, timed in headless Chromium (issue 34).

Run ``python benchmarks/bench_review.py [--n 6] [--toggles 10] [--shot PNG]`` with the
``[view]`` extra, Playwright's Python client and Debian's ``chromium`` (or
``CURVENET_CHROMIUM``). The network is ``grid_box(n)``: ``6 n^2`` patches (216 for
``n = 6``) on ``12 n^2`` curves. Prints:

1. the server side: patch finding, and building the page (the session, 216 meshes, the
   panel) until it serves;
2. the first full scene in the browser: from ``page.goto`` until the panel's last row
   (``patch 216``) exists and two animation frames have been drawn after it (the scene
   messages come before the panel's on the page's one websocket, so by then every mesh
   is in the scene), checked by a second screenshot 2 s later that must be the same;
3. toggle latency, measured in the page: ``performance.now()`` when the checkbox is
   clicked (the pointer resting on it, as a user's), then each animation frame reads
   the pixel under the patch (the WebGL canvas copied into a 1x1 canvas) until it
   changes; the figure is that frame's time minus the click's. The round trip is
   click -> websocket -> Python (the page repaints the mesh, then updates the session)
   -> websocket -> the viser client (a React commit, then a three.js frame). The part
   up to the Python repaint is timed too (the page's and Python's wall clocks).
"""

from __future__ import annotations

import argparse
import io
import os
import shutil
import statistics
import sys
import tempfile
import time

import numpy as np

from curvenet.cycles.find import find_patches
from curvenet.datasets.shapes import grid_box
from curvenet.review.web import ReviewPage

#: Chromium switches for a headless run without a GPU or network.
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update",
                 "--disable-sync"]

#: In the page: click the checkbox, then sample pixel (x, y) every animation frame
#: until it differs from its colour before the click; resolves to milliseconds.
_TOGGLE_JS = """async ([box, x, y]) => {
  const canvas = [...document.querySelectorAll("canvas")].sort(
    (a, b) => b.width * b.height - a.width * a.height)[0];  // the 3D view, not the gizmo
  const probe = document.createElement("canvas");
  probe.width = probe.height = 1;
  const ctx = probe.getContext("2d", {willReadFrequently: true});
  const s = canvas.width / canvas.clientWidth;
  const read = () => {
    ctx.drawImage(canvas, x * s, y * s, 1, 1, 0, 0, 1, 1);
    return ctx.getImageData(0, 0, 1, 1).data;
  };
  const frame = () => new Promise(r => requestAnimationFrame(r));
  await frame();
  const before = read();
  const t0 = performance.now(), wall = Date.now();
  box.click();
  for (;;) {
    const t = await frame();
    const now = read();
    if (Math.max(...[0, 1, 2].map(i => Math.abs(now[i] - before[i]))) > 30)
      return [t - t0, wall];
    if (t - t0 > 10000) return [null, wall];
  }
}"""


def _png(page):
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB"), np.int16)


def _inside(img, page):
    """A point of the window inside the shape's picture (left of the panel)."""
    left = page.get_by_role("button", name="Save", exact=True).bounding_box()["x"] - 20
    ink = np.argwhere(np.abs(img[:, :int(left)] - img[2, 2]).max(axis=-1) > 30)
    y, x = np.median(ink, axis=0)
    return float(x), float(y)


def _load(browser, url: str, last: str) -> float:
    """Seconds from ``goto`` until ``last`` is on the page and two frames drew after it."""
    page = browser.new_page(viewport={"width": 1200, "height": 800})
    t = time.perf_counter()
    page.goto(url)
    page.get_by_text(last, exact=True).wait_for(timeout=120_000)
    page.evaluate("() => new Promise(r => requestAnimationFrame(() => "
                  "requestAnimationFrame(r)))")
    seconds = time.perf_counter() - t
    page.close()
    return seconds


def _baseline(browser, repeats: int) -> list:
    """Load times of an empty viser page (one Markdown line): the client's own start."""
    import viser

    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    server.gui.add_markdown("empty page")
    try:
        return [_load(browser, f"http://127.0.0.1:{server.get_port()}", "empty page")
                for _ in range(repeats)]
    finally:
        server.stop()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=6, help="grid_box(n): 6 n^2 patches")
    ap.add_argument("--toggles", type=int, default=10, help="toggles timed (untick, tick)")
    ap.add_argument("--repeats", type=int, default=3, help="page loads timed")
    ap.add_argument("--shot", help="save a screenshot of the loaded page here")
    args = ap.parse_args(argv)
    from playwright.sync_api import sync_playwright

    chromium = os.environ.get("CURVENET_CHROMIUM") or shutil.which("chromium")
    if not chromium:
        print("no chromium (apt-get install chromium)", file=sys.stderr)
        return 2
    net = grid_box(args.n, samples=9).network
    t = time.perf_counter()
    ps = find_patches(net)
    t_patches = time.perf_counter() - t
    tmp = tempfile.mkdtemp()
    t = time.perf_counter()
    page_server = ReviewPage(ps, output=os.path.join(tmp, "out.json"), port=0)
    t_build = time.perf_counter() - t
    n = len(ps.patches)
    print(f"network: grid_box({args.n}), {net.number_of_edges} curves, {n} patches")
    print(f"server: find_patches {t_patches:.2f} s, page built and serving {t_build:.2f} s")
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=chromium, args=CHROMIUM_ARGS)
            empty = _baseline(browser, args.repeats)
            loads = [_load(browser, page_server.url, f"patch {n}") for _ in range(args.repeats)]
            print(f"browser: first full scene {statistics.median(loads):.2f} s after goto "
                  f"(median of {loads and [round(t, 2) for t in loads]}); an empty viser page "
                  f"{statistics.median(empty):.2f} s ({[round(t, 2) for t in empty]})")
            page = browser.new_page(viewport={"width": 1200, "height": 800})
            t = time.perf_counter()
            page.goto(page_server.url)
            page.get_by_role("checkbox", name=f"patch {n}", exact=True).wait_for(
                timeout=120_000)
            page.evaluate("() => new Promise(r => requestAnimationFrame(() => "
                          "requestAnimationFrame(r)))")
            t_scene = time.perf_counter() - t
            first = _png(page)
            time.sleep(2.0)
            same = float(np.mean(np.abs(_png(page) - first).max(axis=-1) > 30))
            print(f"browser: this load {t_scene:.2f} s; pixels that changed in the next 2 s "
                  f"(the scene was complete): {same:.2%}")
            for close in page.locator(".mantine-Notification-closeButton").all():
                close.click()
            if args.shot:
                page.screenshot(path=args.shot)
            canvas = page.locator("canvas").first.bounding_box()
            x, y = _inside(first, page)
            page.mouse.click(x, y)                       # which patch lies there?
            label = page.get_by_text("curves (").first
            label.wait_for(timeout=30_000)
            name = label.inner_text().split(":")[0]
            page.keyboard.press("Escape")
            page.get_by_text("Click a patch in the view").wait_for(timeout=30_000)
            box = page.get_by_role("checkbox", name=name, exact=True)
            box.hover()                                  # as a user would, over the panel
            time.sleep(0.5)
            box = box.element_handle()
            painted = []                                 # wall clock of each repaint
            paint = page_server._paint_mesh
            page_server._paint_mesh = lambda *a: (paint(*a), painted.append(time.time()))
            ms, server = [], []
            for _ in range(args.toggles):
                del painted[:]
                seen, wall = page.evaluate(_TOGGLE_JS, [box, x - canvas["x"],
                                                        y - canvas["y"]])
                ms.append(seen)
                server.append(1000 * painted[0] - wall if painted else None)
                time.sleep(0.3)                          # let the session catch up
            browser.close()
    finally:
        page_server.close()
        shutil.rmtree(tmp)
    seen = [m for m in ms if m is not None]
    print(f"toggle ({name}, {len(ms)} clicks, alternating untick / tick): seen after a median "
          f"{statistics.median(seen):.0f} ms, max {max(seen):.0f} ms, "
          f"{len(ms) - len(seen)} not seen within 10 s; all {[m and round(m) for m in ms]}")
    server = [m for m in server if m is not None]
    print(f"  of which click -> the page's repaint call in Python: median "
          f"{statistics.median(server):.0f} ms, max {max(server):.0f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
