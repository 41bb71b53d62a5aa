"""The batch's Dask worker plugin: each worker of a cluster the batch runs on, started by it or not, takes
NumPy's arrays from the heap (:func:`~wbfriction.workers.heap_for_arrays`), as a plain process does (issue 41: on
``dask scheduler`` + ``dask worker``, a batch of arm logs took 2.5 times as long as ``--serial``)."""

from __future__ import annotations

from distributed.diagnostics.plugin import WorkerPlugin

from wbfriction.workers import heap_for_arrays


class HeapForArrays(WorkerPlugin):
    """Registered by :func:`~wbfriction.fleet.batch.run_batch` on its client: runs in every worker, those that
    join later included, before it takes a task."""

    name = "wbfriction-heap-for-arrays"

    def setup(self, worker: object) -> None:
        heap_for_arrays()
