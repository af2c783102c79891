import sys

import numpy as np
import pytest
from evolver_helpers import tiny

from evolvers.drivers.runner import EvolutionRun, population_summary
from evolvers.evaluation.distributed import DaskBatchFn, dask_client, split_batches
from evolvers.evaluation.evaluator import local_batch_fn
from evolvers.operators.genome import Individual

pytest.importorskip("distributed")


def test_split_batches_covers_everything():
    assert split_batches(31, 2) == [(0, 16), (16, 31)]
    assert split_batches(3, 8) == [(0, 1), (1, 2), (2, 3)]


def test_local_cluster_with_two_workers_equals_local(tmp_path):
    exp = tiny("controller-pareto")
    rng = np.random.default_rng(0)
    designs = [Individual.random(rng, i, exp.shape).design(exp.shape).to_dict() for i in range(5)]
    local = local_batch_fn(designs, exp.make_task())
    with dask_client("local", n_workers=2, processes=False) as client:
        fn = DaskBatchFn(client)
        remote = fn(designs, exp.make_task())
        assert len(client.nthreads()) == 2
        for key in ("norm_final_dist", "max_xy_dist", "l_coefficient", "n_muscle", "diverged"):
            np.testing.assert_array_equal(remote[key], local[key])
        for a, b in zip(remote["traces"], local["traces"]):
            np.testing.assert_array_equal(a, b)
        run = EvolutionRun(
            exp, tmp_path / "dask", seed=7, generations=1, figures=False, batch_fn=fn
        )
        pop_dask = run.run()
    pop_local = EvolutionRun(exp, tmp_path / "local", seed=7, generations=1, figures=False).run()
    assert population_summary(pop_dask) == population_summary(pop_local)


_MARKER_ENV = "SOFTGYM_TEST_KILL_MARKER"


def _evaluate_or_die_once(payload):
    # the first batch to run kills its worker process; the retry computes it
    import os

    from softgym.evaluate import evaluate_payload

    marker = os.environ[_MARKER_ENV]
    if not os.path.exists(marker):
        with open(marker, "w") as fh:
            fh.write(str(os.getpid()))
        os._exit(1)
    return evaluate_payload(payload)


def test_a_killed_workers_batch_is_recomputed(tmp_path, monkeypatch):
    # worker processes (spawned with this environment); one dies mid-batch
    import cloudpickle

    exp = tiny("controller-pareto")
    rng = np.random.default_rng(1)
    designs = [Individual.random(rng, i, exp.shape).design(exp.shape).to_dict() for i in range(4)]
    local = local_batch_fn(designs, exp.make_task())
    marker = tmp_path / "killed"
    monkeypatch.setenv(_MARKER_ENV, str(marker))
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    try:
        with dask_client("local", n_workers=2, processes=True) as client:
            remote = DaskBatchFn(client, payload_fn=_evaluate_or_die_once)(designs, exp.make_task())
    finally:
        cloudpickle.unregister_pickle_by_value(sys.modules[__name__])
    assert marker.exists()  # a worker really died
    for key in ("norm_final_dist", "max_xy_dist", "l_coefficient", "diverged"):
        np.testing.assert_array_equal(remote[key], local[key])
