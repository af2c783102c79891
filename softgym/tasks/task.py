"""A task: terrain + duration + sampling + the metrics it reports + the reward it derives.

In the spirit of dm_control's Physics / Task / Environment split, the engine
(:class:`~softgym.engine.Simulation`) is the physics, a :class:`Task` says what
a run of it means, and :func:`softgym.evaluate` (optimisers) and the Gymnasium
environments (RL) are two ways of running a task. Both get their task here, so
a design scores the same on ``"wall"`` whichever way it is run.

=========  ===============================================  ==============================
name       terrain (voxel lengths, around the robot's grid)   reward (progress per step of)
=========  ===============================================  ==============================
flat       the floor alone                                  ``norm_final_dist``
wall       the seed's fence: 1 voxel high and thick,        ``max_xy_dist``
           a 10-voxel interior (``"fence"``: alias)
stairs     three concentric rings, each 2 voxels wide and   ``max_xy_dist``
           1 voxel higher than the one inside it
=========  ===============================================  ==============================

The rest of the suite (``stairs_down``, ``rough``, ``gap``, ``tunnel``,
``incline``, ``ice``, ``mud``, ``jump``, ``turn``, ``push``, ``carry``,
``swim``, ``grow``, then ``downhill``, ``moon``, ``goal``, ``hurdles``,
``course``, ``mattress``, ``chimney``, ``ledge``, ``beam``, ``balance``,
``stones``, ``push_uphill``, ``throw``, ``catch``, ``lift``, ``shrink``,
``squeeze``) is defined in :mod:`softgym.tasks.suite`: each has its family
(:data:`~softgym.tasks.suite.FAMILIES`), layout, engine settings, measure and
difficulty arguments (``Task("gap", options={"width": 3})`` or
``get_task("gap:width=3")``).

A custom world is a :class:`~softgym.terrain.Terrain` (or its JSON file),
accepted wherever a task name is: ``softgym.evaluate(d, task=Terrain.stairs())``,
``gym.make("SoftWalker-Flat-v0", task="my_boxes.json")``,
``softgym evolve --task my_boxes.json``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softgym.exceptions import InvalidParameterError, InvalidTerrainError
from softgym.metrics import TASK_MEASURES, WALK_METRICS, dilute, task_measure, walk_metrics
from softgym.tasks.suite import KINDS
from softgym.terrain import Terrain
from softgym.validate import positive

if TYPE_CHECKING:  # annotations only: softgym.engine's __init__ loads compiled code
    from softgym.engine import Rollout, SimConfig

__all__ = [
    "ALIASES",
    "REWARDS",
    "TASKS",
    "Task",
    "TaskLike",
    "get_task",
    "measure_params",
    "register_task",
    "task_names",
]

#: Schema tag of :meth:`Task.to_dict`.
SCHEMA = "softgym.task"

#: Metrics whose per-step progress can be a reward (a task's score): the walking measures of
#: the final position and the suite's measures (:data:`softgym.metrics.TASK_MEASURES`).
REWARDS: tuple[str, ...] = ("norm_final_dist", "max_xy_dist", *TASK_MEASURES)


#: Other names users know a task by (the seed's reports call the wall a fence).
ALIASES: dict[str, str] = {"fence": "wall"}


@dataclass(frozen=True)
class Task:
    """How a design is run and scored: the world, the duration, the sampling and the reward.

    Parameters
    ----------
    terrain : str or Terrain
        A layout placed around each robot's grid (``"flat"``, ``"wall"``,
        ``"stairs"``; ``"fence"`` is read as ``"wall"``), or a
        :class:`~softgym.terrain.Terrain` fixed in the world (voxel lengths,
        the robot's grid corner at the origin).
    seconds : float
        Simulated time (s) per run, settling included (5 in the seed: 1 s
        settling, then the 4 s fitness window; an env episode is the window).
    trace_interval : float
        Seconds between centre-of-mass samples (the L coefficient's
        resolution): 0.5 for the seed's novelty runs, 0.1 otherwise.
    sim : dict
        Overrides of :class:`~softgym.engine.SimConfig` (e.g. ``{"actuation": "symmetric"}``),
        over the settings a suite task sets itself (:attr:`engine_settings`).
    n_threads : int, optional
        OpenMP threads of the simulation (default: softgym's default).
    reward : {"norm_final_dist", "max_xy_dist"}, optional
        The metric whose per-step progress an environment rewards; default
        ``norm_final_dist`` on flat ground, ``max_xy_dist`` (the seed's
        obstacle fitness) with obstacles.
    seed_centre_of_mass : bool
        Score on the seed's own centre of mass, which counts the obstacles as
        its 1-kg wall voxels (:func:`softgym.metrics.dilute`): the numbers of
        the seed's obstacle runs, smaller than the robot's own by
        ``m_robot / (m_robot + m_walls)``. Off by default (robot-only).
    options : dict
        Arguments of a suite task (:mod:`softgym.tasks.suite`: gap width,
        step height, roughness...), checked against their ranges; the ones
        not given take their defaults (all are stored).

    Notes
    -----
    Every task reports the walking measures, :func:`softgym.metrics.walk_metrics`
    of its rollout (:meth:`metrics`): ``norm_final_dist``, ``max_xy_dist``,
    ``l_coefficient`` (:data:`~softgym.metrics.WALK_METRICS`), with
    ``time_max_xy_dist`` and ``diverged``; a suite task adds its measure
    (``reward``), and every task reports ``score``, the value of its reward
    metric.
    """

    terrain: str | Terrain = "flat"
    seconds: float = 5.0
    trace_interval: float = 0.1
    sim: dict[str, Any] = field(default_factory=dict)
    n_threads: int | None = None
    reward: str | None = None
    seed_centre_of_mass: bool = False
    options: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        terrain = self.terrain
        if isinstance(terrain, str):
            terrain = ALIASES.get(terrain, terrain)
            if terrain not in KINDS:
                raise InvalidParameterError(
                    f"unknown terrain layout {self.terrain!r}; expected one of "
                    f"{sorted(KINDS)}, a Terrain, or a registered task name through get_task()"
                )
        elif not isinstance(terrain, Terrain):
            raise InvalidParameterError(
                f"terrain must be a layout name or a Terrain, got {type(terrain).__name__}"
            )
        object.__setattr__(self, "terrain", terrain)
        object.__setattr__(self, "seconds", positive("seconds", self.seconds))
        object.__setattr__(self, "trace_interval", positive("trace_interval", self.trace_interval))
        if not isinstance(self.options, Mapping):
            raise InvalidParameterError(f"options must be a dict, got {type(self.options).__name__}")
        kind = KINDS.get(terrain) if isinstance(terrain, str) else None
        if kind is None or not kind.options:
            if self.options:
                raise InvalidParameterError(
                    f"task {self.name!r} takes no options, got {sorted(self.options)}"
                )
            object.__setattr__(self, "options", {})
            object.__setattr__(self, "sim", dict(self.sim))
        else:
            object.__setattr__(self, "options", kind.resolve(self.options))
            object.__setattr__(self, "sim", dict(self.sim))
        from softgym.engine.config import SimConfig  # (the engine loads compiled code: used late)

        known = sorted(f.name for f in fields(SimConfig))
        unknown = sorted(map(str, set(self.sim) - set(known)))
        if unknown:
            raise InvalidParameterError(
                f"task {self.name!r}: sim has unknown SimConfig field(s) {unknown}; the fields are {known}"
            )
        if self.n_threads is not None:
            object.__setattr__(self, "n_threads", int(self.n_threads))
        reward = self.reward
        if reward is None and kind is not None:
            reward = kind.reward
        if reward is None:
            reward = "norm_final_dist" if terrain == "flat" else "max_xy_dist"
        if reward not in REWARDS:
            raise InvalidParameterError(f"reward must be one of {REWARDS}, got {reward!r}")
        object.__setattr__(self, "reward", reward)

    # ---------------------------------------------------------------- naming
    @property
    def name(self) -> str:
        """The layout's name, or the custom terrain's."""
        return self.terrain if isinstance(self.terrain, str) else self.terrain.name

    @property
    def spec(self) -> str | Terrain:
        """The task as :func:`get_task` reads it: ``"name"`` or ``"name:arg=value,..."``, or its Terrain."""
        if isinstance(self.terrain, Terrain):
            return self.terrain
        kind = KINDS.get(self.terrain)
        if kind is None:
            return self.terrain
        changed = {k: v for k, v in self.options.items() if v != kind.options[k].default}
        if not changed:
            return self.terrain
        return self.terrain + ":" + ",".join(f"{k}={v!r}" for k, v in sorted(changed.items()))

    @property
    def shaping(self) -> tuple[tuple[str, float], ...]:
        """Dense guidance an env may add to its reward (:attr:`TaskKind.shaping
        <softgym.tasks.suite.TaskKind.shaping>`): its kind's, none for a custom terrain.
        """
        return KINDS[self.terrain].shaping if isinstance(self.terrain, str) else ()

    @property
    def senses(self) -> tuple:
        """The task's senses (:class:`softgym.tasks.sensing.TaskSense`): its kind's, or for a custom
        terrain the terrain heights ahead where it has boxes and the object where it has objects.
        """
        from softgym.tasks.sensing import SENSES

        if isinstance(self.terrain, str):
            return KINDS[self.terrain].senses
        out = []
        if self.terrain.boxes or not self.terrain.floor:
            out.append(SENSES["terrain"])
        if self.terrain.objects:
            out.append(SENSES["object"])
        return tuple(out)

    @property
    def metric_names(self) -> tuple[str, ...]:
        """The fitness measures the task reports: :data:`softgym.metrics.WALK_METRICS` and its score."""
        extra = (self.reward,) if self.reward not in WALK_METRICS else ()
        return (*WALK_METRICS, *extra, "score")

    # ----------------------------------------------------------------- world
    def terrain_for(self, shape: Sequence[int]) -> Terrain:
        """The terrain of a robot whose grid of ``shape`` has its corner at the origin."""
        if isinstance(self.terrain, Terrain):
            return self.terrain
        return KINDS[self.terrain].layout(shape, **self.options)

    def config(
        self,
        base: SimConfig | None = None,
        *,
        settings: bool = True,
        trace_interval: float | None = None,
        **overrides: Any,
    ) -> SimConfig:
        """The engine settings of a run of the task: the one place they are assembled.

        ``softgym.evaluate``, the Gymnasium envs (:func:`softgym.envs.walker.make_config`)
        and every caller that simulates a task build their :class:`~softgym.engine.SimConfig` here.

        Parameters
        ----------
        base : SimConfig, optional
            The settings to start from (default the seed's).
        settings : bool
            Apply the task's own settings (:attr:`engine_settings`: its kind's,
            then ``sim``); False keeps a full ``base`` as it is
            (``softgym.evaluate(config=...)``).
        trace_interval : float, optional
            Seconds between the engine's centre-of-mass samples (default the task's).
        **overrides
            :class:`~softgym.engine.SimConfig` fields set last (e.g. an env's
            ``actuation``, ``self_collision``); a None value leaves the field as it is.

        Returns
        -------
        SimConfig
        """
        from softgym.engine import SimConfig

        interval = self.trace_interval if trace_interval is None else trace_interval
        fields = {  # the task's settings, then the trace, then the overrides: one SimConfig
            **(self.engine_settings if settings else {}),
            "trace_interval": float(interval),
            **{k: v for k, v in overrides.items() if v is not None},
        }
        return SimConfig(**fields) if base is None else base.replace(**fields)

    @property
    def engine_settings(self) -> dict[str, Any]:
        """The :class:`~softgym.engine.SimConfig` fields the task sets: its kind's, then ``sim``."""
        kind = KINDS.get(self.terrain) if isinstance(self.terrain, str) else None
        base = kind.sim(self.options) if kind is not None else {}
        return {**base, **dict(self.sim)}

    # --------------------------------------------------------------- scoring
    def metrics(self, rollout: Rollout, terrains: Sequence[Terrain] | None = None) -> dict[str, np.ndarray]:
        """What the task reports of a rollout: :func:`softgym.metrics.walk_metrics`, its measure, ``score``.

        Parameters
        ----------
        rollout : Rollout
        terrains : sequence of Terrain, optional
            Each robot's world (its ``meta`` holds the measure's parameters:
            the gap's edge, the push target); default the task's for each
            robot's grid (read from ``rollout.grid_index``).

        Returns
        -------
        dict of str to ndarray of shape (n_robots,)
            ``norm_final_dist``, ``max_xy_dist``, ``l_coefficient``,
            ``time_max_xy_dist``, ``diverged``, the task's measure (a suite
            task's ``reward``) and ``score`` (the reward metric's value).
        """
        if self.seed_centre_of_mass:
            rollout = dilute(rollout)
        out = walk_metrics(rollout)
        if self.reward not in out:
            if terrains is None:
                off = rollout.voxel_offsets
                terrains = [
                    self.terrain_for(rollout.grid_index[off[i]:off[i + 1]].max(axis=0) + 1)
                    for i in range(rollout.n_robots)
                ]
            out[self.reward] = task_measure(self.reward, rollout, measure_params(terrains))
        out["score"] = out[self.reward].copy()
        return out

    # ------------------------------------------------------------------ data
    def replace(self, **changes: Any) -> Task:
        """A copy with some fields changed (an unknown field is an InvalidParameterError naming it)."""
        unknown = sorted(map(str, set(changes) - {f.name for f in fields(self)}))
        if unknown:
            raise InvalidParameterError(
                f"Task has no field(s) {unknown}; its fields are {[f.name for f in fields(self)]}"
            )
        return replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict (a custom terrain as its :meth:`Terrain.to_dict`)."""
        out: dict[str, Any] = {"schema": SCHEMA}
        for f in fields(self):
            v = getattr(self, f.name)
            out[f.name] = v.to_dict() if isinstance(v, Terrain) else v
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Task:
        """Inverse of :meth:`to_dict`."""
        kw = {k: v for k, v in dict(data).items() if k != "schema"}
        unknown = sorted(set(kw) - {f.name for f in fields(cls)})
        if unknown:
            raise InvalidParameterError(f"unknown task fields {unknown}")
        if isinstance(kw.get("terrain"), Mapping):
            kw["terrain"] = Terrain.from_dict(dict(kw["terrain"]))
        return cls(**kw)


def measure_params(terrains: Sequence[Terrain]) -> dict[str, np.ndarray]:
    """The task measures' per-robot parameters from their terrains' ``meta`` (voxel lengths)."""
    n = len(terrains)
    out = {"center": np.zeros((n, 2)), "edge": np.zeros(n), "target": np.zeros((n, 2))}
    for i, t in enumerate(terrains):
        meta = t.meta or {}
        if "center" in meta:
            out["center"][i] = np.asarray(meta["center"], dtype=np.float64)[:2]
        if "edge" in meta:
            out["edge"][i] = float(meta["edge"])
        if "target" in meta:
            out["target"][i] = np.asarray(meta["target"], dtype=np.float64)[:2]
    return out


#: The named tasks: one name each (``"fence"`` is read as ``"wall"``, see :data:`ALIASES`).
TASKS: dict[str, Task] = {name: Task(terrain=name) for name in KINDS}

#: What :func:`get_task` accepts: a name, a JSON file, a Terrain, a Task or its dict.
TaskLike = str | os.PathLike | Terrain | Task | Mapping[str, Any]


def task_names() -> list[str]:
    """The registered task names (aliases excluded)."""
    return list(TASKS)


def register_task(name: str, task: Task | Terrain, *, overwrite: bool = False) -> Task:
    """Add a named task (``register_envs()`` then gives it a Gym id).

    Parameters
    ----------
    name : str
        The task's one name.
    task : Task or Terrain
        A Terrain becomes ``Task(terrain=terrain)``.
    overwrite : bool
        Replace a task of the same name.

    Returns
    -------
    Task
    """
    if not isinstance(name, str) or not name:
        raise InvalidParameterError(f"a task name must be a non-empty string, got {name!r}")
    if isinstance(task, Terrain):
        task = Task(terrain=task)
    if not isinstance(task, Task):
        raise InvalidParameterError(f"expected a Task or a Terrain, got {type(task).__name__}")
    if (name in TASKS or name in ALIASES) and not overwrite:
        raise InvalidParameterError(f"a task named {name!r} exists; pass overwrite=True")
    TASKS[name] = task
    return task


def _read_file(path: Path) -> Task:
    # a regular file within the terrain cap, read without blocking (a FIFO is
    # refused), JSON of any depth a typed error
    from softgym.io import loads_json, read_capped
    from softgym.terrain import MAX_TERRAIN_JSON_BYTES

    data = read_capped(path, MAX_TERRAIN_JSON_BYTES, "task", InvalidParameterError)
    return get_task(loads_json(data, f"task file {str(path)!r}", InvalidTerrainError))


def _parse_options(spec: str, text: str) -> dict[str, float]:
    out: dict[str, float] = {}
    for item in filter(None, (p.strip() for p in text.split(","))):
        key, eq, value = item.partition("=")
        try:
            if not eq:
                raise ValueError
            v = float(value)
        except ValueError:
            raise InvalidParameterError(
                f"task {spec!r}: arguments are name=number pairs separated by commas "
                f"(e.g. 'gap:width=3,depth=5'), got {item!r}"
            ) from None
        if key.strip() in out:
            raise InvalidParameterError(f"task {spec!r}: argument {key.strip()!r} is given twice")
        out[key.strip()] = int(v) if v.is_integer() and "." not in value else v
    return out


def get_task(spec: TaskLike, **overrides: Any) -> Task:
    """The :class:`Task` of a name, a JSON file, a Terrain, a Task or a dict.

    Parameters
    ----------
    spec : str, path, Terrain, Task or dict
        A registered name (:func:`task_names`) or alias, optionally with
        arguments (``"gap:width=3,depth=5"``); the path of a
        terrain JSON file (``Terrain.to_json``) or of a task JSON file
        (``Task.to_dict``); a :class:`~softgym.terrain.Terrain`; a Task; a
        dict of either.
    **overrides
        Task fields to change (``seconds``, ``trace_interval``, ``sim``...).

    Returns
    -------
    Task

    Raises
    ------
    InvalidParameterError
        For an unknown name or an unreadable file.
    InvalidTerrainError
        For a malformed terrain.
    """
    if isinstance(spec, Task):
        task = spec
    elif isinstance(spec, Terrain):
        task = Task(terrain=spec)
    elif isinstance(spec, Mapping):
        if spec.get("schema") == "softgym.terrain":
            task = Task(terrain=Terrain.from_dict(dict(spec)))
        else:
            task = Task.from_dict(spec)
    elif isinstance(spec, str) and ":" in spec and spec.split(":", 1)[0] in TASKS:
        name, args = spec.split(":", 1)
        task = TASKS[name].replace(options={**TASKS[name].options, **_parse_options(spec, args)})
    elif isinstance(spec, (str, os.PathLike)):
        key = ALIASES.get(str(spec), str(spec))
        if isinstance(spec, str) and key in TASKS:
            task = TASKS[key]
        elif str(spec).endswith(".json") or Path(spec).is_file():
            task = _read_file(Path(spec))
        else:
            raise InvalidParameterError(
                f"unknown task {str(spec)!r}; expected one of {task_names()} "
                f"(aliases {sorted(ALIASES)}), a Terrain, or a terrain JSON file"
            )
    else:
        raise InvalidParameterError(
            f"a task is a name, a JSON file, a Terrain or a Task, got {type(spec).__name__}"
        )
    return task.replace(**overrides) if overrides else task
