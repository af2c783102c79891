"""The claim-by-claim report of a study, written from its run folders alone.

``softgym study report RUNS`` (:func:`write_report`) reads every run folder
under ``RUNS`` (``config.json``, ``log.jsonl``, ``best_designs.json``; the
scenario from ``scenario.json`` beside it, see :mod:`evolvers.study`) and
writes ``README.md`` and figures:

* a table of what ran (seeds, generations reached, complete or not);
* one row per claim of the seed report: what the report says, what we
  measured (median, interquartile range, number of seeds), holds / partly /
  does not hold, and why;
* per scenario, the best-of-generation fitness (median and IQR band over
  seeds) vs. generation, with the report's single-run curve where it has one
  (Fig. 1, Fig. 4; values read from its plots, SEED_REFERENCE §3.9);
* the materials and controller genes of the winners (one point per seed);
* the generation at which a robot first crossed the wall (one point per seed).

Statistics are over seeds: ``median [Q1, Q3], n``. A comparison "A beats B"
holds when A's median is better and a one-sided permutation test of the
Mann-Whitney statistic gives p < 0.05 (20 000 permutations, fixed seed), is
"partly" when the median is better but p >= 0.05, and does not hold
otherwise; A12 (Vargha-Delaney: the chance that a seed of A beats one of B)
is given with it.
"""

from __future__ import annotations

import json
import logging
import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from evolvers.genome import Individual
from evolvers.recorder import read_run_notes
from softgym.design import CONTROLLER_BOUNDS, Controller
from softgym.design.material import EVOLVABLE_BOUNDS, MUSCLE_IDS, TISSUE_IDS
from softgym.exceptions import CheckpointError
from softgym.render.figures import read_log

log = logging.getLogger(__name__)

__all__ = [
    "REPORT_CURVES",
    "Claim",
    "RunData",
    "a12",
    "claims",
    "finished_runs",
    "load_runs",
    "permutation_pvalue",
    "write_report",
]

#: The report's single-run best-fitness curves (generation, NormFinalDist in voxel lengths), read
#: from its figures by eye (+-1; SEED_REFERENCE §3.9; the Fig. 1 step to 24 at generation 6 and
#: the intermediate Fig. 4 steps read from the PNGs in ``shared/seed``).
REPORT_CURVES: dict[str, list[tuple[int, float]]] = {
    "materials-t1": [(0, 15.0), (1, 21.5), (6, 24.0), (45, 28.5), (68, 32.3), (125, 42.7),
                     (150, 43.8), (183, 47.7), (300, 47.7)],
    "basic": [(0, 2.0), (1, 3.8), (3, 3.8), (4, 4.8), (5, 5.3), (7, 5.3), (8, 6.0), (9, 6.0),
              (10, 6.5), (40, 6.5)],
    "controller-tournament": [(0, 2.0), (1, 7.0), (2, 25.8), (5, 25.8), (6, 40.6), (17, 40.6),
                              (18, 43.5), (20, 43.5), (21, 68.6), (24, 68.6), (25, 72.5),
                              (39, 72.5), (40, 77.0)],
    "controller-pareto": [(0, 2.0), (1, 9.5), (2, 9.5), (3, 15.0), (4, 15.2), (5, 15.2),
                          (6, 16.2), (7, 18.2), (8, 18.5), (9, 40.8), (40, 40.8)],
}  # fmt: skip

#: Generations the report ran (or, for the obstacles, the generation its final setup crossed by).
REPORT_GENERATIONS: dict[str, int] = {
    "materials-t1": 300, "materials-t2": 50, "novelty": 200, "novelty-archive": 200,
    "basic-200": 200, "basic": 40, "controller-tournament": 40, "controller-pareto": 40,
    "obstacles": 80, "obstacles-robot-com": 80, "obstacles-attempt1": 80,
    "obstacles-attempt2": 80, "obstacles-attempt1-robot-com": 80, "obstacles-attempt2-robot-com": 80,
}  # fmt: skip

#: The scenarios each claim reads (a claim on shorter runs than the report's is provisional).
CLAIM_SCENARIOS: dict[str, tuple[str, ...]] = {
    "T1-improves": ("materials-t1",),
    "T1-final": ("materials-t1",),
    "T1-materials": ("materials-t1",),
    "T2-voxels": ("materials-t2",),
    "T2-muscles": ("materials-t2",),
    "novelty-fitness": (
        "novelty",
        "materials-t1",
        "materials-t2",
        "controller-tournament",
        "controller-pareto",
        "basic-200",
    ),
    "novelty-muscle": ("novelty",),
    "novelty-loop": ("novelty", "novelty-archive", "basic-200"),
    "ctrl-vs-basic": ("basic", "controller-tournament", "controller-pareto"),
    "tournament-vs-pareto": ("controller-tournament", "controller-pareto"),
    "pareto-muscles": ("controller-tournament", "controller-pareto"),
    "controller-genes": ("controller-tournament", "controller-pareto"),
    "obstacles-attempt1": ("obstacles-attempt1",),
    "obstacles-attempt2": ("obstacles-attempt2",),
    "obstacles-final": ("obstacles",),
}

#: Obstacle scenarios and the report's crossing generation of the final setup.
#: Each has a ``<name>-robot-com`` twin scored on the robot's own centre of mass, not the seed's.
OBSTACLE_SCENARIOS = ("obstacles-attempt1", "obstacles-attempt2", "obstacles")
ROBOT_COM = "-robot-com"
REPORT_CROSSING_GENERATION = 80

HOLDS, PARTLY, FAILS, UNTESTED = "holds", "partly", "does not hold", "not run"

#: The best NormFinalDist of the report's treatment-1 run (Fig. 1, voxel lengths).
REPORT_T1_FINAL = 47.7


# ---------------------------------------------------------------------------- data
@dataclass
class RunData:
    """One run folder, as the report reads it."""

    scenario: str
    path: Path
    config: dict[str, Any]
    rows: list[dict[str, Any]]
    best: dict[str, Any] | None
    complete: bool
    #: The run folder's notes (:func:`evolvers.recorder.read_run_notes`).
    notes: list[dict[str, Any]] = field(default_factory=list)

    @property
    def seed(self) -> int:
        """The run's seed."""
        return int(self.config["seed"])

    @property
    def experiment(self) -> dict[str, Any]:
        """The experiment as config.json records it."""
        return self.config["experiment"]

    @property
    def target(self) -> int:
        """Generations asked for."""
        return int(self.config.get("generations", -1))

    @property
    def generation(self) -> int:
        """Last generation logged (-1 if none)."""
        return int(self.rows[-1]["generation"]) if self.rows else -1

    @property
    def fitness(self) -> str:
        """The first objective (the report's "fitness"), age excluded."""
        names = [o["name"] for o in self.experiment["objectives"] if o["name"] != "age"]
        return names[0] if names else "norm_final_dist"

    @property
    def shape(self) -> tuple[int, int, int]:
        """The robot grid."""
        s = self.experiment["shape"]
        return (int(s[0]), int(s[1]), int(s[2]))

    def series(self, key: str) -> np.ndarray:
        """``key`` per generation 0..last, NaN where missing; ndarray of shape (generation + 1,)."""
        out = np.full(self.generation + 1, np.nan)
        for r in self.rows:
            v = r.get(key)
            if v is not None:
                try:
                    out[int(r["generation"])] = float(v)
                except (TypeError, ValueError):
                    pass
        return out

    def at(self, key: str, generation: int | None = None) -> float:
        """``key`` at ``generation`` (default the last); NaN if missing."""
        s = self.series(key)
        g = len(s) - 1 if generation is None else generation
        return float(s[g]) if 0 <= g < len(s) else float("nan")

    def winner(self) -> Individual | None:
        """The best individual found (hall of fame first), or None."""
        if not self.best or "genome" not in self.best:
            return None
        return Individual.from_dict(self.best["genome"])


