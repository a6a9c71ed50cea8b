"""Which surfacer serves a sketch, and why: the route decision as data.

:func:`curvenet.surface` fills a :class:`RouteDecision`; :meth:`RouteDecision.explain`
turns it into the sentence ``curvenet surface --explain`` prints. ``regions`` is kept
for decisions made per region of the network (one entry per region).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from ..model.patchset import PatchSet

__all__ = ["AUTO_MIN_COVERAGE", "MAX_WIRE_SHARE", "RouteDecision", "REASONS", "coverage",
           "auto_route", "region_route"]

#: auto mode takes the classical route when at least this fraction of the
#: network's curve length lies on curves used by some patch.
AUTO_MIN_COVERAGE = 0.8

#: the per-region route keeps the curves that bound nothing as wires only while they
#: carry at most this fraction of the curve length (else auto's per-sketch rule holds)
MAX_WIRE_SHARE = 0.5

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
}


@dataclass
class RouteDecision:
    """The route :func:`curvenet.surface` took, as data (``dataclasses.asdict`` gives JSON).

    Attributes
    ----------
    method : str
        ``"classical"`` or ``"neural"`` (what ``auto`` chose), or the method requested.
    surfacer : str
        Registry name of the surfacer that ran (:mod:`curvenet.route.registry`).
    reason : str
        A key of :data:`REASONS`: ``"requested"``, ``"no_cycles"``, ``"low_coverage"``
        or ``"covered"``.
    coverage : float or None
        Fraction of the curve length on curves some patch uses (None: no patches sought).
    patches : int or None
        Number of patches found (None: no patches sought).
    min_coverage : float
        The auto threshold the coverage was compared with.
    regions : list
        Per-region decisions, for routes that choose per region (empty otherwise).

    Examples
    --------
    >>> RouteDecision("classical", "catmull-clark", "covered", 1.0, 6).explain()
    'classical: 6 patches cover 100% of the curve length (>= 80%)'
    """

    method: str
    surfacer: str
    reason: str
    coverage: float | None = None
    patches: int | None = None
    min_coverage: float = AUTO_MIN_COVERAGE
    regions: list = field(default_factory=list)

    def explain(self) -> str:
        """``"<method>: <why>"``, the sentence ``--explain`` prints."""
        return f"{self.method}: " + REASONS[self.reason].format(**asdict(self))

    def explain_regions(self) -> list:
        """One line per region: ``"<route>: <n> curves, <share> of the curve length"``.

        A neural fill's line also says along what share of the patch curves it reaches
        it meets the patches (``seam``, :func:`curvenet.route.hybrid.fill_seam`).
        """
        total = sum(r["length"] for r in self.regions) or 1.0
        return [f"{r['route']}: {len(r['curves'])} curves, {r['length'] / total:.0%} of the "
                f"curve length" + (f" ({r['patches']} patches)" if "patches" in r else "")
                + (f"; meets the patches along {r['seam']:.0%} of the shared curves it "
                   f"reaches" if r.get("seam") is not None else "")
                for r in self.regions]


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
        return RouteDecision("neural", stroke_surfacer, "no_cycles", **common)
    if cov < min_coverage:
        return RouteDecision("neural", stroke_surfacer, "low_coverage", **common)
    return RouteDecision("classical", patch_surfacer, "covered", **common)


def region_route(n_patches: int, cov: float, regions: list, covered: dict, *,
                 patch_surfacer: str, stroke_surfacer: str,
                 min_coverage: float = AUTO_MIN_COVERAGE) -> RouteDecision:
    """Auto's rule per region (:func:`curvenet.route.hybrid.plan_regions` made ``regions``).

    Patches where cycles exist; the neural route alone when there are none, or when the
    surface-like regions carry more curve length than the patches; auto's per-sketch
    rule (:func:`auto_route`) when wires would carry more than :data:`MAX_WIRE_SHARE`
    of it; else per region: patches, a neural fill for surface-like regions, wires.

    Parameters
    ----------
    regions : list of dict
        Regions of the curves no patch uses (``route``, ``curves``, ``length``).
    covered : dict
        The classical region: ``route="classical"``, ``curves``, ``length``, ``patches``.

    Examples
    --------
    >>> wire = {"route": "wires", "curves": [7], "length": 1.0}
    >>> patched = {"route": "classical", "curves": [0, 1, 2], "length": 3.0, "patches": 1}
    >>> d = region_route(1, 0.75, [wire], patched, patch_surfacer="catmull-clark",
    ...                  stroke_surfacer="neural")
    >>> d.method
    'classical'
    >>> print(*d.explain_regions(), sep=chr(10))
    classical: 3 curves, 75% of the curve length (1 patches)
    wires: 1 curves, 25% of the curve length
    """
    base = auto_route(n_patches, cov, patch_surfacer=patch_surfacer,
                      stroke_surfacer=stroke_surfacer, min_coverage=min_coverage)
    if not n_patches or not regions:
        return base
    total = covered["length"] + sum(r["length"] for r in regions)
    fill = sum(r["length"] for r in regions if r["route"] == "neural")
    wires = sum(r["length"] for r in regions if r["route"] == "wires")
    common = dict(coverage=cov, patches=n_patches, min_coverage=min_coverage,
                  regions=[covered] + regions)
    if fill > covered["length"]:
        common["regions"] = []
        return RouteDecision("neural", stroke_surfacer, "unstructured", **common)
    if wires > MAX_WIRE_SHARE * total:
        return base
    if not fill:
        reason = "covered" if cov >= min_coverage else "hybrid"
        return RouteDecision("classical", patch_surfacer, reason, **common)
    return RouteDecision("hybrid", f"{patch_surfacer}+{stroke_surfacer}", "hybrid", **common)
