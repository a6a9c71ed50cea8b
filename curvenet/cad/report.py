"""What a CAD export reports, as the lines ``curvenet surface --explain`` prints."""

from __future__ import annotations

__all__ = ["cad_report_lines", "SEAMS_SHOWN"]

#: Smooth seams listed (largest G1 angle first).
SEAMS_SHOWN = 10


def cad_report_lines(cad: dict) -> list:
    """The lines ``curvenet surface --explain`` prints of a CAD export.

    Parameters
    ----------
    cad : dict
        What :func:`curvenet.pipeline.export_cad` returns (``pieces``, ``file``,
        ``faces``, ``seams``, ``sew_tolerance``).

    Returns
    -------
    list of str
        Faces by kind, the B-spline pieces, the file check, the seams and the
        worst smooth ones (largest G1 angle first).
    """
    pr, fr = cad["pieces"], cad["file"]
    kinds: dict = {}
    for f in cad["faces"]:
        kinds[f["kind"]] = kinds.get(f["kind"], 0) + 1
    analytic = [f["residual"] for f in cad["faces"] if f["residual"] is not None]
    lines = [f"cad: {len(cad['faces'])} faces ("
             + ", ".join(f"{n} {k}" for k, n in sorted(kinds.items())) + ")"
             + (f", largest analytic residual {max(analytic):.1e} of the diagonal"
                if analytic else "")]
    if kinds.get("bspline"):
        lines.append(f"cad: B-spline faces: {pr['n_exact']} of {pr['n_pieces']} pieces exact "
                     f"(level {pr['level']}, graded {max(pr['grades_used'], default=0)}), max "
                     f"deviation {pr['max_deviation']:.2e} of the diagonal")
    if "shells" in fr:                  # STEP; a 3DM report has breps (and valid too)
        lines.append(f"cad: {fr['shells']} shells, {fr['solids']} solids, {fr['free_edges']} "
                     f"free edges, valid {fr['valid']}, sewing tolerance "
                     f"{cad['sew_tolerance']:.2e}")
    else:
        lines.append(f"cad: {fr['breps']} joined Breps, {fr['solids']} closed, valid "
                     f"{fr['valid']}")
    seams = cad["seams"]
    smooth = [s for s in seams if not s["crease"]]
    lines.append(f"cad: {len(seams)} seams ({len(seams) - len(smooth)} creases), largest G0 gap "
                 f"{max((s['gap'] for s in seams), default=0.0):.1e} of the diagonal, largest "
                 f"G1 angle off creases {max((s['angle'] for s in smooth), default=0.0):.2f} deg"
                 f" ({max((s['corner_angle'] for s in smooth), default=0.0):.2f} at face "
                 f"corners)")
    for s in sorted(smooth, key=lambda s: -s["angle"])[:SEAMS_SHOWN]:
        lines.append(f"seam patches {s['patches'][0]}-{s['patches'][1]} curves {s['curves']}: "
                     f"G0 {s['gap']:.1e}, G1 {s['angle']:.2f} deg, deviation "
                     f"{s['deviation']:.1e}")
    return lines