def load_runs(root: str | os.PathLike[str]) -> dict[str, list[RunData]]:
    """Every run folder under ``root``, by scenario, each list sorted by seed.

    The scenario is the name in ``scenario.json`` of the run folder's parent
    (written by :func:`evolvers.study.run_study`), else the experiment's name.
    """
    root = Path(root)
    runs: dict[str, list[RunData]] = {}
    for cfg_path in sorted(root.rglob("config.json")):
        try:
            cfg = json.loads(cfg_path.read_text())
        except (OSError, ValueError):
            continue
        if not isinstance(cfg, dict) or cfg.get("schema") != "softgym.run":
            continue
        run_dir = cfg_path.parent
        scenario = cfg["experiment"]["name"]
        sc_path = run_dir.parent / "scenario.json"
        if sc_path.exists():
            try:
                scenario = json.loads(sc_path.read_text())["name"]
            except (OSError, ValueError, KeyError):
                pass
        try:
            rows = read_log(run_dir)
        except CheckpointError as exc:  # one damaged run must not stop the report
            log.warning("skipping a run: %s", exc)
            continue
        if not rows:  # started, no generation logged yet: nothing to report
            log.info("skipping %s: no generation logged yet", run_dir)
            continue
        best = None
        try:
            best = json.loads((run_dir / "best_designs.json").read_text())["best"][0]
        except (OSError, ValueError, KeyError, IndexError):
            pass
        gens = int(cfg.get("generations", -1))
        complete = (
            (run_dir / "final_population.json").exists()
            and bool(rows)
            and int(rows[-1]["generation"]) >= gens
        )
        try:
            notes = read_run_notes(run_dir)
        except CheckpointError as exc:
            log.warning("%s", exc)
            notes = [{"text": f"unreadable notes: {exc}"}]
        runs.setdefault(scenario, []).append(
            RunData(scenario, run_dir, cfg, rows, best, complete, notes)
        )
    for v in runs.values():
        v.sort(key=lambda r: r.seed)
    return runs


# ---------------------------------------------------------------------------- statistics
def _finite(values: Sequence[float]) -> np.ndarray:
    a = np.asarray([v for v in values if v is not None], dtype=np.float64)
    return a[np.isfinite(a)]


def _summary(values: Sequence[float], fmt: str = "{:.3g}") -> str:
    """``median [Q1, Q3], n=N`` of the finite values."""
    a = _finite(values)
    if a.size == 0:
        return "none"
    q1, med, q3 = np.percentile(a, [25, 50, 75])
    return f"{fmt.format(med)} [{fmt.format(q1)}, {fmt.format(q3)}], n={a.size}"


def _median(values: Sequence[float]) -> float:
    a = _finite(values)
    return float(np.median(a)) if a.size else float("nan")


def a12(x: Sequence[float], y: Sequence[float]) -> float:
    """Vargha-Delaney A12: P(X > Y) + P(X = Y) / 2 over pairs (NaN if either is empty)."""
    x, y = _finite(x), _finite(y)
    if x.size == 0 or y.size == 0:
        return float("nan")
    d = x[:, None] - y[None, :]
    return float(((d > 0).sum() + 0.5 * (d == 0).sum()) / d.size)


def permutation_pvalue(
    x: Sequence[float], y: Sequence[float], n_perm: int = 20000, seed: int = 0
) -> float:
    """One-sided p-value that X tends to be larger than Y (Mann-Whitney statistic, permutations).

    The statistic is A12 (:func:`a12`); labels are permuted ``n_perm`` times
    with a fixed seed, so the value is reproducible. NaN if a sample is empty.
    """
    x, y = _finite(x), _finite(y)
    if x.size == 0 or y.size == 0:
        return float("nan")
    pooled = np.concatenate([x, y])
    ranks = _ranks(pooled)
    nx = x.size
    observed = ranks[:nx].sum()
    rng = np.random.default_rng(seed)
    perms = np.argsort(rng.random((n_perm, pooled.size)), axis=1)[:, :nx]
    stats = ranks[perms].sum(axis=1)
    return float((1 + (stats >= observed - 1e-9).sum()) / (n_perm + 1))


def _ranks(a: np.ndarray) -> np.ndarray:
    """Ranks with ties averaged."""
    order = np.argsort(a, kind="mergesort")
    ranks = np.empty(a.size)
    ranks[order] = np.arange(1, a.size + 1)
    for v in np.unique(a):
        tie = a == v
        if tie.sum() > 1:
            ranks[tie] = ranks[tie].mean()
    return ranks


def _sign_pvalue(k: int, n: int) -> float:
    """One-sided binomial p of at least ``k`` successes in ``n`` fair trials."""
    if n == 0:
        return float("nan")
    return sum(math.comb(n, i) for i in range(k, n + 1)) / 2.0**n


def _compare(
    a: Sequence[float], b: Sequence[float], larger: bool = True
) -> tuple[str, str, float, float]:
    """Verdict of "A is larger (or smaller) than B" and its evidence text."""
    a, b = _finite(a), _finite(b)
    if a.size == 0 or b.size == 0:
        return UNTESTED, "a scenario has no finished seed", float("nan"), float("nan")
    x, y = (a, b) if larger else (-a, -b)
    p = permutation_pvalue(x, y)
    eff = a12(x, y)
    better = np.median(x) > np.median(y)
    verdict = HOLDS if better and p < 0.05 else PARTLY if better else FAILS
    return verdict, f"one-sided permutation p={p:.3g}, A12={eff:.2f}", p, eff


# ---------------------------------------------------------------------------- measures
@dataclass
class Winner:
    """What the report reads of a run's best robot."""

    seed: int
    objectives: dict[str, float]
    genes: dict[str, float]
    n_voxels: int
    n_muscle: int
    n_bone: int
    muscle_abs_cte: float  # voxel-weighted mean |CTE| of muscle voxels (1/°C)
    muscle_density: float  # voxel-weighted mean density of muscle voxels (kg/m^3)
    tissue_density: float
    tissue_youngs: float
    new_muscle_share: float  # share of muscle voxels made of evolved materials 8/9
    muscle_signs: int  # distinct CTE signs among muscle voxels (2: both phases)


def winner_of(run: RunData) -> Winner | None:
    """The run's best robot and the materials it uses."""
    ind = run.winner()
    if ind is None:
        return None
    design = ind.design(run.shape)
    grid = np.asarray(design.grid)
    pal = design.palette
    ids, counts = np.unique(grid[grid > 0], return_counts=True)
    used = dict(zip(ids.tolist(), counts.tolist()))

    def mean(ids_: Sequence[int], attr: str, absval: bool = False) -> float:
        w = [(used[i], getattr(pal[i], attr)) for i in ids_ if i in used]
        if not w:
            return float("nan")
        n = sum(c for c, _ in w)
        return float(sum(c * (abs(v) if absval else v) for c, v in w) / n)

    n_muscle = sum(used.get(i, 0) for i in MUSCLE_IDS)
    signs = {np.sign(pal[i].cte) for i in MUSCLE_IDS if i in used and pal[i].cte != 0}
    return Winner(
        seed=run.seed,
        objectives=dict(run.best["objectives"]) if run.best else {},
        genes=ind.genes(),
        n_voxels=int(sum(used.values())),
        n_muscle=int(n_muscle),
        n_bone=int(used.get(2, 0)),
        muscle_abs_cte=mean(MUSCLE_IDS, "cte", absval=True),
        muscle_density=mean(MUSCLE_IDS, "density"),
        tissue_density=mean(TISSUE_IDS, "density"),
        tissue_youngs=mean(TISSUE_IDS, "youngs_modulus"),
        new_muscle_share=(used.get(8, 0) + used.get(9, 0)) / n_muscle if n_muscle else float("nan"),
        muscle_signs=len(signs),
    )


def _winners(runs: Sequence[RunData]) -> list[Winner]:
    return [w for w in (winner_of(r) for r in runs) if w is not None]


def best_ever(run: RunData, metric: str | None = None) -> float:
    """The best value of ``metric`` (default the fitness) over the run's generations."""
    s = run.series(f"{metric or run.fitness}_best")
    s = s[np.isfinite(s)]
    return float(s.max()) if s.size else float("nan")


def crossing_generation(run: RunData) -> float:
    """First generation whose population holds a robot past the wall (NaN: never, or not logged)."""
    s = run.series("crossed")
    hit = np.flatnonzero(np.isfinite(s) & (s > 0))
    return float(hit[0]) if hit.size else float("nan")


def crossing_robot(run: RunData) -> dict[str, float] | None:
    """Composition of the best robot past the wall at the crossing generation."""
    g = crossing_generation(run)
    if not math.isfinite(g):
        return None
    row = next(r for r in run.rows if int(r["generation"]) == int(g))
    n = float(row.get("crosser_n_voxels", float("nan")))
    return {
        "generation": g,
        "n_voxels": n,
        "muscle_fraction": float(row.get("crosser_n_muscle", float("nan"))) / n
        if n
        else float("nan"),
        "n_bone": float(row.get("crosser_n_bone", float("nan"))),
    }


def repeated_share(run: RunData, skip_first: bool = True) -> float:
    """Share of new individuals (generations >= 1) whose phenotype was already simulated in the run."""
    new = run.series("new_individuals")
    rep = run.series("repeated_phenotypes")
    sl = slice(1, None) if skip_first else slice(None)
    n, r = np.nansum(new[sl]), np.nansum(rep[sl])
    return float(r / n) if n > 0 else float("nan")


