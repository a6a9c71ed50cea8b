"""Many sketches in one call: a process pool or a Dask cluster, a manifest to resume
from, a report."""

from .run import (MANIFEST_NAME, STATUSES, BatchOptions, BatchResult, DaskExecutor,
                  LocalExecutor, plan_outputs, run_batch, surface_task)

__all__ = ["BatchOptions", "BatchResult", "LocalExecutor", "DaskExecutor", "run_batch",
           "surface_task", "plan_outputs", "MANIFEST_NAME", "STATUSES"]
