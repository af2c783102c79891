"""One call from robot designs to the seed's metrics: ``softgym.evaluate``.

Any optimiser (CMA-ES, Nevergrad, evosax, pymoo, DEAP, your own loop) can
score designs with one function: it batches every design into a single
:class:`~softgym.engine.Simulation` (robots run in parallel and give the same
result alone or in a batch), runs it for the task's ``seconds`` of simulated
time, and returns the task's metrics (:meth:`softgym.tasks.Task.metrics`) and
each design's composition as arrays. The task is anything
:func:`softgym.tasks.get_task` reads: a name (``"flat"``, ``"wall"``,
``"stairs"``), a :class:`~softgym.terrain.Terrain`, a terrain JSON file or a
:class:`~softgym.tasks.Task`.

>>> import softgym
>>> from softgym.design import default_walker
>>> m = softgym.evaluate([default_walker()], task="flat", seconds=2.0)
>>> sorted(m)[:3]
['diverged', 'l_coefficient', 'max_xy_dist']
"""

from __future__ import annotations

import contextlib
import sys
import threading
from collections.abc import Iterable, Iterator, Mapping
from typing import Any

import numpy as np

from softgym.exceptions import InvalidDesignError, InvalidParameterError
from softgym.tasks import Task, TaskLike, get_task
from softgym.validate import positive, show, threads

__all__ = [
    "METRIC_KEYS",
    "Task",
    "caller_shows_progress",
    "estimated_cost",
    "evaluate",
    "evaluate_payload",
]

#: Keys of the dict returned by :func:`evaluate` (traces come with ``traces=True``).
METRIC_KEYS: tuple[str, ...] = (
    "norm_final_dist",
    "max_xy_dist",
    "l_coefficient",
    "time_max_xy_dist",
    "score",
    "diverged",
    "n_voxels",
    "n_muscle",
    "n_old_materials",
    "n_bone",
    "n_tissue",
)
_COUNTS = ("n_voxels", "n_muscle", "n_old_materials", "n_bone", "n_tissue")


def estimated_cost(design: Any, voxel_size: float = 0.01) -> float:
    """Relative simulation cost of a design: voxel-steps per simulated second.

    The engine's own figure (:func:`softgym.engine.voxel_steps_per_second`):
    a robot with a bone-bone link takes 10x more steps. Used to order a batch
    longest-first, so the engine's dynamic schedule over robots balances the
    threads.
    """
    from softgym.engine import SimConfig, voxel_steps_per_second

    return voxel_steps_per_second(design, SimConfig(voxel_size=float(voxel_size)))


def _as_design(obj: Any):
    from softgym.design import RobotDesign

    if isinstance(obj, RobotDesign):
        return obj
    if isinstance(obj, Mapping):
        return RobotDesign.from_dict(obj)
    raise InvalidParameterError(
        f"expected a RobotDesign or its to_dict(), got {type(obj).__name__}"
    )


#: A batch estimated to take longer than this (s) shows a progress bar by default.
PROGRESS_AFTER_S = 5.0

_caller_bars = 0  # progress bars callers show around evaluations (caller_shows_progress)
_caller_lock = threading.Lock()


@contextlib.contextmanager
def caller_shows_progress() -> Iterator[None]:
    """While active, :func:`evaluate` shows no progress bar of its own by default.

    One bar at a time: a caller that shows its own (a run's bar over its
    generations) wraps its loop in this, and the batches it evaluates stay
    quiet unless a call asks for a bar (``progress=True``).
    """
    global _caller_bars
    with _caller_lock:
        _caller_bars += 1
    try:
        yield
    finally:
        with _caller_lock:
            _caller_bars -= 1
_VOXEL_STEPS_PER_S = 5e6
# a closed-loop episode samples the centre of mass itself: the engine's trace stays off
_NO_TRACE = 1.0e9  # per thread, for that estimate (the seed preset's order of magnitude)


