import dataclasses
import json
import math
import re

import numpy as np
import pytest
from evolver_helpers import tiny

from evolvers.evaluation.evaluator import EvalStats
from evolvers.operators.genome import Individual
from evolvers.recording.recorder import add_run_note, read_run_notes
from evolvers.recording.rows import study_columns
from evolvers.study.data import load_runs
from evolvers.study.runs import (
    SEED_REPORT,
    plan,
    run_order,
    run_status,
    run_study,
    settings_difference,
    time_to_go,
)
from evolvers.study.stats import a12, permutation_pvalue
from softgym.exceptions import InvalidParameterError
from softgym.metrics import obstacle_footprint
from softgym_cli import main

TINY = ["--pop", "4", "--seconds", "1.5", "--shape", "4", "4", "4", "--quiet"]
VERDICTS = {"holds", "partly", "does not hold", "not run"}


def _statuses(out: str) -> list[str]:
    return re.findall(r"seed \d+\s+(\w+)\s+generation", out)


def test_study_runs_resumes_skips_and_reports(tmp_path, capsys):
    # the CI version of the study: 2 scenarios x 2 seeds x 2 generations, then the report
    root = tmp_path / "study"
    study = ["study", "--scenarios", "controller-tournament,controller-pareto", "--seeds", "2",
             "--out", str(root), *TINY]  # fmt: skip
    assert main([*study, "--generations", "1"]) == 0
    capsys.readouterr()
    main([*study, "--generations", "1", "--plan"])
    assert capsys.readouterr().out.count("complete") == 4
    main([*study, "--generations", "2", "--plan"])  # each run has logged generations 0 and 1
    assert "4 runs, 4 unfinished" in (last := capsys.readouterr().out.splitlines()[-1])
    assert "(4 timed from their own logged generations, 0 from their scenario's, 0 " in last
    # a larger --generations resumes each run from its checkpoint; then everything is complete
    logging_off = [a for a in study if a != "--quiet"]
    assert main([*logging_off, "--generations", "2"]) == 0
    assert _statuses(capsys.readouterr().out) == ["resumed"] * 4
    assert main([*logging_off, "--generations", "2"]) == 0
    assert _statuses(capsys.readouterr().out) == ["skipped"] * 4
    for name in ("controller-tournament", "controller-pareto"):
        for k in (0, 1):
            run = root / name / f"seed-{k}"
            assert run_status(run, 2) == "complete"
            rows = [json.loads(x) for x in (run / "log.jsonl").read_text().splitlines()]
            assert [r["generation"] for r in rows] == [0, 1, 2]
            assert {"top_period", "top_n_muscle", "repeated_phenotypes"} <= set(rows[-1])
        assert json.loads((root / name / "scenario.json").read_text())["seeds"] == [0, 1]

    # a note in a run folder (e.g. left by a repair) is quoted by the report
    add_run_note(root / "controller-pareto" / "seed-1", "repaired after a bad resume", generation=1)
    assert read_run_notes(root / "controller-pareto" / "seed-1")[0]["generation"] == 1
    out = root / "report"  # by default the report goes beside the runs, not over docs/study
    assert main(["study", "report", str(root)]) == 0
    text = (out / "README.md").read_text()
    assert "controller-pareto seed 1 (" in text and "repaired after a bad resume" in text
    claims = json.loads((out / "claims.json").read_text())
    assert len(claims) >= 15 and {c["verdict"] for c in claims} <= VERDICTS
    by_id = {c["id"]: c for c in claims}
    for cid in ("tournament-vs-pareto", "pareto-muscles", "controller-genes"):
        c = by_id[cid]
        assert c["verdict"] != "not run"
        assert re.search(r"\d+(\.\d+)? \[\d.*\], n=[24]\b", c["measured"]), c
        assert f"| {cid} |" in text
    assert by_id["T1-final"]["verdict"] == "not run"  # no materials runs here
    assert "Provisional" in by_id["tournament-vs-pareto"]["why"]  # 2 of the report's 40 gens
    for fig in ("fitness_controller-tournament.png", "fitness_controller-pareto.png",
                "fig4_trio.png", "winners_controller.png"):  # fmt: skip
        path = out / "figures" / fig
        assert path.stat().st_size > 5000, fig
        assert f"figures/{fig}" in text
    finals = by_id["tournament-vs-pareto"]["data"]["tournament"]
    assert len(finals) == 2 and all(math.isfinite(v) for v in finals)
    assert main(["study", "report", str(tmp_path / "nothing"), "--out", str(out)]) == 2
    # a run that has started but logged no generation yet is left out, not a crash
    started = root / "controller-pareto" / "seed-2"
    started.mkdir()
    (started / "config.json").write_text(
        (root / "controller-pareto" / "seed-0" / "config.json").read_text()
    )
    (started / "log.jsonl").write_text("")
    assert [r.path.name for r in load_runs(root)["controller-pareto"]] == ["seed-0", "seed-1"]
    assert main(["study", "report", str(root), "--out", str(out)]) == 0
    # an unfinished seed beside complete ones is listed, and left out of the claims (its early
    # generation would be compared with the other seeds' last one)
    first_row = (root / "controller-pareto" / "seed-0" / "log.jsonl").read_text().splitlines()[0]
    (started / "log.jsonl").write_text(first_row + "\n")
    cfg = json.loads((started / "config.json").read_text())
    (started / "config.json").write_text(json.dumps({**cfg, "seed": 2}))
    assert [r.complete for r in load_runs(root)["controller-pareto"]] == [True, True, False]
    assert main(["study", "report", str(root), "--out", str(out)]) == 0
    text = (out / "README.md").read_text()
    assert "controller-pareto seed 2 (generation 0 of 2)" in text
    by_id = {c["id"]: c for c in json.loads((out / "claims.json").read_text())}
    assert len(by_id["tournament-vs-pareto"]["data"]["pareto"]) == 2
    assert "best at generation 2:" in by_id["tournament-vs-pareto"]["measured"]
    assert "Unfinished seeds left out: controller-pareto 2" in by_id["tournament-vs-pareto"]["why"]


