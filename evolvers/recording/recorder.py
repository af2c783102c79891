"""The run folder of an evolutionary run, shared by every driver (native, DEAP, pymoo).

A :class:`RunRecorder` owns what a run leaves on disk; a driver owns its search
loop and hands the recorder each finished generation::

    config.json            experiment, seed, backend (what resume checks), generations,
                           the budget's other limits (``budget``, when set)
    log.csv, log.jsonl     one row per generation: best/median/mean/worst of
                           every objective, evaluations, robot-seconds, cache hits,
                           wall time (the generation's, and the run's over sittings),
                           the best individual's genes and composition (top_*),
                           repeated phenotypes, obstacle crossings
                           (rows.py)
    checkpoints/           ckpt-NNNNNN.{json,npz}, atomic, versioned, no pickle
    best_design.json       the best robot found (a RobotDesign file) and
    best_design.vxa        the same robot for VoxCAD / evosoro
    best_designs.json      hall of fame: genomes, designs and objectives
    best_designs/          each of them as rank-K_id-N.json and .vxa
    final_population.json  the last population
    figures/               fitness trend, best robot, its trajectory, its GIF
    notes.jsonl            remarks on the run's history that its numbers cannot tell
                           (e.g. a repair, :func:`add_run_note`); study reports quote them

A checkpoint holds the recorder's state (log rows, hall of fame, totals: simulations,
robot-seconds, wall time; the run's ``budget``: its limits, what is used, what stopped it)
and whatever the driver adds (its random states, counters, the phenotype cache).

The recorder also shows the run's progress (a tqdm bar over generations, off
with ``progress=False``), logs one line per generation to the ``evolvers``
logger, and turns a Ctrl-C into :class:`RunInterrupted`, which names the last
checkpoint and the command that resumes.
"""

from __future__ import annotations

import contextlib
import csv
import datetime as _dt
import io
import json
import logging
import math
import os
import uuid
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from evolvers.evaluation.evaluator import EvalStats
from evolvers.evaluation.experiments import MAX_SEED, Experiment
from evolvers.operators.genome import Individual
from evolvers.recording.rows import log_row, population_summary
from softgym.evaluate import caller_shows_progress
from softgym.exceptions import CheckpointError, InvalidParameterError, SoftGymError
from softgym.io import (
    RunLock,
    atomic_write_json,
    atomic_write_text,
    json_sha256,
    latest_checkpoint,
    load_latest_intact,
    read_json,
    read_json_lines,
    read_json_records,
    remove_stale_temp_files,
    save_checkpoint,
    temp_file_target,
)
from softgym.validate import show

__all__ = [
    "HALL_OF_FAME_SIZE",
    "IDENTITY_FILE",
    "RUN_SCHEMA",
    "RunRecorder",
    "add_run_note",
    "config_difference",
    "read_best_designs",
    "read_run_config",
    "read_run_notes",
]

log = logging.getLogger("evolvers")

#: A run folder's notes, one JSON object per line (:func:`add_run_note`).
NOTES_FILE = "notes.jsonl"


def add_run_note(run_dir: str | os.PathLike[str], text: str, **fields: Any) -> None:
    """Append a note to a run folder's ``notes.jsonl`` (atomic rewrite).

    For what the logs cannot show: a repair, a resume across a change that
    affected results. ``fields`` (plain JSON values) are stored with the text
    and the time.
    """
    path = Path(run_dir) / NOTES_FILE
    notes = read_run_notes(run_dir)
    when = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
    notes.append({"time": when, "text": str(text), **fields})
    atomic_write_text(path, "".join(json.dumps(n) + "\n" for n in notes))


