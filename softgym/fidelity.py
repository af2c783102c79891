"""The protocol that holds the seed preset to the seed study's own engine.

softgym's seed preset is checked against the engine the seed study ran (a
program not shipped with softgym; its outputs are committed as JSON data under
``benchmarks/data/seed_engine/``, with the scripts that made them). This module
is that protocol's vocabulary, shared by the benchmark (``benchmarks/
fidelity_seed.py``, ``fidelity_evolved.py``), the scripts that generated the
data and the tests (``tests/engine/test_seed_oracle.py``):

* :data:`REGIMES`: the three actuation regimes (temperature amplitude, period,
  muscle CTE), "gentle" being the seed's default;
* :class:`Case` and :func:`cases_from_data`: the robots of a stored data file;
* :func:`perturb`, :func:`perturbed_voxel`, :func:`case_design`: draw ``k > 0``
  multiplies the density of one voxel (the ``k``-th of a permutation seeded by
  the case name) by ``1 + 1e-6`` (:data:`PERTURBATION`), the probe of how
  sensitive a body is (the seed's engine changes by up to 10x under it);
* :data:`METRIC`, :func:`fence_terrain`: what is compared on flat ground and in
  the seed's fence (:data:`FENCE`);
* :func:`micro_trace`: softgym's centre-of-mass trace at the sample steps of a
  stored micro-case;
* :func:`load_evolved`: the evolved robots of ``evolved.json`` and the seed
  engine's metric per draw.

* :func:`sample_draws`, :func:`mean_figures`, :func:`targets_met`: softgym's draws in
  samples of the oracle halves' size, the samples' figures averaged, and the targets
  judged on that mean (one sample's strong-regime figures move as much as any change of
  bits moves them);
* :func:`paired_comparison` and :data:`PAIRED_MARGINS`: two formulations (presets,
  builds) run on the same cases and draws, each case's distance from the seed's engine
  compared in pairs, with bootstrap confidence intervals on the differences and a
  non-inferiority verdict: whether "this change costs no fidelity" holds.

The statistics of one sample (rank correlation against the engine's own
self-agreement, the within-2x share, moved-vs-still mismatches) live in
``benchmarks/fidelity_seed.py``; the results in ``benchmarks/RESULTS.md``.
"""

from __future__ import annotations

import hashlib
import json
import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from softgym.design.controller import Controller
from softgym.design.material import default_palette
from softgym.design.robot import DESIGN_SCHEMA, DESIGN_VERSION, RobotDesign
from softgym.engine import SimConfig, Simulation
from softgym.exceptions import InvalidDesignError, InvalidParameterError
from softgym.terrain import Terrain

__all__ = [
    "FENCE",
    "METRIC",
    "PERTURBATION",
    "REGIMES",
    "SIM_SETTINGS",
    "SOFTGYM_METRIC",
    "Case",
    "case_design",
    "cases_from_data",
    "check_grid",
    "controller",
    "fence_terrain",
    "load_evolved",
    "mean_figures",
    "micro_trace",
    "paired_comparison",
    "perturb",
    "perturbed_voxel",
    "sample_draws",
    "targets_met",
]

#: Actuation regimes: temperature amplitude dT (degC), period (s), muscle CTE magnitude
#: (1/degC; ``Active_+`` gets +cte, ``Active_-`` gets -cte). "gentle" is the seed's default.
REGIMES: dict[str, dict[str, float]] = {
    "gentle": dict(dT=14, period=0.25, cte=0.01),
    "medium": dict(dT=18, period=0.15, cte=0.025),
    "strong": dict(dT=20, period=0.1, cte=0.04),
}

#: Simulation settings of every run (``softgym.design.vxa.to_vxa`` keyword arguments;
#: these are its defaults and the seed's, docs/PHYSICS.md). to_vxa also writes
#: BondDampingZ 1, ColDampingZ 0.8, SlowDampingZ 0.01, ColSystem 3, CollisionHorizon 2,
#: flat floor, gravity -9.81, Lattice_Dim 0.01 m.
SIM_SETTINGS: dict[str, Any] = dict(
    voxel_size=0.01, sim_time=5.0, init_time=1.0, dt_frac=0.9, self_collisions=True
)