def test_plan_defaults_and_errors(tmp_path):
    specs = plan(tmp_path)
    counts = {}
    for s in specs:
        counts[s.scenario] = counts.get(s.scenario, 0) + 1
    assert counts["controller-tournament"] >= 10 and counts["materials-t1"] >= 5
    assert {s.generations for s in specs if s.scenario == "materials-t1"} == {300}
    assert sum(counts.values()) == sum(sc.seeds for sc in SEED_REPORT.scenarios)
    assert 30 * 3600 < sum(s.cost for s in specs) < 50 * 3600  # the measured ~40 CPU hours
    small = plan(tmp_path, scenarios=["basic"], seeds=3, generations=4, first_seed=7, pop_size=4)
    assert [s.seed for s in small] == [7, 8, 9] and small[0].experiment.pop_size == 4
    assert small[0].out == tmp_path / "basic" / "seed-7"
    # rounds of seeds: every scenario's seed 0 before any seed 1, longest first within a round
    order = run_order(specs)
    first_round = order[: len(SEED_REPORT.scenarios)]
    assert {s.seed for s in first_round} == {0}
    assert {s.scenario for s in first_round} == {sc.name for sc in SEED_REPORT.scenarios}
    assert [s.cost for s in first_round] == sorted((s.cost for s in first_round), reverse=True)
    assert [s.seed for s in order] == sorted(s.seed for s in order)
    with pytest.raises(InvalidParameterError, match="no scenario"):
        plan(tmp_path, scenarios=["nope"])
    with pytest.raises(InvalidParameterError):
        plan(tmp_path, seeds=0)


def test_a_run_started_with_other_settings_fails_alone(tmp_path, capsys):
    root = tmp_path / "s"
    assert not run_study(plan(root, scenarios=["basic"], seeds=1, generations=1, pop_size=4,
                              seconds=1.0, shape=(4, 4, 4)))[0]["status"] == "failed"  # fmt: skip
    res = run_study(plan(root, scenarios=["basic"], seeds=1, generations=2, pop_size=5,
                         seconds=1.0, shape=(4, 4, 4)))  # fmt: skip
    assert res[0]["status"] == "failed" and "pop_size" in res[0]["error"]
    # a complete run is not counted as another setting's either (e.g. a scenario's changed
    # overrides): it fails, naming the setting, instead of being skipped
    res = run_study(plan(root, scenarios=["basic"], seeds=1, generations=1, pop_size=4,
                         seconds=1.0, shape=(4, 4, 4), seed_centre_of_mass=True))  # fmt: skip
    assert res[0]["status"] == "failed"
    assert "experiment.seed_centre_of_mass: False (recorded) != True" in res[0]["error"]
    same = plan(root, scenarios=["basic"], seeds=1, generations=1, pop_size=4, seconds=1.0,
                shape=(4, 4, 4))  # fmt: skip
    assert settings_difference(same[0]) is None and run_study(same)[0]["status"] == "skipped"
    reworded = same[0].experiment.replace(description="reworded")  # not a setting
    assert settings_difference(dataclasses.replace(same[0], experiment=reworded)) is None
    # --plan says so before anything runs
    main(["study", "--scenarios", "basic", "--seeds", "1", "--generations", "1", "--pop", "4",
          "--seconds", "1", "--shape", "4", "4", "4", "--out", str(root), "--plan"])  # fmt: skip
    assert "run with other settings: experiment.pop_size" not in capsys.readouterr().out
    main(["study", "--scenarios", "basic", "--seeds", "1", "--generations", "1", "--pop", "6",
          "--seconds", "1", "--shape", "4", "4", "4", "--out", str(root), "--plan"])  # fmt: skip
    lines = capsys.readouterr().out.splitlines()
    assert " other " in lines[0] and "run with other settings: experiment.pop_size: 4" in lines[0]
    assert lines[-1].startswith("1 runs, 0 unfinished; 1 made with other settings, refused")


