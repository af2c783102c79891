"""One call from robot designs to the seed's metrics: ``softgym.evaluate``.

Any optimiser (CMA-ES, Nevergrad, evosax, pymoo, DEAP, your own loop) can
score designs with one function: it batches every design into a single
:class:`~softgym.engine.Simulation` (robots run in parallel and give the same
result alone or in a batch), runs it for ``seconds`` of simulated time, and
returns the seed's measures as arrays.

>>> import softgym
>>> from softgym.design import default_walker
>>> m = softgym.evaluate([default_walker()], task="flat", seconds=2.0)
>>> sorted(m)[:3]
['diverged', 'l_coefficient', 'max_xy_dist']
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from softgym.exceptions import InvalidParameterError

__all__ = ["TASKS", "Task", "estimated_cost", "evaluate", "evaluate_payload", "make_terrain"]

#: Task names understood by :func:`evaluate`: flat ground, or the seed's 1-voxel fence.
TASKS: tuple[str, ...] = ("flat", "fence")

#: Keys of the dict returned by :func:`evaluate` (traces come with ``traces=True``).
METRIC_KEYS: tuple[str, ...] = (
    "norm_final_dist",
    "max_xy_dist",
    "l_coefficient",
    "time_max_xy_dist",
    "diverged",
    "n_voxels",
    "n_muscle",
    "n_old_materials",
    "n_bone",
    "n_tissue",
)


@dataclass(frozen=True)
class Task:
    """How designs are scored: the world, the duration and the sampling.

    Parameters
    ----------
    terrain : {"flat", "fence"}
        ``"flat"``: the floor alone. ``"fence"``: the seed's obstacle, a
        1-voxel-high square fence with a 10-voxel interior centred on each
        robot's footprint (:meth:`softgym.terrain.Terrain.fence`).
    seconds : float
        Simulated time (s) per robot; 5 in the seed (1 s settling included).
    trace_interval : float
        Seconds between centre-of-mass samples: 0.5 for the seed's novelty
        runs, 0.1 for its obstacle runs (and the L coefficient).
    sim : dict
        Overrides of :class:`~softgym.engine.SimConfig` (e.g. ``{"actuation": "symmetric"}``).
    n_threads : int, optional
        OpenMP threads of the simulation (default: softgym's default).
    """

    terrain: str = "flat"
    seconds: float = 5.0
    trace_interval: float = 0.1
    sim: dict[str, Any] = field(default_factory=dict)
    n_threads: int | None = None

    def __post_init__(self) -> None:
        if self.terrain not in TASKS:
            raise InvalidParameterError(f"unknown task {self.terrain!r}; expected one of {TASKS}")
        if not (np.isfinite(self.seconds) and self.seconds > 0):
            raise InvalidParameterError(f"seconds must be > 0, got {self.seconds!r}")
        if not (np.isfinite(self.trace_interval) and self.trace_interval > 0):
            raise InvalidParameterError(f"trace_interval must be > 0, got {self.trace_interval!r}")

    def config(self):
        """The :class:`~softgym.engine.SimConfig` of this task."""
        from softgym.engine import SimConfig

        return SimConfig(trace_interval=float(self.trace_interval), **dict(self.sim))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Task:
        """Inverse of :meth:`to_dict`."""
        return cls(**dict(data))


def make_terrain(task: str, shape: Sequence[int]):
    """The terrain of ``task`` for a robot grid of ``shape`` placed at the origin.

    Parameters
    ----------
    task : {"flat", "fence"}
    shape : (nx, ny, nz)
        Grid shape; the fence is centred on the footprint ``(nx / 2, ny / 2)``.

    Returns
    -------
    softgym.terrain.Terrain
    """
    from softgym.terrain import Terrain

    if task == "flat":
        return Terrain.flat()
    if task == "fence":
        nx, ny = int(shape[0]), int(shape[1])
        inner = max(10.0, max(nx, ny) + 4.0)  # the seed's 2-voxel gap around a 6-wide robot
        return Terrain.fence(inner=inner, center=(nx / 2.0, ny / 2.0))
    raise InvalidParameterError(f"unknown task {task!r}; expected one of {TASKS}")


def estimated_cost(design: Any, voxel_size: float = 0.01) -> float:
    """Relative simulation cost of a design: voxels x steps per simulated second.

    The engine steps each robot at ``dt ~ 1 / sqrt(max k_axial / m)`` over its
    links (a robot with a bone-bone link takes 10x more steps); the cost is
    ``n_voxels * sqrt(max k / m)``. Used to order a batch longest-first, so
    the engine's dynamic schedule over robots balances the threads.
    """
    grid = np.asarray(design.grid)
    table = design.material_table()
    L = float(voxel_size)
    E = table["youngs_modulus"][grid]
    m = table["density"][grid] * L**3
    filled = grid > 0
    w2 = 0.0
    for ax in range(3):
        lo = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[ax] = slice(0, -1)
        hi[ax] = slice(1, None)
        ok = filled[tuple(lo)] & filled[tuple(hi)]
        if not ok.any():
            continue
        a, b = E[tuple(lo)][ok], E[tuple(hi)][ok]
        k = 2.0 * a * b / (a + b) * L
        w2 = max(w2, float(np.max(np.maximum(k / m[tuple(lo)][ok], k / m[tuple(hi)][ok]))))
    if w2 == 0.0 and filled.any():
        w2 = float(np.max(E[filled] * L / m[filled]))
    return float(filled.sum()) * float(np.sqrt(w2))


def _as_design(obj: Any):
    from softgym.design import RobotDesign

    if isinstance(obj, RobotDesign):
        return obj
    if isinstance(obj, Mapping):
        return RobotDesign.from_dict(obj)
    raise InvalidParameterError(
        f"expected a RobotDesign or its to_dict(), got {type(obj).__name__}"
    )


def evaluate(
    designs: Any,
    task: str | Task = "flat",
    seconds: float | None = None,
    *,
    trace_interval: float | None = None,
    traces: bool = False,
    n_threads: int | None = None,
    config: Any = None,
) -> dict[str, Any]:
    """Simulate designs together and return the seed's metrics.

    Parameters
    ----------
    designs : RobotDesign, dict, or sequence of them
        Robots to score (a design's ``to_dict()`` is accepted). They may
        differ in shape, materials and controller.
    task : {"flat", "fence"} or Task
        The world (see :class:`Task`).
    seconds : float, optional
        Simulated time per robot (s); default 5 (the seed's), or the Task's.
    trace_interval : float, optional
        Seconds between centre-of-mass samples (default 0.1, or the Task's).
    traces : bool
        Also return each robot's centre-of-mass trace from ``init_time`` on.
    n_threads : int, optional
        OpenMP threads (default: softgym's default).
    config : SimConfig, optional
        Full engine settings; replaces the task's (its ``trace_interval`` wins).

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

        m = softgym.evaluate([d1, d2], task="fence", seconds=5.0)
        fitness = m["max_xy_dist"]
    """
    from softgym.design import RobotDesign

    if isinstance(designs, (RobotDesign, Mapping)):
        designs = [designs]
    designs = [_as_design(d) for d in designs]
    if isinstance(task, str):
        task = Task(terrain=task)
    if not isinstance(task, Task):
        raise InvalidParameterError(f"task must be a name or a Task, got {type(task).__name__}")
    changes: dict[str, Any] = {}
    if seconds is not None:
        changes["seconds"] = float(seconds)
    if trace_interval is not None:
        changes["trace_interval"] = float(trace_interval)
    if n_threads is not None:
        changes["n_threads"] = int(n_threads)
    if changes:
        task = Task(**{**task.to_dict(), **changes})
    n = len(designs)
    out: dict[str, Any] = {k: np.zeros(n) for k in METRIC_KEYS}
    out["diverged"] = np.zeros(n, dtype=bool)
    for k in ("n_voxels", "n_muscle", "n_old_materials", "n_bone", "n_tissue"):
        out[k] = np.zeros(n, dtype=np.int64)
    if traces:
        out["traces"] = [None] * n
    if n == 0:
        return out
    from softgym.engine import Simulation
    from softgym.metrics import (
        composition_counts,
        l_coefficient_details,
        max_xy_dist,
        norm_final_dist,
    )

    cfg = task.config() if config is None else config.replace(trace_interval=task.trace_interval)
    # longest first: the kernel's dynamic schedule then balances the threads (results do not
    # depend on a robot's place in the batch, so the order is free)
    order = sorted(range(n), key=lambda i: -estimated_cost(designs[i], cfg.voxel_size))
    batch = [designs[i] for i in order]
    terrains = [make_terrain(task.terrain, d.shape) for d in batch]
    sim = Simulation(batch, config=cfg, n_threads=task.n_threads, terrain=terrains)
    rollout = _reorder(sim.run(task.seconds), np.argsort(order))
    out["norm_final_dist"] = norm_final_dist(rollout)
    out["max_xy_dist"] = max_xy_dist(rollout)
    out["diverged"] = rollout.diverged.copy()
    details = l_coefficient_details(rollout)
    from softgym.metrics import WORST_FITNESS

    out["l_coefficient"] = np.array(
        [WORST_FITNESS if d is None else d.l_coefficient for d in details]
    )
    out["time_max_xy_dist"] = np.array(
        [np.inf if d is None else d.time_max_xy_dist for d in details]
    )
    for i, d in enumerate(designs):
        c = composition_counts(d)
        out["n_voxels"][i] = c.n_voxels
        out["n_muscle"][i] = c.n_muscle
        out["n_old_materials"][i] = c.n_old_materials
        out["n_bone"][i] = c.n_bone
        out["n_tissue"][i] = c.n_tissue
    if traces:
        out["traces"] = [
            None if rollout.diverged[i] else rollout.trace(i, since=rollout.init_time)
            for i in range(n)
        ]
    return out


def _reorder(rollout: Any, perm: np.ndarray) -> Any:
    """The rollout with its robots taken in ``perm`` order (per-voxel arrays regrouped)."""
    from dataclasses import replace

    off = rollout.voxel_offsets
    pieces = [np.arange(off[i], off[i + 1]) for i in perm]
    vox = np.concatenate(pieces) if pieces else np.zeros(0, dtype=np.int64)
    counts = np.array([len(p) for p in pieces], dtype=np.int64)
    per_robot = ("times", "cm", "cm_init", "init_reached", "cm_final", "dt", "steps", "time",
                 "diverged", "diverged_time", "mass")  # fmt: skip
    changes = {k: getattr(rollout, k)[perm] for k in per_robot}
    changes.update(
        positions=rollout.positions[vox], orientations=rollout.orientations[vox],
        grid_index=rollout.grid_index[vox],
        voxel_offsets=np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
    )  # fmt: skip
    return replace(rollout, **changes)


def evaluate_payload(payload: Mapping[str, Any]) -> dict[str, Any]:
    """Evaluate a plain-data batch: the unit of work shipped to Dask workers.

    Parameters
    ----------
    payload : dict
        ``{"designs": [design.to_dict(), ...], "task": Task.to_dict()}``.

    Returns
    -------
    dict
        :func:`evaluate`'s output with ``traces=True``, as lists and arrays.
    """
    task = Task.from_dict(payload["task"])
    return evaluate(list(payload["designs"]), task=task, traces=True)