# ---------------------------------------------------------------------------- claims
@dataclass
class Claim:
    """One row of the claim table."""

    id: str
    section: str
    report: str
    measured: str
    verdict: str
    why: str
    data: dict[str, Any] = field(default_factory=dict)


def _missing(runs: Mapping[str, list[RunData]], *names: str) -> list[str]:
    return [n for n in names if not runs.get(n)]


def _combine(verdicts: Sequence[str]) -> str:
    """One verdict of several comparisons.

    All hold: holds; all fail: does not hold; else partly. "not run" ones are
    left out (all "not run": not run).
    """
    vs = [v for v in verdicts if v != UNTESTED]
    if not vs:
        return UNTESTED
    return (
        HOLDS if all(v == HOLDS for v in vs) else FAILS if all(v == FAILS for v in vs) else PARTLY
    )


def _ratio(a: Sequence[float], b: Sequence[float]) -> float:
    """Ratio of the medians of ``a`` and ``b`` (NaN when ``b``'s is 0)."""
    mb = _median(b)
    return _median(a) / mb if mb else float("nan")


def _untested(cid: str, section: str, report: str, missing: Sequence[str]) -> Claim:
    return Claim(cid, section, report, "-", UNTESTED, f"no run folder of {', '.join(missing)}")


def _gens(runs: Sequence[RunData]) -> str:
    g = sorted({r.generation for r in runs})
    return str(g[0]) if len(g) == 1 else f"{g[0]}-{g[-1]}"


def _seeds(seeds: Sequence[int]) -> str:
    """The label of some seeds: ``seed 3`` or ``seeds 1, 2``."""
    return ("seed " if len(seeds) == 1 else "seeds ") + ", ".join(map(str, seeds))


#: Muscles lighter than this (kg/m^3, a tenth of the initial 1e6) mark T1's flying winners; the
#: T1-materials claim calls denser muscles and tissue "high density".
LIGHT_MUSCLE = 1e5


def flies(run: RunData) -> bool:
    """Whether the run's winner flies.

    A flier has muscles lighter than :data:`LIGHT_MUSCLE` and a best above ten
    times the report's 47.7 body lengths, which no walking gait reaches.
    """
    w = winner_of(run)
    return (
        w is not None and w.muscle_density < LIGHT_MUSCLE and best_ever(run) > 10 * REPORT_T1_FINAL
    )


def claim_t1_improves(runs: Mapping[str, list[RunData]]) -> Claim:
    """Materials T1: the best keeps improving over 300 generations."""
    cid, sec = "T1-improves", "III-A, Fig. 1"
    rep = ("Treatment 1 (300 generations): 'increasing the number of generations lead to robots "
           "which become increasingly better'; the single run's best rises until ~gen 183 (47.7).")  # fmt: skip
    if m := _missing(runs, "materials-t1"):
        return _untested(cid, sec, rep, m)
    rs = runs["materials-t1"]
    last_impr, late_gain = [], []
    for r in rs:
        s = r.series(f"{r.fitness}_best")
        best_so_far = np.fmax.accumulate(np.nan_to_num(s, nan=-np.inf))
        gains = np.flatnonzero(np.diff(best_so_far) > 1e-9)
        last_impr.append(float(gains[-1] + 1) if gains.size else 0.0)
        half = len(s) // 2
        late_gain.append(float(best_so_far[-1] - best_so_far[half]))
    improving = [r.seed for r, g in zip(rs, late_gain) if g > 1e-9]
    walking = [r.seed for r, g in zip(rs, late_gain) if g > 1e-9 and not flies(r)]
    n = len(rs)
    k = len(improving)
    w = len(walking)
    verdict = HOLDS if w * 3 >= 2 * n else PARTLY if w else FAILS
    why = ("counts seeds that improve without flying (see T1-final); holds when >= 2/3 of the "
           "seeds still improve in the second half of the run, partly when some do")  # fmt: skip
    if k > w:
        why += f"; {k - w} of the {k} improving seeds improve only by flying"
    return Claim(
        cid, sec, rep,
        f"last improvement at generation {_summary(last_impr, '{:.0f}')}; best gained in the second "
        f"half of the run in {k}/{n} seeds (gain {_summary(late_gain)}), {len(walking)} of "
        f"them without flying; generations {_gens(rs)}",
        verdict, why,
        {"last_improvement": last_impr, "late_gain": late_gain, "improving_walkers": walking},
    )  # fmt: skip


def claim_t1_final(runs: Mapping[str, list[RunData]]) -> Claim:
    """Materials T1: where the best ends vs. the report's ~47.7."""
    cid, sec = "T1-final", "III-A, Fig. 1"
    rep = "Treatment 1 ends at a best NormFinalDist of ~47.7 voxel lengths (single run, gen 300)."
    if m := _missing(runs, "materials-t1"):
        return _untested(cid, sec, rep, m)
    rs = runs["materials-t1"]
    final = [r.at(f"{r.fitness}_best") for r in rs]
    a = _finite(final)
    q1, q3 = np.percentile(a, [25, 75]) if a.size else (np.nan, np.nan)
    ref = REPORT_T1_FINAL
    inside = bool(a.size and q1 <= ref <= q3)
    in_range = bool(a.size and a.min() <= ref <= a.max())
    pct = float((a < ref).mean() * 100) if a.size else float("nan")
    verdict = HOLDS if inside else PARTLY if in_range else FAILS
    why = "holds when 47.7 lies in the IQR over seeds, partly when within their range"
    # the flying exploit: light muscles (the density gene's floor is 1e3 kg/m^3) and a best
    # far beyond any walking gait
    fliers = [r.seed for r in rs if flies(r)]
    if fliers:
        why += (
            f". {len(fliers)}/{len(rs)} winners fly: muscles lighter than {LIGHT_MUSCLE:.0e} "
            f"kg/m^3 (voxel-weighted) and a best above 477 body lengths ({_seeds(fliers)}); the "
            "seed's own engine flies such winners too (benchmarks/fidelity_evolved.py)"
        )
    return Claim(
        cid, sec, rep,
        f"final best {_summary(final)} (generation {_gens(rs)}); 47.7 is above {pct:.0f}% of the seeds",
        verdict, why, {"final_best": final, "flying_seeds": fliers},
    )  # fmt: skip


#: "Highly deformable" tissue: Young's modulus at most this (Pa; the gene spans [5e6, 5e8]).
SOFT_TISSUE = 1e7


def claim_t1_materials(runs: Mapping[str, list[RunData]]) -> Claim:
    """Materials T1: winners' muscle CTE at the bound and high density."""
    cid, sec = "T1-materials", "III-A"
    rep = ("T1 winners: a muscle with 'the highest/lowest CTE possible' (fastest: -0.04) and a highly "
           "deformable tissue (E 5 MPa), 'both with a high density' (fastest: muscle 586 635, "
           "tissue 1 273 400 kg/m^3).")  # fmt: skip
    if m := _missing(runs, "materials-t1"):
        return _untested(cid, sec, rep, m)
    ws = _winners(runs["materials-t1"])
    if not ws:
        return _untested(cid, sec, rep, ["materials-t1 winners"])
    cte = [w.muscle_abs_cte for w in ws]
    at_bound = sum(c >= 0.035 for c in cte if math.isfinite(c))
    dens = [w.muscle_density for w in ws]
    tdens = [w.tissue_density for w in ws]
    tE = [w.tissue_youngs for w in ws]
    n = len(ws)
    with_tissue = int(_finite(tdens).size)
    parts = {
        "muscle CTE at the bound": at_bound * 2 > n,
        "dense muscle": _median(dens) >= LIGHT_MUSCLE,
        # the tissue must be there (in most winners), dense and soft (E near its 5 MPa floor)
        "dense soft tissue": with_tissue * 2 > n
        and _median(tdens) >= LIGHT_MUSCLE
        and _median(tE) <= SOFT_TISSUE,
    }
    held = [k for k, ok in parts.items() if ok]
    verdict = HOLDS if len(held) == len(parts) else PARTLY if held else FAILS
    return Claim(
        cid, sec, rep,
        f"muscle |CTE| {_summary(cte)} (>= 0.035 in {at_bound}/{n}); muscle density "
        f"{_summary(dens)}; "
        + (f"tissue (in {with_tissue}/{n} winners) density {_summary(tdens)}, "
           f"E {_summary(tE)} Pa" if with_tissue else f"no winner uses tissue (0/{n})"),
        verdict,
        "three parts: muscle |CTE| within 0.005 of the 0.04 bound in most winners; median muscle "
        f"density >= {LIGHT_MUSCLE:.0e} kg/m^3 (the report's 586 635 passes; the gene's floor is "
        f"1e3); tissue in most winners with median density >= {LIGHT_MUSCLE:.0e} and E <= "
        f"{SOFT_TISSUE:.0e} Pa. Held: {', '.join(held) or 'none'}",
        {"muscle_abs_cte": cte, "muscle_density": dens, "tissue_density": tdens,
         "tissue_youngs": tE},
    )  # fmt: skip


