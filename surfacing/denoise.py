"""Per-sample noise of drawn curves: smoothed away for the fit, put back on the mesh.

A curve drawn with a tracker's jitter or a shaking hand turns at every sample. The fit
interpolates the samples (Orbay & Kara 2011, Sec. 4.3.2), the pieces of a curve grow
with its turning (:func:`surfacing.pieces.piece_counts`), and the noise goes into the
faces: a sparse torus drawn so comes out crumpled, with thousands of control vertices
where a hundred shape it.

:func:`smooth_curves` finds the curves whose samples stray from their neighbours' chord
by more than the fit's tolerance (by the median), fits each with a smoothing spline whose
weight generalised cross-validation chooses (Craven & Wahba 1979, through
:func:`scipy.interpolate.make_smoothing_spline`), its ends held, and keeps the smoothing
only where what it took away looks like noise: above the tolerance, and white (its
lag-1 autocorrelation at most :data:`MAX_AUTOCORRELATION`), as a drawn shape's detail
is not. The patches are surfaced from the smoothed curves; :func:`restore` then puts
what was taken away back on the mesh, exactly at the vertices on the curves and
harmonically inside the patches, so the mesh still meets every stroke where it was
drawn and the faces between keep the fit's smooth shape.

Notes
-----
Not in the papers: Orbay and Kara take the curves as exact. The mesh keeps the strokes;
the control net (and a CAD export of it) is the smoothed surface, off the strokes by
their noise.
"""

from __future__ import annotations

import numpy as np

from curvenet.core.geometry import bbox_diagonal, cumulative_length, harmonic_fill
from curvenet.core.tolerances import ZERO_LENGTH

from .polyline import closest_on_segments

__all__ = ["smooth_curves", "restore", "chord_offsets", "explain_denoised", "MIN_SAMPLES",
           "MAX_AUTOCORRELATION", "END_WEIGHT"]

#: Fewest samples of a curve that is smoothed: fewer do not tell noise from shape.
MIN_SAMPLES = 16
#: Largest lag-1 autocorrelation of what a kept smoothing takes away. Jitter is white
#: (near 0); the smoothing of a drawn detail takes away a correlated bump (near 1).
MAX_AUTOCORRELATION = 0.5


def chord_offsets(curve) -> np.ndarray:
    """Distance of each interior sample of a polyline from the chord of its neighbours.

    Parameters
    ----------
    curve : (m, 3) float64

    Returns
    -------
    (max(m - 2, 0),) float64

    Examples
    --------
    >>> chord_offsets(np.array([[0.0, 0, 0], [1, 1, 0], [2, 0, 0]])).tolist()
    [1.0]
    """
    c = np.asarray(curve, dtype=np.float64)
    if len(c) < 3:
        return np.zeros(0)
    return closest_on_segments(c[1:-1], c[:-2], c[2:])[1]


#: Weight of a curve's two end samples in its smoothing (the others weigh 1): the ends
#: are junctions, which the smoothing must keep.
END_WEIGHT = 1e6


def _smoothed(curve: np.ndarray) -> np.ndarray | None:
    """The GCV smoothing spline of each coordinate over arc length, its ends weighted
    :data:`END_WEIGHT` and then held exactly (the residual's linear blend between them
    added back); None where it cannot be fitted."""
    from scipy.interpolate import make_smoothing_spline
    cum = cumulative_length(curve)
    keep = np.r_[True, np.diff(cum) > ZERO_LENGTH]
    x = cum[keep]
    if len(x) < MIN_SAMPLES:
        return None
    w = np.ones(len(x))
    w[[0, -1]] = END_WEIGHT
    try:
        s = np.stack([make_smoothing_spline(x, curve[keep, k], w=w)(cum) for k in range(3)],
                     axis=1)
    except (ValueError, np.linalg.LinAlgError):
        return None
    t = (cum / cum[-1])[:, None]
    r = curve - s
    return s + (1.0 - t) * r[0] + t * r[-1]