#: Relative density change of the perturbed voxel.
PERTURBATION = 1e-6

#: The seed's fence task (docs/PHYSICS.md): a 50x50x6 workspace, the 6x6x6
#: robot box at voxel indices x, y in 22..27, z in 0..5, a square wall of material 5
#: (Obstacle, E 5e9 Pa, 1 kg per voxel) 1 voxel thick and 1 high at x in {19, 30}
#: (y 19..30) and y in {19, 30} (x 19..30): 44 fixed voxels. In softgym:
#: ``Terrain.fence()`` with the robot's grid corner at the origin (the wall at -3 and 8).
FENCE: dict[str, Any] = dict(
    env_size=(50, 50, 6),
    robot_offset=(22, 22, 0),
    side=12,
    wall_lo=19,
    wall_hi=30,
    height=1,
    wall_material=5,
    n_wall_voxels=44,
    wall_mass_kg=44.0,
    softgym_terrain="Terrain.fence(inner=10, height=1, thickness=1, center=(3, 3))",
)


@dataclass(frozen=True)
class Case:
    """One robot of the benchmark.

    Attributes
    ----------
    name : str
        Stable, unique name (also the seed of its perturbations).
    set : str
        ``"structured"``, ``"random"`` or ``"fence"``.
    design : RobotDesign
        The body with the default (seed) palette and controller; see :func:`case_design`.
    terrain : str
        ``"flat"`` or ``"fence"`` (:data:`FENCE`).
    meta : dict
        Description and facts: ``has_bone``, ``n_voxels``, ``robot_mass_kg``,
        ``mirror_x`` / ``mirror_y`` (grid equal to its mirror image), origin of a
        random body (``seed``, ``rules``, ``mutations``).
    """

    name: str
    set: str
    design: RobotDesign
    terrain: str = "flat"
    meta: dict[str, Any] = field(default_factory=dict, compare=False)


# --------------------------------------------------------------------------------------------
# Regimes, perturbation, designs
# --------------------------------------------------------------------------------------------


def controller(regime: str) -> Controller:
    """The :class:`~softgym.design.Controller` of a regime name of :data:`REGIMES`."""
    r = REGIMES[regime]
    return Controller(temp_amplitude=r["dT"], period=r["period"], muscle_cte=r["cte"])


def _name_seed(name: str) -> int:
    return int.from_bytes(hashlib.sha256(name.encode("utf-8")).digest()[:8], "little")


def perturbed_voxel(
    case: Case | RobotDesign, draw: int, name: str | None = None
) -> tuple[int, int, int] | None:
    """The voxel (i, j, k) whose density draw ``draw`` perturbs; None for draw 0.

    Parameters
    ----------
    case : Case or RobotDesign
        The case (its name seeds the choice) or a design with ``name`` given.
    draw : int
        0 (unperturbed) or k >= 1.
    name : str, optional
        Seed of the choice when ``case`` is a bare design.

    The filled voxels, in C order, are permuted by a generator seeded with the name;
    draw k takes entry ``(k - 1) % n_voxels``, so draws 1..n_voxels differ.
    """
    if draw < 0 or int(draw) != draw:
        raise InvalidParameterError(f"draw must be an integer >= 0, got {draw!r}")
    if draw == 0:
        return None
    design, key = _design_and_name(case, name)
    filled = np.flatnonzero(design.grid.ravel())
    order = np.random.default_rng(_name_seed(key)).permutation(filled.size)
    flat = int(filled[order[(int(draw) - 1) % filled.size]])
    i, j, k = np.unravel_index(flat, design.shape)
    return int(i), int(j), int(k)


def _design_and_name(case: Case | RobotDesign, name: str | None) -> tuple[RobotDesign, str]:
    if isinstance(case, Case):
        return case.design, case.name if name is None else name
    if name is None:
        raise InvalidParameterError("perturbing a bare RobotDesign needs the case name (name=...)")
    return case, name


