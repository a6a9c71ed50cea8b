"""The CAD test set (issue 31): OpenCascade parts, their edges as curves, rebuilt as B-reps.

Every part of :func:`curvenet.datasets.cad_parts.cad_parts` (plates with bores and
counterbores, bosses, slots, hex nuts, flanges, washers, L-brackets, stepped shafts,
filleted and chamfered blocks, knobs, pins; dimensions drawn from one seed) is built
with OpenCascade; its B-rep edges are sampled as the input network
(:func:`~curvenet.datasets.cad_parts.part_network`), the classical pipeline surfaces
it, the result is written as STEP and as 3DM, the STEP is read back and scored against
the part (:func:`curvenet.datasets.cad_truth.score_against`):

* ``solid``: the STEP holds one valid (``BRepCheck_Analyzer``) closed solid whose
  volume is within 1% of the part's; ``vol err`` the relative volume error;
* ``F mesh`` / ``F cad``: F-score x 100 (threshold 0.01 of the longest side) of the
  mesh output and of the STEP's triangulation against the part's triangulation;
* ``analytic``: share of the part's analytic area (plane, cylinder, cone, sphere,
  torus faces) lying on a STEP face of the same kind;
* ``3dm``: rhino3dm's ``IsValid`` and ``IsSolid`` of the joined Brep(s);
* ``error``: the one-line message of a failure (``input`` for a ``CurvenetError``,
  ``internal`` for anything else).

Run: ``python benchmarks/cad_parts.py [--seed N] [--json] [--only FAMILY,...]``
(needs ``pip install 'curvenet[cad]'``).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from curvenet import cad  # noqa: E402
from curvenet.core.errors import CurvenetError  # noqa: E402
from curvenet.datasets.cad_parts import cad_parts, part_network  # noqa: E402
from curvenet.datasets.cad_truth import score_against, shape_truth  # noqa: E402
from curvenet.pipeline import surface  # noqa: E402


def run_part(part, folder: Path, *, seed: int = 0) -> dict:
    """Surface one part's network, write STEP and 3DM, score the STEP read back."""
    truth = shape_truth(part.shape)
    net = part_network(part.shape)
    row = {"part": part.name, "family": part.family, "curves": net.number_of_edges,
           "true_faces": len(truth.kinds), "error": None}
    t0 = time.perf_counter()
    try:
        res = surface(net, method="classical")
        row["patches"] = len(res.patchset.patches)
        step = folder / f"{part.name}.step"
        res.save(step)
        row["kinds"] = {}
        shape = cad.read_step(step)
        row.update(score_against(truth, shape, res.mesh, seed=seed))
        rep3 = {}
        try:
            res.save(folder / f"{part.name}.3dm")
            rep3 = res.diagnostics["cad"]["file"]
        except CurvenetError as err:
            row["error"] = f"3dm input: {err}"
        row["3dm_valid"] = bool(rep3.get("valid"))
        row["3dm_solid"] = bool(rep3.get("solids", 0) == rep3.get("breps", -1) == 1)
    except CurvenetError as err:
        row["error"] = f"input: {err}"
    except Exception as err:  # noqa: BLE001 - the benchmark reports every failure
        row["error"] = f"internal: {type(err).__name__}: {err}"
    row["seconds"] = time.perf_counter() - t0
    return row


def totals(rows) -> dict:
    """Shares over the set: solids ok, F >= 99 (mesh and CAD), mean analytic share,
    3DM valid, internal errors."""
    n = len(rows)

    def share(pred):
        return sum(1 for r in rows if pred(r)) / max(n, 1)
    return {"parts": n,
            "solid_ok": share(lambda r: r.get("solid_ok")),
            "f_mesh_99": share(lambda r: (r.get("f_mesh") or 0) >= 99),
            "f_cad_99": share(lambda r: (r.get("f_cad") or 0) >= 99),
            "analytic_mean": sum(r.get("analytic_recovered", 0.0) for r in rows) / max(n, 1),
            "3dm_valid": share(lambda r: r.get("3dm_valid")),
            "3dm_solid": share(lambda r: r.get("3dm_solid")),
            "internal_errors": sum(1 for r in rows if (r["error"] or "").startswith("internal")),
            "errors": sum(1 for r in rows if r["error"])}


def _fmt(x, spec):
    return "-" if x is None else format(x, spec)


def table(rows) -> str:
    head = ("| part | curves | patches | solid | vol err | F mesh | F cad | analytic | "
            "3dm valid, solid | kinds | s | error |")
    lines = [head, "|" + "---|" * 12]
    for r in rows:
        kinds = ", ".join(f"{n} {k}" for k, n in r.get("kinds", {}).items())
        lines.append(
            f"| {r['part']} | {r['curves']} | {r.get('patches', '-')} | "
            f"{'yes' if r.get('solid_ok') else 'no'} | {_fmt(r.get('volume_error'), '.1e')} | "
            f"{_fmt(r.get('f_mesh'), '.1f')} | {_fmt(r.get('f_cad'), '.1f')} | "
            f"{_fmt(r.get('analytic_recovered'), '.3f')} | "
            f"{'yes' if r.get('3dm_valid') else 'no'}, {'yes' if r.get('3dm_solid') else 'no'} | "
            f"{kinds} | {r['seconds']:.1f} | {r['error'] or ''} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--only", help="comma-separated families or part names")
    ap.add_argument("--json", action="store_true", help="rows and totals as JSON")
    args = ap.parse_args(argv)
    parts = cad_parts(args.seed)
    if args.only:
        want = set(args.only.split(","))
        parts = [p for p in parts if p.family in want or p.name in want]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for p in parts:
            rows.append(run_part(p, Path(tmp), seed=args.seed))
            if not args.json:
                print(f"{p.name}: {rows[-1]['seconds']:.1f} s {rows[-1]['error'] or ''}",
                      file=sys.stderr, flush=True)
    tot = totals(rows)
    if args.json:
        print(json.dumps({"rows": rows, "totals": tot}, indent=1, default=float))
    else:
        print(table(rows))
        print()
        print(", ".join(f"{k} {v:.3f}" if isinstance(v, float) else f"{k} {v}"
                        for k, v in tot.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