def claim_t2_fewer_voxels(runs: Mapping[str, list[RunData]]) -> Claim:
    """Materials T2 uses fewer voxels than T1 (at T2's last generation).

    Reads every run (:data:`READS_UNFINISHED_RUNS`): T2's complete runs (all
    of them when none is complete), and each T1 run that has reached that
    generation, complete or not (T1 runs 300 generations, this reads 50).
    """
    cid, sec = "T2-voxels", "III-A"
    rep = "Treatment 2 (fewer voxels penalised) achieves locomotion 'using a little number of materials'."
    if m := _missing(runs, "materials-t2", "materials-t1"):
        return _untested(cid, sec, rep, m)
    t2 = [r for r in runs["materials-t2"] if r.complete] or runs["materials-t2"]
    g = min(r.generation for r in t2)
    t1 = [r for r in runs["materials-t1"] if r.generation >= g]
    if not t1:
        return _untested(cid, sec, rep, [f"materials-t1 at generation {g}"])
    v2 = [r.at("top_n_voxels", g) for r in t2]
    v1 = [r.at("top_n_voxels", g) for r in t1]
    verdict, why, _, _ = _compare(v2, v1, larger=False)
    partial = [r.seed for r in t1 if not r.complete]
    t2_out = [r.seed for r in runs["materials-t2"] if r not in t2]
    short = [r.seed for r in runs["materials-t1"] if r.generation < g]
    notes = [f"T2 < T1: {why}"]
    if partial:
        notes.append(f"Unfinished T1 {_seeds(partial)} past generation {g} counted")
    if short:
        notes.append(f"T1 {_seeds(short)} left out (not yet at generation {g})")
    if t2_out:
        notes.append(f"T2 {_seeds(t2_out)} left out (unfinished)")
    return Claim(
        cid, sec, rep,
        f"voxels of the best robot at generation {g}: T2 {_summary(v2, '{:.0f}')} vs. T1 "
        f"{_summary(v1, '{:.0f}')}",
        verdict, ". ".join(notes), {"t2": v2, "t1": v1},
    )  # fmt: skip


def claim_t2_muscles(runs: Mapping[str, list[RunData]]) -> Claim:
    """Materials T2 winners: mostly muscles of CTE +-0.04."""
    cid, sec = "T2-muscles", "III-A"
    rep = ("T2 winners 'mostly exploit muscles that expand and contract with a high CTE'; the fastest "
           "uses two muscles of CTE +0.04 and -0.04.")  # fmt: skip
    if m := _missing(runs, "materials-t2"):
        return _untested(cid, sec, rep, m)
    ws = _winners(runs["materials-t2"])
    if not ws:
        return _untested(cid, sec, rep, ["materials-t2 winners"])
    frac = [w.n_muscle / w.n_voxels for w in ws if w.n_voxels]
    cte = [w.muscle_abs_cte for w in ws]
    high = sum(c >= 0.035 for c in cte if math.isfinite(c))
    both = sum(w.muscle_signs == 2 and w.muscle_abs_cte >= 0.035 for w in ws)
    n = len(ws)
    # the general part (most winners: mostly muscle of high CTE) and the fastest robot's
    fastest = max(ws, key=lambda w: w.objectives.get("norm_final_dist", -math.inf))
    general = _median(frac) > 0.5 and high * 2 > n
    fast_ok = fastest.muscle_signs == 2 and fastest.muscle_abs_cte >= 0.035
    verdict = HOLDS if general and fast_ok else PARTLY if general or fast_ok else FAILS
    return Claim(
        cid, sec, rep,
        f"muscle share {_summary(frac, '{:.2f}')}; muscle |CTE| {_summary(cte)} (>= 0.035 in "
        f"{high}/{n}); both phases with |CTE| >= 0.035 in {both}/{n}; the fastest winner (seed "
        f"{fastest.seed}) uses {'both phases' if fastest.muscle_signs == 2 else 'one phase'}, "
        f"voxel-weighted |CTE| {fastest.muscle_abs_cte:.3g}",
        verdict,
        "two parts: most winners mostly muscle (median share > 0.5) of |CTE| >= 0.035; the "
        f"fastest winner over seeds uses both phases near 0.04. General part "
        f"{'holds' if general else 'fails'}, fastest part {'holds' if fast_ok else 'fails'}",
        {"muscle_fraction": frac, "muscle_abs_cte": cte, "fastest_seed": fastest.seed},
    )  # fmt: skip


def claim_novelty_fitness(runs: Mapping[str, list[RunData]]) -> Claim:
    """Novelty: fitness 'much lower' than the other two techniques (materials, controller)."""
    cid, sec = "novelty-fitness", "III-B"
    rep = ("After 200 generations novelty search's fitness 'is not comparable w.r.t. the other two "
           "evolution techniques [materials and controller evolution], it is much lower'.")  # fmt: skip
    if m := _missing(runs, "novelty"):
        return _untested(cid, sec, rep, m)
    nov = [best_ever(r) for r in runs["novelty"]]
    groups = {
        "materials evolution (T1, T2)": runs.get("materials-t1", []) + runs.get("materials-t2", []),
        "controller evolution (tournament, Pareto)": runs.get("controller-tournament", [])
        + runs.get("controller-pareto", []),
    }
    groups = {k: v for k, v in groups.items() if v}
    if not groups:
        return _untested(cid, sec, rep, ["materials or controller evolution runs"])
    verdicts, measured, whys, data = [], [], [], {"novelty": nov}
    for label, rs in groups.items():
        ref = [best_ever(r) for r in rs]
        v, why, _, _ = _compare(nov, ref, larger=False)
        ratio = _ratio(nov, ref)
        if v == HOLDS and not ratio <= 0.5:
            v, why = PARTLY, f"{why}, lower but not 'much' (ratio of medians {ratio:.2f} > 0.5)"
        verdicts.append(v)
        measured.append(f"{label} {_summary(ref)}, ratio of medians {ratio:.2g}")
        whys.append(f"novelty < {label}: {why}")
        data[label] = ref
    verdict = _combine(verdicts)
    if basic := runs.get("basic-200"):  # the same 200 generations, fitness-based, no extra genes
        ref = [best_ever(r) for r in basic]
        _, why, _, _ = _compare(nov, ref, larger=False)
        ratio = _ratio(nov, ref)
        measured.append(f"(not the report's comparison) basic evolution over the same 200 "
                        f"generations {_summary(ref)}, ratio {ratio:.2f}")  # fmt: skip
        whys.append(f"novelty < basic-200 (context): {why}")
        data["basic-200"] = ref
    return Claim(
        cid, sec, rep,
        f"best NormFinalDist of the run: novelty {_summary(nov)} vs. " + "; ".join(measured),
        verdict, "; ".join(whys) + "; 'much' = ratio of medians <= 0.5", data,
    )  # fmt: skip


def claim_novelty_muscle(runs: Mapping[str, list[RunData]]) -> Claim:
    """Novelty robots are mostly muscle."""
    cid, sec = "novelty-muscle", "III-B"
    rep = "Novelty-evolved robots 'are mainly composed of muscles'."
    if m := _missing(runs, "novelty"):
        return _untested(cid, sec, rep, m)
    fr = [float(np.nanmedian(r.series("muscle_fraction_median")[-20:])) for r in runs["novelty"]]
    ref = [
        float(np.nanmedian(r.series("muscle_fraction_median")[-20:]))
        for r in runs.get("basic-200", [])
    ]
    mostly = _median(fr) > 0.5
    verdict = HOLDS if mostly else FAILS
    extra = f"; fitness-based (basic-200) {_summary(ref, '{:.2f}')}" if ref else ""
    return Claim(
        cid, sec, rep,
        f"population median muscle share over the last 20 generations: {_summary(fr, '{:.2f}')}{extra}",
        verdict, "holds when the median over seeds is above 0.5",
        {"novelty": fr, "fitness": ref},
    )  # fmt: skip