def evaluate(
    designs: Any,
    task: TaskLike = "flat",
    seconds: float | None = None,
    *,
    trace_interval: float | None = None,
    traces: bool = False,
    n_threads: int | None = None,
    config: Any = None,
    progress: bool | None = None,
) -> dict[str, Any]:
    """Simulate designs together and return the task's metrics.

    Parameters
    ----------
    designs : RobotDesign, dict, or sequence of them
        Robots to score (a design's ``to_dict()`` is accepted). They may
        differ in shape, materials and controller.
    task : str, Terrain, path or Task
        The world and its scoring (:func:`softgym.tasks.get_task`): ``"flat"``,
        ``"wall"`` (alias ``"fence"``), ``"stairs"``, a custom
        :class:`~softgym.terrain.Terrain` or its JSON file, or a Task.
    seconds : float, optional
        Simulated time per robot (s); default the task's (5, the seed's).
    trace_interval : float, optional
        Seconds between centre-of-mass samples (default the task's, 0.1).
    traces : bool
        Also return each robot's centre-of-mass trace from ``init_time`` on.
    n_threads : int, optional
        OpenMP threads (default: softgym's default).
    config : SimConfig, optional
        Full engine settings; replaces the task's (its ``trace_interval`` wins).
    progress : bool, optional
        Show a tqdm bar over the simulated time; default: only for a batch
        estimated to take more than :data:`PROGRESS_AFTER_S` seconds, on an
        interactive terminal, when no caller shows a bar of its own
        (:func:`caller_shows_progress`). The bar is removed when the batch is
        done, so calls in a loop show one bar at a time.

    Returns
    -------
    dict of str to ndarray of shape (n_designs,)
        ``norm_final_dist``, ``max_xy_dist`` (voxel lengths),
        ``l_coefficient`` (voxel lengths^2 / s), ``time_max_xy_dist`` (s),
        ``diverged`` (bool) and the composition counts ``n_voxels``,
        ``n_muscle``, ``n_old_materials``, ``n_bone``, ``n_tissue``.
        Diverged robots get :data:`~softgym.metrics.WORST_FITNESS` on the
        fitness measures. With ``traces=True``, ``"traces"`` is a list of
        arrays of shape (n_points, 4), rows (x, y, z, t) in m and s, or None
        for diverged robots.

    Examples
    --------
    Score a batch with any optimiser's candidates (here two copies)::

        m = softgym.evaluate([d1, d2], task="wall", seconds=5.0)
        fitness = m["max_xy_dist"]
    """
    from softgym.design import RobotDesign
    from softgym.engine import SimConfig

    if isinstance(designs, (RobotDesign, Mapping)):
        designs = [designs]
    if isinstance(designs, (str, bytes)) or not isinstance(designs, Iterable):
        raise InvalidDesignError(
            f"designs must be a RobotDesign, a design dict or a sequence of them, got {show(designs)}"
        )
    designs = [_as_design(d) for d in designs]
    # strict types: a bool, a string or a list is not a number (issue 31)
    changes: dict[str, Any] = {}
    if seconds is not None:
        changes["seconds"] = positive("seconds", seconds, unit=" (s)")
    if trace_interval is not None:
        changes["trace_interval"] = positive("trace_interval", trace_interval, unit=" (s)")
    if n_threads is not None:
        changes["n_threads"] = threads(n_threads)
    if config is not None and not isinstance(config, SimConfig):
        raise InvalidParameterError(
            f"config must be a softgym SimConfig (or None for the task's), got {show(config)}"
        )
    task = get_task(task, **changes)
    n = len(designs)
    out: dict[str, Any] = {k: np.zeros(n) for k in METRIC_KEYS}
    out["diverged"] = np.zeros(n, dtype=bool)
    for k in _COUNTS:
        out[k] = np.zeros(n, dtype=np.int64)
    if traces:
        out["traces"] = [None] * n
    if n == 0:
        return out
    from softgym.metrics import composition_counts

    cfg = task.config(config, settings=config is None)  # a full config replaces the task's
    for i, d in enumerate(designs):
        c = composition_counts(d)
        for k in _COUNTS:
            out[k][i] = getattr(c, k)
    # designs with a brain run as closed-loop control episodes (softgym.tasks.brains); the
    # others on the seed's open-loop path below, bit for bit as without them
    closed = [i for i, d in enumerate(designs) if d.brain is not None]
    if closed:
        from softgym.tasks.brains import run_brains

        metrics, closed_traces = run_brains(
            [designs[i] for i in closed], task, cfg.replace(trace_interval=_NO_TRACE),
            n_threads=task.n_threads,
        )  # fmt: skip
        for k, v in metrics.items():
            if k not in out:
                out[k] = np.zeros(n, dtype=v.dtype)
            out[k][closed] = v
        if traces:
            for j, i in enumerate(closed):
                out["traces"][i] = None if metrics["diverged"][j] else closed_traces[j]
    idx = [i for i, d in enumerate(designs) if d.brain is None]
    if not idx:
        return out
    _open_loop(out, [designs[i] for i in idx], np.asarray(idx), task, cfg, traces, progress)
    return out


