import numpy as np
import pytest
from evolver_helpers import tiny

import softgym
from evolvers.evaluation.evaluator import STORED_METRICS, Evaluator, PhenotypeCache
from evolvers.operators.genome import Individual
from softgym.design import default_walker
from softgym.evaluate import Task
from softgym.exceptions import CheckpointError


def test_softgym_evaluate_returns_metrics_for_a_batch():
    d = default_walker()
    m = softgym.evaluate([d, d], task="flat", seconds=1.5)
    for key in (
        "norm_final_dist",
        "max_xy_dist",
        "l_coefficient",
        "diverged",
        "n_voxels",
        "n_muscle",
    ):
        assert m[key].shape == (2,)
    assert m["norm_final_dist"][0] == m["norm_final_dist"][1]  # batch-independent, bit for bit
    assert m["n_voxels"][0] == 216 and m["n_muscle"][0] == 180
    alone = softgym.evaluate(d, task=Task("fence", seconds=1.5), traces=True)
    assert alone["traces"][0].shape[1] == 4


def test_identical_phenotypes_are_simulated_once_and_cache_matches_fresh():
    exp = tiny()
    rng = np.random.default_rng(0)
    a = Individual.random(rng, 0, exp.shape)
    b = a.child(1)  # same phenotype
    c = Individual.random(rng, 2, exp.shape)
    ev = Evaluator(exp)
    st = ev.evaluate([a, b, c])
    assert st.n_simulated == 2 and st.n_cached == 1
    assert a.objectives == b.objectives
    st2 = ev.evaluate([a.child(3)])
    assert st2.n_simulated == 0 and st2.n_cached == 1
    fresh = Evaluator(exp)
    c2 = Individual.from_dict(c.to_dict())
    fresh.evaluate([c2])  # alone, in a new Simulation
    assert c2.objectives == c.objectives
    np.testing.assert_array_equal(c2.trace, c.trace)
    back = PhenotypeCache.from_arrays(ev.cache.to_arrays())
    assert (
        len(back) == 2
        and back.get(a.phenotype_key(exp.shape))[0] == ev.cache.get(a.phenotype_key(exp.shape))[0]
    )


def test_invalid_bodies_are_not_simulated():
    exp = tiny()
    ind = Individual.random(np.random.default_rng(0), 0, exp.shape)
    ind._grid = np.zeros(exp.shape, dtype=np.int8)
    ind._grid[0, 0, 0] = 3
    ind._grid_shape = exp.shape
    st = Evaluator(exp).evaluate([ind])
    assert st.n_invalid == 1 and st.n_simulated == 0
    assert ind.objectives["norm_final_dist"] == pytest.approx(-1e7)


def test_evaluate_shows_a_progress_bar_on_request_and_results_do_not_change(capsys):
    import numpy as np

    import softgym
    from softgym.design import default_walker

    quiet = softgym.evaluate([default_walker()], seconds=0.3, progress=False)
    shown = softgym.evaluate([default_walker()], seconds=0.3, progress=True)
    assert "simulating 1 robots" in capsys.readouterr().err
    for k in ("norm_final_dist", "max_xy_dist", "l_coefficient"):
        np.testing.assert_array_equal(quiet[k], shown[k])


def _cache_with_one_entry() -> tuple[PhenotypeCache, dict[str, float]]:
    obj = {
        "norm_final_dist": 3.5, "max_xy_dist": 4.0, "l_coefficient": 7.0, "score": 3.5,
        "diverged": 0.0, "n_voxels": 120.0, "n_muscle": 60.0, "n_old_materials": 2.0,
        "n_bone": 5.0, "n_tissue": 55.0,
    }  # fmt: skip
    assert set(obj) == set(STORED_METRICS)
    cache = PhenotypeCache()
    cache.put("k", obj, np.arange(8.0).reshape(2, 4))
    return cache, obj


def test_cache_columns_are_read_back_by_name_not_position():
    cache, obj = _cache_with_one_entry()
    arrays = cache.to_arrays()
    assert PhenotypeCache.from_arrays(arrays).get("k")[0] == obj
    # a checkpoint whose columns come in another order (e.g. written by a version
    # with a different metric list) still maps every value to its own metric
    order = np.arange(len(STORED_METRICS))[::-1]
    shuffled = dict(arrays)
    shuffled["cache_metrics"] = arrays["cache_metrics"][order]
    shuffled["cache_values"] = arrays["cache_values"][:, order]
    assert PhenotypeCache.from_arrays(shuffled).get("k")[0] == obj


def test_cache_from_a_checkpoint_without_column_names_uses_the_old_layout():
    # checkpoints written before the names were stored had no "score" column:
    # nine columns, diverged right after the three fitness measures
    cache, obj = _cache_with_one_entry()
    arrays = cache.to_arrays()
    del arrays["cache_metrics"]
    arrays["cache_values"] = np.array([[3.5, 4.0, 7.0, 0.0, 120.0, 60.0, 2.0, 5.0, 55.0]])
    back = PhenotypeCache.from_arrays(arrays).get("k")[0]
    assert back == {k: v for k, v in obj.items() if k != "score"}


