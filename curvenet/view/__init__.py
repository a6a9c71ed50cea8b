"""Pictures: ``--preview`` renders of networks, patches and surfaces, and the batch contact sheet."""

from .preview import (render_preview, patch_polygons, decimate_clustering, DEFAULT_VIEWS, MAX_PREVIEW_FACES,
    ROUTE_COLOURS, WIRE_COLOUR)
from .contact_sheet import contact_sheet

__all__ = ['render_preview', 'patch_polygons', 'decimate_clustering', 'DEFAULT_VIEWS',
    'MAX_PREVIEW_FACES', 'ROUTE_COLOURS', 'WIRE_COLOUR', 'contact_sheet']
