"""Is each task meaningful? Random actions, the seed's sinusoid and a controller evolution, per task.

For every registered task (``softgym.tasks.task_names()``), on the default
6x6x6 walker, 3 s episodes after the 1 s settling:

* **random**: uniform random actions in [-1, 1] in the task's Gym vector env
  (``SoftWalkerVectorEnv``, 0.05 s control steps), mean score of 3 episodes;
* **sinusoid**: the design's own controller (the seed's open-loop sinusoid,
  what ``softgym.evaluate`` reports), the walker placed as designed;
* **best heading**: the best of that sinusoid with the walker turned 0, 90,
  180 and 270 degrees about the vertical (its gait heads -x as designed; a
  task with a fixed direction, incline's +x uphill, wants it turned round);
* **evolved**: the best score of an evolution of the walker's controller (the
  body stays the default walker's), median and range over 3 seeds. The
  genome: the heading (one of the four, inherited), a drive phase and an
  amplitude (0-1, a factor on the cell's CTE: never more drive than the
  seed's) per voxel, and the period (in the seed's controller bounds, 0.01 to
  0.75 s); the engine's own sinusoid runs it, each cell its own material row.
  An elitist (mu + lambda) strategy, (3 + 10) by default for 20 generations
  (200 controllers a seed), starts from the sinusoid at the four headings and
  mutants of them; mutations (:func:`mutate`) change a tenth of the cells, add
  a travelling phase wave, shift the phase or scale the amplitude of a region,
  or change the period and overall amplitude. Each generation is one batched
  Simulation restored from the settled states; scores are deterministic, so
  parents are not re-scored;
* **env steps/s**: robot control steps (0.05 s) per second of wall time of the
  task's vector env with 3 robots under random actions.

A task is meaningful when the evolved controller beats random actions and the
seed's sinusoid (and the scores differ). The score is the task's ``score`` (its
reward metric: voxel lengths, radians for ``turn``, voxel lengths^2 for
``grow``).

    python benchmarks/bench_tasks.py              # (3 + 10) x 20 generations x 3 seeds (~1.5-2 h)
    python benchmarks/bench_tasks.py --quick      # a few minutes: (2 + 4) x 2 generations x 1 seed
    python benchmarks/bench_tasks.py --tasks gap,push --seeds 1 --no-append
"""

from __future__ import annotations

import argparse
import json
import logging
import tempfile
import time
from dataclasses import dataclass

import numpy as np
import results_log  # benchmarks/results_log.py

from softgym.design import CONTROLLER_BOUNDS, default_walker
from softgym.engine import Body, Simulation
from softgym.envs import SoftWalkerVectorEnv
from softgym.tasks import get_task, task_names


def _run_episode(env: SoftWalkerVectorEnv, policy) -> np.ndarray:
    """One episode of every sub-env; returns the ``score`` each had when its episode ended."""
    obs, _ = env.reset(seed=0)
    score = np.full(env.num_envs, np.nan)
    t = 0
    while np.isnan(score).any():
        obs, _, term, trunc, info = env.step(policy(obs, t))
        t += 1
        ended = (term | trunc) & np.isnan(score)
        score[ended] = np.asarray(info["score"], dtype=np.float64)[ended]
    return score


def _make(task: str, n: int, args: argparse.Namespace) -> SoftWalkerVectorEnv:
    steps = int(round(args.episode / args.control_dt))
    return SoftWalkerVectorEnv(num_envs=n, task=task, episode_seconds=args.episode,
                               control_dt=args.control_dt, max_episode_steps=steps,
                               n_threads=args.threads)  # fmt: skip


def random_score(task: str, args: argparse.Namespace) -> tuple[float, float]:
    """Mean score of 3 random-action episodes and the env's robot steps per second."""
    env = _make(task, 3, args)
    rng = np.random.default_rng(0)
    shape = env.single_action_space.shape

    def policy(obs, t):
        return rng.uniform(-1.0, 1.0, (env.num_envs, *shape))

    env.reset(seed=0)  # the first reset settles: not timed
    t0 = time.perf_counter()
    score = _run_episode(env, policy)
    wall = time.perf_counter() - t0
    return float(score.mean()), 3 * int(round(args.episode / args.control_dt)) / wall