def claim_novelty_loop(runs: Mapping[str, list[RunData]]) -> Claim:
    """Novelty: the 'patterns loop' (repeated phenotypes) vs. fitness-based and with the archive."""
    cid, sec = "novelty-loop", "III-B"
    rep = ("Without memory of past generations the same voxel patterns come back ('patterns loop'); "
           "the report suggests penalising repeats (here: the novelty archive).")  # fmt: skip
    if m := _missing(runs, "novelty"):
        return _untested(cid, sec, rep, m)
    others = {  # label: (scenario, what the comparison tests)
        "fitness-based (basic-200)": ("basic-200", "the loop"),
        "archive": ("novelty-archive", "the remedy"),
    }
    others = {k: v for k, v in others.items() if runs.get(v[0])}
    if not others:
        return _untested(cid, sec, rep, ["basic-200 or novelty-archive"])
    a = [repeated_share(r) for r in runs["novelty"]]
    verdicts, measured, whys, data = [], [], [], {"novelty": a}
    for label, (name, tests) in others.items():
        b = [repeated_share(r) for r in runs[name]]
        v, why, _, _ = _compare(a, b, larger=True)
        verdicts.append(v)
        measured.append(f"{label} {_summary(b, '{:.2f}')}")
        whys.append(f"{tests}: no archive > {label}: {why}")
        data[name] = b
    verdict = _combine(verdicts)
    return Claim(
        cid, sec, rep,
        f"share of new robots whose phenotype was already simulated in the run: novelty without "
        f"archive {_summary(a, '{:.2f}')}; " + "; ".join(measured),
        verdict,
        "holds when novelty without memory repeats more than fitness-based selection (the loop) "
        "and than novelty with the archive (the remedy); " + "; ".join(whys),
        data,
    )  # fmt: skip


def _final_best(rs: Sequence[RunData], generation: int | None = None) -> list[float]:
    return [r.at(f"{r.fitness}_best", generation) for r in rs]


def claim_controller_beats_basic(runs: Mapping[str, list[RunData]]) -> Claim:
    """Fig. 4: controller evolution beats basic evolution."""
    cid, sec = "ctrl-vs-basic", "III-C, Fig. 4"
    rep = "'The controller evolution outperforms the basic one' (Fig. 4: 77 and 40.8 vs. 6.5 at gen 40)."
    if m := _missing(runs, "basic", "controller-tournament", "controller-pareto"):
        return _untested(cid, sec, rep, m)
    g = min(
        r.generation
        for n in ("basic", "controller-tournament", "controller-pareto")
        for r in runs[n]
    )
    b = _final_best(runs["basic"], g)
    t = _final_best(runs["controller-tournament"], g)
    p = _final_best(runs["controller-pareto"], g)
    vt, wt, _, _ = _compare(t, b)
    vp, wp, _, _ = _compare(p, b)
    verdict = (
        HOLDS
        if vt == vp == HOLDS
        else FAILS
        if FAILS in (vt, vp) and HOLDS not in (vt, vp)
        else PARTLY
    )
    return Claim(
        cid, sec, rep,
        f"best at generation {g}: basic {_summary(b)}, tournament {_summary(t)}, Pareto {_summary(p)}",
        verdict, f"tournament > basic: {wt}; Pareto > basic: {wp}",
        {"basic": b, "tournament": t, "pareto": p},
    )  # fmt: skip


def claim_tournament_beats_pareto(runs: Mapping[str, list[RunData]]) -> Claim:
    """Fig. 4: the tournament covers more distance than Pareto."""
    cid, sec = "tournament-vs-pareto", "III-C, Fig. 4"
    rep = "'The fitness tournament achieves better results than the Pareto selection in terms of distance'."
    if m := _missing(runs, "controller-tournament", "controller-pareto"):
        return _untested(cid, sec, rep, m)
    g = min(r.generation for n in ("controller-tournament", "controller-pareto") for r in runs[n])
    t = _final_best(runs["controller-tournament"], g)
    p = _final_best(runs["controller-pareto"], g)
    verdict, why, _, _ = _compare(t, p)
    return Claim(
        cid, sec, rep, f"best at generation {g}: tournament {_summary(t)} vs. Pareto {_summary(p)}",
        verdict, f"tournament > Pareto: {why}", {"tournament": t, "pareto": p},
    )  # fmt: skip


def claim_pareto_fewer_muscles(runs: Mapping[str, list[RunData]]) -> Claim:
    """Fig. 5: Pareto winners have fewer muscles."""
    cid, sec = "pareto-muscles", "III-C, Fig. 5"
    rep = "The best robot of Pareto selection 'has far fewer muscles' than the tournament's."
    if m := _missing(runs, "controller-tournament", "controller-pareto"):
        return _untested(cid, sec, rep, m)
    t = [w.n_muscle for w in _winners(runs["controller-tournament"])]
    p = [w.n_muscle for w in _winners(runs["controller-pareto"])]
    verdict, why, _, _ = _compare(p, t, larger=False)
    return Claim(
        cid, sec, rep,
        f"muscle voxels of the winners: Pareto {_summary(p, '{:.0f}')} vs. tournament {_summary(t, '{:.0f}')}",
        verdict, f"Pareto < tournament: {why}", {"tournament": t, "pareto": p},
    )  # fmt: skip


def claim_controller_genes(runs: Mapping[str, list[RunData]]) -> Claim:
    """Fig. 4 winners: short period, high amplitude, high CTE."""
    cid, sec = "controller-genes", "III-C"
    rep = "Best controllers have 'lower period and higher temperature amplitude and CTE'."
    if m := _missing(runs, "controller-tournament", "controller-pareto"):
        return _untested(cid, sec, rep, m)
    ws = _winners(runs["controller-tournament"]) + _winners(runs["controller-pareto"])
    if not ws:
        return _untested(cid, sec, rep, ["controller winners"])
    init = Controller()
    parts, significant, direction = [], [], []
    for gene, ref, lower in (("period", init.period, True),
                             ("temp_amplitude", init.temp_amplitude, False),
                             ("muscle_cte", init.muscle_cte, False)):  # fmt: skip
        vals = [w.genes[gene] for w in ws]
        moved = [v for v in vals if v != ref]  # the sign test drops ties
        k = sum((v < ref) if lower else (v > ref) for v in moved)
        p = _sign_pvalue(k, len(moved)) if moved else 1.0
        significant.append(p < 0.05)
        direction.append(2 * k > len(moved))
        ties = f", {len(vals) - len(moved)} unchanged" if len(moved) < len(vals) else ""
        parts.append(f"{gene} {_summary(vals)} ({'<' if lower else '>'} initial {ref:g} in "
                     f"{k}/{len(moved)}{ties}, sign test p={p:.3g})")  # fmt: skip
    verdict = HOLDS if all(significant) else PARTLY if any(direction) else FAILS
    return Claim(
        cid, sec, rep, "; ".join(parts), verdict,
        "winners of both controller scenarios vs. the initial controller (14 °C, 0.25 s, 0.01); "
        "holds when all three moved as claimed (sign test p < 0.05), partly when some moved "
        "that way in most seeds",
        {"genes": [w.genes for w in ws]},
    )  # fmt: skip


def _crossing(runs: Mapping[str, list[RunData]], name: str) -> tuple[list[float], int]:
    rs = runs[name]
    return [crossing_generation(r) for r in rs], len(rs)


def _decided(rs: Sequence[RunData], horizon: int) -> tuple[list[RunData], list[int]]:
    """The runs that crossed, ran ``horizon`` generations or are complete; the undecided seeds.

    A complete run shorter than ``horizon`` is read as it is (marked provisional).
    """
    done = [
        r for r in rs
        if r.complete or math.isfinite(crossing_generation(r)) or r.generation >= horizon
    ]  # fmt: skip
    return done, [r.seed for r in rs if r not in done]


def _undecided_note(seeds: Sequence[int], horizon: int) -> str:
    return (f". Left out: {_seeds(seeds)}, not yet crossed nor at generation {horizon}"
            if seeds else "")  # fmt: skip


def _robot_com_note(runs: Mapping[str, list[RunData]], name: str) -> str:
    """How the scenario's twin on the robot's own centre of mass did, if it ran."""
    twin = name + ROBOT_COM
    if not runs.get(twin):
        return ""
    rs, undecided = _decided(runs[twin], REPORT_CROSSING_GENERATION)
    gens = [crossing_generation(r) for r in rs]
    k = sum(math.isfinite(g) for g in gens)
    first = f", first at generation {_summary(gens, '{:.0f}')}" if k else ""
    more = f" ({_seeds(undecided)} undecided)" if undecided else ""
    return (f"; selected on the robot's own centre of mass instead ({twin}): crossed in "
            f"{k}/{len(rs)} seeds{first}{more}")  # fmt: skip