def _open_loop(out: dict[str, Any], designs: list, where: np.ndarray, task: Task, cfg: Any,
               traces: bool, progress: bool | None) -> None:  # fmt: skip
    # the seed's path: one Simulation of the designs, its rollout scored by the task
    from softgym.engine import Simulation, voxel_steps_per_second

    n = len(designs)
    # longest first: the kernel's dynamic schedule then balances the threads (results do not
    # depend on a robot's place in the batch, so the order is free)
    order = sorted(range(n), key=lambda i: -estimated_cost(designs[i], cfg.voxel_size))
    batch = [designs[i] for i in order]
    terrains = [task.terrain_for(d.shape) for d in batch]
    sim = Simulation(batch, config=cfg, n_threads=task.n_threads, terrain=terrains)
    if progress is None:
        work = sum(voxel_steps_per_second(d, cfg) for d in batch) * task.seconds
        progress = (work / (_VOXEL_STEPS_PER_S * sim.n_threads) > PROGRESS_AFTER_S
                    and _caller_bars == 0 and sys.stderr.isatty())  # fmt: skip
    if progress:
        from tqdm.auto import tqdm

        with tqdm(total=task.seconds, unit="s", desc=f"simulating {n} robots", leave=False,
                  bar_format="{l_bar}{bar}| {n:.2f}/{total:.2f} s [{elapsed}<{remaining}]") as bar:
            sim.advance_to(task.seconds, progress=lambda t: bar.update(t - bar.n))
    else:
        sim.advance_to(task.seconds)
    back = np.argsort(order)
    rollout = _reorder(sim.rollout(), back)
    for k, v in task.metrics(rollout, [terrains[i] for i in back]).items():
        if k not in out:
            out[k] = np.zeros(len(out["diverged"]), dtype=v.dtype)
        out[k][where] = v
    if traces:
        for i in range(n):
            out["traces"][where[i]] = (
                None if rollout.diverged[i] else rollout.trace(i, since=rollout.init_time)
            )


def _reorder(rollout: Any, perm: np.ndarray) -> Any:
    """The rollout with its robots taken in ``perm`` order."""
    return rollout.take(perm)


def evaluate_payload(payload: Mapping[str, Any]) -> dict[str, Any]:
    """Evaluate a plain-data batch: the unit of work shipped to Dask workers.

    Parameters
    ----------
    payload : dict
        ``{"designs": [design.to_dict(), ...], "task": Task.to_dict()}`` (or a task name).

    Returns
    -------
    dict
        :func:`evaluate`'s output with ``traces=True``, as lists and arrays.
    """
    return evaluate(list(payload["designs"]), task=get_task(payload["task"]), traces=True)
