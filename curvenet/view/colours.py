"""The colours pictures give routes, wires, curves and patches: one table for previews,
contact sheets and the review page."""

from __future__ import annotations

import colorsys

import numpy as np

from ..route.decision import Route

__all__ = ["ROUTE_COLOURS", "WIRE_COLOUR", "FAILED_COLOUR", "CURVE_COLOURS",
           "HIGHLIGHT_COLOUR", "patch_colours"]

#: RGB in [0, 1] per route (and per patch surfacer that has a colour of its own): the
#: faces a route made in a preview, the frame of a contact-sheet tile.
ROUTE_COLOURS = {Route.CLASSICAL: (0.55, 0.68, 0.88), Route.NEURAL: (0.93, 0.60, 0.32),
                 Route.HYBRID: (0.66, 0.50, 0.80), "soapfilm": (0.45, 0.74, 0.52)}
#: Wires (strokes kept beside the surface).
WIRE_COLOUR = (0.10, 0.55, 0.25)
#: A contact-sheet tile of a file that failed.
FAILED_COLOUR = (0.75, 0.15, 0.18)
#: Network curves by label.
CURVE_COLOURS = {"boundary": (0.12, 0.23, 0.45), "crease": (0.75, 0.22, 0.17)}
#: Highlight (a selected or suggested patch): saturated orange, never made by
#: :func:`patch_colours` (its saturation is 0.45), so tests can find it in a picture.
HIGHLIGHT_COLOUR = (1.0, 0.45, 0.0)
#: Hue step of :func:`patch_colours` (the golden ratio's fractional part: neighbours in
#: the list differ in hue, and no two of the first hundreds coincide).
_HUE_STEP = 0.618033988749895


def patch_colours(k: int) -> np.ndarray:
    """``(k, 3) float64`` RGB in [0, 1], one per patch: golden-ratio hue steps.

    Saturation 0.45 and value 0.95, so patches read as pastel fills under the
    network's dark curves; patch ``i`` has the same colour in every picture.
    """
    hues = (0.1 + _HUE_STEP * np.arange(int(k))) % 1.0
    return np.array([colorsys.hsv_to_rgb(h, 0.45, 0.95) for h in hues],
                    dtype=np.float64).reshape(-1, 3)
