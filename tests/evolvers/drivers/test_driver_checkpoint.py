"""The Driver writes and restores the evaluator's part of every checkpoint (its simulation
count and phenotype cache), once, for every backend."""

import json

import pytest
from evolver_helpers import tiny
from poet_helpers import fake_batch_fn

from evolvers.drivers.deap_runner import DeapRun
from evolvers.drivers.poet import PoetRun, poet_experiment
from evolvers.drivers.pymoo_runner import PymooRun
from evolvers.drivers.random_search import RandomSearchRun
from evolvers.drivers.runner import EvolutionRun
from softgym.io import json_sha256, latest_checkpoint, load_checkpoint

CACHE_KEYS = {"cache_keys", "cache_metrics", "cache_values", "cache_traces", "cache_trace_len"}


def _make(backend, out, gens):
    kw = {"seed": 1, "figures": False}
    if backend == "poet":
        return PoetRun(poet_experiment(pop_size=4, seconds=1.5), out, iterations=gens,
                       batch_fn=fake_batch_fn, **kw)  # fmt: skip
    cls = {"native": EvolutionRun, "deap": DeapRun, "pymoo": PymooRun,
           "random": RandomSearchRun}[backend]  # fmt: skip
    return cls(tiny(), out, generations=gens, gif=False, **kw)


@pytest.mark.parametrize("backend", ["native", "deap", "pymoo", "random", "poet"])
def test_every_checkpoint_holds_the_evaluators_count_and_cache_written_by_the_driver(tmp_path, backend):
    run = _make(backend, tmp_path / "r", 1)
    run.run()
    state, arrays = load_checkpoint(latest_checkpoint(tmp_path / "r" / "checkpoints"))
    assert state["evaluations_counter"] == run.evaluator.n_evaluations > 0
    assert "n_simulated" not in state  # one key for every driver
    assert CACHE_KEYS <= set(arrays)
    assert len(arrays["cache_keys"]) == len(run.evaluator.cache) > 0
    resumed = _make(backend, tmp_path / "r", 2)
    assert resumed.resume()
    assert resumed.evaluator.n_evaluations == run.evaluator.n_evaluations
    assert len(resumed.evaluator.cache) == len(run.evaluator.cache)
    assert all(str(k) in resumed.evaluator.cache for k in arrays["cache_keys"])


def test_a_poet_checkpoint_of_before_keeps_its_count(tmp_path):
    # POET's checkpoints once counted simulations under "n_simulated"
    out = tmp_path / "p"
    run = _make("poet", out, 1)
    run.run()
    path = latest_checkpoint(out / "checkpoints")
    doc = json.loads(path.read_text())
    doc["state"]["n_simulated"] = doc["state"].pop("evaluations_counter")
    doc["sha256"] = json_sha256({k: v for k, v in doc.items() if k != "sha256"})
    path.write_text(json.dumps(doc))
    resumed = _make("poet", out, 2)
    assert resumed.resume()
    assert resumed.evaluator.n_evaluations == run.evaluator.n_evaluations
    assert len(resumed.evaluator.cache) == len(run.evaluator.cache)
