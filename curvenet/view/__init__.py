"""Pictures: ``--preview`` renders of networks, patches and surfaces, and the batch
contact sheet, in one set of colours."""

from .colours import (CURVE_COLOURS, FAILED_COLOUR, HIGHLIGHT_COLOUR, ROUTE_COLOURS,
                      WIRE_COLOUR, patch_colours)
from .contact_sheet import contact_sheet
from .decimate import decimate_clustering
from .preview import DEFAULT_VIEWS, MAX_PREVIEW_FACES, patch_polygons, render_preview

__all__ = ["render_preview", "patch_polygons", "decimate_clustering", "DEFAULT_VIEWS",
           "MAX_PREVIEW_FACES", "contact_sheet", "ROUTE_COLOURS", "WIRE_COLOUR",
           "FAILED_COLOUR", "CURVE_COLOURS", "HIGHLIGHT_COLOUR", "patch_colours"]
