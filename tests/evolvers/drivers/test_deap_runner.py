import random

import numpy as np
from deap import tools
from evolver_helpers import tiny

from evolvers.drivers.deap_runner import DeapRun, make_toolbox
from evolvers.drivers.runner import population_summary


def test_toolbox_is_built_the_deap_way_and_map_is_batched():
    exp = tiny("controller-pareto")
    tb = make_toolbox(exp, rng=3)
    for name in (
        "individual",
        "population",
        "evaluate",
        "map",
        "clone",
        "mutate",
        "mate",
        "selPareto",
        "selFitnessTournament",
        "selNovelty",
        "selNSGA2",
        "selTournament",
        "select",
    ):
        assert hasattr(tb, name), name
    assert tb.selNSGA2.func is tools.selNSGA2
    pop = tb.population(n=4)
    fits = tb.map(tb.evaluate, pop)
    assert tb.evaluate.func.last_stats.n_individuals == 4  # one batched call for the whole list
    for ind, fit in zip(pop, fits):
        ind.fitness.values = fit
    assert all(ind.fitness.valid and len(ind.fitness.values) == 2 for ind in pop)
    assert len(tb.selNSGA2(pop, 2)) == 2 and len(tb.select(pop, 2)) == 2
    assert len(tb.selTournament(pop, 3)) == 3
    hof = tools.HallOfFame(2)
    hof.update(pop)
    assert len(hof) == 2


def test_deap_run_resumes_exactly_and_seeds_python_random(tmp_path):
    exp = tiny("controller-tournament")
    r = DeapRun(exp, tmp_path / "a", seed=4, generations=2, figures=False)
    ref = r.run()
    assert len(r.logbook) == 3 and len(r.hof) > 0
    x1 = random.random()

    class Crash(Exception):
        pass

    def crash(run, row):
        if row["generation"] == 1:
            raise Crash

    b = DeapRun(exp, tmp_path / "b", seed=4, generations=2, figures=False, on_generation=crash)
    try:
        b.run()
    except Crash:
        pass
    resumed = DeapRun(exp, tmp_path / "b", seed=4, generations=2, figures=False).run(resume=True)
    assert population_summary(resumed) == population_summary(ref)
    assert random.random() == x1  # Python's random continued from the checkpointed state
    assert np.isfinite([ind.fitness.values[0] for ind in resumed]).all()