def perturb(case: Case | RobotDesign, draw: int, name: str | None = None) -> RobotDesign:
    """The design with one voxel's density multiplied by ``1 + PERTURBATION`` (draw 0: unchanged).

    Parameters
    ----------
    case : Case or RobotDesign
        A case (perturbs ``case.design``) or a design (then ``name`` is required;
        pass the case name, e.g. ``perturb(case_design(c, "strong"), 3, name=c.name)``).
    draw : int
        0 (unperturbed) or k >= 1 (see :func:`perturbed_voxel`).
    name : str, optional
        The case name when ``case`` is a bare design.

    Returns
    -------
    RobotDesign
        Same controller; the voxel :func:`perturbed_voxel` holds a new palette id
        (``palette.max_id + 1``) whose material copies the voxel's material with the
        density multiplied.
    """
    design, key = _design_and_name(case, name)
    voxel = perturbed_voxel(design, draw, key)
    if voxel is None:
        return design
    mid = int(design.grid[voxel])
    new_id = design.palette.max_id + 1
    mat = design.palette[mid]
    copy = mat.replace(name=f"{mat.name}_perturbed", density=mat.density * (1.0 + PERTURBATION))
    grid = design.grid.copy()
    grid[voxel] = new_id
    return design.replace(grid=grid, palette=design.palette.with_material(new_id, copy))


def case_design(case: Case, regime: str, draw: int = 0) -> RobotDesign:
    """The design of ``case`` driven by ``regime``'s controller, with draw ``draw``'s perturbation."""
    return perturb(case.design.with_controller(controller(regime)), draw, name=case.name)


def cases_from_data(data: dict[str, Any]) -> list[Case]:
    """The cases of a loaded oracle data file (``json.load`` of ``structured.json``, ...), from its stored grids.

    Needs neither the CPPN code nor ``evolvers``: each case gets the stored grid, the
    default (seed) palette and controller, its stored terrain and meta, and the set
    named in the file's header. :func:`case_design` and :func:`perturbed_voxel` then
    give the same designs and voxels as for the generated cases.
    """
    out = []
    set_ = data["header"]["set"]
    for name, entry in data["cases"].items():
        design = RobotDesign.from_dict(
            {
                "schema": DESIGN_SCHEMA,
                "version": DESIGN_VERSION,
                "grid": entry["grid"],
                "palette": default_palette().to_list(),
                "controller": Controller().to_dict(),
            }
        )
        out.append(
            Case(name, set_, design, entry.get("terrain", "flat"), dict(entry.get("meta", {})))
        )
    return out


def check_grid(case: Case, stored: dict[str, Any]) -> None:
    """Raise InvalidDesignError unless ``case``'s grid equals a grid stored by the oracle data.

    ``stored`` is the ``"grid"`` entry of :meth:`RobotDesign.to_dict` (as written in
    the data files' ``"cases"``).
    """
    mine = case.design.to_dict()["grid"]
    if mine != stored:
        raise InvalidDesignError(
            f"case {case.name!r}: the grid differs from the one the oracle ran "
            "(did the CPPN code change?); use the stored grid"
        )


#: The metric compared per terrain: the seed's fitness on flat ground and on its fence.
METRIC = {"flat": "NormFinalDist", "fence": "MaxXYDist"}
#: softgym's name of each oracle metric.
SOFTGYM_METRIC = {"NormFinalDist": "norm_final_dist", "MaxXYDist": "max_xy_dist"}


def fence_terrain() -> Terrain:
    """The seed's fence around a 6x6x6 robot at the origin (:data:`FENCE`)."""
    return Terrain.fence(inner=10, height=1, thickness=1, center=(3, 3))


