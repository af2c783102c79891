import numpy as np
import pytest
from evolver_helpers import tiny

import softgym
from evolvers.evaluation import Evaluator, PhenotypeCache
from evolvers.genome import Individual
from softgym.design import default_walker
from softgym.evaluate import Task


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
