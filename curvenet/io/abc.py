"""Reader of the ABC dataset's feature-curve files (``*_features_*.yml``).

An ABC model (Koch et al. 2019, Onshape CAD models) ships its B-rep edges as a
YAML file with two lists. ``curves`` holds one mapping per edge::

    - type: Circle            # Line, Circle, Ellipse, BSpline or Other
      sharp: true             # a sharp (C0) edge of the solid
      vert_indices: [3, 17, 18, 4]        # mesh vertices along the edge
      vert_parameters: [0.0, 0.52, 1.05, 1.57]   # curve parameter at each
      location: [x, y, z]     # plus the analytic fields of the type below

with the analytic fields ``Line``: ``location``, ``direction``; ``Circle``:
``location``, ``radius``, ``x_axis``, ``y_axis``, ``z_axis``; ``Ellipse``:
``focus1``, ``focus2`` (or ``location``), ``maj_radius``, ``min_radius``,
``x_axis``, ``y_axis``, ``z_axis``; ``BSpline``: ``degree``, ``knots`` (the full
knot vector), ``poles``, ``weights``, ``rational``, ``closed``, ``periodic``.
``surfaces`` lists the faces with their ``type`` (Plane, Cylinder, ...); only the
type counts are kept.

Each curve is evaluated at its ``vert_parameters`` (no mesh needed): lines as
``location + t * direction``, circles and ellipses in their frame, splines with
:class:`scipy.interpolate.BSpline` (rational ones in homogeneous coordinates).
Points with the same ``vert_indices`` entry are one mesh vertex, so they are
merged to their mean: curves that meet share their end point exactly, which is
the junction. A full circle or a closed spline whose samples do not repeat the
first vertex is closed. ``sharp: true`` curves are labelled ``crease``, the others
``boundary``. ``Other`` curves carry no analytic form and are skipped with a
warning.

The public files store, for some circles and ellipses, the parameters between
the first and the last multiplied by 1000 (the first and last are not). The
parameters along an edge run one way, so a circle or ellipse whose parameters do
not, and do once the interior ones are divided by 1000, is read so.
"""

from __future__ import annotations

import warnings

import numpy as np

from ..core.errors import MissingDependencyError, SketchFormatError

__all__ = ["read_abc_features", "looks_like_abc"]

#: Curve types with an analytic form this reader evaluates.
CURVE_TYPES = ("Line", "Circle", "Ellipse", "BSpline")
_TWO_PI = 2.0 * np.pi


class _CurveError(ValueError):
    """A curve entry is malformed (message without file or curve; added by the caller)."""


def looks_like_abc(text: str) -> bool:
    """Whether ``text`` starts like an ABC features file (a top-level ``curves:`` or
    ``surfaces:`` key before any other content)."""
    for ln in text.splitlines()[:200]:
        s = ln.strip()
        if not s or s.startswith("#") or s == "---":
            continue
        return s.startswith(("curves:", "surfaces:"))
    return False


def _vec(c, key, n=3):
    """Field ``key`` of curve mapping ``c`` as a finite ``(n,) float64``."""
    if key not in c:
        raise _CurveError(f"missing {key!r}")
    try:
        v = np.asarray(c[key], dtype=np.float64)
    except (TypeError, ValueError):
        raise _CurveError(f"{key!r} is not a list of numbers") from None
    if v.shape != (n,) or not np.isfinite(v).all():
        raise _CurveError(f"{key!r} must be {n} finite numbers, got {c[key]!r}")
    return v


def _scalar(c, key):
    v = _vec(c, key, 1) if isinstance(c.get(key), list) else None
    if v is not None:
        return float(v[0])
    if key not in c:
        raise _CurveError(f"missing {key!r}")
    try:
        x = float(c[key])
    except (TypeError, ValueError):
        raise _CurveError(f"{key!r} is not a number: {c[key]!r}") from None
    if not np.isfinite(x):
        raise _CurveError(f"{key!r} is not finite")
    return x


def _monotone(t):
    d = np.diff(t)
    return bool((d > 0).all() or (d < 0).all())


