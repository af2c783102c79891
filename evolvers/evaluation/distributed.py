"""Population evaluation on Dask: a LocalCluster or an existing scheduler.

:class:`DaskBatchFn` is a drop-in ``batch_fn`` for
:class:`~evolvers.evaluation.evaluator.Evaluator`: it splits a generation's designs into
one contiguous batch per worker thread, ships each batch as plain JSON-ready
data (``design.to_dict()``) to :func:`softgym.evaluate.evaluate_payload`, and
concatenates the results in order. Each batch is one batched Simulation on the
worker. A robot's result does not depend on its batch, so the results equal a
local run bit for bit. A batch lost with its worker is recomputed by Dask on
another worker (tasks are submitted with ``retries``).

Dask is an optional extra: ``pip install "softgym[distributed]"``. Without it,
:func:`dask_client` raises :class:`MissingExtraError` naming the extra.

>>> from evolvers.evaluation.distributed import dask_client
>>> with dask_client("local", n_workers=2) as client:   # doctest: +SKIP
...     run = EvolutionRun(exp, "runs/x", batch_fn=DaskBatchFn(client))
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np

from softgym.evaluate import evaluate_payload
from softgym.exceptions import InvalidParameterError, SoftGymError
from softgym.tasks import Task
from softgym.validate import is_int, show

__all__ = [
    "DaskBatchFn",
    "MissingExtraError",
    "dask_client",
    "require_distributed",
    "split_batches",
]


class MissingExtraError(SoftGymError, ImportError):
    """An optional dependency is not installed; the message names the pip extra that brings it."""


def require_distributed() -> Any:
    """The ``distributed`` module (Dask's scheduler and workers).

    Raises
    ------
    MissingExtraError
        If Dask is not installed: ``pip install "softgym[distributed]"``.
    """
    try:
        import distributed
    except ImportError as exc:
        raise MissingExtraError(
            'Dask evaluation (--dask) needs the "distributed" extra: '
            'pip install "softgym[distributed]"'
        ) from exc
    return distributed


def split_batches(n: int, n_batches: int) -> list[tuple[int, int]]:
    """Split ``range(n)`` into at most ``n_batches`` contiguous, near-equal ``(start, stop)`` slices."""
    n_batches = max(1, min(int(n_batches), n))
    edges = np.linspace(0, n, n_batches + 1).round().astype(int)
    return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a]


def _merge(parts: list[dict[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key in parts[0]:
        if key == "traces":
            out[key] = [t for p in parts for t in p[key]]
        else:
            out[key] = np.concatenate([np.asarray(p[key]) for p in parts])
    return out


class DaskBatchFn:
    """Evaluate a batch of designs over the workers of a Dask client.

    Parameters
    ----------
    client : distributed.Client
    n_batches : int, optional
        Batches per generation (default: the cluster's total worker threads).
    retries : int
        Times a batch that raised is resubmitted. (A batch whose worker died
        is recomputed on another worker by the scheduler itself.)
    payload_fn : callable, optional
        What runs a batch on a worker (default
        :func:`softgym.evaluate.evaluate_payload`).
    """

    def __init__(
        self,
        client: Any,
        n_batches: int | None = None,
        retries: int = 3,
        payload_fn: Any = evaluate_payload,
    ) -> None:
        self.client = client
        self.n_batches = n_batches
        self.retries = int(retries)
        self.payload_fn = payload_fn

    def _default_batches(self) -> int:
        try:
            return max(1, sum(self.client.nthreads().values()))
        except Exception:  # pragma: no cover - scheduler without the call
            return 1

    def __call__(self, designs: list[Any], task: Task) -> dict[str, Any]:
        """``(designs, task) -> metrics``, like :func:`evolvers.evaluation.evaluator.local_batch_fn`
        (RobotDesigns or their dicts).
        """
        slices = split_batches(len(designs), self.n_batches or self._default_batches())
        return _merge(self.jobs([(designs[a:b], task) for a, b in slices]))

    def jobs(self, jobs: list[tuple[list[Any], Task]]) -> list[dict[str, Any]]:
        """``[(designs, task), ...] -> [metrics, ...]``: one Dask task per batch, all at
        once (POET's terrains; :class:`~evolvers.drivers.poet.PoetRun` uses it when given this
        ``batch_fn``). Designs travel as plain dicts (``RobotDesign.to_dict()``).
        """
        # one engine thread per batch: workers already run batches in parallel
        payloads = [{"designs": [x if isinstance(x, Mapping) else x.to_dict() for x in d],
                     "task": {**t.to_dict(), "n_threads": 1}} for d, t in jobs]  # fmt: skip
        futures = self.client.map(self.payload_fn, payloads, pure=False, retries=self.retries)
        return list(self.client.gather(futures))


@contextlib.contextmanager
def dask_client(
    address: str = "local", n_workers: int = 2, processes: bool = True
) -> Iterator[Any]:
    """A Dask client: ``"local"`` starts a LocalCluster, anything else is a scheduler address.

    Parameters
    ----------
    address : str
        ``"local"`` or e.g. ``"tcp://10.0.0.5:8786"``.
    n_workers : int
        Workers of the LocalCluster (one thread each).
    processes : bool
        LocalCluster workers as processes (True) or threads of this process
        (the engine releases the GIL, so threads run in parallel too).

    Raises
    ------
    MissingExtraError
        If Dask is not installed (``pip install ".[distributed]"``).
    InvalidParameterError
        If ``n_workers`` is not an integer >= 1 (a cluster without workers
        would wait for one forever), or ``address`` is not ``"local"`` nor a
        scheduler address.
    """
    if address == "local" and (not is_int(n_workers) or n_workers < 1):
        raise InvalidParameterError(
            f"a local Dask cluster needs n_workers >= 1 (--workers), got {show(n_workers)}"
        )
    distributed = require_distributed()
    Client, LocalCluster = distributed.Client, distributed.LocalCluster

    if address == "local":
        cluster = LocalCluster(
            n_workers=n_workers, threads_per_worker=1, processes=processes,
            dashboard_address=None,
        )  # fmt: skip
        client = Client(cluster)
        try:
            yield client
        finally:
            client.close()
            cluster.close()
    else:
        try:
            client = Client(address)
        except (ValueError, TypeError) as exc:  # not an address: no port, unknown protocol...
            raise InvalidParameterError(
                f"Dask scheduler address (--dask) must be 'local' or e.g. tcp://HOST:8786, "
                f"got {show(address)} ({exc!s:.120})"
            ) from None
        try:
            yield client
        finally:
            client.close()
