"""Benchmark: the batch engine serially, with 2 local processes and on a 2-worker LocalCluster.

Run from the repository root (needs ``curvenet[cluster]``)::

    python benchmarks/bench_batch.py [--method classical] [--sets networks,vns]

Inputs: the 29 public networks (``networks/*/*.obj``) and the 22 VNS sketches
(``sketches/vns/*.obj`` and ``input/gamepad.obj``) under ``$CURVENET_DATA`` (default
``../shared/data``). Two networks share the stem ``trebol``, which a batch refuses, so
each input is linked (not copied) into a temporary folder as ``FOLDER_STEM.obj``.

Prints per set and executor: wall time, the sum of the per-task times, ok / failed, and
whether the outputs are byte-identical to the serial run; then the cluster's overhead
per task, measured two ways: (cluster wall - 2-process wall) / files, and the round trip
of 200 no-op tasks carrying 100 kB each.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import tempfile
import time
from pathlib import Path

from curvenet.batch.run import BatchOptions, DaskExecutor, LocalExecutor, run_batch

DATA = Path(os.environ.get("CURVENET_DATA",
                           Path(__file__).resolve().parents[1].parent / "shared" / "data"))


def _inputs(name: str, folder: Path) -> list:
    if name == "networks":
        files = sorted(DATA.glob("networks/*/*.obj"))
    else:
        files = sorted(DATA.glob("sketches/vns/*.obj")) + sorted(
            DATA.glob("sketches/vns/input/*.obj"))
    folder.mkdir(parents=True)
    links = []
    for f in files:
        link = folder / f"{f.parent.name}_{f.stem}.obj"
        link.symlink_to(f)
        links.append(link)
    return links


def _digests(out: Path) -> dict:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in out.glob("*.obj")}


def _noop(payload: bytes) -> int:
    return len(payload)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--method", default="classical")
    ap.add_argument("--sets", default="networks,vns")
    args = ap.parse_args()
    from distributed import Client, LocalCluster
    options = BatchOptions(method=args.method)
    tmp = Path(tempfile.mkdtemp(prefix="bench-batch-"))
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    client = Client(cluster)
    client.run(lambda: __import__("curvenet.pipeline"))  # warm imports, as a pool would
    print(f"{'set':<9} {'executor':<10} {'files':>5} {'wall s':>7} {'task s':>7} "
          f"{'ok':>3} {'fail':>4}  same as serial")
    per_task = []
    for name in args.sets.split(","):
        inputs = _inputs(name, tmp / name / "in")
        walls, serial = {}, None
        for label, executor in (("serial", LocalExecutor(1)), ("jobs 2", LocalExecutor(2)),
                                ("dask 2", DaskExecutor(client))):
            out = tmp / name / label.replace(" ", "")
            t = time.perf_counter()
            res = run_batch(inputs, out, options, executor=executor)
            walls[label] = time.perf_counter() - t
            task_s = sum(r.get("t_total", 0.0) for r in res.rows)
            dig = _digests(out)
            serial = dig if serial is None else serial
            ok = res.counts["ok"]
            print(f"{name:<9} {label:<10} {len(inputs):>5} {walls[label]:>7.1f} "
                  f"{task_s:>7.1f} {ok:>3} {len(inputs) - ok:>4}  {dig == serial}")
        per_task.append((walls["dask 2"] - walls["jobs 2"]) / len(inputs))
    payload = os.urandom(100_000)
    t = time.perf_counter()
    futures = [client.submit(_noop, payload, pure=False) for _ in range(200)]
    client.gather(futures)
    noop = (time.perf_counter() - t) / 200
    print("cluster overhead per task: "
          + ", ".join(f"{s}: {1e3 * d:+.0f} ms vs jobs 2" for s, d in
                      zip(args.sets.split(","), per_task))
          + f"; no-op 100 kB task round trip {1e3 * noop:.1f} ms")
    client.close()
    cluster.close()


if __name__ == "__main__":
    main()