def heading_design(design, k: int):
    """``design`` turned ``k`` quarter turns about the vertical axis (its grid rotated in x-y)."""
    if k % 4 == 0:
        return design
    return design.replace(grid=np.ascontiguousarray(np.rot90(design.grid, k, axes=(0, 1))))


def phase_body(design, phase: np.ndarray, amp: np.ndarray, period: float | None = None) -> Body:
    """``design``'s body with a drive phase (rad) and amplitude (0-1, on its CTE) per filled cell.

    Each filled cell becomes its own material id (its material's row, CTE times
    ``amp``, phase ``phase``), so the engine's own sinusoid drives it: the seed's
    continuous drive, shifted and scaled cell by cell. ``period`` (s) replaces
    the controller's period when given.
    """
    base = design.to_body()
    flat = design.grid.ravel()
    cells = np.flatnonzero(flat)
    mat = flat[cells].astype(np.intp)
    grid = np.zeros(flat.size, dtype=np.int32)
    grid[cells] = np.arange(1, cells.size + 1)

    def table(values: np.ndarray) -> np.ndarray:
        return np.concatenate([[0.0], np.asarray(values, dtype=np.float64)])

    return Body(
        grid=grid.reshape(design.grid.shape),
        youngs_modulus=table(base.youngs_modulus[mat]),
        density=table(base.density[mat]),
        poisson=table(base.poisson[mat]),
        cte=table(base.cte[mat] * amp[cells]),
        mu_static=table(base.mu_static[mat]),
        mu_kinetic=table(base.mu_kinetic[mat]),
        phase=table(phase[cells]),
        temp_amplitude=base.temp_amplitude,
        period=base.period if period is None else float(period),
    )


@dataclass
class Genome:
    """A controller of the default walker: its heading, a drive phase and amplitude per cell, a period.

    ``heading`` (quarter turns about the vertical axis) is where the walker is
    placed facing; it is inherited, never mutated. ``phase`` (rad) and ``amp``
    (0-1, a factor on the cell's CTE: never more drive than the seed's) are
    indexed by the turned grid's cells; ``period`` (s) stays in the seed's
    controller bounds.
    """

    heading: int
    phase: np.ndarray
    amp: np.ndarray
    period: float


class PhaseRunner:
    """Scores :class:`Genome` controllers of the default walker on a task, batched.

    The settled state of each heading (1 s, no actuation: the same for every
    controller) is simulated once and restored robot by robot; each batch then
    runs ``episode`` seconds of the engine's own drive and reports the task's
    ``score`` (its :meth:`~softgym.tasks.Task.metrics`, as ``softgym.evaluate``).
    Scores are deterministic (robots are independent and bit-identical whatever
    the batch), so the evolution never re-scores a parent.
    """

    def __init__(self, task: str, n: int, args: argparse.Namespace) -> None:
        self.base = default_walker()
        self.designs = [heading_design(self.base, k) for k in range(4)]
        self.task = get_task(task, seconds=1.0 + args.episode)
        self.config = self.task.config()
        self.n, self.threads = n, args.threads
        self.cells = self.base.grid.size
        self.terrains = [self.task.terrain_for(d.shape) for d in self.designs]  # one per heading
        self.settled = []
        for d, terrain in zip(self.designs, self.terrains):
            zero = phase_body(d, np.zeros(self.cells), np.ones(self.cells))
            sim = Simulation(
                [zero] * n, config=self.config, terrain=[terrain] * n, n_threads=self.threads
            )
            sim.advance_to(self.config.init_time)
            self.settled.append(sim.get_state())
        self.evaluations = 0

    def scores(self, genomes: list[Genome]) -> np.ndarray:
        out = []
        for i in range(0, len(genomes), self.n):
            out.append(self._batch(genomes[i : i + self.n]))
        return np.concatenate(out)

    def _batch(self, genomes: list[Genome]) -> np.ndarray:
        m = len(genomes)
        pad = genomes + [genomes[0]] * (self.n - m)  # the settled states are of n robots
        bodies = [phase_body(self.designs[g.heading], g.phase, g.amp, g.period) for g in pad]
        terrains = [self.terrains[g.heading] for g in pad]
        sim = Simulation(bodies, config=self.config, terrain=terrains, n_threads=self.threads)
        heads = np.array([g.heading for g in pad])
        sim.set_state(self.settled[int(heads[0])])
        for k in set(heads[1:].tolist()) - {int(heads[0])}:
            sim.restore_robots(self.settled[k], np.flatnonzero(heads == k))
        sim.advance_to(self.task.seconds)
        self.evaluations += m
        return self.task.metrics(sim.rollout(), terrains)["score"][:m]


