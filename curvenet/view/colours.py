"""The colours pictures give routes and wires: one table for previews and contact sheets."""

from __future__ import annotations

from ..route.decision import Route

__all__ = ["ROUTE_COLOURS", "WIRE_COLOUR", "FAILED_COLOUR"]

#: RGB in [0, 1] per route (and per patch surfacer that has a colour of its own): the
#: faces a route made in a preview, the frame of a contact-sheet tile.
ROUTE_COLOURS = {Route.CLASSICAL: (0.55, 0.68, 0.88), Route.NEURAL: (0.93, 0.60, 0.32),
                 Route.HYBRID: (0.66, 0.50, 0.80), "soapfilm": (0.45, 0.74, 0.52)}
#: Wires (strokes kept beside the surface).
WIRE_COLOUR = (0.10, 0.55, 0.25)
#: A contact-sheet tile of a file that failed.
FAILED_COLOUR = (0.75, 0.15, 0.18)