def test_statistics():
    assert a12([3, 4, 5], [0, 1, 2]) == 1.0 and a12([1, 1], [1, 1]) == 0.5
    assert permutation_pvalue([10, 11, 12, 13, 14], [0, 1, 2, 3, 4]) < 0.01
    assert permutation_pvalue([0, 1, 2, 3, 4], [10, 11, 12, 13, 14]) > 0.99
    assert math.isnan(permutation_pvalue([], [1.0]))


def test_study_columns_count_wall_crossings():
    exp = tiny("obstacles-attempt2")
    x0, x1, y0, y1 = obstacle_footprint(exp.make_task().terrain_for(exp.shape))
    assert (x0, x1) == (-4.0, 8.0)  # the fence around a 4x4 grid: 10-voxel interior, 1 thick
    rng = np.random.default_rng(0)
    inds = []
    for i, final_x in enumerate((2.0, 8.5, 10.0)):  # inside, past, further past (voxel lengths)
        ind = Individual.random(rng, i, exp.shape)
        ind.objectives = {"max_xy_dist": final_x - 2.0, "norm_final_dist": 1.0, "n_voxels": 10.0, "n_muscle": 10.0 - i,
                          "n_bone": float(i)}  # fmt: skip
        ind.trace = np.array([[0.02, 0.02, 0.01, 1.0], [final_x * 0.01, 0.02, 0.01, 5.0]])
        inds.append(ind)
    row = study_columns(exp, inds, EvalStats(n_new=3, n_repeated=1))
    assert row["crossed"] == 2 and row["top_crossed"] == 1 and row["top_id"] == 2
    assert row["crosser_id"] == 2 and row["crosser_n_bone"] == 2.0
    assert row["top_final_x"] == pytest.approx(10.0)
    assert (row["new_individuals"], row["repeated_phenotypes"]) == (3, 1)
    flat = study_columns(tiny("basic"), inds, EvalStats())
    assert "crossed" not in flat and flat["top_period"] == 0.25


@pytest.mark.filterwarnings("ignore::DeprecationWarning")
def test_seeds_run_in_parallel_on_a_local_cluster(tmp_path):
    pytest.importorskip("distributed")
    specs = plan(tmp_path, scenarios=["controller-tournament"], seeds=2, generations=1,
                 pop_size=4, seconds=1.0, shape=(4, 4, 4))  # fmt: skip
    res = run_study(specs, workers=2)
    assert sorted(r["status"] for r in res) == ["ran", "ran"]
    runs = load_runs(tmp_path)["controller-tournament"]
    assert [r.seed for r in runs] == [0, 1] and all(r.complete for r in runs)


def test_parallel_runs_start_in_run_order(tmp_path):
    # 2 workers, 4 runs submitted in run_order through a window of 2: the third starts only
    # once a run has ended, the fourth once two have. (Which of the first two writes its
    # folder first is up to the workers: a worker still importing can start the second run
    # after the other has ended the first and taken the third, as a CI run saw)
    pytest.importorskip("distributed")
    specs = plan(tmp_path, scenarios=["basic", "controller-tournament"], seeds=2, generations=1,
                 pop_size=4, seconds=1.0, shape=(3, 3, 3))  # fmt: skip
    res = run_study(specs, workers=2)
    assert sorted(r["status"] for r in res) == ["ran"] * 4
    ordered = run_order(specs)
    started = [(s.out / "config.json").stat().st_mtime for s in ordered]
    ended = [(s.out / "final_population.json").stat().st_mtime for s in ordered]
    assert started[2] >= min(ended[:2]) and started[3] >= sorted(ended[:3])[1]
    # completion order: every result is reported, each run once
    assert sorted((r["scenario"], r["seed"]) for r in res) == sorted(
        (s.scenario, s.seed) for s in specs
    )