def smooth_curves(curves, tol: float):
    """Curves with per-sample noise, smoothed.

    Parameters
    ----------
    curves : list of (m_i, 3) float64
    tol : float
        Fraction of the curves' diagonal: a curve is tried when the median of its
        :func:`chord_offsets` is above it, and its smoothing kept when the residual's
        root mean square is too (and the residual is white).

    Returns
    -------
    smoothed : list of (m_i, 3) float64
        The curves, smoothed ones replaced (same samples, same ends).
    report : list of dict
        Per smoothed curve ``{"curve": index, "rms": residual RMS, "max": largest
        residual}``, fractions of the diagonal.

    Examples
    --------
    >>> t = np.linspace(0, 2 * np.pi, 200)
    >>> ring = np.c_[np.cos(t), np.sin(t), 0 * t]
    >>> noisy = ring + np.random.default_rng(0).normal(0, 0.004, ring.shape)
    >>> noisy[[0, -1]] = ring[[0, -1]]
    >>> out, rep = smooth_curves([ring, noisy], 1e-4)
    >>> [r["curve"] for r in rep], bool(np.abs(out[0] - ring).max() == 0)
    ([1], True)
    >>> off = lambda p: np.abs(np.linalg.norm(p, axis=1) - 1).mean()  # from the circle
    >>> bool(off(out[1]) < 0.4 * off(noisy))
    True
    """
    curves = [np.asarray(c, dtype=np.float64) for c in curves]
    diag = bbox_diagonal(curves) or 1.0
    out, report = list(curves), []
    for i, c in enumerate(curves):
        if len(c) < MIN_SAMPLES or np.median(chord_offsets(c)) <= tol * diag:
            continue
        s = _smoothed(c)
        if s is None:
            continue
        r = c - s
        rms = float(np.sqrt((r * r).sum(axis=1).mean()))
        white = (r[:-1] * r[1:]).sum() <= MAX_AUTOCORRELATION * (r * r).sum()
        if rms > tol * diag and white:
            out[i] = s
            report.append({"curve": i, "rms": rms / diag,
                           "max": float(np.linalg.norm(r, axis=1).max()) / diag})
    return out, report


def restore(V, F, face_patch, smoothed, curves) -> np.ndarray:
    """Put the noise :func:`smooth_curves` took away back on a mesh of the smoothed curves.

    Parameters
    ----------
    V : (n, 3) float64
        Mesh vertices; those on the curves (used by faces of two patches, or on an open
        border) lie on ``smoothed``.
    F : (f, 3) int64
    face_patch : (f,) int64
        Patch of each triangle.
    smoothed, curves : list of (m_i, 3) float64
        The smoothed curves and the drawn ones, sample for sample.

    Returns
    -------
    (n, 3) float64
        A copy of ``V``: each vertex on a curve moved by the residual (drawn minus
        smoothed) at its closest point of the nearest smoothed curve, linear between
        samples; the vertices inside the patches by the residuals' harmonic interpolation.
    """
    from scipy.spatial import cKDTree
    from .regions import interior_patch
    V = np.array(V, dtype=np.float64)
    if not len(V) or all(s is c for s, c in zip(smoothed, curves)):
        return V
    pts = np.concatenate([np.asarray(s, np.float64) for s in smoothed])
    res = np.concatenate([np.asarray(c, np.float64) - np.asarray(s, np.float64)
                          for s, c in zip(smoothed, curves)])
    sizes = np.array([len(s) for s in smoothed])
    first = np.repeat(np.cumsum(sizes) - sizes, sizes)
    last = first + np.repeat(sizes, sizes) - 1
    edges, owner = interior_patch(F, face_patch, len(V))
    on = np.flatnonzero(owner == -1)
    _, j = cKDTree(pts).query(V[on])
    best_d = np.full(len(on), np.inf)
    shift = np.zeros((len(on), 3))
    for a, b in ((np.maximum(j - 1, first[j]), j), (j, np.minimum(j + 1, last[j]))):
        t, d = closest_on_segments(V[on], pts[a], pts[b])
        t = t[:, None]
        closer = d < best_d
        best_d = np.where(closer, d, best_d)
        shift[closer] = ((1.0 - t) * res[a] + t * res[b])[closer]
    values = np.zeros_like(V)
    values[on] = shift
    return V + harmonic_fill(edges, owner != -1, values)


def explain_denoised(report) -> str | None:
    """The line ``--explain`` prints about the curves :func:`smooth_curves` smoothed.

    Parameters
    ----------
    report : dict or None
        A :func:`surfacing.sectors.surface_boundaries` report (its ``denoised``).

    Returns
    -------
    str or None
        None when no curve was smoothed.

    Examples
    --------
    >>> print(explain_denoised({"denoised": [{"curve": 3, "rms": 0.002, "max": 0.0061},
    ...                                      {"curve": 7, "rms": 0.0018, "max": 0.0052}]}))
    smoothed: 2 curves of per-sample noise (RMS 0.18%-0.20%, at most 0.61% of the diagonal)
    >>> print(explain_denoised({"denoised": [{"curve": 0, "rms": 0.001, "max": 0.0021}]}))
    smoothed: 1 curve of per-sample noise (RMS 0.10%, at most 0.21% of the diagonal)
    """
    rows = (report or {}).get("denoised")
    if not rows:
        return None
    lo, hi = (f"{f([r['rms'] for r in rows]):.2%}" for f in (min, max))
    return (f"smoothed: {len(rows)} curve{'s' * (len(rows) > 1)} of per-sample noise "
            f"(RMS {lo if lo == hi else f'{lo}-{hi}'}, at most "
            f"{max(r['max'] for r in rows):.2%} of the diagonal)")