def _positions(design) -> np.ndarray:
    # cell centres (voxel lengths) about the grid's centre, in the grid's flat order
    idx = np.indices(design.grid.shape).reshape(3, -1).T.astype(np.float64)
    return idx - idx.mean(axis=0)


def mutate(g: Genome, pos: np.ndarray, rng: np.random.Generator) -> Genome:
    """A child of ``g``: one or two of four mutations of the drive, each as likely.

    * cells: a tenth of the cells' phases (sd 0.7 rad) and amplitudes (sd 0.25);
    * wave: a phase gradient along a random direction (sd 0.6 rad per voxel
      length), a travelling wave through the body;
    * region: the phase (sd 1.5 rad) or the amplitude (factor e^N(0, 0.5)) of the
      cells within 1-3 voxel lengths of a random cell;
    * global: the period (factor e^N(0, 0.2), in the seed's controller bounds)
      and every amplitude (factor e^N(0, 0.2)).
    """
    phase, amp, period = g.phase.copy(), g.amp.copy(), g.period
    n = phase.size
    for op in rng.choice(4, size=1 + int(rng.random() < 0.5), replace=False):
        if op == 0:
            mask = rng.random(n) < 0.1
            phase += mask * rng.normal(0.0, 0.7, n)
            amp += mask * rng.normal(0.0, 0.25, n)
        elif op == 1:
            d = rng.normal(size=3)
            phase += rng.normal(0.0, 0.6) * (pos @ (d / np.linalg.norm(d)))
        elif op == 2:
            near = np.linalg.norm(pos - pos[rng.integers(n)], axis=1) <= rng.uniform(1.0, 3.0)
            if rng.random() < 0.5:
                phase[near] += rng.normal(0.0, 1.5)
            else:
                amp[near] *= np.exp(rng.normal(0.0, 0.5))
        else:
            period *= float(np.exp(rng.normal(0.0, 0.2)))
            amp *= np.exp(rng.normal(0.0, 0.2))
    lo, hi, _ = CONTROLLER_BOUNDS["period"]
    return Genome(
        g.heading, np.mod(phase, 2 * np.pi), np.clip(amp, 0.0, 1.0), float(np.clip(period, lo, hi))
    )


def evolve(runner: PhaseRunner, seed: int, args: argparse.Namespace) -> dict[str, float]:
    """An elitist (mu + lambda) evolution of the walker's controller from the seed's sinusoid.

    Generation 0: the seed's sinusoid at the four headings and mutants of them
    (``lambda`` in all); then each generation ``lambda`` children of the best
    ``mu`` so far. Returns the best score, the seed sinusoid's (heading 0), the
    best of the four headings' sinusoids, the winner's heading (degrees),
    period and :class:`Genome`.
    """
    rng = np.random.default_rng(seed)
    pos = _positions(runner.base)
    n = runner.cells
    start = [Genome(k, np.zeros(n), np.ones(n), runner.base.controller.period) for k in range(4)]
    pop = list(start[: args.pop])
    while len(pop) < args.pop:
        pop.append(mutate(start[len(pop) % 4], pos, rng))
    score = runner.scores(pop)
    sinusoid, headings = float(score[0]), float(score[: min(4, args.pop)].max())
    for _ in range(1, args.generations):
        elite = np.argsort(-score, kind="stable")[: args.mu]
        parents, pscore = [pop[i] for i in elite], score[elite]
        children = [mutate(parents[rng.integers(args.mu)], pos, rng) for _ in range(args.pop)]
        cscore = runner.scores(children)
        pop, score = parents + children, np.concatenate([pscore, cscore])
    best = int(np.argmax(score))
    return {"best": float(score[best]), "sinusoid": sinusoid, "headings": headings,
            "heading": 90 * pop[best].heading, "period": pop[best].period, "genome": pop[best]}  # fmt: skip


