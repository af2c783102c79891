"""Ctrl-C during a run: RunInterrupted names the checkpoint and the resume call; resume is exact."""

import logging

import pytest
from evolver_helpers import tiny

from evolvers.drivers.deap_runner import DeapRun
from evolvers.drivers.pymoo_runner import PymooRun
from evolvers.drivers.runner import EvolutionRun, population_summary
from evolvers.recording.recorder import RunInterrupted
from softgym.exceptions import CheckpointError


def _ctrl_c_after(gen):
    def cb(run, row):
        if row["generation"] == gen:
            raise KeyboardInterrupt

    return cb


@pytest.mark.parametrize("Run", [EvolutionRun, DeapRun, PymooRun])
def test_ctrl_c_names_the_checkpoint_and_resumes_exactly(tmp_path, Run, caplog):
    exp = tiny("controller-pareto")
    ref = Run(exp, tmp_path / "ref", seed=3, generations=2, figures=False, progress=False).run()
    run = Run(exp, tmp_path / "r", seed=3, generations=2, figures=False, progress=False,
              on_generation=_ctrl_c_after(1))  # fmt: skip
    with caplog.at_level(logging.INFO, logger="evolvers"), pytest.raises(RunInterrupted) as info:
        run.run()
    exc = info.value
    assert isinstance(exc, KeyboardInterrupt)
    assert exc.generation == 1 and exc.checkpoint.name == "ckpt-000001.json"
    assert "resume" in str(exc) and "run(resume=True)" in exc.resume
    assert "interrupted" in caplog.text
    again = Run(exp, tmp_path / "r", seed=3, generations=2, figures=False, progress=False)
    assert population_summary(again.run(resume=True)) == population_summary(ref)


def test_progress_bar_and_log_lines(tmp_path, caplog, capsys):
    exp = tiny()
    with caplog.at_level(logging.INFO, logger="evolvers"):
        EvolutionRun(exp, tmp_path / "r", seed=0, generations=1, figures=False).run()
    assert caplog.text.count("generation") >= 2  # one line per generation
    err = capsys.readouterr().err
    assert "controller-tournament [native]" in err and "2/2" in err  # the tqdm bar
    EvolutionRun(exp, tmp_path / "q", seed=0, generations=1, figures=False, progress=False).run()
    assert "[native]" not in capsys.readouterr().err


def test_one_progress_bar_at_a_time(tmp_path, capsys, monkeypatch):
    # a run shows its bar over the generations and its batches none of their own
    # (issue 30: one bar at a time), even a long batch on a terminal; a quiet run none
    import importlib

    ev = importlib.import_module("softgym.evaluate")  # the module (the package exports the function)
    monkeypatch.setattr(ev, "PROGRESS_AFTER_S", 0.0)  # every batch counts as long
    monkeypatch.setattr(ev.sys.stderr, "isatty", lambda: True, raising=False)
    EvolutionRun(tiny(), tmp_path / "loud", seed=0, generations=0, figures=False).run()
    err = capsys.readouterr().err
    assert "[native]" in err and "simulating" not in err
    EvolutionRun(tiny(), tmp_path / "q", seed=0, generations=0, figures=False, progress=False).run()
    assert capsys.readouterr().err == ""
    # outside a run, a long batch on a terminal shows its own bar, which it removes
    ev.evaluate([_walker()], seconds=0.05)
    assert "simulating 1 robots" in capsys.readouterr().err


def _walker():
    from softgym.design import default_walker

    return default_walker()


def test_resume_mismatch_names_the_one_setting(tmp_path):
    EvolutionRun(tiny(), tmp_path / "r", seed=0, generations=0, figures=False,
                 progress=False).run()  # fmt: skip
    other = EvolutionRun(tiny(pop_size=5), tmp_path / "r", seed=0, generations=0, figures=False,
                         progress=False)  # fmt: skip
    with pytest.raises(CheckpointError) as info:
        other.run(resume=True)
    msg = str(info.value)
    assert "experiment.pop_size: 4 (recorded) != 5" in msg
    assert len(msg) < 250  # no experiment dicts


def test_vxa_next_to_every_best_design(tmp_path):
    from softgym.design import RobotDesign
    from softgym.design.vxa import load_vxa

    run = EvolutionRun(tiny(), tmp_path / "r", seed=0, generations=1, figures=False,
                       progress=False)  # fmt: skip
    run.run()
    out = tmp_path / "r"
    best = RobotDesign.load(out / "best_design.json")
    assert (load_vxa(out / "best_design.vxa").grid == best.grid).all()
    jsons = sorted((out / "best_designs").glob("*.json"))
    assert jsons and all(p.with_suffix(".vxa").is_file() for p in jsons)