def test_time_to_go_uses_logged_generations(tmp_path):
    # a partial run is timed by its own generations, a new one by its scenario's rate, a
    # scenario with nothing logged by the static estimate; complete runs need nothing
    specs = plan(tmp_path, scenarios=["basic", "controller-tournament"], seeds=2, generations=9)
    basic0, basic1, tourn0, _ = sorted(specs, key=lambda s: (s.scenario, s.seed))
    basic0.out.mkdir(parents=True)
    rows = [{"generation": g, "wall_time": 2.0} for g in range(4)]
    (basic0.out / "log.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    togo = dict(zip([id(s) for s in specs], time_to_go(specs)))
    assert togo[id(basic0)] == (pytest.approx(6 * 2.0), "measured")
    assert togo[id(basic1)] == (pytest.approx(10 * 2.0), "scenario")
    assert togo[id(tourn0)] == (pytest.approx(tourn0.cost), "estimate")
    rows += [{"generation": g, "wall_time": 2.0} for g in range(4, 10)]
    (basic0.out / "log.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    (basic0.out / "final_population.json").write_text("{}")
    assert time_to_go([basic0])[0] == (0.0, "complete")


def _fake_run(scenario, seed, voxels, target, best=1.0, repeats=0):
    """A RunData whose best robot has ``voxels[g]`` voxels at generation g and fitness
    ``best + g``; each generation >= 1 has 10 new robots of which ``repeats`` were seen before."""
    from pathlib import Path

    from evolvers.study.data import RunData

    rows = [{"generation": g, "top_n_voxels": v, "norm_final_dist_best": best + g,
             "new_individuals": 10, "repeated_phenotypes": repeats}
            for g, v in enumerate(voxels)]  # fmt: skip
    exp = {"name": scenario, "objectives": [{"name": "norm_final_dist"}]}
    cfg = {"seed": seed, "generations": target, "experiment": exp}
    return RunData(scenario, Path(f"{scenario}/seed-{seed}"), cfg, rows, None,
                   len(voxels) - 1 >= target)  # fmt: skip


def test_fixed_generation_claim_counts_unfinished_runs_past_it():
    # T2-voxels reads T1 at T2's last generation (3 here): T1 seeds that passed it count,
    # complete or not; a seed short of it is left out and named
    from evolvers.study.claims import claims

    t2 = [_fake_run("materials-t2", s, [200, 150, 100, 50 + s], 3) for s in range(4)]
    t1 = [
        _fake_run("materials-t1", 0, [216] * 11, 10),  # complete
        _fake_run("materials-t1", 1, [210] * 6, 10),  # unfinished, past generation 3
        _fake_run("materials-t1", 2, [1] * 3, 10),  # unfinished, at generation 2
    ]
    by_id = {c.id: c for c in claims({"materials-t2": t2, "materials-t1": t1})}
    c = by_id["T2-voxels"]
    assert c.data["t1"] == [216.0, 210.0] and c.data["t2"] == [50.0, 51.0, 52.0, 53.0]
    assert "at generation 3:" in c.measured and "n=2" in c.measured
    assert "Unfinished T1 seed 1 past generation 3 counted" in c.why
    assert "T1 seed 2 left out (not yet at generation 3)" in c.why
    assert "Unfinished seeds left out" not in c.why
    # the claims that read T1's last generation still use its complete run only
    assert "Unfinished seeds left out: materials-t1 1, 2" in by_id["T1-final"].why


def test_t1_final_names_the_flying_winners():
    # the committed study data: materials-t1 seed 0's winner has muscles at the density floor and
    # flies (thousands of body lengths); the claim says so and which seeds
    from pathlib import Path

    from evolvers.study.claims import LIGHT_MUSCLE, claims, winner_of

    root = Path(__file__).resolve().parents[3] / "benchmarks" / "data" / "study" / "runs"
    runs = load_runs(root / "materials-t1")
    seed0 = next(r for r in runs["materials-t1"] if r.seed == 0)
    assert seed0.complete and winner_of(seed0).muscle_density < LIGHT_MUSCLE
    c = next(c for c in claims(runs) if c.id == "T1-final")
    assert 0 in c.data["flying_seeds"]
    # improving only by flying is not the report's "increasingly better" robots
    alone = {c.id: c for c in claims({"materials-t1": [seed0]})}["T1-improves"]
    assert alone.verdict == "does not hold" and alone.data["improving_walkers"] == []
    assert "1 of the 1 improving seeds improve only by flying" in alone.why
    assert "winners fly: muscles lighter than 1e+05 kg/m^3" in c.why
    # runs without a recorded winner name none
    t1 = [_fake_run("materials-t1", 0, [216] * 11, 10)]
    fake = next(c for c in claims({"materials-t1": t1}) if c.id == "T1-final")
    assert fake.data["flying_seeds"] == []


def test_novelty_claims_compare_with_the_reports_baselines():
    # novelty-fitness: the report compares novelty with "the other two evolution techniques"
    # (materials and controller evolution); basic evolution with the same generations is context
    from evolvers.study.claims import claims

    def runs(name, best, repeats=0, n=5):
        return [_fake_run(name, k, [100] * 4, 3, best=best + k, repeats=repeats) for k in range(n)]

    data = {
        "novelty": runs("novelty", 3.0, repeats=6),
        "novelty-archive": runs("novelty-archive", 3.0, repeats=3),
        "basic-200": runs("basic-200", 3.5, repeats=4),  # as good as novelty
        "materials-t2": runs("materials-t2", 30.0),
        "controller-tournament": runs("controller-tournament", 60.0),
    }
    by_id = {c.id: c for c in claims(data)}
    c = by_id["novelty-fitness"]
    assert c.verdict == "holds", c.why
    assert "materials evolution (T1, T2) 35 [34, 36], n=5" in c.measured
    assert "controller evolution (tournament, Pareto) 65 [64, 66], n=5" in c.measured
    assert "(not the report's comparison) basic evolution" in c.measured
    # novelty at most half as good as one technique but not the other: partly
    data["materials-t2"] = runs("materials-t2", 5.0)
    assert {c.id: c for c in claims(data)}["novelty-fitness"].verdict == "partly"
    # the loop: novelty without archive repeats more than fitness-based and than with the archive
    loop = by_id["novelty-loop"]
    assert loop.verdict == "holds"
    assert loop.data["novelty"] == [0.6] * 5 and loop.data["basic-200"] == [0.4] * 5
    data["basic-200"] = runs("basic-200", 3.5, repeats=8)  # fitness-based repeats more
    assert {c.id: c for c in claims(data)}["novelty-loop"].verdict == "partly"
    # logs without the repeat columns: nothing to compare, so "not run" (not "partly")
    for name in ("novelty", "novelty-archive", "basic-200"):
        for r in data[name]:
            for row in r.rows:
                del row["new_individuals"], row["repeated_phenotypes"]
    assert {c.id: c for c in claims(data)}["novelty-loop"].verdict == "not run"


def test_obstacle_claims_wait_for_seeds_that_have_not_decided():
    # a seed that has neither crossed nor run 80 generations says nothing yet about crossing
    # "in 80 generations": it is left out (named), not counted as a failure
    from evolvers.study.claims import claims

    def run(seed, generations, crossed_at=None):
        r = _fake_run("obstacles", seed, [100] * (generations + 1), 120)
        for row in r.rows:
            row["crossed"] = int(crossed_at is not None and row["generation"] >= crossed_at)
        return r

    data = {"obstacles": [run(0, 100), run(1, 30), run(2, 25, crossed_at=20)]}
    c = {c.id: c for c in claims(data)}["obstacles-final"]
    assert c.verdict == "holds" and math.isnan(c.data["crossing"][0])
    assert c.data["crossing"][1:] == [20.0]
    assert "by generation 80 in 1/2 seeds" in c.measured
    assert "Left out: seed 1, not yet crossed nor at generation 80" in c.why
    data = {"obstacles": [run(1, 30)]}
    assert {c.id: c for c in claims(data)}["obstacles-final"].verdict == "not run"
    # a complete run shorter than 80 generations (a short study) is read, marked provisional
    short = _fake_run("obstacles", 0, [100] * 11, 10)
    for row in short.rows:
        row["crossed"] = 0
    c = {c.id: c for c in claims({"obstacles": [short]})}["obstacles-final"]
    assert c.verdict == "does not hold" and "Provisional: obstacles reached generation 10" in c.why