def codesign(task: str, seed: int, args: argparse.Namespace) -> dict[str, float]:
    """Best score of a body and controller co-design run: ``softgym evolve``'s own evolution.

    The ``controller-tournament`` experiment (6x6x6 CPPN bodies from random,
    the seed's controller GA, fitness tournament) on the task, selecting on the
    task's ``score``, ``--cd-pop`` robots for ``--cd-generations`` generations
    of ``1 + episode`` s (the same 1 s settling and 3 s window). Returns the
    best score any generation reached and the evaluations it took.
    """
    from evolvers.drivers.runner import EvolutionRun
    from evolvers.evaluation.experiments import get_experiment
    from evolvers.operators.selection import Objective

    exp = get_experiment("controller-tournament", task=task, seconds=1.0 + args.episode,
                         pop_size=args.cd_pop, objectives=(Objective("score", True),))  # fmt: skip
    with tempfile.TemporaryDirectory() as out:
        run = EvolutionRun(exp, out, seed=seed, generations=args.cd_generations,
                           n_threads=args.threads, figures=False, gif=False, progress=False)  # fmt: skip
        run.run()
    return {"best": max(g["score_best"] for g in run.rows), "evaluations": run.evaluations_total}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true", help="4 children x 2 generations, 1 seed")
    p.add_argument("--tasks", help="comma-separated task names (default: all)")
    p.add_argument("--pop", type=int, help="children per generation (lambda; default 10)")
    p.add_argument("--mu", type=int, help="parents kept (default 3)")
    p.add_argument("--generations", type=int, help="generations (default 20)")
    p.add_argument("--seeds", type=int, help="evolution seeds (default 3)")
    p.add_argument(
        "--codesign", help="comma-separated tasks that also get a body + controller co-design run"
    )
    p.add_argument("--cd-pop", type=int, default=15, help="co-design population (default 15)")
    p.add_argument(
        "--cd-generations", type=int, default=14, help="co-design generations after generation 0"
    )
    p.add_argument("--codesign-only", action="store_true", help="only the --codesign runs")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--control-dt", type=float, default=0.05, help="seconds per random action")
    p.add_argument("--no-append", action="store_true", help="do not append to RESULTS.md")
    p.add_argument("--json", action="store_true", help="print the rows as JSON at the end")
    args = p.parse_args()
    # (a robot-second costs ~0.1-0.3 s of wall time on a busy 2-core machine: the full run
    # simulates 16 tasks x 3 seeds x 20 generations x 10 robots x 3 s)
    sizes = (4, 2, 2, 1) if args.quick else (10, 3, 20, 3)
    for name, default in zip(("pop", "mu", "generations", "seeds"), sizes):
        if getattr(args, name) is None:
            setattr(args, name, default)
    args.episode = 3.0
    names = [] if args.codesign_only else (args.tasks.split(",") if args.tasks else task_names())
    cd_names = args.codesign.split(",") if args.codesign else []
    if cd_names:
        # (a .vxa cannot hold a world off the lattice, e.g. the tunnel's roof: run folders warn per file)
        logging.getLogger("evolvers").addFilter(
            lambda r: "without the terrain" not in r.getMessage()
        )
    rows = []
    t_all = time.perf_counter()
    for name in names:
        task = get_task(name)
        t0 = time.perf_counter()
        rnd, steps_per_s = random_score(name, args)
        runner = PhaseRunner(name, args.pop, args)
        runs = [evolve(runner, seed, args) for seed in range(args.seeds)]
        bests = [r["best"] for r in runs]
        q1, med, q3 = np.percentile(bests, [25, 50, 75])
        row = {
            "task": name, "measure": task.reward, "random": rnd, "sinusoid": runs[0]["sinusoid"],
            "headings": runs[0]["headings"], "evolved": float(med), "evolved_q1": float(q1),
            "evolved_q3": float(q3), "evolved_min": float(min(bests)), "evolved_max": float(max(bests)),
            "bests": bests, "winner_heading": [r["heading"] for r in runs],
            "winner_period": [r["period"] for r in runs], "evaluations": runner.evaluations,
            "steps_per_s": steps_per_s, "seconds": time.perf_counter() - t0,
        }  # fmt: skip
        rows.append(row)
        print(f"{name:12s} {task.reward:16s} random {rnd:8.3f}  sinusoid {row['sinusoid']:8.3f}  "
              f"headings {row['headings']:8.3f}  evolved {med:8.3f} [{row['evolved_min']:.3f}, "
              f"{row['evolved_max']:.3f}]  heading {row['winner_heading']}  "
              f"{row['steps_per_s']:7.0f} steps/s  ({row['seconds']:.0f} s)", flush=True)  # fmt: skip
    cd_rows = []
    for name in cd_names:
        t0 = time.perf_counter()
        runs = [codesign(name, seed, args) for seed in range(args.seeds)]
        bests = [r["best"] for r in runs]
        row = {
            "task": name, "measure": get_task(name).reward, "codesign": float(np.median(bests)),
            "codesign_min": float(min(bests)), "codesign_max": float(max(bests)), "bests": bests,
            "evaluations": [r["evaluations"] for r in runs], "seconds": time.perf_counter() - t0,
        }  # fmt: skip
        cd_rows.append(row)
        print(f"{name:12s} co-design {row['codesign']:8.3f} [{row['codesign_min']:.3f}, "
              f"{row['codesign_max']:.3f}]  {row['evaluations']} evaluations  ({row['seconds']:.0f} s)",
              flush=True)  # fmt: skip
    total = time.perf_counter() - t_all
    text = ""
    if rows:
        lines = [
            "| task | measure | random | seed sinusoid | best heading | evolved (median [min, max]) | env steps/s |",
            "|---|---|---:|---:|---:|---:|---:|",
        ]
        for r in rows:
            lines.append(
                f"| {r['task']} | {r['measure']} | {r['random']:.2f} | {r['sinusoid']:.2f} | "
                f"{r['headings']:.2f} | {r['evolved']:.2f} [{r['evolved_min']:.2f}, "
                f"{r['evolved_max']:.2f}] | {r['steps_per_s']:.0f} |"
            )
        evals = rows[0]["evaluations"] // args.seeds
        text += (
            results_log.heading(
                "bench_tasks.py",
                args.quick,
                (
                    f"(mu + lambda) = ({args.mu} + {args.pop}), {args.generations} generations "
                    f"({evals} controllers a seed), {args.seeds} seed(s), {args.episode:g} s episodes",
                    f"{args.threads} threads",
                    f"{total / 60:.0f} min",
                ),
            )
            + "\n"
            "`benchmarks/bench_tasks.py`: the default walker; random actions in the task's Gym "
            "env (mean of 3); the seed's sinusoid (the design's controller); the best of that "
            "sinusoid at the walker's four headings (0, 90, 180, 270 degrees about the vertical); "
            "the best of an evolution of the walker's controller (heading, drive phase and "
            "amplitude per voxel, period) started from those four (median [min, max] over "
            "seeds). Scores are each task's `score` (voxel lengths; rad for turn; voxel "
            "lengths^2 for grow); env steps/s: 0.05 s steps of a 3-robot vector env under "
            "random actions.\n\n" + "\n".join(lines) + "\n"
        )
    if cd_rows:
        lines = [
            "| task | measure | co-design (median [min, max]) | evaluations a seed |",
            "|---|---|---:|---:|",
        ]
        for r in cd_rows:
            lines.append(
                f"| {r['task']} | {r['measure']} | {r['codesign']:.2f} [{r['codesign_min']:.2f}, "
                f"{r['codesign_max']:.2f}] | {int(np.median(r['evaluations']))} |"
            )
        text += (
            results_log.heading(
                "bench_tasks.py --codesign",
                args.quick,
                (
                    f"body + controller co-design, {args.cd_pop} robots, {args.cd_generations} "
                    f"generations, {args.seeds} seed(s), {args.episode:g} s episodes",
                    f"{args.threads} threads",
                    f"{total / 60:.0f} min",
                ),
            )
            + "\n"
            "`benchmarks/bench_tasks.py --codesign`: `softgym evolve`'s controller-tournament "
            "experiment (6x6x6 CPPN bodies from random and the seed's controller GA) selecting "
            "on the task's `score`; the best score reached (median [min, max] over seeds).\n\n"
            + "\n".join(lines)
            + "\n"
        )
    print(text)
    print(f"total {total:.0f} s")
    if text and not args.no_append:
        results_log.append(text)
    if args.json:
        print(json.dumps(rows + cd_rows))


if __name__ == "__main__":
    main()