def micro_trace(
    case: dict[str, Any], model: str = "seed", link_precision: str | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The centre of mass softgym computes at the oracle's sample steps of a micro-case.

    ``case`` is one entry of ``micro.json``'s ``"cases"`` (grid, regime, times and
    the seed engine's trace); ``model`` and ``link_precision`` as in
    :class:`~softgym.engine.SimConfig`. Returns ``(ours, oracle)``, each of shape
    (n_samples, 3) in metres.
    """
    dT, period, cte = (REGIMES[case["regime"]][k] for k in ("dT", "period", "cte"))
    design = RobotDesign(np.asarray(case["grid"]), controller=Controller(dT, period, cte))
    cfg = SimConfig(init_time=case["init_time"], model=model, link_precision=link_precision)
    sim = Simulation([design], cfg, n_threads=1)
    dt = float(sim.dt[0])
    sim = Simulation([design], cfg.replace(trace_interval=dt), n_threads=1)
    rollout = sim.run(case["sim_time"])
    oracle = np.asarray(case["trace"], dtype=np.float64)
    steps = np.rint(oracle[:, 3] / dt).astype(np.intp)  # the oracle samples at step times
    steps = np.clip(steps, 0, rollout.cm.shape[1] - 1)
    return rollout.cm[0, steps], oracle[:, :3]


def load_evolved(path: str | Path) -> tuple[dict[str, dict[str, Any]], dict[tuple[str, int], float]]:
    """The designs of an ``evolved.json`` file and the oracle's metric by (design, draw).

    The metric is :data:`METRIC` of each design's terrain; NaN where the seed's
    engine hung.
    """
    data = json.loads(Path(path).read_text())
    values = {}
    for rec in data["records"]:
        terrain = data["cases"][rec["case"]]["terrain"]
        v = rec.get(METRIC[terrain])
        values[(rec["case"], int(rec["draw"]))] = (
            float("nan") if rec.get("hung") or v is None else float(v)
        )
    return data["cases"], values


def sample_draws(first: int, per_sample: int, samples: int) -> list[list[int]]:
    """Draws of softgym's perturbed runs: ``samples`` consecutive samples of ``per_sample``.

    They start at draw ``first`` (draws past 6 perturb voxels the oracle's draws did not).
    """
    if first < 1 or per_sample < 1 or samples < 1:
        raise InvalidParameterError(
            f"first draw, draws per sample and samples must be >= 1, got {first}, "
            f"{per_sample}, {samples}"
        )
    return [list(range(first + k * per_sample, first + (k + 1) * per_sample)) for k in range(samples)]


def mean_figures(figures: list[dict[str, float]]) -> dict[str, float]:
    """Samples' agreement figures as one.

    The figures (``n``, ``spearman``, ``median_abs_log10``, ``within_2x``, ``within_3x``,
    ``moved_vs_still``): the mean of each, the cases ``n`` of the first, the moved-vs-still
    mismatches summed (one in any sample counts).
    """
    if not figures:
        raise InvalidParameterError("mean_figures needs at least one sample's figures")
    out: dict[str, float] = {"n": figures[0]["n"]}
    for key in ("spearman", "median_abs_log10", "within_2x", "within_3x"):
        out[key] = float(np.mean([f[key] for f in figures]))
    out["moved_vs_still"] = int(sum(f["moved_vs_still"] for f in figures))
    return out


def targets_met(soft: dict[str, float], self_: dict[str, float]) -> dict[str, bool]:
    """The seed-fidelity targets on (mean) figures.

    softgym's rank correlation and within-2x share against the oracle at least 0.9 x the
    oracle halves' own, and no body moved by one engine and left still by the other.
    """
    return {
        "spearman": bool(soft["spearman"] >= 0.9 * self_["spearman"]),
        "within_2x": bool(soft["within_2x"] >= 0.9 * self_["within_2x"]),
        "moved_vs_still": bool(soft["moved_vs_still"] == 0),
    }


#: Non-inferiority margins of :func:`paired_comparison`: how much worse than formulation B
#: formulation A may be and still "cost no fidelity". ``abs_log10``: the mean per-case
#: ``abs(log10(softgym / seed engine))`` (0.02 is a 4.7 % larger typical ratio); ``spearman``: the
#: rank correlation with the seed's engine; ``within_2x``: the share of cases within a
#: factor 2 of it.
PAIRED_MARGINS: dict[str, float] = {"abs_log10": 0.02, "spearman": 0.02, "within_2x": 0.03}


def _ranks(x: np.ndarray) -> np.ndarray:
    from scipy.stats import rankdata

    return rankdata(x, axis=-1)


def _pearson(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    x = x - x.mean(axis=-1, keepdims=True)
    y = y - y.mean(axis=-1, keepdims=True)
    den = np.sqrt((x * x).sum(axis=-1) * (y * y).sum(axis=-1))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, (x * y).sum(axis=-1) / np.where(den > 0, den, 1.0), np.nan)


def paired_comparison(
    a,
    b,
    reference,
    *,
    floor: float = 0.01,
    margins: dict[str, float] | None = None,
    confidence: float = 0.95,
    n_resamples: int = 4000,
    seed: int = 0,
) -> dict[str, Any]:
    """Formulation A against formulation B, paired on the same cases and draws.

    Each case's distance (voxel lengths) is its median over a sample of perturbed draws;
    both formulations ran the same draws of the same cases, so case difficulty and the
    draws cancel in the differences. Three figures, each as A's *loss* against B
    (positive: A is farther from the seed's engine):

    * ``abs_log10``: mean over cases of A's ``abs(log10(A / ref))`` minus B's (each case's error
      is its mean over the samples);
    * ``spearman``: B's rank correlation with the reference minus A's (each the mean over
      the samples; ties get average ranks);
    * ``within_2x``: B's share of (case, sample) pairs within 2x of the reference minus A's.

    Confidence intervals come from :func:`scipy.stats.bootstrap` (BCa, resampling cases
    with their pairs). A *costs no fidelity* against B on a figure when the interval's
    upper end is at most that figure's margin (a non-inferiority test); ``"better"`` /
    ``"worse"`` when the interval excludes 0.

    Parameters
    ----------
    a, b : array_like of shape (n_cases, n_samples)
        Per case and sample, the median distance of formulation A / B.
    reference : array_like of shape (n_cases,)
        The seed's engine's per-case distance (e.g. the median of its draws).
    floor : float
        Distances under it are raised to it before ratios (a body both leave still agrees).
    margins : dict, optional
        Non-inferiority margins by figure (default :data:`PAIRED_MARGINS`).
    confidence : float
        Confidence level of the intervals, in (0, 1).
    n_resamples : int
        Bootstrap resamples (>= 100).
    seed : int
        Seed of the bootstrap's random generator.

    Returns
    -------
    dict
        ``n_cases``, ``n_samples``, per figure ``{"a", "b", "loss", "low", "high",
        "margin", "no_loss", "direction"}`` under ``figures``, ``wins`` (cases where A's
        error is smaller, larger, equal), and ``no_loss`` (every figure non-inferior).

    Raises
    ------
    InvalidParameterError
        For shapes that differ, fewer than 3 cases, non-finite or negative distances, or
        a confidence, resample count or margin out of range.
    """
    from scipy.stats import bootstrap

    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    ref = np.asarray(reference, dtype=np.float64)
    if a.ndim == 1:
        a = a[:, None]
    if b.ndim == 1:
        b = b[:, None]
    if a.ndim != 2 or a.shape != b.shape or ref.shape != (a.shape[0],):
        raise InvalidParameterError(
            f"paired_comparison needs a and b of one shape (n_cases, n_samples) and a "
            f"reference of shape (n_cases,), got {a.shape}, {b.shape} and {ref.shape}"
        )
    if a.shape[0] < 3 or a.shape[1] < 1:
        raise InvalidParameterError(
            f"paired_comparison needs at least 3 cases and 1 sample, got {a.shape}"
        )
    for name, x in (("a", a), ("b", b), ("reference", ref)):
        if not np.all(np.isfinite(x)) or np.any(x < 0):
            raise InvalidParameterError(f"paired_comparison: {name} must be finite distances >= 0")
    if not 0.0 < float(confidence) < 1.0:
        raise InvalidParameterError(f"confidence must be in (0, 1), got {confidence!r}")
    if int(n_resamples) < 100:
        raise InvalidParameterError(f"n_resamples must be >= 100, got {n_resamples!r}")
    if not (isinstance(floor, (int, float)) and math.isfinite(floor) and floor > 0):
        raise InvalidParameterError(f"floor must be a number > 0, got {floor!r}")
    marg = dict(PAIRED_MARGINS)
    marg.update(margins or {})
    for k, v in marg.items():
        if k not in PAIRED_MARGINS or not (math.isfinite(float(v)) and float(v) >= 0):
            raise InvalidParameterError(
                f"margins: keys in {sorted(PAIRED_MARGINS)} with values >= 0, got {k!r}: {v!r}"
            )
    n, s = a.shape
    la = np.log10(np.maximum(a, floor) / np.maximum(ref, floor)[:, None])
    lb = np.log10(np.maximum(b, floor) / np.maximum(ref, floor)[:, None])
    ea, eb = np.abs(la), np.abs(lb)
    wa = (ea <= math.log10(2.0)).mean(axis=1)
    wb = (eb <= math.log10(2.0)).mean(axis=1)
    lref = np.log10(np.maximum(ref, floor))

    def figures(ea_, eb_, wa_, wb_, la_, lb_, lref_, axis=-1):
        # la_, lb_: (..., n, s) moved to (..., s, n) for the per-sample correlations
        ra = _ranks(np.moveaxis(la_ + lref_[..., None], -2, -1))
        rb = _ranks(np.moveaxis(lb_ + lref_[..., None], -2, -1))
        rr = _ranks(lref_)[..., None, :]
        rho_a = _pearson(ra, np.broadcast_to(rr, ra.shape)).mean(axis=-1)
        rho_b = _pearson(rb, np.broadcast_to(rr, rb.shape)).mean(axis=-1)
        return np.stack([ea_.mean(axis=-1) - eb_.mean(axis=-1), rho_b - rho_a,
                         wb_.mean(axis=-1) - wa_.mean(axis=-1), rho_a, rho_b])

    point = figures(ea.mean(axis=1), eb.mean(axis=1), wa, wb, la, lb, lref)

    def statistic(ea_, eb_, wa_, wb_, ia, axis=-1):
        # ia: resampled case indices (float), to gather the per-sample rows
        idx = ia.astype(np.intp)
        return figures(ea_, eb_, wa_, wb_, la[idx], lb[idx], lref[idx])[:3]

    data = (ea.mean(axis=1), eb.mean(axis=1), wa, wb, np.arange(n, dtype=np.float64))
    losses = point[:3]
    if np.allclose(ea, eb) and np.allclose(wa, wb) and np.allclose(la, lb):
        low = high = losses.copy()  # identical results: no interval to draw
    else:
        with warnings.catch_warnings():  # an undefined BCa interval falls back below
            warnings.simplefilter("ignore")
            res = bootstrap(data, statistic, paired=True, vectorized=True,
                            n_resamples=int(n_resamples), confidence_level=float(confidence),
                            method="BCa", random_state=np.random.default_rng(int(seed)))  # fmt: skip
        low, high = (np.asarray(res.confidence_interval.low, dtype=np.float64),
                     np.asarray(res.confidence_interval.high, dtype=np.float64))  # fmt: skip
        bad = ~(np.isfinite(low) & np.isfinite(high))
        if bad.any():  # BCa undefined (a degenerate figure): the percentile interval
            res = bootstrap(data, statistic, paired=True, vectorized=True,
                            n_resamples=int(n_resamples), confidence_level=float(confidence),
                            method="percentile", random_state=np.random.default_rng(int(seed)))  # fmt: skip
            low = np.where(bad, res.confidence_interval.low, low)
            high = np.where(bad, res.confidence_interval.high, high)
    values = {
        "abs_log10": (float(ea.mean()), float(eb.mean())),
        "spearman": (float(point[3]), float(point[4])),
        "within_2x": (float(wa.mean()), float(wb.mean())),
    }
    out_fig = {}
    for i, key in enumerate(("abs_log10", "spearman", "within_2x")):
        lo, hi = float(low[i]), float(high[i])
        out_fig[key] = {
            "a": values[key][0], "b": values[key][1], "loss": float(losses[i]),
            "low": lo, "high": hi, "margin": float(marg[key]),
            "no_loss": bool(hi <= marg[key]),
            "direction": "worse" if lo > 0 else ("better" if hi < 0 else "no difference shown"),
        }  # fmt: skip
    per_case = ea.mean(axis=1) - eb.mean(axis=1)
    return {
        "n_cases": int(n),
        "n_samples": int(s),
        "confidence": float(confidence),
        "figures": out_fig,
        "wins": {"a": int(np.sum(per_case < 0)), "b": int(np.sum(per_case > 0)),
                 "tie": int(np.sum(per_case == 0))},  # fmt: skip
        "no_loss": all(f["no_loss"] for f in out_fig.values()),
    }