def claim_attempt1(runs: Mapping[str, list[RunData]]) -> Claim:
    """Obstacles attempt 1 never crosses the wall."""
    cid, sec = "obstacles-attempt1", "III-D"
    rep = "Attempt 1 (default controller, Pareto with muscle count): 'not enough energy to overcome the wall'."
    if m := _missing(runs, "obstacles-attempt1"):
        return _untested(cid, sec, rep, m)
    horizon = REPORT_CROSSING_GENERATION
    rs, undecided = _decided(runs["obstacles-attempt1"], horizon)
    if not rs:
        return _untested(cid, sec, rep, [f"obstacles-attempt1 at generation {horizon}"])
    gens, n = [crossing_generation(r) for r in rs], len(rs)
    k = sum(math.isfinite(g) for g in gens)
    verdict = HOLDS if k == 0 else PARTLY if k * 2 < n else FAILS
    return Claim(
        cid, sec, rep,
        f"crossed in {k}/{n} seeds within {_gens(rs)} generations"
        + (f" (first at generation {_summary(gens, '{:.0f}')})" if k else "")
        + _robot_com_note(runs, "obstacles-attempt1"),
        verdict,
        "holds when no seed crosses; partly when a minority does"
        + _undecided_note(undecided, horizon),
        {"crossing": gens},
    )  # fmt: skip


def claim_attempt2(runs: Mapping[str, list[RunData]]) -> Claim:
    """Obstacles attempt 2 crosses, with all-muscle robots."""
    cid, sec = "obstacles-attempt2", "III-D"
    rep = "Attempt 2 (controller evolution, tournament): 'some robots succeeded ... composed only of muscles'."
    if m := _missing(runs, "obstacles-attempt2"):
        return _untested(cid, sec, rep, m)
    horizon = REPORT_CROSSING_GENERATION
    rs, undecided = _decided(runs["obstacles-attempt2"], horizon)
    if not rs:
        return _untested(cid, sec, rep, [f"obstacles-attempt2 at generation {horizon}"])
    gens, n = [crossing_generation(r) for r in rs], len(rs)
    robots = [c for c in (crossing_robot(r) for r in rs) if c]
    k = len(robots)
    frac = [c["muscle_fraction"] for c in robots]
    all_muscle = sum(f >= 0.999 for f in frac if math.isfinite(f))
    verdict = FAILS if k == 0 else HOLDS if all_muscle * 2 > k else PARTLY
    return Claim(
        cid, sec, rep,
        f"crossed in {k}/{n} seeds (first at generation {_summary(gens, '{:.0f}')}); muscle share of "
        f"the first robot past the wall {_summary(frac, '{:.2f}')}, all-muscle in {all_muscle}/{k}"
        + _robot_com_note(runs, "obstacles-attempt2"),
        verdict,
        "holds when some seeds cross and most crossing robots are all muscle"
        + _undecided_note(undecided, horizon),
        {"crossing": gens, "muscle_fraction": frac},
    )  # fmt: skip


def claim_obstacles_final(runs: Mapping[str, list[RunData]]) -> Claim:
    """Obstacles final setup crosses (by generation 80), using bone."""
    cid, sec = "obstacles-final", "III-D, Fig. 6"
    rep = ("Final setup (Pareto on MaxXYDist, L coefficient, age; >= 10 % tissue, >= 1 bone): a robot "
           "crossed the wall 'in 80 generations', using its bone as a pivot.")  # fmt: skip
    if m := _missing(runs, "obstacles"):
        return _untested(cid, sec, rep, m)
    horizon = REPORT_CROSSING_GENERATION
    rs, undecided = _decided(runs["obstacles"], horizon)
    if not rs:
        return _untested(cid, sec, rep, [f"obstacles at generation {horizon}"])
    gens, n = [crossing_generation(r) for r in rs], len(rs)
    k80 = sum(math.isfinite(g) and g <= horizon for g in gens)
    k = sum(math.isfinite(g) for g in gens)
    robots = [c for c in (crossing_robot(r) for r in rs) if c]
    bone = [c["n_bone"] for c in robots]
    verdict = HOLDS if k80 * 2 >= n else PARTLY if k else FAILS
    return Claim(
        cid, sec, rep,
        f"crossed by generation {REPORT_CROSSING_GENERATION} in {k80}/{n} seeds, at all in {k}/{n} "
        f"within {_gens(rs)} generations (first crossing {_summary(gens, '{:.0f}')}); "
        f"bone voxels of the first robot past the wall {_summary(bone, '{:.0f}')}"
        + _robot_com_note(runs, "obstacles"),
        verdict,
        "holds when at least half the seeds cross by generation 80; bone is required by the rules "
        "(its use as a pivot is not measured)" + _undecided_note(undecided, horizon),
        {"crossing": gens, "n_bone": bone},
    )  # fmt: skip


#: Every claim, in report order.
CLAIMS: tuple[Callable[[Mapping[str, list[RunData]]], Claim], ...] = (
    claim_t1_improves, claim_t1_final, claim_t1_materials, claim_t2_fewer_voxels,
    claim_t2_muscles, claim_novelty_fitness, claim_novelty_muscle, claim_novelty_loop,
    claim_controller_beats_basic, claim_tournament_beats_pareto, claim_pareto_fewer_muscles,
    claim_controller_genes, claim_attempt1, claim_attempt2, claim_obstacles_final,
)  # fmt: skip


#: Claims read at a fixed generation that take every run, complete or not, and
#: choose (and name) the runs that reached it themselves; the others read
#: :func:`finished_runs`.
READS_UNFINISHED_RUNS: frozenset[Callable[[Mapping[str, list[RunData]]], Claim]] = frozenset(
    {claim_t2_fewer_voxels}
)


def claims(runs: Mapping[str, list[RunData]]) -> list[Claim]:
    """Every claim's row, measured on ``runs`` (:func:`load_runs`).

    A claim read on runs shorter than the report's (:data:`REPORT_GENERATIONS`)
    says so in its ``why`` ("provisional").
    """
    used, left_out = finished_runs(runs)
    out = []
    for f in CLAIMS:
        own_choice = f in READS_UNFINISHED_RUNS
        c = f(runs if own_choice else used)
        names = CLAIM_SCENARIOS.get(c.id, ())
        short = [
            f"{n} reached generation {min(r.generation for r in used[n])} of the report's "
            f"{REPORT_GENERATIONS[n]}"
            for n in names
            if used.get(n) and n in REPORT_GENERATIONS
            and min(r.generation for r in used[n]) < REPORT_GENERATIONS[n]
        ]  # fmt: skip
        skipped = [
            f"{n} {', '.join(str(s) for s in left_out[n])}"
            for n in names
            if left_out.get(n) and not own_choice
        ]
        if c.verdict != UNTESTED:
            if short:
                c.why = f"{c.why}. Provisional: {'; '.join(short)}"
            if skipped:
                c.why = f"{c.why}. Unfinished seeds left out: {'; '.join(skipped)}"
        out.append(c)
    return out


def finished_runs(
    runs: Mapping[str, list[RunData]],
) -> tuple[dict[str, list[RunData]], dict[str, list[int]]]:
    """The runs the claims read, and the seeds left out, by scenario.

    A scenario with at least one complete run is read on its complete runs
    only (an unfinished seed would compare an early generation with other
    seeds' last one); a scenario with none is read on all its runs, and its
    claims are marked provisional.
    """
    used: dict[str, list[RunData]] = {}
    left_out: dict[str, list[int]] = {}
    for name, rs in runs.items():
        done = [r for r in rs if r.complete]
        used[name] = done or list(rs)
        if done and len(done) < len(rs):
            left_out[name] = [r.seed for r in rs if not r.complete]
    return used, left_out


# ---------------------------------------------------------------------------- figures
def _plt():
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt


