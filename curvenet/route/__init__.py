"""Which surfacer serves which region, and the registry of surfacers."""

from .decision import (AUTO_MIN_COVERAGE, MAX_WIRE_SHARE, RouteDecision, REASONS, coverage, auto_route, region_route)
from .registry import (NEEDS, SurfaceSettings, SurfaceInput, Surfacer, register_surfacer, unregister_surfacer,
    get_surfacer, surfacer_names)

__all__ = ['AUTO_MIN_COVERAGE', 'MAX_WIRE_SHARE', 'RouteDecision', 'REASONS', 'coverage', 'auto_route',
    'region_route', 'NEEDS', 'SurfaceSettings', 'SurfaceInput', 'Surfacer', 'register_surfacer',
    'unregister_surfacer', 'get_surfacer', 'surfacer_names']
