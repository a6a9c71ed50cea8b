"""Which surfacer serves a sketch, and why: the route decision as data.

:func:`curvenet.surface` fills a :class:`RouteDecision`; :meth:`RouteDecision.explain`
turns it into the sentence ``curvenet surface --explain`` prints. A decision made per
region of the network (``auto``) lists its :class:`Region` s, the patched one first.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from enum import Enum

import numpy as np

from ..model.patchset import PatchSet

__all__ = ["Route", "Region", "AUTO_MIN_COVERAGE", "MAX_WIRE_SHARE", "RouteDecision", "REASONS",
           "coverage", "auto_route", "region_route"]

#: auto mode takes the classical route when at least this fraction of the
#: network's curve length lies on curves used by some patch.
AUTO_MIN_COVERAGE = 0.8

#: the per-region route keeps the curves that bound nothing as wires only while they
#: carry at most this fraction of the curve length (else auto's per-sketch rule holds)
MAX_WIRE_SHARE = 0.5


class Route(str, Enum):
    """The routes a surface (or a part of it) can take.

    A ``str`` subclass: ``Route.CLASSICAL == "classical"``, and it prints, formats and
    serialises to JSON as its value.

    Examples
    --------
    >>> Route("neural"), f"{Route.HYBRID}", Route.CLASSICAL == "classical"
    (<Route.NEURAL: 'neural'>, 'hybrid', True)
    """

    CLASSICAL = "classical"   # patches, surfaced from their boundary curves
    NEURAL = "neural"         # an implicit surface fitted to the strokes
    HYBRID = "hybrid"         # patches, and a neural fill for the regions no patch covers
    WIRES = "wires"           # strokes kept as polylines, no surface

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)


@dataclass
class Region:
    """A group of network curves and the route auto chose for it.

    Attributes
    ----------
    route : Route
        ``CLASSICAL`` (the curves some patch uses), ``NEURAL`` (a surface-like region of
        unused curves: a neural fill) or ``WIRES``.
    curves : list of int
        Curve (edge) ids of the network.
    length : float
        Their curve length, input units.
    patches : int or None
        Patches of the classical region (None for the others).
    fill, spread : float or None
        The figures of the surface-like test (:func:`curvenet.route.regions.plan_regions`):
        share of the region's convex hull near a curve, short over long side.
    faces, anchors : int or None
        A fill's kept faces and the patch samples it was fitted with (after surfacing).
    seam_fit, seam, seam_fit_p95, seam_p95, seam_moved : float or None
        Where a fill meets the patches (:func:`curvenet.route.hybrid.fill_seam`) before
        and after its boundary is moved onto them, and the longest move (fractions of
        the network's diagonal; shares for ``seam_fit``, ``seam``).
    """

    route: Route
    curves: list
    length: float
    patches: int | None = None
    fill: float | None = None
    spread: float | None = None
    faces: int | None = None
    anchors: int | None = None
    seam_fit: float | None = None
    seam: float | None = None
    seam_fit_p95: float | None = None
    seam_p95: float | None = None
    seam_moved: float | None = None

    def __post_init__(self):
        self.route = Route(self.route)

    def explain(self, total: float) -> str:
        """``"<route>: <n> curves, <share> of the curve length ..."``, ``total`` the whole
        network's curve length; a fill also says how it meets the patches."""
        return (f"{self.route}: {len(self.curves)} curves, {self.length / total:.0%} of the "
                f"curve length" + (f" ({self.patches} patches)" if self.patches is not None
                                   else "")
                + (f"; meets the patches along {self.seam:.0%} of the shared curves it "
                   f"reaches" if self.seam is not None else ""))


#: reason code -> sentence (``str.format`` over the decision's fields)
REASONS = {
    "requested": "requested",
    "no_cycles": "the strokes form no cycles that can be patches",
    "low_coverage": "patches cover only {coverage:.0%} of the curve length "
                    "(< {min_coverage:.0%})",
    "covered": "{patches} patches cover {coverage:.0%} of the curve length "
               "(>= {min_coverage:.0%})",
    "hybrid": "{patches} patches cover {coverage:.0%} of the curve length; the rest "
              "is filled per region",
    "unstructured": "patches cover only {coverage:.0%} of the curve length and most of "
                    "the rest spans area: one neural surface",
    "judged": "{patches} patches cover {coverage:.0%} of the curve length, but every patch "
              "set leaves walls inside the shape (check below): one neural surface",
}


@dataclass
class RouteDecision:
    """The route :func:`curvenet.surface` took, as data (``dataclasses.asdict`` gives JSON).

    Attributes
    ----------
    route : Route or str
        The route auto chose, or the method requested (a surfacer's name).
    surfacer : str
        Registry name of the surfacer that runs (:mod:`curvenet.route.registry`); the
        hybrid route's is the composite ``"hybrid"``.
    reason : str
        A key of :data:`REASONS`.
    coverage : float or None
        Fraction of the curve length on curves some patch uses (None: no patches sought).
    patches : int or None
        Number of patches found (None: no patches sought).
    min_coverage : float
        The auto threshold the coverage was compared with.
    regions : list of Region
        Per-region routes, the patched region first (empty unless auto chose per region).
    check : dict or None
        ``auto``'s judgement of the classical surface (:func:`curvenet.route.check.
        judge_patches`): ``walls`` (patch mode -> patches inside the shape the others
        bound), ``nonmanifold`` (curves bounding three or more patches), ``taken`` (the
        patch mode kept, or ``"neural"``); None when not judged.

    Examples
    --------
    >>> RouteDecision(Route.CLASSICAL, "catmull-clark", "covered", 1.0, 6).explain()
    'classical: 6 patches cover 100% of the curve length (>= 80%)'
    """

    route: Route | str
    surfacer: str
    reason: str
    coverage: float | None = None
    patches: int | None = None
    min_coverage: float = AUTO_MIN_COVERAGE
    regions: list = field(default_factory=list)
    check: dict | None = None

    def __post_init__(self):
        if self.route in Route._value2member_map_:
            self.route = Route(self.route)

    def explain(self) -> str:
        """``"<route>: <why>"``, the sentence ``--explain`` prints."""
        return f"{self.route}: " + REASONS[self.reason].format(**asdict(self))

    def explain_check(self) -> str | None:
        """The check's line of ``--explain`` (None when the surface was not judged): the
        walls (patches inside the shape the others bound) of each patch set judged.

        Examples
        --------
        >>> d = RouteDecision("classical", "catmull-clark", "covered", 1.0, 9,
        ...                   check={"walls": {"basis": 2, "faces": 0}, "nonmanifold": 2,
        ...                          "taken": "faces"})
        >>> print(d.explain_check())
        check: walls: basis 2, faces 0; kept the faces patches; 2 curves in 3+ patches
        """
        if self.check is None:
            return None
        walls = ", ".join(f"{mode} {n}" for mode, n in self.check["walls"].items())
        taken = self.check["taken"]
        kept = "took the neural route" if taken == "neural" else f"kept the {taken} patches"
        return f"check: walls: {walls}; {kept}; {self.check['nonmanifold']} curves in 3+ patches"

    def explain_regions(self) -> list:
        """One line per region (:meth:`Region.explain`)."""
        total = sum(r.length for r in self.regions) or 1.0
        return [r.explain(total) for r in self.regions]


def coverage(ps: PatchSet) -> tuple[float, list]:
    """Fraction of curve length on edges used by a patch, and the unused edge ids."""
    net = ps.network
    if not net.edges:
        return 0.0, []
    lengths = np.array([e.length() for e in net.edges])
    used = np.zeros(len(lengths), bool)
    for p in ps.patches:
        used[list(p.all_edges)] = True
    total = lengths.sum()
    cov = float(lengths[used].sum() / total) if total > 0 else 0.0
    return cov, [int(i) for i in np.flatnonzero(~used)]


def auto_route(n_patches: int, cov: float, *, patch_surfacer: str, stroke_surfacer: str,
               min_coverage: float = AUTO_MIN_COVERAGE) -> RouteDecision:
    """The auto rule: the classical route when patches cover at least ``min_coverage`` of
    the curve length, else the neural route.

    Examples
    --------
    >>> auto_route(0, 0.0, patch_surfacer="catmull-clark", stroke_surfacer="neural").explain()
    'neural: the strokes form no cycles that can be patches'
    """
    common = dict(coverage=cov, patches=n_patches, min_coverage=min_coverage)
    if not n_patches:
        return RouteDecision(Route.NEURAL, stroke_surfacer, "no_cycles", **common)
    if cov < min_coverage:
        return RouteDecision(Route.NEURAL, stroke_surfacer, "low_coverage", **common)
    return RouteDecision(Route.CLASSICAL, patch_surfacer, "covered", **common)


def region_route(n_patches: int, cov: float, regions: list, covered: Region, *,
                 patch_surfacer: str, stroke_surfacer: str, hybrid_surfacer: str = "hybrid",
                 min_coverage: float = AUTO_MIN_COVERAGE) -> RouteDecision:
    """Auto's rule per region (:func:`curvenet.route.regions.plan_regions` made ``regions``).

    Patches where cycles exist; the neural route alone when there are none, or when the
    surface-like regions carry more curve length than the patches; auto's per-sketch
    rule (:func:`auto_route`) when wires would carry more than :data:`MAX_WIRE_SHARE`
    of it; else per region: patches, a neural fill for surface-like regions, wires.

    Parameters
    ----------
    regions : list of Region
        Regions of the curves no patch uses.
    covered : Region
        The classical region: the curves the patches use.

    Examples
    --------
    >>> wire = Region(Route.WIRES, [7], 1.0)
    >>> patched = Region(Route.CLASSICAL, [0, 1, 2], 3.0, patches=1)
    >>> d = region_route(1, 0.75, [wire], patched, patch_surfacer="catmull-clark",
    ...                  stroke_surfacer="neural")
    >>> d.route
    <Route.CLASSICAL: 'classical'>
    >>> print(*d.explain_regions(), sep=chr(10))
    classical: 3 curves, 75% of the curve length (1 patches)
    wires: 1 curves, 25% of the curve length
    """
    base = auto_route(n_patches, cov, patch_surfacer=patch_surfacer,
                      stroke_surfacer=stroke_surfacer, min_coverage=min_coverage)
    if not n_patches or not regions:
        return base
    total = covered.length + sum(r.length for r in regions)
    fill = sum(r.length for r in regions if r.route is Route.NEURAL)
    wires = sum(r.length for r in regions if r.route is Route.WIRES)
    common = dict(coverage=cov, patches=n_patches, min_coverage=min_coverage,
                  regions=[covered] + regions)
    if fill > covered.length:
        common["regions"] = []
        return RouteDecision(Route.NEURAL, stroke_surfacer, "unstructured", **common)
    if wires > MAX_WIRE_SHARE * total:
        return base
    if not fill:
        reason = "covered" if cov >= min_coverage else "hybrid"
        return RouteDecision(Route.CLASSICAL, patch_surfacer, reason, **common)
    return RouteDecision(Route.HYBRID, hybrid_surfacer, "hybrid", **common)