def _unscale_interior(t):
    """Undo the x1000 storage of interior circle/ellipse parameters where it shows.

    Returns the corrected parameters and whether they were rescaled.
    """
    if len(t) < 3 or _monotone(t):
        return t, False
    fixed = t.copy()
    fixed[1:-1] /= 1000.0
    if _monotone(fixed):
        return fixed, True
    return t, False


def _conic(c, t, kind):
    """Circle or ellipse points at parameters ``t``; returns (points, rescaled)."""
    x_ax, y_ax = _vec(c, "x_axis"), _vec(c, "y_axis")
    if kind == "Circle":
        a = b = _scalar(c, "radius")
        centre = _vec(c, "location")
    else:
        a, b = _scalar(c, "maj_radius"), _scalar(c, "min_radius")
        centre = (_vec(c, "location") if "location" in c else
                  0.5 * (_vec(c, "focus1") + _vec(c, "focus2")))
    if not (a > 0 and b > 0):
        raise _CurveError(f"radii must be > 0, got {a!r}, {b!r}")
    t, rescaled = _unscale_interior(t)
    pts = centre + np.outer(a * np.cos(t), x_ax) + np.outer(b * np.sin(t), y_ax)
    return pts, t, rescaled


def _bspline(c, t):
    """B-spline (rational when ``rational``) points at parameters ``t``."""
    from scipy.interpolate import BSpline

    try:
        deg = int(c["degree"])
        knots = np.asarray(c["knots"], dtype=np.float64)
        poles = np.asarray(c["poles"], dtype=np.float64)
    except KeyError as err:
        raise _CurveError(f"missing {err.args[0]!r}") from None
    except (TypeError, ValueError):
        raise _CurveError("degree, knots and poles must be numbers") from None
    if poles.ndim != 2 or poles.shape[1] != 3 or deg < 1:
        raise _CurveError(f"poles must be a list of [x, y, z] and degree >= 1, got "
                          f"{poles.shape} poles of degree {deg}")
    if knots.shape != (len(poles) + deg + 1,):
        raise _CurveError(f"{len(knots)} knots for {len(poles)} poles of degree {deg}; "
                          f"expected {len(poles) + deg + 1}")
    if np.any(np.diff(knots) < 0) or not (np.isfinite(knots).all() and np.isfinite(poles).all()):
        raise _CurveError("knots must be finite and non-decreasing, poles finite")
    coef = poles
    if c.get("rational", False):
        w = np.asarray(c.get("weights", np.ones(len(poles))), dtype=np.float64)
        if w.shape != (len(poles),) or not (w > 0).all():
            raise _CurveError(f"weights must be {len(poles)} positive numbers")
        coef = np.hstack([poles * w[:, None], w[:, None]])
    ext = "periodic" if c.get("periodic", False) else True
    val = BSpline(knots, coef, deg, extrapolate=ext)(t)
    return val[:, :3] / val[:, 3:] if coef is not poles else val


def _evaluate(c):
    """Points ``(m, 3)``, vertex ids ``(m,)`` and whether the x1000 fix applied."""
    if not isinstance(c, dict):
        raise _CurveError("is not a mapping")
    try:
        t = np.asarray(c["vert_parameters"], dtype=np.float64).ravel()
        vid = np.asarray(c["vert_indices"], dtype=np.int64).ravel()
    except KeyError as err:
        raise _CurveError(f"missing {err.args[0]!r}") from None
    except (TypeError, ValueError):
        raise _CurveError("vert_parameters / vert_indices are not lists of numbers") from None
    if len(t) != len(vid):
        raise _CurveError(f"{len(vid)} vert_indices but {len(t)} vert_parameters")
    if not np.isfinite(t).all():
        raise _CurveError("non-finite vert_parameters")
    kind, rescaled, closed = c.get("type"), False, bool(c.get("closed", False))
    if kind == "Line":
        pts = _vec(c, "location") + np.outer(t, _vec(c, "direction"))
    elif kind in ("Circle", "Ellipse"):
        pts, t, rescaled = _conic(c, t, kind)
        step = np.median(np.abs(np.diff(t))) if len(t) > 1 else 0.0
        closed = len(t) > 2 and abs(t[-1] - t[0]) + 1.5 * step >= _TWO_PI
    else:
        pts = _bspline(c, t)
    if closed and len(vid) > 2 and vid[0] != vid[-1]:
        pts, vid = np.vstack([pts, pts[:1]]), np.append(vid, vid[0])
    return pts, vid, rescaled


