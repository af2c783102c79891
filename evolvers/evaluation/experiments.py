"""The seed study's scenarios as named, runnable configurations.

==========================  =====================  ==============  ============================================
name                        variation              selection       objectives
==========================  =====================  ==============  ============================================
``basic``                   CPPN                   Pareto          NormFinalDist (max), muscle voxels (min)
``materials-t1``            CPPN + material GA     Pareto          NormFinalDist (max), old materials (min)
``materials-t2``            CPPN + material GA     Pareto          ... + robot voxels (min)
``novelty``                 CPPN                   AMSS (seed)     novelty; fitness and energy logged
``novelty-archive``         CPPN                   AMSS + archive  novelty against past generations too
``controller-tournament``   CPPN + controller GA   tournament (2)  NormFinalDist (max)
``controller-pareto``       CPPN + controller GA   Pareto          NormFinalDist (max), muscle voxels (min)
``obstacles``               CPPN + controller GA   Pareto + age    MaxXYDist (max), L coeff. (max), age (min)
``obstacles-attempt1``      CPPN                   Pareto          MaxXYDist (max), muscle voxels (min)
``obstacles-attempt2``      CPPN + controller GA   tournament (2)  MaxXYDist (max)
``codesign``                CPPN + controller GA   tournament (2)  the task's score (max)
``codesign-afpo``           CPPN + controller GA   Pareto + age    the task's score (max), age (min)
==========================  =====================  ==============  ============================================

``materials`` is an alias of ``materials-t1``. The two ``codesign`` experiments search
bodies and controllers on any task's own measure (its ``score``, also on the walking
tasks, whose other experiments select on NormFinalDist or MaxXYDist): the co-design
leaderboard's search space (benchmarks/leaderboard.py); ``codesign-afpo`` is age-fitness
Pareto optimisation (Schmidt and Lipson 2011). Obstacle experiments run on the
``wall`` task (:mod:`softgym.tasks`: the seed's 1-voxel-high fence, 10-voxel
interior) with centre-of-mass samples every 0.1 s; ``obstacles`` also applies
the seed's composition constraints (>= 10 % tissue, >= 1 bone, >= 10 % muscle).
Any experiment runs on another task with ``get_experiment(name, task="stairs")``
(or a Terrain, or a terrain JSON file: ``softgym evolve --task FILE.json``). Every experiment: 6x6x6 CPPN robots,
population 15, 15 children and 1 random newcomer per generation, 5 s simulated.

Any experiment evolves bodies and brains with ``controller="central"`` or
``"distributed"`` (a network controller, :mod:`softgym.design.brain`, whose
weights are genes next to the CPPN; ``hidden``, ``signals``, ``control_dt``
size it), or a brain alone on a fixed ``body`` (a RobotDesign's ``to_dict()``):
``get_experiment("basic", controller="distributed", body=default_walker().to_dict())``.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any

from evolvers.operators.genome import Individual
from evolvers.operators.selection import SELECTORS, Objective
from softgym.design import MATERIAL_TREE_4, MATERIAL_TREE_8, CompositionRules
from softgym.design.brain import CONTROL_DT_RANGE, MAX_HIDDEN, MAX_SIGNALS, BrainSpec
from softgym.design.robot import RobotDesign
from softgym.exceptions import InvalidParameterError, SoftGymError
from softgym.metrics import WALK_METRICS
from softgym.tasks import Task, get_task
from softgym.terrain import Terrain
from softgym.validate import is_int, is_real, show

__all__ = [
    "CONTROLLERS",
    "EXPERIMENTS",
    "MAX_GENERATIONS",
    "MAX_POP_SIZE",
    "MAX_SEED",
    "SELECTIONS",
    "Experiment",
    "check_generations",
    "check_seed",
    "get_experiment",
    "list_experiments",
]

#: Largest population an experiment accepts (each individual is simulated every
#: generation: 100,000 6x6x6 robots are ~10 CPU-hours a generation).
MAX_POP_SIZE = 100_000

#: Most generations (POET: iterations) a run accepts: a million generations of the
#: smallest population are weeks of CPU; a typo of more digits is refused at once.
MAX_GENERATIONS = 1_000_000

#: Largest seed of a run (the seeds every random generator of the drivers accepts).
MAX_SEED = 2**32 - 1



def check_generations(value: Any, name: str = "generations") -> int:
    """``value`` as a number of generations (iterations), an integer in [0, MAX_GENERATIONS].

    Raises
    ------
    InvalidParameterError
        Naming ``name`` and the accepted range (bools and floats are not counts).
    """
    if not is_int(value) or not 0 <= value <= MAX_GENERATIONS:
        raise InvalidParameterError(
            f"{name} must be an integer in [0, {MAX_GENERATIONS}], got {show(value)}"
        )
    return int(value)


def check_seed(value: Any, name: str = "seed") -> int:
    """``value`` as a run's seed, an integer in [0, MAX_SEED].

    Raises
    ------
    InvalidParameterError
        Naming ``name`` and the accepted range.
    """
    if not is_int(value) or not 0 <= value <= MAX_SEED:
        raise InvalidParameterError(f"{name} must be an integer in [0, {MAX_SEED}], got {show(value)}")
    return int(value)


#: Selection schemes an experiment may name.
SELECTIONS: tuple[str, ...] = tuple(SELECTORS)

#: Controllers an experiment may name: the seed's open-loop sinusoid, or a network
#: (:mod:`softgym.design.brain`) whose weights evolve.
CONTROLLERS: tuple[str, ...] = ("sinusoid", "central", "distributed")


@dataclass(frozen=True)
class Experiment:
    """A runnable evolutionary scenario.

    Parameters
    ----------
    name : str
    description : str
    objectives : tuple of Objective
        Selection objectives, most important first (the first is "the
        fitness" shown in progress bars and trend figures).
    logged : tuple of str
        Extra metrics recorded in the log (not selected on).
    selection : {"pareto", "tournament", "novelty", "novelty-archive", "nsga2"}
    evolve_controller, evolve_materials : bool
        Whether the controller / material genes evolve (crossover + mutation).
    cppn_outputs : tuple of str
        CPPN outputs: the 4-output tree, or the 8-output tree of materials evolution.
    rules : CompositionRules
        Validity of a body (enforced by generation and mutation; pymoo's G).
    task : Task, str or Terrain
        The world: a task name of :mod:`softgym.tasks` (``"flat"``, ``"wall"``,
        ``"stairs"``, ``"gap:width=3"``; ``"fence"`` is read as ``"wall"``), a
        custom :class:`~softgym.terrain.Terrain` (a terrain JSON file's path is
        read into one, so the run folder's config.json holds the whole world) or
        a Task. Read once, here: the experiment holds it as a
        :class:`~softgym.tasks.Task` of the world alone (terrain and arguments);
        :meth:`make_task` adds the duration and sampling.
    seconds : float
        Simulated seconds per evaluation (5).
    trace_interval : float
        Seconds between centre-of-mass samples (0.5 novelty, 0.1 otherwise).
    pop_size, n_random : int
        Population size (15) and random newcomers per generation (1).
    generations : int
        Default number of generations (the report's).
    crossover_rate : float
        Arithmetic crossover rate (0.4).
    shape : tuple of 3 int
        Robot grid (6, 6, 6).
    sim : dict
        :class:`~softgym.engine.SimConfig` overrides.
    seed_centre_of_mass : bool
        Score on the seed's centre of mass, which counts the obstacles' 1-kg
        wall voxels (``Task(seed_centre_of_mass=True)``,
        :func:`softgym.metrics.dilute`): the MaxXYDist and L coefficient the
        seed's obstacle runs selected on. Off by default (the robot's own
        voxels); the study's obstacle scenarios turn it on. Traces, and so a
        crossing of the wall, stay the robot's own.
    controller : {"sinusoid", "central", "distributed"}
        The seed's open-loop sinusoid alone, or a network controller (a
        brain, :func:`softgym.tasks.brains.brain_spec`) whose weights evolve
        (random at first, arithmetic crossover, bounded Gaussian mutation).
    hidden : int
        Hidden units of the network, in [0, MAX_HIDDEN].
    signals : int
        Values a distributed brain's voxel sends each neighbour, in [0,
        MAX_SIGNALS] (unused by a central brain).
    control_dt : float
        Seconds between two control steps of the network.
    body : dict, optional
        A fixed body (a :class:`~softgym.design.RobotDesign`'s ``to_dict()``;
        its own brain is dropped): no CPPN evolves, every robot has this grid
        and palette, and only the brain (and controller genes) vary. Its grid
        must be ``shape`` and pass ``rules``.
    """

    name: str
    description: str
    objectives: tuple[Objective, ...]
    logged: tuple[str, ...] = ()
    selection: str = "pareto"
    evolve_controller: bool = False
    evolve_materials: bool = False
    cppn_outputs: tuple[str, ...] = MATERIAL_TREE_4
    rules: CompositionRules = field(default_factory=CompositionRules.seed)
    task: Task | str | Terrain = "flat"
    seconds: float = 5.0
    trace_interval: float = 0.1
    pop_size: int = 15
    n_random: int = 1
    generations: int = 40
    crossover_rate: float = 0.4
    shape: tuple[int, int, int] = (6, 6, 6)
    sim: dict[str, Any] = field(default_factory=dict)
    seed_centre_of_mass: bool = False
    controller: str = "sinusoid"
    hidden: int = 8
    signals: int = 1
    control_dt: float = 0.05
    body: dict[str, Any] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "_cache", {})
        if self.selection not in SELECTIONS:
            raise InvalidParameterError(
                f"unknown selection {self.selection!r}; expected one of {SELECTIONS}"
            )
        if not is_int(self.pop_size) or not 2 <= self.pop_size <= MAX_POP_SIZE:
            raise InvalidParameterError(
                f"pop_size must be an integer in [2, {MAX_POP_SIZE}], got {show(self.pop_size)}"
            )
        if not self.objectives:
            raise InvalidParameterError("an experiment needs at least one objective")
        object.__setattr__(self, "generations", check_generations(self.generations))
        object.__setattr__(self, "shape", tuple(int(s) for s in self.shape))
        task = get_task(self.task)  # a name, alias, Terrain, JSON file or Task; raises if unknown
        # the world alone (what config.json records, Task.spec): the experiment sets the rest
        task = Task(terrain=task.terrain, options=dict(task.options))
        object.__setattr__(self, "task", task)
        if task.reward not in WALK_METRICS:
            # a suite task that is not about walking: its score replaces the walking distances
            objectives, seen = [], set()
            for o in self.objectives:
                if o.name in ("norm_final_dist", "max_xy_dist"):
                    o = Objective("score", True)
                if o.name not in seen:
                    objectives.append(o)
                    seen.add(o.name)
            object.__setattr__(self, "objectives", tuple(objectives))
        self._check_controller()

    def _check_controller(self) -> None:
        """Validate the controller fields and the fixed body (typed errors naming the field)."""
        if not isinstance(self.controller, str) or self.controller not in CONTROLLERS:
            raise InvalidParameterError(
                f"controller must be one of {list(CONTROLLERS)}, got {show(self.controller)}"
            )
        if not is_int(self.hidden) or not 0 <= self.hidden <= MAX_HIDDEN:
            raise InvalidParameterError(
                f"hidden must be an integer in [0, {MAX_HIDDEN}], got {show(self.hidden)}"
            )
        if not is_int(self.signals) or not 0 <= self.signals <= MAX_SIGNALS:
            raise InvalidParameterError(
                f"signals must be an integer in [0, {MAX_SIGNALS}], got {show(self.signals)}"
            )
        lo, hi = CONTROL_DT_RANGE
        if not is_real(self.control_dt) or not lo <= float(self.control_dt) <= hi:
            raise InvalidParameterError(
                f"control_dt must be a number in [{lo}, {hi}] s, got {show(self.control_dt)}"
            )
        object.__setattr__(self, "hidden", int(self.hidden))
        object.__setattr__(self, "signals", int(self.signals))
        object.__setattr__(self, "control_dt", float(self.control_dt))
        if self.body is not None:
            if not isinstance(self.body, Mapping):
                raise InvalidParameterError(
                    f"body must be a robot design's to_dict() or None, got {type(self.body).__name__}"
                )
            try:
                design = RobotDesign.from_dict(self.body).replace(brain=None)
            except (SoftGymError, KeyError, TypeError, ValueError) as exc:
                raise InvalidParameterError(f"body is not a robot design: {exc}") from None
            if tuple(design.grid.shape) != self.shape:
                raise InvalidParameterError(
                    f"body grid {tuple(design.grid.shape)} does not fit the experiment's shape "
                    f"{self.shape} (use shape={tuple(design.grid.shape)})"
                )
            if not design.is_valid(self.rules):
                raise InvalidParameterError(
                    f"body breaks experiment {self.name!r}'s composition rules"
                )
            if self.evolve_materials:
                raise InvalidParameterError(
                    f"body: a fixed body keeps its own materials; experiment {self.name!r} "
                    "evolves material genes (choose an experiment without materials evolution)"
                )
            if self.controller == "sinusoid" and not self.evolve_controller:
                raise InvalidParameterError(
                    f"body: on a fixed body with the sinusoid controller nothing of experiment "
                    f"{self.name!r} evolves; use controller='central' or 'distributed'"
                )
            object.__setattr__(self, "body", design.to_dict())
            self._cache["body"] = design
        try:
            self.brain_spec()
        except SoftGymError as exc:
            raise InvalidParameterError(f"controller {self.controller!r}: {exc}") from None

    @property
    def evolve_brain(self) -> bool:
        """Whether robots carry an evolving network controller (``controller`` is not sinusoid)."""
        return self.controller != "sinusoid"

    @property
    def evolve_body(self) -> bool:
        """Whether the CPPN body evolves (no fixed ``body``)."""
        return self.body is None

    def fixed_body(self) -> RobotDesign | None:
        """The fixed body as a :class:`~softgym.design.RobotDesign` (None: bodies evolve)."""
        return self._cache.get("body")

    def brain_spec(self) -> BrainSpec | None:
        """The :class:`~softgym.design.brain.BrainSpec` of the robots' brains (None for sinusoid)."""
        if self.controller == "sinusoid":
            return None
        if "brain_spec" not in self._cache:
            from softgym.tasks.brains import brain_spec

            signals = self.signals if self.controller == "distributed" else None
            self._cache["brain_spec"] = brain_spec(
                self.controller, self.make_task(), self.shape, self.hidden, signals,
                self.control_dt,
            )  # fmt: skip
        return self._cache["brain_spec"]

    def random_individual(self, rng: Any, id: int) -> Individual:
        """A random individual of this experiment (CPPN or fixed body; a random brain if any)."""
        return Individual.random(
            rng, id, self.shape, self.cppn_outputs, self.rules,
            brain_spec=self.brain_spec(), body=self.fixed_body(),
        )  # fmt: skip

    def variation(self) -> dict[str, Any]:
        """The keywords of :func:`~evolvers.operators.variation.make_children` for this experiment."""
        return {
            "shape": self.shape, "rules": self.rules, "evolve_controller": self.evolve_controller,
            "evolve_materials": self.evolve_materials, "crossover_rate": self.crossover_rate,
            "evolve_brain": self.evolve_brain, "evolve_body": self.evolve_body,
        }  # fmt: skip

    @property
    def fitness(self) -> Objective:
        """The first (most important) objective."""
        return self.objectives[0]

    @property
    def metrics(self) -> tuple[str, ...]:
        """Every metric recorded: the objectives' (age excluded) and the logged ones."""
        names = [o.name for o in self.objectives if o.name != "age"] + list(self.logged)
        return tuple(dict.fromkeys(names))

    def make_task(self, n_threads: int | None = None) -> Task:
        """The :class:`softgym.tasks.Task` evaluations run (the task with this duration and sampling)."""
        return self.task.replace(
            seconds=self.seconds,
            trace_interval=self.trace_interval,
            sim=dict(self.sim),
            n_threads=n_threads,
            seed_centre_of_mass=self.seed_centre_of_mass,
        )

    def replace(self, **changes: Any) -> Experiment:
        """A copy with some fields changed (e.g. ``pop_size``, ``seconds``, ``shape``).

        A ``task`` given as a task JSON file (``Task.to_json``: schema ``softgym.task``)
        brings its run settings too, as :func:`softgym.evaluate` reads them: its
        ``seconds``, ``trace_interval`` and ``sim``, unless changed here as well (a typed
        ``--seconds`` wins over the file's).
        """
        if "task" in changes:
            for key, value in task_file_settings(changes["task"]).items():
                changes.setdefault(key, value)
        return replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        out: dict[str, Any] = {}
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name == "objectives":
                v = [o.to_dict() for o in v]
            elif f.name == "task":  # as get_task reads it: "name", "name:arg=value", a terrain
                v = v.spec.to_dict() if isinstance(v.spec, Terrain) else v.spec
            elif f.name == "rules":
                v = v.to_dict()
            elif isinstance(v, tuple):
                v = list(v)
            out[f.name] = v
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Experiment:
        """Inverse of :meth:`to_dict` (also reads older run folders' ``terrain`` key).

        Raises
        ------
        InvalidParameterError
            Naming the key, if ``data`` is not an experiment's record (a missing,
            unknown or malformed key).
        """
        if not isinstance(data, Mapping):
            raise InvalidParameterError(f"an experiment must be an object, got {show(data)}")
        kw = dict(data)
        if "terrain" in kw:  # before the task layer: "terrain": "flat" | "fence"
            kw["task"] = kw.pop("terrain")
        known = {f.name for f in fields(cls)}
        unknown = sorted(str(k) for k in kw if k not in known)
        if unknown:
            raise InvalidParameterError(
                f"experiment: unknown key {unknown[0]!r:.60}; the keys are {sorted(known)}"
            )
        for name in ("name", "objectives", "rules", "logged", "cppn_outputs", "shape"):
            if name not in kw:
                raise InvalidParameterError(f"experiment: the key {name!r} is missing")
        if isinstance(kw.get("task"), Mapping):
            kw["task"] = Terrain.from_dict(dict(kw["task"]))
        objectives = kw["objectives"]
        if not isinstance(objectives, list) or not all(isinstance(o, Mapping) for o in objectives):
            raise InvalidParameterError(
                f"experiment: 'objectives' must be a list of objects, got {show(objectives)}"
            )
        try:
            kw["objectives"] = tuple(Objective(**o) for o in objectives)
        except TypeError as exc:  # a missing or unknown key of an objective
            raise InvalidParameterError(f"experiment: 'objectives' {exc!s:.120}") from None
        if not isinstance(kw["rules"], Mapping):
            raise InvalidParameterError(f"experiment: 'rules' must be an object, got {show(kw['rules'])}")
        try:
            kw["rules"] = CompositionRules.from_dict(kw["rules"])
        except (TypeError, KeyError, ValueError) as exc:
            raise InvalidParameterError(f"experiment: 'rules' is malformed ({exc!s:.120})") from None
        for name in ("logged", "cppn_outputs", "shape"):
            if not isinstance(kw[name], (list, tuple)):
                raise InvalidParameterError(f"experiment: {name!r} must be a list, got {show(kw[name])}")
            kw[name] = tuple(kw[name])
        try:
            return cls(**kw)
        except (TypeError, ValueError, KeyError, AttributeError) as exc:
            raise InvalidParameterError(f"experiment: a malformed key ({exc!s:.160})") from None


_FIT = Objective("norm_final_dist", True)
_ENERGY = Objective("n_muscle", False)

EXPERIMENTS: dict[str, Experiment] = {
    e.name: e
    for e in (
        Experiment(
            "basic",
            "evosoro's baseline: CPPN mutation, Pareto on distance and muscle count (report Fig. 4)",
            (_FIT, _ENERGY),
            selection="pareto",
            generations=40,
        ),
        Experiment(
            "materials-t1",
            "materials evolution, treatment 1: distance vs. use of the old materials (report Fig. 1)",
            (_FIT, Objective("n_old_materials", False)),
            logged=("n_voxels",),
            evolve_materials=True,
            cppn_outputs=MATERIAL_TREE_8,
            generations=300,
        ),
        Experiment(
            "materials-t2",
            "materials evolution, treatment 2: treatment 1 plus fewer voxels",
            (_FIT, Objective("n_old_materials", False), Objective("n_voxels", False)),
            evolve_materials=True,
            cppn_outputs=MATERIAL_TREE_8,
            generations=50,
        ),
        Experiment(
            "novelty",
            "novelty search: AMSS similarity of centre-of-mass trajectories within the generation",
            (_FIT,),
            logged=("n_muscle",),
            selection="novelty",
            trace_interval=0.5,
            generations=200,
        ),
        Experiment(
            "novelty-archive",
            "novelty search with an archive of past behaviours (k nearest neighbours)",
            (_FIT,),
            logged=("n_muscle",),
            selection="novelty-archive",
            trace_interval=0.5,
            generations=200,
        ),
        Experiment(
            "controller-tournament",
            "controller evolution with the fitness tournament (report Fig. 4)",
            (_FIT,),
            logged=("n_muscle",),
            selection="tournament",
            evolve_controller=True,
            generations=40,
        ),
        Experiment(
            "controller-pareto",
            "controller evolution with Pareto on distance and muscle count (report Fig. 4)",
            (_FIT, _ENERGY),
            selection="pareto",
            evolve_controller=True,
            generations=40,
        ),
        Experiment(
            "obstacles",
            "evolution vs. a 1-voxel wall, final setup: MaxXYDist, L coefficient and age, composition rules",
            (
                Objective("max_xy_dist", True),
                Objective("l_coefficient", True),
                Objective("age", False),
            ),
            logged=("n_muscle", "n_bone"),
            selection="pareto",
            evolve_controller=True,
            rules=CompositionRules.obstacles(),
            task="wall",
            generations=80,
        ),
        Experiment(
            "obstacles-attempt1",
            "evolution vs. a wall, attempt 1: default controller, Pareto on MaxXYDist and muscle count",
            (Objective("max_xy_dist", True), _ENERGY),
            logged=("l_coefficient",),
            selection="pareto",
            task="wall",
            generations=20,
        ),
        Experiment(
            "obstacles-attempt2",
            "evolution vs. a wall, attempt 2: controller evolution with the fitness tournament on MaxXYDist",
            (Objective("max_xy_dist", True),),
            logged=("l_coefficient", "n_muscle"),
            selection="tournament",
            evolve_controller=True,
            task="wall",
            generations=20,
        ),
        Experiment(
            "codesign",
            "body and controller co-design on the task's own score, fitness tournament "
            "(the leaderboard's search space)",
            (Objective("score", True),),
            logged=("n_muscle",),
            selection="tournament",
            evolve_controller=True,
            generations=40,
        ),
        Experiment(
            "codesign-afpo",
            "body and controller co-design on the task's own score, age-fitness Pareto "
            "(score up, age down)",
            (Objective("score", True), Objective("age", False)),
            logged=("n_muscle",),
            selection="pareto",
            evolve_controller=True,
            generations=40,
        ),
    )
}
EXPERIMENTS["materials"] = EXPERIMENTS["materials-t1"]


def list_experiments() -> list[str]:
    """Names of the named experiments."""
    return list(EXPERIMENTS)


def task_file_settings(task: Any) -> dict[str, Any]:
    """The run settings of a task JSON file (schema ``softgym.task``): ``seconds``,
    ``trace_interval`` and ``sim`` as :func:`softgym.tasks.get_task` reads them; ``{}`` for
    anything else (a task name, a Task, a Terrain or a terrain file carry no run settings of
    their own here).
    """
    if not isinstance(task, (str, os.PathLike)) or not str(task).endswith(".json"):
        return {}
    from softgym.io import read_json

    try:
        doc = read_json(task)
    except SoftGymError:
        return {}  # get_task names what is wrong with the file
    if not (isinstance(doc, Mapping) and doc.get("schema") == "softgym.task"):
        return {}
    t = Task.from_dict(doc)  # the document already read, checked as get_task checks it
    return {"seconds": float(t.seconds), "trace_interval": float(t.trace_interval), "sim": dict(t.sim)}


def get_experiment(name: str, **overrides: Any) -> Experiment:
    """A named experiment, with optional field overrides.

    Raises
    ------
    InvalidParameterError
        If the name is unknown.
    """
    try:
        exp = EXPERIMENTS[name]
    except KeyError:
        raise InvalidParameterError(
            f"unknown experiment {name!r}; expected one of {list_experiments()}"
        ) from None
    return exp.replace(**overrides) if overrides else exp


#: Environment variable: ``SOFTGYM_SMOKE=1`` cuts every run to smoke-test sizes
#: (:func:`smoke_sizes`), so documentation examples run verbatim in seconds (the
#: README's test sets it). Never set it for a real run: a warning says it is on.
SMOKE_ENV = "SOFTGYM_SMOKE"


def smoke_sizes(experiment: Experiment, generations: int) -> tuple[Experiment, int]:
    """``(experiment, generations)``, cut to 1 generation of 4 robots of 4x4x4, 1.5 s each,
    when ``SOFTGYM_SMOKE`` is set to a non-zero value (else unchanged).
    """
    if os.environ.get(SMOKE_ENV, "0").strip() in ("", "0"):
        return experiment, generations
    logging.getLogger("evolvers").warning(
        "%s is set: %s cut to smoke-test sizes (1 generation, 4 robots of 4x4x4, 1.5 s)",
        SMOKE_ENV, experiment.name,
    )  # fmt: skip
    small = experiment.replace(
        pop_size=min(experiment.pop_size, 4),
        seconds=min(experiment.seconds, 1.5),
        # a fixed body keeps its own grid
        shape=experiment.shape if experiment.body else tuple(min(n, 4) for n in experiment.shape),
    )
    return small, min(int(generations), 1)
