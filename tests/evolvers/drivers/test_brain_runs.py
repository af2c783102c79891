"""Bodies and brains on every driver: runs carry brains, resume bit-identically; CMA-ES on a fixed body."""

import json

import numpy as np
import pytest
from brain_helpers import brainy, small_body

from evolvers.drivers.deap_runner import DeapRun
from evolvers.drivers.pymoo_runner import PymooRun
from evolvers.drivers.runner import EvolutionRun, population_summary
from evolvers.recording.recorder import RunInterrupted
from softgym.exceptions import InvalidParameterError


def _rows(run):
    return [
        {k: v for k, v in r.items() if "wall" not in k and "seconds" not in k} for r in run.rows
    ]


def _make(kind):
    if kind == "qd":
        pytest.importorskip("ribs")
        from evolvers.drivers.qd import QDConfig, QDRun

        return lambda exp, out, **kw: QDRun(exp, out, config=QDConfig(cells=(4,)), **kw)
    if kind.startswith("pymoo"):
        algorithm = kind.split("-", 1)[1]
        return lambda exp, out, **kw: PymooRun(exp, out, algorithm=algorithm, **kw)
    return {"native": EvolutionRun, "deap": DeapRun}[kind]


def _crash(run, row):
    if row["generation"] == 1:
        raise KeyboardInterrupt


@pytest.mark.parametrize(
    "kind, controller, body",
    [
        ("native", "distributed", False), ("native", "central", False), ("native", "distributed", True),
        ("deap", "distributed", False), ("pymoo-nsga2", "distributed", False),
        ("pymoo-ga", "central", False), ("pymoo-cmaes", "distributed", True),
        ("qd", "distributed", False),
    ],
)  # fmt: skip
def test_network_runs_carry_brains_and_resume_bit_identically(tmp_path, kind, controller, body):
    exp = brainy(controller, body=body)
    make = _make(kind)
    kw = {"seed": 3, "generations": 2, "figures": False, "gif": False, "progress": False}
    ref = make(exp, tmp_path / "ref", **kw)
    ref_pop = ref.run()
    spec = exp.brain_spec()
    assert ref_pop and all(ind.brain is not None and ind.brain_spec == spec for ind in ref_pop)
    assert all(np.abs(ind.brain).max() <= 3.0 for ind in ref_pop)
    assert len({ind.phenotype_key(exp.shape) for ind in ref_pop}) > 1
    if body:
        assert all(np.array_equal(ind.grid(exp.shape), small_body().grid) for ind in ref_pop)
    best = json.loads((tmp_path / "ref" / "best_design.json").read_text())
    assert best["brain"]["kind"] == controller  # the best design carries its brain

    cut = make(exp, tmp_path / "cut", on_generation=_crash, **kw)
    with pytest.raises(RunInterrupted):
        cut.run()
    again = make(exp, tmp_path / "cut", **kw)
    pop = again.run(resume=True)
    assert population_summary(pop) == population_summary(ref_pop)
    assert _rows(again) == _rows(ref)
    assert [h["individual"] for h in again.hall_of_fame] == [
        h["individual"] for h in ref.hall_of_fame
    ]


def test_sinusoid_runs_are_unchanged_by_the_brain_fields(tmp_path):
    exp = brainy("sinusoid")  # the default controller, spelled out
    a = EvolutionRun(
        exp, tmp_path / "a", seed=2, generations=1, figures=False, progress=False
    ).run()
    assert all(ind.brain is None and "brain" not in ind.to_dict() for ind in a)
    assert exp.to_dict()["controller"] == "sinusoid" and exp.brain_spec() is None


def test_cmaes_on_a_fixed_body_needs_a_brain_and_refuses_material_genes(tmp_path):
    with pytest.raises(InvalidParameterError, match="network"):
        PymooRun(brainy("sinusoid", body=True), tmp_path / "y", algorithm="cmaes")
    with pytest.raises(InvalidParameterError, match="material genes"):
        PymooRun(brainy("sinusoid", name="materials"), tmp_path / "x", algorithm="cmaes")
    assert not (tmp_path / "x").exists() and not (tmp_path / "y").exists()


def test_cmaes_run_extended_by_resume_matches_an_uninterrupted_one(tmp_path):
    # cma draws from numpy's global generator, seeded once (seed 0 would mean "the clock"):
    # the driver keeps that generator apart, so a replay without simulations draws the same
    exp = brainy(body=True)
    kw = {"seed": 0, "figures": False, "gif": False, "progress": False, "algorithm": "cmaes"}
    ref = PymooRun(exp, tmp_path / "ref", generations=3, **kw).run()
    PymooRun(exp, tmp_path / "ext", generations=1, **kw).run()
    np.random.rand(7)  # noqa: NPY002 - another user of numpy's global generator
    ext = PymooRun(exp, tmp_path / "ext", generations=3, **kw).run(resume=True)
    assert population_summary(ext) == population_summary(ref)