def _load_yaml(text, path):
    try:
        import yaml
    except ImportError:  # pragma: no cover - pyyaml is a core dependency
        raise MissingDependencyError("reading ABC .yml files needs PyYAML "
                                     "(pip install pyyaml)") from None
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    try:
        return yaml.load(text, Loader=loader)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        what = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise SketchFormatError(f"invalid YAML: {what}", path=path,
                                line=None if mark is None else mark.line + 1) from None


def _curve_line(text, i):
    """1-based line where ``curves[i]`` starts (composed only on the error path)."""
    import yaml

    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    try:
        root = yaml.compose(text, Loader=loader)
        for key, val in root.value:
            if key.value == "curves":
                return val.value[i].start_mark.line + 1
    except (yaml.YAMLError, AttributeError, IndexError, TypeError):
        return None
    return None


def _type_counts(items):
    out: dict = {}
    for it in items:
        k = str(it.get("type", "?")) if isinstance(it, dict) else "?"
        out[k] = out.get(k, 0) + 1
    return out


def read_abc_features(text: str, path=None):
    """Strokes of an ABC features file.

    Parameters
    ----------
    text : str
        The YAML text.
    path : str or os.PathLike, optional
        The file, for messages.

    Returns
    -------
    strokes : list of (m_i, 3) float64
        One polyline per evaluated curve, in file order; shared vertices identical.
    labels : list of str
        ``crease`` for ``sharp: true`` curves, else ``boundary``.
    metadata : dict
        ``abc``: ``curve_types`` and ``surface_types`` (counts), ``curve_index`` (file
        index of each stroke), ``rescaled_curves`` (file indices read with the x1000
        fix) and ``skipped_curves`` (file indices of curves with no analytic form).
        ``warnings`` names the skipped curves (also issued as a warning).

    Raises
    ------
    SketchFormatError
        Invalid YAML (with its line) or a malformed curve: the message names the file,
        the curve index and, where it can be found, the curve's line.
    """
    data = _load_yaml(text, path)
    if not isinstance(data, dict) or not isinstance(data.get("curves"), list):
        raise SketchFormatError("not an ABC features file (no list 'curves')", path=path)
    curves = data["curves"]
    pts, vids, labels, index, rescaled, skipped, warns = [], [], [], [], [], [], []
    for i, c in enumerate(curves):
        if isinstance(c, dict) and c.get("type") not in CURVE_TYPES:
            skipped.append(i)
            warns.append(f"curves[{i}]: type {c.get('type')!r} has no analytic form")
            continue
        try:
            p, v, fix = _evaluate(c)
        except _CurveError as err:
            kind = c.get("type") if isinstance(c, dict) else type(c).__name__
            raise SketchFormatError(f"curves[{i}] ({kind}): {err}", path=path,
                                    line=_curve_line(text, i)) from None
        pts.append(p)
        vids.append(v)
        labels.append("crease" if isinstance(c, dict) and c.get("sharp") is True
                      else "boundary")
        index.append(i)
        if fix:
            rescaled.append(i)
    if pts:
        allp, allv = np.vstack(pts), np.concatenate(vids)
        _, inv, cnt = np.unique(allv, return_inverse=True, return_counts=True)
        mean = np.stack([np.bincount(inv, allp[:, k]) for k in range(3)], axis=1) / cnt[:, None]
        merged = mean[inv]
        pts = np.split(merged, np.cumsum([len(p) for p in pts])[:-1])
    surfaces = data.get("surfaces") or []
    meta = {"abc": {"curve_types": _type_counts(curves),
                    "surface_types": _type_counts(surfaces if isinstance(surfaces, list) else []),
                    "curve_index": index, "rescaled_curves": rescaled,
                    "skipped_curves": skipped}}
    if warns:
        meta["warnings"] = warns
        more = f" and {len(warns) - 1} more" if len(warns) > 1 else ""
        warnings.warn(f"{path}: {warns[0]}{more} (skipped)", stacklevel=3)
    return list(pts), labels, meta
