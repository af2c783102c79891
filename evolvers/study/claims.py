"""The seed report's claims, each checked against a study's runs (holds / partly / does not hold)."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from evolvers.study.data import (
    CLAIM_SCENARIOS,
    FAILS,
    HOLDS,
    PARTLY,
    REPORT_CROSSING_GENERATION,
    REPORT_GENERATIONS,
    REPORT_T1_FINAL,
    ROBOT_COM,
    UNTESTED,
    RunData,
)
from evolvers.study.stats import compare, finite_values, median, sign_pvalue, summary
from softgym.design import Controller
from softgym.design.material import MUSCLE_IDS, TISSUE_IDS

__all__ = [
    "CLAIMS",
    "Claim",
    "LIGHT_MUSCLE",
    "READS_UNFINISHED_RUNS",
    "SOFT_TISSUE",
    "Winner",
    "best_ever",
    "claims",
    "crossing_generation",
    "crossing_robot",
    "decided",
    "finished_runs",
    "flies",
    "repeated_share",
    "winner_of",
    "winners",
]


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


def winners(runs: Sequence[RunData]) -> list[Winner]:
    """The recorded winners of the runs (runs without one left out)."""
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
    mb = median(b)
    return median(a) / mb if mb else float("nan")


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
        f"last improvement at generation {summary(last_impr, '{:.0f}')}; best gained in the second "
        f"half of the run in {k}/{n} seeds (gain {summary(late_gain)}), {len(walking)} of "
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
    a = finite_values(final)
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
        f"final best {summary(final)} (generation {_gens(rs)}); 47.7 is above {pct:.0f}% of the seeds",
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
    ws = winners(runs["materials-t1"])
    if not ws:
        return _untested(cid, sec, rep, ["materials-t1 winners"])
    cte = [w.muscle_abs_cte for w in ws]
    at_bound = sum(c >= 0.035 for c in cte if math.isfinite(c))
    dens = [w.muscle_density for w in ws]
    tdens = [w.tissue_density for w in ws]
    tE = [w.tissue_youngs for w in ws]
    n = len(ws)
    with_tissue = int(finite_values(tdens).size)
    parts = {
        "muscle CTE at the bound": at_bound * 2 > n,
        "dense muscle": median(dens) >= LIGHT_MUSCLE,
        # the tissue must be there (in most winners), dense and soft (E near its 5 MPa floor)
        "dense soft tissue": with_tissue * 2 > n
        and median(tdens) >= LIGHT_MUSCLE
        and median(tE) <= SOFT_TISSUE,
    }
    held = [k for k, ok in parts.items() if ok]
    verdict = HOLDS if len(held) == len(parts) else PARTLY if held else FAILS
    return Claim(
        cid, sec, rep,
        f"muscle |CTE| {summary(cte)} (>= 0.035 in {at_bound}/{n}); muscle density "
        f"{summary(dens)}; "
        + (f"tissue (in {with_tissue}/{n} winners) density {summary(tdens)}, "
           f"E {summary(tE)} Pa" if with_tissue else f"no winner uses tissue (0/{n})"),
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
    verdict, why, _, _ = compare(v2, v1, larger=False)
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
        f"voxels of the best robot at generation {g}: T2 {summary(v2, '{:.0f}')} vs. T1 "
        f"{summary(v1, '{:.0f}')}",
        verdict, ". ".join(notes), {"t2": v2, "t1": v1},
    )  # fmt: skip


def claim_t2_muscles(runs: Mapping[str, list[RunData]]) -> Claim:
    """Materials T2 winners: mostly muscles of CTE +-0.04."""
    cid, sec = "T2-muscles", "III-A"
    rep = ("T2 winners 'mostly exploit muscles that expand and contract with a high CTE'; the fastest "
           "uses two muscles of CTE +0.04 and -0.04.")  # fmt: skip
    if m := _missing(runs, "materials-t2"):
        return _untested(cid, sec, rep, m)
    ws = winners(runs["materials-t2"])
    if not ws:
        return _untested(cid, sec, rep, ["materials-t2 winners"])
    frac = [w.n_muscle / w.n_voxels for w in ws if w.n_voxels]
    cte = [w.muscle_abs_cte for w in ws]
    high = sum(c >= 0.035 for c in cte if math.isfinite(c))
    both = sum(w.muscle_signs == 2 and w.muscle_abs_cte >= 0.035 for w in ws)
    n = len(ws)
    # the general part (most winners: mostly muscle of high CTE) and the fastest robot's
    fastest = max(ws, key=lambda w: w.objectives.get("norm_final_dist", -math.inf))
    general = median(frac) > 0.5 and high * 2 > n
    fast_ok = fastest.muscle_signs == 2 and fastest.muscle_abs_cte >= 0.035
    verdict = HOLDS if general and fast_ok else PARTLY if general or fast_ok else FAILS
    return Claim(
        cid, sec, rep,
        f"muscle share {summary(frac, '{:.2f}')}; muscle |CTE| {summary(cte)} (>= 0.035 in "
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
        v, why, _, _ = compare(nov, ref, larger=False)
        ratio = _ratio(nov, ref)
        if v == HOLDS and not ratio <= 0.5:
            v, why = PARTLY, f"{why}, lower but not 'much' (ratio of medians {ratio:.2f} > 0.5)"
        verdicts.append(v)
        measured.append(f"{label} {summary(ref)}, ratio of medians {ratio:.2g}")
        whys.append(f"novelty < {label}: {why}")
        data[label] = ref
    verdict = _combine(verdicts)
    if basic := runs.get("basic-200"):  # the same 200 generations, fitness-based, no extra genes
        ref = [best_ever(r) for r in basic]
        _, why, _, _ = compare(nov, ref, larger=False)
        ratio = _ratio(nov, ref)
        measured.append(f"(not the report's comparison) basic evolution over the same 200 "
                        f"generations {summary(ref)}, ratio {ratio:.2f}")  # fmt: skip
        whys.append(f"novelty < basic-200 (context): {why}")
        data["basic-200"] = ref
    return Claim(
        cid, sec, rep,
        f"best NormFinalDist of the run: novelty {summary(nov)} vs. " + "; ".join(measured),
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
    mostly = median(fr) > 0.5
    verdict = HOLDS if mostly else FAILS
    extra = f"; fitness-based (basic-200) {summary(ref, '{:.2f}')}" if ref else ""
    return Claim(
        cid, sec, rep,
        f"population median muscle share over the last 20 generations: {summary(fr, '{:.2f}')}{extra}",
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
        v, why, _, _ = compare(a, b, larger=True)
        verdicts.append(v)
        measured.append(f"{label} {summary(b, '{:.2f}')}")
        whys.append(f"{tests}: no archive > {label}: {why}")
        data[name] = b
    verdict = _combine(verdicts)
    return Claim(
        cid, sec, rep,
        f"share of new robots whose phenotype was already simulated in the run: novelty without "
        f"archive {summary(a, '{:.2f}')}; " + "; ".join(measured),
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
    vt, wt, _, _ = compare(t, b)
    vp, wp, _, _ = compare(p, b)
    verdict = (
        HOLDS
        if vt == vp == HOLDS
        else FAILS
        if FAILS in (vt, vp) and HOLDS not in (vt, vp)
        else PARTLY
    )
    return Claim(
        cid, sec, rep,
        f"best at generation {g}: basic {summary(b)}, tournament {summary(t)}, Pareto {summary(p)}",
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
    verdict, why, _, _ = compare(t, p)
    return Claim(
        cid, sec, rep, f"best at generation {g}: tournament {summary(t)} vs. Pareto {summary(p)}",
        verdict, f"tournament > Pareto: {why}", {"tournament": t, "pareto": p},
    )  # fmt: skip


def claim_pareto_fewer_muscles(runs: Mapping[str, list[RunData]]) -> Claim:
    """Fig. 5: Pareto winners have fewer muscles."""
    cid, sec = "pareto-muscles", "III-C, Fig. 5"
    rep = "The best robot of Pareto selection 'has far fewer muscles' than the tournament's."
    if m := _missing(runs, "controller-tournament", "controller-pareto"):
        return _untested(cid, sec, rep, m)
    t = [w.n_muscle for w in winners(runs["controller-tournament"])]
    p = [w.n_muscle for w in winners(runs["controller-pareto"])]
    verdict, why, _, _ = compare(p, t, larger=False)
    return Claim(
        cid, sec, rep,
        f"muscle voxels of the winners: Pareto {summary(p, '{:.0f}')} vs. tournament {summary(t, '{:.0f}')}",
        verdict, f"Pareto < tournament: {why}", {"tournament": t, "pareto": p},
    )  # fmt: skip


def claim_controller_genes(runs: Mapping[str, list[RunData]]) -> Claim:
    """Fig. 4 winners: short period, high amplitude, high CTE."""
    cid, sec = "controller-genes", "III-C"
    rep = "Best controllers have 'lower period and higher temperature amplitude and CTE'."
    if m := _missing(runs, "controller-tournament", "controller-pareto"):
        return _untested(cid, sec, rep, m)
    ws = winners(runs["controller-tournament"]) + winners(runs["controller-pareto"])
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
        p = sign_pvalue(k, len(moved)) if moved else 1.0
        significant.append(p < 0.05)
        direction.append(2 * k > len(moved))
        ties = f", {len(vals) - len(moved)} unchanged" if len(moved) < len(vals) else ""
        parts.append(f"{gene} {summary(vals)} ({'<' if lower else '>'} initial {ref:g} in "
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


def decided(rs: Sequence[RunData], horizon: int) -> tuple[list[RunData], list[int]]:
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
    rs, undecided = decided(runs[twin], REPORT_CROSSING_GENERATION)
    gens = [crossing_generation(r) for r in rs]
    k = sum(math.isfinite(g) for g in gens)
    first = f", first at generation {summary(gens, '{:.0f}')}" if k else ""
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
    rs, undecided = decided(runs["obstacles-attempt1"], horizon)
    if not rs:
        return _untested(cid, sec, rep, [f"obstacles-attempt1 at generation {horizon}"])
    gens, n = [crossing_generation(r) for r in rs], len(rs)
    k = sum(math.isfinite(g) for g in gens)
    verdict = HOLDS if k == 0 else PARTLY if k * 2 < n else FAILS
    return Claim(
        cid, sec, rep,
        f"crossed in {k}/{n} seeds within {_gens(rs)} generations"
        + (f" (first at generation {summary(gens, '{:.0f}')})" if k else "")
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
    rs, undecided = decided(runs["obstacles-attempt2"], horizon)
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
        f"crossed in {k}/{n} seeds (first at generation {summary(gens, '{:.0f}')}); muscle share of "
        f"the first robot past the wall {summary(frac, '{:.2f}')}, all-muscle in {all_muscle}/{k}"
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
    rs, undecided = decided(runs["obstacles"], horizon)
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
        f"within {_gens(rs)} generations (first crossing {summary(gens, '{:.0f}')}); "
        f"bone voxels of the first robot past the wall {summary(bone, '{:.0f}')}"
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
