import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from softgym_cli import main

TINY = ["--pop", "4", "--seconds", "1.5", "--shape", "4", "4", "4", "--quiet"]


def test_simulate_still_works(tmp_path):
    assert main(["simulate", "--seconds", "0.5", "--out", str(tmp_path)]) == 0
    assert (tmp_path / "trajectory.png").exists()


def test_evolve_writes_the_run_folder_and_replay_reproduces_it(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["evolve", "--generations", "1", "--out", str(out), "--no-gif", *TINY]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["experiment"] == "controller-tournament" and summary["generations"] == 1
    for name in (
        "config.json",
        "log.csv",
        "log.jsonl",
        "best_design.json",
        "best_designs.json",
        "figures/fitness_trend.png",
        "figures/best_robot.png",
        "figures/best_trajectory.png",
    ):
        assert (out / name).exists(), name
    assert main(["replay", str(out), "--no-gif"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["metrics"]["norm_final_dist"] == rep["recorded"]["norm_final_dist"]
    assert main(["compare", str(out), str(out), "--out", str(tmp_path / "cmp.png")]) == 0
    assert (tmp_path / "cmp.png").exists()
    capsys.readouterr()
    assert main(["experiments"]) == 0
    assert "obstacles-attempt2" in capsys.readouterr().out
    assert main(["evolve", "--experiment", "nope", "--out", str(tmp_path / "x"), *TINY]) == 2


def _final(out: Path):
    return json.loads((out / "final_population.json").read_text())


def test_kill_9_then_resume_equals_uninterrupted(tmp_path):
    args = [
        "evolve",
        "--experiment",
        "controller-pareto",
        "--generations",
        "5",
        "--seed",
        "11",
        "--no-figures",
        *TINY,
    ]
    killed = tmp_path / "killed"
    env = {**os.environ, "SOFTGYM_NUM_THREADS": "1"}
    proc = subprocess.Popen(
        [sys.executable, "-m", "softgym_cli", *args, "--out", str(killed)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env,
    )
    ckpt = killed / "checkpoints" / "ckpt-000001.json"
    deadline = time.time() + 120
    while not ckpt.exists() and proc.poll() is None and time.time() < deadline:
        time.sleep(0.005)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    if (killed / "final_population.json").exists():
        pytest.skip("the run finished before it could be killed")
    assert main([*args, "--out", str(killed), "--resume"]) == 0
    ref = tmp_path / "ref"
    assert main([*args, "--out", str(ref)]) == 0
    assert _final(killed) == _final(ref)
    rows = [json.loads(x) for x in (killed / "log.jsonl").read_text().splitlines()]
    assert [r["generation"] for r in rows] == list(range(6))


def test_evolve_on_stairs_and_on_a_terrain_file(tmp_path, capsys):
    from softgym.terrain import Terrain

    path = tmp_path / "boxes.json"
    path.write_text(Terrain.from_boxes([((7, -3, 0), (8, 9, 1))], name="east_wall").to_json())
    for task in ("stairs", str(path)):
        out = tmp_path / f"run-{len(task)}"
        args = ["evolve", "--generations", "0", "--task", task, "--no-figures", "--out", str(out)]
        assert main([*args, *TINY]) == 0
        cfg = json.loads((out / "config.json").read_text())
        world = cfg["experiment"]["task"]
        assert world == "stairs" if task == "stairs" else world["name"] == "east_wall"
    capsys.readouterr()
    assert main(["evolve", "--task", "lava", "--out", str(tmp_path / "x"), *TINY]) == 2
    assert "unknown task 'lava'" in capsys.readouterr().err


def test_dask_without_the_extra_names_it(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # as if Dask were not installed
    from evolvers.evaluation.distributed import MissingExtraError, require_distributed

    with pytest.raises(MissingExtraError, match=r"softgym\[distributed\]") as err:
        require_distributed()
    assert isinstance(err.value, ImportError)
    args = ["evolve", "--dask", "local", "--generations", "0", "--out", str(tmp_path / "d")]
    assert main([*args, *TINY]) == 2
    assert 'pip install "softgym[distributed]"' in capsys.readouterr().err


def test_a_task_string_is_read_once_per_command(tmp_path, monkeypatch, capsys):
    import importlib

    import evolvers.evaluation.experiments
    from softgym.tasks import get_task

    strings = []

    def spy(spec, **kw):
        if isinstance(spec, str):
            strings.append(spec)
        return get_task(spec, **kw)

    evaluate_module = importlib.import_module("softgym.evaluate")  # not the function
    for module in (evolvers.evaluation.experiments, evaluate_module):
        monkeypatch.setattr(module, "get_task", spy)
    args = ["evolve", "--task", "stairs", "--generations", "1", "--no-figures", "--no-gif"]
    assert main([*args, "--out", str(tmp_path / "r"), *TINY]) == 0
    assert strings == ["stairs"]  # the experiment holds the Task from there to the kernel


def test_random_search_and_cmaes_on_the_design_vector_from_the_command_line(tmp_path, capsys):
    out = tmp_path / "random"
    flags = ["--experiment", "codesign", "--task", "gap", "--out", str(out), "--no-gif",
             "--no-figures"]  # fmt: skip
    assert main(["evolve", "--backend", "random", "--generations", "1", "--selection", "pareto",
                 *flags, *TINY]) == 0  # fmt: skip
    captured = capsys.readouterr()
    assert "--selection pareto is ignored with --backend random" in captured.err
    summary = json.loads(captured.out)
    assert summary["backend"] == "random" and summary["evaluations"] == 8
    assert main(["evolve", "--generations", "2", "--resume", *flags, "--quiet"]) == 0
    assert json.loads(capsys.readouterr().out)["evaluations"] == 12
    cma = tmp_path / "cmaes"
    assert main(["evolve", "--backend", "pymoo", "--algorithm", "cmaes", "--experiment", "codesign",
                 "--max-evals", "8", "--generations", "50", "--out", str(cma), "--no-gif",
                 "--no-figures", *TINY]) == 0  # fmt: skip
    summary = json.loads(capsys.readouterr().out)
    assert summary["stopped_by"] == "max_evals" and summary["evaluations"] >= 8
    genome = json.loads((cma / "best_designs.json").read_text())["best"][0]["genome"]
    assert len(genome["cppn"]["edges"]) == 83  # the fixed-topology CPPN of the design vector
