"""Which surfacer serves which region of a sketch, and the registry of surfacers.

Importing this package registers the built-in surfacers (:mod:`.builtins`).
"""

from . import builtins as _builtins  # noqa: F401  (registers the built-in surfacers)
from .decision import (AUTO_MIN_COVERAGE, MAX_WIRE_SHARE, REASONS, Region, Route,
                       RouteDecision, auto_route, coverage, region_route)
from .registry import (NEEDS, SurfaceInput, Surfacer, SurfaceSettings, get_surfacer,
                       register_surfacer, surfacer_names, unregister_surfacer)

__all__ = ["Route", "Region", "RouteDecision", "REASONS", "AUTO_MIN_COVERAGE",
           "MAX_WIRE_SHARE", "coverage", "auto_route", "region_route", "NEEDS",
           "SurfaceSettings", "SurfaceInput", "Surfacer", "register_surfacer",
           "unregister_surfacer", "get_surfacer", "surfacer_names"]