def read_run_notes(run_dir: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """The notes of a run folder (an empty list if it has none).

    Raises
    ------
    CheckpointError
        If ``notes.jsonl`` is not JSON lines.
    """
    path = Path(run_dir) / NOTES_FILE
    if not (path.exists() or path.is_symlink()):
        return []
    return read_json_lines(path)


#: ``"schema"`` of a run's config.json.
RUN_SCHEMA = "softgym.run"
#: The file of a run folder that names the run (:attr:`RunRecorder.identity`).
IDENTITY_FILE = "identity.json"
#: Best individuals kept in ``best_designs.json``.
HALL_OF_FAME_SIZE = 5
#: Checkpoints kept on disk (older ones are removed).
KEEP_CHECKPOINTS = 3
# the recorder's part of a checkpoint's state
_RECORDER_KEYS = (
    "rows", "hall_of_fame", "evaluations_total", "wall_total", "robot_seconds_total",
    "wall_clock_total",
)  # fmt: skip
#: Entries of config.json that a resume may change (not settings: no part of the run's identity).
_EXTENDABLE = ("generations", "budget")


class RunInterrupted(KeyboardInterrupt):
    """A run stopped by Ctrl-C (or SIGTERM under the CLI); its last checkpoint is intact.

    A ``KeyboardInterrupt``, so code that lets Ctrl-C through still does.

    Attributes
    ----------
    out : Path
        The run folder.
    generation : int
        The last finished (checkpointed) generation, -1 if none.
    checkpoint : Path or None
        Its checkpoint file.
    resume : str
        How to continue (a shell command or a Python call).
    """

    def __init__(self, out: Path, generation: int, checkpoint: Path | None, resume: str) -> None:
        self.out = Path(out)
        self.generation = int(generation)
        self.checkpoint = checkpoint
        self.resume = resume
        where = (
            f"generation {generation} is checkpointed in {checkpoint}"
            if checkpoint is not None
            else "no generation had finished"
        )
        super().__init__(f"interrupted: {where}; resume with: {resume}")


def read_run_config(out: str | Path) -> dict[str, Any]:
    """The config.json of a run folder (experiment, seed, backend, generations...).

    Raises
    ------
    CheckpointError
        If the folder holds no readable run config (the message names the file).
    """
    path = Path(out) / "config.json"
    cfg = read_json(path)  # CheckpointError naming the file if it is missing or corrupt
    if not isinstance(cfg, dict) or not isinstance(cfg.get("experiment"), dict):
        raise CheckpointError(f"{path}: not a softgym run config")
    try:
        Experiment.from_dict(cfg["experiment"])
    except SoftGymError as exc:
        raise CheckpointError(f"{path}: 'experiment' is not a valid experiment ({exc})") from None
    seed, backend = cfg.get("seed"), cfg.get("backend")
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
        raise CheckpointError(f"{path}: 'seed' must be an integer in [0, {MAX_SEED}], got {show(seed)}")
    if not isinstance(backend, str):
        raise CheckpointError(f"{path}: 'backend' must be a string, got {show(backend)}")
    gens = cfg.get("generations", 0)
    if isinstance(gens, bool) or not isinstance(gens, int) or gens < 0:
        raise CheckpointError(f"{path}: 'generations' must be an integer >= 0, got {show(gens)}")
    if not isinstance(cfg.get("budget", {}), dict):
        raise CheckpointError(f"{path}: 'budget' must be an object of limits, got {show(cfg['budget'])}")
    return cfg


def read_best_designs(out: str | Path) -> list[dict[str, Any]]:
    """The hall of fame of a run folder's ``best_designs.json``, best first (through the
    capped reader): each entry a dict with ``design`` and ``objectives`` objects.

    Raises
    ------
    CheckpointError
        Naming the file and the key, if it is missing, not a regular file, oversized,
        malformed, or holds no entry.
    """
    path = Path(out) / "best_designs.json"
    best = read_json_records(path, "best", "entries")
    for i, entry in enumerate(best):
        for key in ("design", "objectives"):
            value = entry.get(key)
            if not isinstance(value, dict):
                raise CheckpointError(f"{path}: 'best'[{i}] needs the object {key!r}, got {show(value)}")
    return best


def config_difference(recorded: Any, given: Any, name: str = "") -> str | None:
    """The first setting where two configs differ, as ``"name: recorded != given"``, or None."""
    if isinstance(recorded, Mapping) and isinstance(given, Mapping):
        for k in list(recorded) + [k for k in given if k not in recorded]:
            diff = config_difference(
                recorded.get(k), given.get(k), f"{name}.{k}" if name else str(k)
            )
            if diff is not None:
                return diff
        return None
    if isinstance(recorded, (list, tuple)) and isinstance(given, (list, tuple)):
        if len(recorded) == len(given):
            for i, (a, b) in enumerate(zip(recorded, given)):
                diff = config_difference(a, b, f"{name}[{i}]")
                if diff is not None:
                    return diff
            return None
    if recorded == given:
        return None
    return f"{name}: {recorded!r} (recorded) != {given!r}"


def _settings_sha256(config: Mapping[str, Any]) -> str:
    """The digest of a run's settings (its config.json but ``generations`` and ``budget``,
    which a resume may extend): ``config_sha256`` of ``identity.json``.
    """
    return json_sha256({k: v for k, v in config.items() if k not in _EXTENDABLE})


class RunRecorder:
    """Run folder, config, log, hall of fame, atomic checkpoints, best designs and figures.

    Parameters
    ----------
    out : path
        Run folder.
    experiment : Experiment
    seed : int
    backend : str
        The driver (``"native"``, ``"deap"``, ``"pymoo"``...); with the
        experiment and the seed, what a resume must match.
    figures, gif : bool
        Write the figures (and the best robot's GIF) when the run finishes.
    extra_config : dict, optional
        More entries of config.json (e.g. the pymoo algorithm), also checked on resume.
    progress : bool
        Show a tqdm bar over the generations (on stderr).
    """

    def __init__(
        self,
        out: str | Path,
        experiment: Experiment,
        seed: int,
        backend: str,
        figures: bool = True,
        gif: bool = True,
        extra_config: Mapping[str, Any] | None = None,
        progress: bool = True,
    ) -> None:
        self.out = Path(out)
        self.experiment = experiment
        self.figures = figures
        self.gif = gif
        self.progress = progress
        self._bar: Any = None
        self.config: dict[str, Any] = {
            "schema": RUN_SCHEMA,
            "version": 1,
            "experiment": experiment.to_dict(),
            "seed": int(seed),
            "backend": backend,
            **dict(extra_config or {}),
        }
        #: The run's identity, recorded in ``identity.json`` when it starts and in
        #: every checkpoint (``run_id``: random per run; ``config_sha256``: its
        #: settings): a checkpoint of another run copied into this folder is never
        #: resumed. Not a setting: config.json (what runs are compared by) holds none.
        self.identity: dict[str, str] | None = None
        # a folder resumed from before runs had identities gets one with its first new
        # checkpoint (until then its checkpoints, which record none, stay resumable)
        self._identity_unwritten = False
        self.rows: list[dict[str, Any]] = []
        self.hall_of_fame: list[dict[str, Any]] = []
        self.evaluations_total = 0
        self.wall_total = 0.0
        #: Simulated seconds summed over the simulated robots, every sitting.
        self.robot_seconds_total = 0.0
        #: Wall-clock seconds of the run, every sitting (checkpoint writes included; the
        #: ``wall_total`` of the log counts the generations' own time).
        self.wall_clock_total = 0.0
        self.generations: int | None = None
        #: The budget's limits beyond the generations (config.json's ``budget``; empty: none).
        self.budget: dict[str, Any] = {}

    @property
    def checkpoint_dir(self) -> Path:
        """Folder of the checkpoints."""
        return self.out / "checkpoints"

    def _has_checkpoint(self) -> bool:
        return self.checkpoint_dir.exists() and any(self.checkpoint_dir.glob("ckpt-*.json"))

    # ------------------------------------------------------------------ opening
    def start(self, generations: int) -> None:
        """Create the run folder (refusing one that holds another run's checkpoints, or
        other files and no run: they could be overwritten).
        """
        self.out.mkdir(parents=True, exist_ok=True)
        if self._has_checkpoint():
            raise CheckpointError(
                f"{self.out}: the folder already holds a run; use resume (--resume) or another --out"
            )
        self._refuse_foreign_files()
        remove_stale_temp_files(self.out)
        self.generations = generations
        self._new_identity()
        self._write_config()

    def _refuse_foreign_files(self) -> None:
        """A folder that holds no run (no config.json) must be empty but for what a run
        writes before its config (its lock, its identity): a user's files in it would be
        overwritten (log.csv, figures...).
        """
        if (self.out / "config.json").exists():
            return
        own = {RunLock.FILE_NAME, IDENTITY_FILE, "config.json"}
        foreign = sorted(
            p.name for p in self.out.iterdir()
            if p.name not in own and temp_file_target(p.name) not in own
        )  # fmt: skip
        if foreign:
            shown = ", ".join(foreign[:3]) + (f" and {len(foreign) - 3} more" if len(foreign) > 3 else "")
            raise CheckpointError(
                f"{self.out} is not empty ({shown}) and holds no run (no config.json): its files "
                "could be overwritten; choose an empty or new folder (another --out)"
            )

    def _new_identity(self, write: bool = True) -> None:
        self.identity = {"run_id": uuid.uuid4().hex, "config_sha256": _settings_sha256(self.config)}
        self._identity_unwritten = True
        if write:
            self._write_identity()

    def _write_identity(self) -> None:
        atomic_write_json(self.out / IDENTITY_FILE, self.identity)
        self._identity_unwritten = False

    def _recorded_identity(self, cfg: Mapping[str, Any]) -> dict[str, str] | None:
        """The run's identity from ``identity.json`` (None in a folder written before runs
        had one), its ``config_sha256`` checked against config.json's settings.

        Raises
        ------
        CheckpointError
            If ``identity.json`` is not an identity, or config.json was edited after
            the run started (an edited population size would resume as the same run).
        """
        path = self.out / IDENTITY_FILE
        if not (path.exists() or path.is_symlink()):
            return None
        ident = read_json(path)
        if not (isinstance(ident, dict) and all(isinstance(ident.get(k), str)
                                                for k in ("run_id", "config_sha256"))):  # fmt: skip
            raise CheckpointError(
                f"{path}: not a run identity (the strings run_id and config_sha256 expected)"
            )
        if ident["config_sha256"] != _settings_sha256(cfg):
            raise CheckpointError(
                f"{self.out / 'config.json'} was changed after the run started (its settings no "
                f"longer match config_sha256 in {path}); restore it, or start a new run in "
                "another --out"
            )
        return {"run_id": ident["run_id"], "config_sha256": ident["config_sha256"]}

    def _write_config(self) -> None:
        extendable = {"generations": self.generations}
        if self.budget:
            extendable["budget"] = dict(self.budget)
        atomic_write_json(self.out / "config.json", {**self.config, **extendable})

    def _same(self, key: str, recorded: Any) -> bool:
        if key != "experiment":
            return recorded == self.config[key]
        try:  # read through Experiment: older folders spell some fields differently
            was = Experiment.from_dict(recorded).to_dict()
        except Exception:
            return False
        now = dict(self.config[key])
        for d in (was, now):  # a reworded description does not change a run
            d.pop("description", None)
        return was == now

    def resume(self, generations: int) -> tuple[dict[str, Any], dict[str, np.ndarray]] | None:
        """Load the latest intact checkpoint of the run folder and the recorder's part of it.

        If the newest checkpoint is corrupt (e.g. truncated by a kill), the
        newest intact one is used instead and one warning line on the
        ``softgym.io`` logger names the skipped file(s); the driver then redoes
        the lost generations, which finishes exactly like an uninterrupted run
        (:func:`softgym.io.load_latest_intact`).

        Returns
        -------
        (state, arrays) or None
            The checkpoint (for the driver to restore its part), or None if
            the folder has no checkpoint yet (the run starts fresh).

        Raises
        ------
        CheckpointError
            If config.json names another experiment/seed/backend, or no
            checkpoint in ``checkpoints/`` is intact (the message names each
            file and why).
        """
        cfg_path = self.out / "config.json"
        if not cfg_path.exists():
            return None
        cfg = read_run_config(self.out)
        # config.json as the run started (identity.json holds its digest), then as given
        recorded_identity = self._recorded_identity(cfg)
        for key in self.config:
            if key in ("schema", "version"):
                continue
            if not self._same(key, cfg.get(key)):
                recorded = cfg.get(key)
                if key == "experiment" and isinstance(recorded, dict):
                    try:
                        recorded = Experiment.from_dict(recorded).to_dict()
                    except Exception:  # an unreadable record: compare it as it is
                        pass
                diff = config_difference(recorded, self.config[key], key)
                raise CheckpointError(
                    f"{self.out} was started with another {diff or key}; "
                    "resume with the run's own settings (softgym evolve --out DIR --resume)"
                )
        # the settings as recorded (a reworded description or an older spelling is the same
        # run): config.json keeps matching its digest in identity.json
        self.config = {k: v for k, v in cfg.items() if k not in _EXTENDABLE}
        if recorded_identity is not None:
            self.identity = recorded_identity
        else:  # a folder written before runs had an identity: it gets one from now on
            self._new_identity(write=False)
        # what a killed write left (.NAME.tmpPID): this run holds the folder's lock
        remove_stale_temp_files(self.out)
        if not self._has_checkpoint():
            if self._identity_unwritten:
                self._write_identity()
            return None
        # a checkpoint that records another run's identity, or none (copied in, whatever
        # its name), is skipped, and the run's own newest one resumed, or none: an error
        legacy = self._identity_unwritten
        state, arrays, found, _ = load_latest_intact(
            self.checkpoint_dir, identity=None if legacy else self.identity,
            settings_sha256=self.identity["config_sha256"] if legacy else None,
        )  # fmt: skip
        if legacy:  # a folder without identity.json
            recorded = read_json(found).get("identity")
            if isinstance(recorded, dict) and isinstance(recorded.get("run_id"), str):
                # the run's own checkpoint (its settings checked): a kill came between it
                # and identity.json, which the run keeps
                self.identity = {"run_id": recorded["run_id"],
                                 "config_sha256": recorded["config_sha256"]}  # fmt: skip
                self._write_identity()
        try:
            self.rows = list(state["rows"])
            self.hall_of_fame = list(state["hall_of_fame"])
            self.evaluations_total = int(state["evaluations_total"])
            self.wall_total = float(state["wall_total"])
            # checkpoints from before budgets: every simulation ran the experiment's seconds
            self.robot_seconds_total = float(state.get(
                "robot_seconds_total", self.evaluations_total * float(self.experiment.seconds)
            ))  # fmt: skip
            self.wall_clock_total = float(state.get("wall_clock_total", self.wall_total))
            counts = (self.evaluations_total, self.wall_total, self.robot_seconds_total,
                      self.wall_clock_total)  # fmt: skip
            if not all(math.isfinite(x) and x >= 0 for x in counts):
                raise ValueError("the run's counts (evaluations, seconds) must be finite and >= 0")
            if not all(isinstance(r, dict) for r in self.rows):
                raise TypeError("'rows' must be a list of objects")
            for h in self.hall_of_fame:  # as update_hall_of_fame and write_best read them
                if not (isinstance(h, dict) and isinstance(h.get("generation"), int)):
                    raise TypeError("'hall_of_fame' entries need an integer 'generation'")
                Individual.from_dict(h.get("individual"))
        except (KeyError, TypeError, ValueError) as exc:
            raise CheckpointError(
                f"{self.checkpoint_dir}: checkpoint content is invalid ({exc!r})"
            ) from exc
        self.generations = generations
        self._write_config()
        return state, arrays

    # ------------------------------------------------------------------ progress
    def open_progress(self, generation: int, generations: int, desc: str) -> None:
        """Start the progress bar at ``generation`` (the last finished one) of ``generations``."""
        self.close_progress()
        if not self.progress:
            return
        from tqdm.auto import tqdm

        self._bar = tqdm(
            total=generations + 1, initial=generation + 1, desc=desc, unit="gen",
            dynamic_ncols=True, leave=True,
        )  # fmt: skip
        # one bar at a time: the batches of the run show none of their own
        self._bar_scope = contextlib.ExitStack()
        self._bar_scope.enter_context(caller_shows_progress())

    def close_progress(self) -> None:
        """Close the progress bar (if any)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None
            self._bar_scope.close()

    def _report(self, row: Mapping[str, Any], generations: int | None) -> None:
        fit = self.experiment.fitness
        best = row.get(f"{fit.name}_best", float("nan"))
        of = "" if generations is None else f"/{generations}"
        log.info(
            "%s generation %d%s: best %s %.4g, %d simulated (%d in all), %.1f s",
            self.out, row["generation"], of, fit.name, best, row["evaluations"],
            row["evaluations_total"], row["wall_time"],
        )  # fmt: skip
        if self._bar is not None:
            self._bar.n = int(row["generation"]) + 1
            if isinstance(best, float) and math.isfinite(best):
                self._bar.set_postfix(best=f"{best:.3f}", evals=row["evaluations_total"],
                                      refresh=False)  # fmt: skip
            self._bar.refresh()

    def interrupted(self, generation: int, resume: str) -> RunInterrupted:
        """Close the bar, log where the run stopped (INFO: the exception says it to the user,
        the CLI in one message) and return the :class:`RunInterrupted` to raise.

        Parameters
        ----------
        generation : int
            The last finished (checkpointed) generation, -1 if none.
        resume : str
            The command (or call) that resumes.
        """
        self.close_progress()
        ckpt = latest_checkpoint(self.checkpoint_dir) if self.checkpoint_dir.exists() else None
        exc = RunInterrupted(self.out, generation, ckpt, resume)
        log.info("%s: %s", self.out, exc)
        return exc

    # ------------------------------------------------------------------ records
    def update_hall_of_fame(self, individuals: Sequence[Individual], generation: int) -> None:
        """Add evaluated individuals found in ``generation``; keep the best (by the fitness)."""
        fit = self.experiment.fitness
        known = {h["individual"]["id"] for h in self.hall_of_fame}
        for ind in individuals:
            if ind.id in known or not ind.objectives:
                continue
            self.hall_of_fame.append({"generation": int(generation), "individual": ind.to_dict()})
            known.add(ind.id)
        sign = -1.0 if fit.maximize else 1.0

        def key(h: dict[str, Any]) -> tuple[float, int]:
            d = h["individual"]
            v = d["age"] if fit.name == "age" else d["objectives"][fit.name]
            return (sign * float(v), int(d["id"]))

        self.hall_of_fame.sort(key=key)
        del self.hall_of_fame[HALL_OF_FAME_SIZE:]

    def best(self) -> Individual:
        """The best individual found so far (by the first objective)."""
        if not self.hall_of_fame:
            raise InvalidParameterError("the run has no evaluated individual yet")
        return Individual.from_dict(self.hall_of_fame[0]["individual"])

    def end_generation(
        self,
        generation: int,
        population: Sequence[Individual],
        stats: EvalStats,
        wall: float,
        state: Mapping[str, Any],
        arrays: Mapping[str, np.ndarray],
        columns: Mapping[str, Any] | None = None,
        elapsed: float | None = None,
        budget: Callable[[], Mapping[str, Any]] | None = None,
    ) -> dict[str, Any]:
        """Book-keeping after a generation: totals, log row, checkpoint, log files, best designs.

        Parameters
        ----------
        generation : int
        population : sequence of Individual
            The population after selection.
        stats : EvalStats
            What the generation's evaluation did.
        wall : float
            Its wall time (s).
        state, arrays : dict
            The driver's part of the checkpoint (random states, counters, caches).
        columns : dict, optional
            More log columns of the driver (e.g. a quality-diversity archive's
            QD-score and coverage), added to the row before it is checkpointed.
        elapsed : float, optional
            The run's wall-clock seconds so far, every sitting (default: the total adds
            ``wall``).
        budget : callable, optional
            ``budget()``, called once the totals count this generation: the run's budget
            (limits, use, what stopped it), checkpointed as ``budget``.

        Returns
        -------
        dict
            The log row.
        """
        self.wall_total += wall
        self.evaluations_total += stats.n_simulated
        self.robot_seconds_total += stats.robot_seconds
        self.wall_clock_total = self.wall_clock_total + wall if elapsed is None else float(elapsed)
        row = log_row(
            self.experiment, generation, population, stats, wall,
            self.evaluations_total, self.wall_total,
        )  # fmt: skip
        row.update(
            robot_seconds=stats.robot_seconds, robot_seconds_total=self.robot_seconds_total,
            wall_clock_total=self.wall_clock_total,
        )  # fmt: skip
        row.update(columns or {})
        self.rows.append(row)
        if budget is not None:
            state = {**state, "budget": dict(budget())}
        self.checkpoint(generation, population, state, arrays)
        self.write_log()
        self.write_best()
        self._report(row, self.generations)
        return row

    def checkpoint(
        self,
        generation: int,
        population: Sequence[Individual],
        state: Mapping[str, Any],
        arrays: Mapping[str, np.ndarray],
    ) -> Path:
        """Write a checkpoint (atomic; keeps the previous ones)."""
        full = {
            **dict(state),
            "generation": int(generation),
            "population": population_summary(population),
            **{k: getattr(self, k) for k in _RECORDER_KEYS},
        }
        path = save_checkpoint(
            self.checkpoint_dir, generation, full, dict(arrays), keep=KEEP_CHECKPOINTS,
            identity=self.identity,
        )
        if self._identity_unwritten:  # after the checkpoint: a kill between leaves no
            self._write_identity()  # identity.json that the folder's checkpoints lack
        return path

    def write_log(self) -> None:
        """Write log.csv and log.jsonl (atomic)."""
        if not self.rows:
            return
        keys: list[str] = []
        for r in self.rows:
            for k in r:
                if k not in keys:
                    keys.append(k)
        buf = io.StringIO()
        w = csv.DictWriter(buf, fieldnames=keys, lineterminator="\n")
        w.writeheader()
        for r in self.rows:
            w.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in r.items()})
        atomic_write_text(self.out / "log.csv", buf.getvalue())
        atomic_write_text(self.out / "log.jsonl", "".join(json.dumps(r) + "\n" for r in self.rows))

    def write_best(self) -> None:
        """Write best_designs.json (the hall of fame) and best_design.json."""
        if not self.hall_of_fame:
            return
        exp = self.experiment
        entries = []
        for h in self.hall_of_fame:
            ind = Individual.from_dict(h["individual"])
            entries.append(
                {
                    "generation": h["generation"],
                    "id": ind.id,
                    "objectives": ind.objectives,
                    "design": ind.design(exp.shape).to_dict(),
                    "genome": h["individual"],
                }
            )
        atomic_write_json(self.out / "best_designs.json", {"experiment": exp.name, "best": entries})
        atomic_write_json(self.out / "best_design.json", entries[0]["design"])
        self._write_design_files(entries)

    def _vxa_text(self, design: Any, to_vxa: Any) -> str:
        # the .vxa of a design in the run's world: obstacles on the lattice as the
        # seed's fixed wall voxels; a world the seed could not hold gives the robot alone
        from softgym.exceptions import InvalidTerrainError

        seconds = float(self.experiment.seconds)
        terrain = self.experiment.make_task().terrain_for(design.shape)
        try:
            return to_vxa(design, sim_time=seconds, terrain=terrain)
        except InvalidTerrainError as exc:
            log.warning("%s: .vxa without the terrain (%s)", self.out, exc)
            return to_vxa(design, sim_time=seconds)

    def _write_design_files(self, entries: list[dict[str, Any]]) -> None:
        """best_design.vxa and best_designs/rank-K_id-N.{json,vxa} (stale ones removed)."""
        from softgym.design import RobotDesign
        from softgym.design.vxa import to_vxa

        folder = self.out / "best_designs"
        folder.mkdir(exist_ok=True)
        keep = set()
        for rank, e in enumerate(entries, start=1):
            stem = f"rank-{rank}_id-{e['id']}"
            keep.update({f"{stem}.json", f"{stem}.vxa"})
            atomic_write_json(folder / f"{stem}.json", e["design"])
            try:
                design = RobotDesign.from_dict(e["design"])
                text = self._vxa_text(design, to_vxa)
            except Exception as exc:  # a design VoxCAD cannot hold must not stop the run
                log.warning("%s: no .vxa for design %s (%s)", self.out, e["id"], exc)
                continue
            atomic_write_text(folder / f"{stem}.vxa", text)
            if rank == 1:
                atomic_write_text(self.out / "best_design.vxa", text)
        for old in folder.glob("rank-*"):
            if old.name not in keep:
                old.unlink(missing_ok=True)

    def finish(self, generation: int, population: Sequence[Individual],
               stopped_by: str | None = None) -> None:  # fmt: skip
        """Write the final population (with the budget that stopped the run), the best
        designs and the figures.
        """
        self.close_progress()
        final: dict[str, Any] = {"generation": generation}
        if stopped_by is not None:
            final["stopped_by"] = stopped_by
        atomic_write_json(
            self.out / "final_population.json",
            {**final, "population": population_summary(population)},
        )
        self.write_best()
        if self.figures:
            try:
                from softgym.render.figures import run_figures

                run_figures(self.out, gif=self.gif)
            except Exception:  # figures must never lose a finished run
                log.exception("could not write the figures of %s", self.out)