def test_cache_with_columns_that_do_not_match_their_names_is_a_checkpoint_error():
    cache, _ = _cache_with_one_entry()
    arrays = cache.to_arrays()
    arrays["cache_values"] = arrays["cache_values"][:, :-1]
    with pytest.raises(CheckpointError, match="cache_values"):
        PhenotypeCache.from_arrays(arrays)


def test_seed_centre_of_mass_scores_obstacle_runs_as_the_seed_did():
    # the seed's centre of mass counts the fence's 1-kg wall voxels: MaxXYDist shrinks by
    # m_robot / (m_robot + m_walls), the L coefficient by its square (the time of the maximum
    # stays within a trace sample); the trace stays the robot's own
    from evolvers.evaluation.experiments import Experiment

    exp = tiny("obstacles-attempt2", shape=(6, 6, 6), seconds=2.0)
    seed = exp.replace(seed_centre_of_mass=True)
    assert Experiment.from_dict(seed.to_dict()) == seed and seed.make_task().seed_centre_of_mass
    assert Experiment.from_dict({k: v for k, v in exp.to_dict().items()
                                 if k != "seed_centre_of_mass"}) == exp  # fmt: skip
    ind = Individual.from_dict(
        Individual.random(np.random.default_rng(3), 0, exp.shape, rules=exp.rules).to_dict()
    )
    twin = Individual.from_dict(ind.to_dict())
    Evaluator(exp).evaluate([ind])
    Evaluator(seed).evaluate([twin])
    np.testing.assert_array_equal(ind.trace, twin.trace)
    walls = sum(
        float(np.prod(np.subtract(b.hi, b.lo)))
        for b in exp.make_task().terrain_for(exp.shape).boxes
    )
    m = ind.objectives["n_voxels"]  # 1 kg voxels (density 1e6 kg/m^3, 1 cm)
    assert walls == 44 and ind.objectives["max_xy_dist"] > 1e-3
    f = m / (m + walls)
    assert twin.objectives["max_xy_dist"] == pytest.approx(
        f * ind.objectives["max_xy_dist"], rel=1e-6
    )


def test_one_evaluator_keys_results_by_task_and_phenotype():
    # the ordinary drivers' task (key None) and any other task (POET's terrains) share one
    # cache: a phenotype is simulated once per task, batched per task in one jobs_fn call
    from poet_helpers import fake_batch_fn

    exp = tiny()
    calls = []

    def jobs_fn(jobs):
        calls.append([(len(designs), task.name) for designs, task in jobs])
        return [fake_batch_fn(designs, task) for designs, task in jobs]

    ev = Evaluator(exp, jobs_fn=jobs_fn)
    rng = np.random.default_rng(0)
    a = Individual.random(rng, 0, exp.shape)
    c = Individual.random(rng, 2, exp.shape)
    wall = ev.task.replace(terrain="wall")
    res, st = ev.evaluate_jobs(
        [(None, ev.task, [a, c]), ("wall", wall, [a, c, c.child(3)])], assign=False
    )
    assert calls == [[(2, ev.task.name), (2, "wall")]]
    assert (st.n_individuals, st.n_simulated, st.n_cached) == (5, 4, 1)
    assert not a.objectives and res[1][2] == res[1][1]  # assign=False only reads
    shape = exp.shape
    assert PhenotypeCache.key(a.phenotype_key(shape)) == a.phenotype_key(shape)
    for key in (None, "wall"):
        assert PhenotypeCache.key(a.phenotype_key(shape), key) in ev.cache
    assert len(PhenotypeCache.key(a.phenotype_key(shape), "wall")) == 64  # the stored <U64 keys
    st = ev.evaluate([a])  # the run's own task: cached by phenotype alone
    assert st.n_cached == 1 and st.n_simulated == 0 and a.objectives == res[0][0]
    _, st = ev.evaluate_jobs([("wall", wall, [c.child(4)])])
    assert st.n_cached == 1 and len(calls) == 1 and ev.n_evaluations == 4


def test_a_task_file_means_the_same_run_to_evolution_and_to_softgym_evaluate(tmp_path):
    # a task JSON file's seconds, trace_interval and sim were dropped by
    # `softgym evolve --task t.json` (only its world was kept) while softgym.evaluate used
    # them: one file, one run; a typed --seconds still wins
    import json

    from evolvers.evaluation.experiments import get_experiment, task_file_settings
    from softgym.tasks import get_task

    path = tmp_path / "t.json"
    task = get_task("ice").replace(seconds=2.5, trace_interval=0.25, sim={"friction": 0.05})
    path.write_text(json.dumps(task.to_dict()))
    assert task_file_settings(path) == {"seconds": 2.5, "trace_interval": 0.25,
                                        "sim": {"friction": 0.05}}  # fmt: skip
    assert task_file_settings("ice") == {} and task_file_settings(tmp_path / "none.json") == {}
    exp = get_experiment("controller-tournament", task=str(path))
    assert (exp.seconds, exp.trace_interval, dict(exp.sim)) == (2.5, 0.25, {"friction": 0.05})
    assert get_experiment("controller-tournament", task=str(path), seconds=2.0).seconds == 2.0
    direct = softgym.evaluate([default_walker()], task=str(path))
    run = softgym.evaluate([default_walker()], task=exp.make_task())
    assert run["norm_final_dist"][0] == direct["norm_final_dist"][0]