def _save(fig: Any, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    _plt().close(fig)
    return path


def _band(rs: Sequence[RunData], key: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Generations, median, Q1, Q3 of ``key`` over seeds (generations where any seed has it)."""
    n = max(r.generation for r in rs) + 1
    m = np.full((len(rs), n), np.nan)
    for i, r in enumerate(rs):
        s = r.series(key)
        m[i, : len(s)] = s
    ok = np.isfinite(m).any(axis=0)
    g = np.flatnonzero(ok)
    q1, med, q3 = (np.nanpercentile(m[:, ok], q, axis=0) for q in (25, 50, 75))
    return g, med, q1, q3


def _plot_band(ax: Any, rs: Sequence[RunData], key: str, label: str, color: Any) -> None:
    g, med, q1, q3 = _band(rs, key)
    ax.fill_between(g, q1, q3, color=color, alpha=0.25, linewidth=0)
    ax.plot(g, med, color=color, label=f"{label}: median, IQR (n={len(rs)})")


def _plot_reference(ax: Any, name: str, color: Any) -> None:
    pts = REPORT_CURVES.get(name)
    if pts:
        x, y = zip(*pts)
        ax.plot(x, y, "--", color=color, linewidth=1.2, label=f"{name}: the report's single run")


def _log_if_wide(ax: Any, decades: float = 2.0) -> None:
    """Log y axis when the plotted values span more than ``decades`` (e.g. a run that found the
    low-density flying exploit next to the report's curve), so the smaller curves stay readable.
    """
    ys = [np.asarray(line.get_ydata(), dtype=float) for line in ax.get_lines()]
    ys = [y[np.isfinite(y) & (y > 0)] for y in ys]
    y = np.concatenate(ys) if ys else np.empty(0)
    if y.size and np.log10(y.max() / y.min()) > decades:
        ax.set_yscale("log")
        ax.set_ylabel(f"{ax.get_ylabel()}, log scale")


def fitness_figure(name: str, rs: Sequence[RunData], path: Path) -> Path:
    """Best-of-generation fitness of one scenario: median and IQR over seeds, seeds thin, report dashed."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    key = f"{rs[0].fitness}_best"
    for r in rs:
        s = r.series(key)
        ax.plot(np.arange(len(s)), s, color="0.75", linewidth=0.6)
    _plot_band(ax, rs, key, name, "C0")
    _plot_reference(ax, name, "C3")
    ax.set_xlabel("generation")
    ax.set_ylabel(f"best {rs[0].fitness} (voxel lengths)")
    _log_if_wide(ax)
    ax.set_title(f"{name}: best of generation over {len(rs)} seeds")
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return _save(fig, path)


def group_figure(
    names: Sequence[str], runs: Mapping[str, list[RunData]], path: Path, title: str
) -> Path | None:
    """Several scenarios' best-of-generation bands in one axes, each with its report curve."""
    present = [n for n in names if runs.get(n)]
    if not present:
        return None
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for i, n in enumerate(present):
        rs = runs[n]
        _plot_band(ax, rs, f"{rs[0].fitness}_best", n, f"C{i}")
        _plot_reference(ax, n, f"C{i}")
    ax.set_xlabel("generation")
    ax.set_ylabel("best fitness (voxel lengths)")
    _log_if_wide(ax)
    ax.set_title(title)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    return _save(fig, path)


def repeats_figure(runs: Mapping[str, list[RunData]], path: Path) -> Path | None:
    """Share of new robots with an already-simulated phenotype per generation (novelty, archive, basic)."""
    names = [n for n in ("novelty", "novelty-archive", "basic-200") if runs.get(n)]
    if not names:
        return None
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for i, n in enumerate(names):
        rs = runs[n]
        shares = []
        for r in rs:
            with np.errstate(invalid="ignore", divide="ignore"):
                shares.append(r.series("repeated_phenotypes") / r.series("new_individuals"))
        m = np.full((len(rs), max(len(s) for s in shares)), np.nan)
        for j, s in enumerate(shares):
            m[j, : len(s)] = s
        ok = np.isfinite(m).any(axis=0)
        if not ok.any():
            continue
        g = np.flatnonzero(ok)
        q1, med, q3 = (np.nanpercentile(m[:, ok], q, axis=0) for q in (25, 50, 75))
        ax.fill_between(g, q1, q3, color=f"C{i}", alpha=0.2, linewidth=0)
        ax.plot(g, med, color=f"C{i}", label=f"{n} (n={len(rs)})")
    ax.set_xlabel("generation")
    ax.set_ylabel("repeated phenotypes / new robots")
    ax.set_ylim(-0.02, 1.02)
    ax.set_title("'Patterns loop': new robots that repeat an earlier phenotype")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return _save(fig, path)


def _strip(
    ax: Any, groups: Sequence[tuple[str, Sequence[float]]], rng: np.random.Generator
) -> None:
    for i, (_, vals) in enumerate(groups):
        v = _finite(vals)
        if v.size:
            ax.scatter(i + rng.uniform(-0.12, 0.12, v.size), v, s=16, color=f"C{i}", zorder=3)
            ax.hlines(np.median(v), i - 0.25, i + 0.25, color="k", linewidth=1.5, zorder=4)
    ax.set_xticks(range(len(groups)))
    ax.set_xticklabels([g for g, _ in groups], fontsize=7, rotation=15)


def materials_figure(runs: Mapping[str, list[RunData]], path: Path) -> Path | None:
    """Materials of the winners of treatments 1 and 2 (one point per seed, black bar the median)."""
    names = [n for n in ("materials-t1", "materials-t2") if runs.get(n)]
    if not names:
        return None
    ws = {n: _winners(runs[n]) for n in names}
    panels = (
        ("muscle |CTE| (1/°C)", "muscle_abs_cte", EVOLVABLE_BOUNDS.cte_magnitude, 0.04),
        ("muscle density (kg/m^3)", "muscle_density", EVOLVABLE_BOUNDS.density, 586635.0),
        ("tissue density (kg/m^3)", "tissue_density", EVOLVABLE_BOUNDS.density, 1273400.0),
        ("tissue Young's modulus (Pa)", "tissue_youngs", EVOLVABLE_BOUNDS.youngs_modulus, 5e6),
        ("voxels", "n_voxels", (0, None), None),
    )
    plt = _plt()
    fig, axes = plt.subplots(1, len(panels), figsize=(3.0 * len(panels), 3.4))
    rng = np.random.default_rng(0)
    for ax, (label, attr, bounds, ref) in zip(axes, panels):
        _strip(ax, [(n, [getattr(w, attr) for w in ws[n]]) for n in names], rng)
        for b in bounds:
            if b:
                ax.axhline(b, color="0.6", linestyle=":", linewidth=1)
        if ref is not None:
            ax.axhline(ref, color="C3", linestyle="--", linewidth=1, label="report (T1 fastest)")
        if "density" in attr or "youngs" in attr:
            ax.set_yscale("log")
        ax.set_title(label, fontsize=8)
    axes[0].legend(fontsize=6)
    fig.suptitle(
        "Materials of the winners (dotted: GA bounds; dashed: the report's fastest T1 robot)",
        fontsize=9,
    )
    fig.tight_layout()
    return _save(fig, path)


def controller_figure(runs: Mapping[str, list[RunData]], path: Path) -> Path | None:
    """Controller genes and muscle voxels of the winners of the controller-evolving scenarios."""
    names = [n for n in ("controller-tournament", "controller-pareto", "obstacles-attempt2", "obstacles")
             if runs.get(n)]  # fmt: skip
    if not names:
        return None
    ws = {n: _winners(runs[n]) for n in names}
    init = Controller()
    panels = [(f"{g} ({CONTROLLER_BOUNDS[g][2]})", g, CONTROLLER_BOUNDS[g][:2], getattr(init, g))
              for g in ("period", "temp_amplitude", "muscle_cte")]  # fmt: skip
    plt = _plt()
    fig, axes = plt.subplots(1, 4, figsize=(12.5, 3.4))
    rng = np.random.default_rng(0)
    for ax, (label, gene, bounds, ref) in zip(axes, panels):
        _strip(ax, [(n, [w.genes[gene] for w in ws[n]]) for n in names], rng)
        for b in bounds:
            ax.axhline(b, color="0.6", linestyle=":", linewidth=1)
        ax.axhline(ref, color="C3", linestyle="--", linewidth=1, label="initial")
        ax.set_title(label, fontsize=8)
    _strip(axes[3], [(n, [w.n_muscle for w in ws[n]]) for n in names], rng)
    axes[3].set_title("muscle voxels", fontsize=8)
    axes[0].legend(fontsize=6)
    fig.suptitle(
        "Controllers of the winners (dotted: GA bounds; dashed: the initial controller)", fontsize=9
    )
    fig.tight_layout()
    return _save(fig, path)


def crossing_figure(runs: Mapping[str, list[RunData]], path: Path) -> Path | None:
    """First generation with a robot past the wall, one point per seed; seeds that never crossed on top."""
    names = [m for n in OBSTACLE_SCENARIOS for m in (n, n + ROBOT_COM) if runs.get(m)]
    if not names:
        return None
    plt = _plt()
    fig, ax = plt.subplots(figsize=(3.2 + 1.1 * len(names), 3.6))
    rng = np.random.default_rng(0)
    top = max(REPORT_CROSSING_GENERATION, *(r.generation for n in names for r in runs[n])) + 5
    for i, n in enumerate(names):
        g = np.array([crossing_generation(r) for r in runs[n]])
        _, undecided = _decided(runs[n], REPORT_CROSSING_GENERATION)
        running = np.array([r.seed in undecided for r in runs[n]], dtype=bool)
        reached = np.array([r.generation for r in runs[n]], dtype=float)
        x = i + rng.uniform(-0.12, 0.12, g.size)
        hit = np.isfinite(g)
        never = ~hit & ~running
        ax.scatter(x[hit], g[hit], s=18, color=f"C{i}", zorder=3)
        ax.scatter(x[never], np.full(never.sum(), top), marker="x", s=22, color=f"C{i}", zorder=3)
        # a seed still running: an open circle at the generation it has reached
        ax.scatter(x[running], reached[running], s=22, facecolors="none", edgecolors=f"C{i}",
                   zorder=3)  # fmt: skip
        more = f" ({running.sum()} running)" if running.any() else ""
        ax.text(i, top + 2, f"{hit.sum()}/{(~running).sum()} crossed{more}", ha="center",
                fontsize=7)  # fmt: skip
    ax.axhline(REPORT_CROSSING_GENERATION, color="C3", linestyle="--", linewidth=1,
               label=f"report: final setup crossed at generation {REPORT_CROSSING_GENERATION}")  # fmt: skip
    ax.set_xticks(range(len(names)))
    ax.set_xticklabels([n.replace(ROBOT_COM, "\n(robot CoM)") for n in names], fontsize=7)
    ax.set_ylabel("first generation past the wall\n(x: not crossed; o: running, before gen. 80)")
    ax.set_ylim(-2, top + 8)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    return _save(fig, path)


# ---------------------------------------------------------------------------- README
def _cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _settings(rs: Sequence[RunData]) -> str:
    e = rs[0].experiment
    sim = e.get("sim") or {}
    return (f"pop {e['pop_size']}, {e['seconds']:g} s, shape {'x'.join(map(str, e['shape']))}, "
            f"{e['selection']}" + (f", sim {json.dumps(sim)}" if sim else "")
            + (", seed's centre of mass" if e.get("seed_centre_of_mass") else ""))  # fmt: skip


def write_report(
    root: str | os.PathLike[str],
    out: str | os.PathLike[str] = "docs/study",
    command: str | None = None,
) -> Path:
    """Write ``out/README.md`` and ``out/figures/*.png`` from the run folders under ``root``.

    Parameters
    ----------
    root : path
        A study's root folder (or any folder holding run folders).
    out : path
        Where the README and its figures go.
    command : str, optional
        The command that made the runs (quoted in the README).

    Returns
    -------
    Path
        The README.
    """
    runs = load_runs(root)
    out = Path(out)
    figs = out / "figures"
    figs.mkdir(parents=True, exist_ok=True)
    rows = claims(runs)
    pictures: list[tuple[str, Path]] = []
    for name, rs in runs.items():
        if rs and rs[0].rows:
            pictures.append((f"{name}: best-of-generation fitness over seeds",
                             fitness_figure(name, rs, figs / f"fitness_{name}.png")))  # fmt: skip
    for caption, p in (
        ("Fig. 4 trio: basic vs. controller evolution (dashed: the report's runs)",
         group_figure(("basic", "controller-tournament", "controller-pareto"), runs,
                      figs / "fig4_trio.png", "Fig. 4 over seeds")),
        ("Novelty vs. fitness-based selection: best fitness",
         group_figure(("novelty", "novelty-archive", "basic-200"), runs,
                      figs / "novelty_vs_fitness.png", "Novelty vs. fitness-based selection")),
        ("Repeated phenotypes per generation (the 'patterns loop')",
         repeats_figure(runs, figs / "repeated_phenotypes.png")),
        ("Materials of the winners", materials_figure(runs, figs / "winners_materials.png")),
        ("Controllers of the winners", controller_figure(runs, figs / "winners_controller.png")),
        ("Obstacle crossing generation, one point per seed",
         crossing_figure(runs, figs / "obstacle_crossing.png")),
    ):  # fmt: skip
        if p is not None:
            pictures.append((caption, p))

    lines = [
        "# The seed report's claims over many seeds",
        "",
        "Written by `softgym study report` from the run folders alone "
        f"(`{Path(root)}`; regenerate with `softgym study report {Path(root)} --out {out}`).",
        "",
    ]
    if command:
        lines += [f"Runs made with `{command}`.", ""]
    lines += ["## Runs", "",
              "| scenario | experiment | seeds | complete | generations asked | reached (min-max) | report's | settings |",
              "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for name, rs in runs.items():
        reached = [r.generation for r in rs]
        lines.append(
            f"| {name} | {rs[0].experiment['name']} | {len(rs)} | {sum(r.complete for r in rs)} "
            f"| {max(r.target for r in rs)} | {min(reached)}-{max(reached)} "
            f"| {REPORT_GENERATIONS.get(name, '-')} | {_cell(_settings(rs))} |"
        )
    unfinished = [(n, r) for n, rs in runs.items() for r in rs if not r.complete]
    if unfinished:
        lines += ["", "Not finished: " + ", ".join(
            f"{n} seed {r.seed} (generation {r.generation} of {r.target})" for n, r in unfinished) + "."]  # fmt: skip
    noted = [(n, r) for n, rs in runs.items() for r in rs if r.notes]
    if noted:
        lines += ["", "Notes the run folders carry (`notes.jsonl`):", ""]
        for n, r in noted:
            for note in r.notes:
                when = f" ({note['time'][:10]})" if "time" in note else ""
                lines.append(f"* {n} seed {r.seed}{when}: {note['text']}")
    lines += [
        "",
        "## Claims",
        "",
        "Values are over seeds: median [first quartile, third quartile], n seeds.",
        "",
        "| # | claim | section | the report says | we measured | verdict | why |",
        "|---|---|---|---|---|---|---|",
    ]
    for i, c in enumerate(rows, 1):
        lines.append(
            f"| {i} | {c.id} | {c.section} | {_cell(c.report)} | {_cell(c.measured)} | **{c.verdict}** | {_cell(c.why)} |"
        )
    lines += ["", "## Figures", ""]
    for caption, p in pictures:
        lines += [f"### {caption}", "", f"![{caption}](figures/{p.name})", ""]
    lines += [
        "## How it is measured",
        "",
        "* **Best of generation**: the `<fitness>_best` column of each run's `log.jsonl` (the "
        "population after selection); the report's curves are read from its Fig. 1 and Fig. 4 by eye.",
        "* **Winner**: the first entry of `best_designs.json` (the best robot a run found). Its "
        "materials are voxel-weighted over the materials its body uses.",
        "* **Crossed the wall**: a robot's final centre of mass lies outside the footprint of the "
        "fence (past its outer face); the log's `crossed` column counts them per generation; the "
        "crossing generation is the first generation whose population holds one.",
        "* **Obstacle scores**: the obstacle scenarios select on the seed's centre of mass, "
        "which counts the fence's 44 one-kilogram wall voxels (MaxXYDist scaled by m_robot / "
        "(m_robot + 44 kg)), as the seed's runs did; the `-robot-com` scenarios are the same "
        "experiments selected on the robot's own centre of mass. Crossing the wall is judged "
        "on the robot's own centre of mass in both.",
        "* **Repeated phenotype**: a robot evaluated for the first time (child or newcomer) whose "
        "phenotype (body, used materials, controller) was already simulated earlier in the run; "
        "the share is over generations >= 1.",
        "* **Verdicts**: comparisons use a one-sided permutation test of the Mann-Whitney statistic "
        "(p < 0.05 holds; right direction but p >= 0.05 partly) and A12; other rules are in each row.",
        "* **Unfinished seeds**: a scenario with complete runs is judged on those only (an "
        "unfinished seed's early generation is not compared with other seeds' last one; the row "
        "names the seeds left out); a scenario with none is judged on what has run, marked "
        "provisional. A claim read at a fixed generation (T2-voxels: T1 at generation 50) also "
        "counts unfinished runs that have passed it. The figures show every seed.",
        "",
    ]
    readme = out / "README.md"
    readme.write_text("\n".join(lines))
    (out / "claims.json").write_text(
        json.dumps([_plain(dict(c.__dict__)) for c in rows], indent=1, allow_nan=False) + "\n"
    )
    return readme


def _plain(v: Any) -> Any:
    """JSON-ready values (NaN and infinities as None)."""
    if isinstance(v, Mapping):
        return {str(k): _plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple, np.ndarray)):
        return [_plain(x) for x in v]
    if isinstance(v, (np.generic, int, float)) and not isinstance(v, bool):
        f = float(v)
        if not math.isfinite(f):
            return None
        return int(v) if isinstance(v, (int, np.integer)) else f
    return v
