"""The stored PPO runs (benchmarks/data/rl/) and the figure script that draws them (issue 13)."""

import importlib.util
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"
KEYS = {"command", "preset", "timesteps", "train_seconds", "wall_seconds", "actuation",
        "control_dt", "curve", "ppo", "ppo_sampled", "random", "sinusoid"}  # fmt: skip


def _plot_rl():
    spec = importlib.util.spec_from_file_location("plot_rl", BENCH / "plot_rl.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_stored_rl_runs_are_complete():
    plot_rl = _plot_rl()
    paths = plot_rl.stored_runs()
    assert len(paths) >= 2
    for path in paths:
        run = plot_rl.load(path)
        assert KEYS <= run.keys(), f"{path.name} lacks {KEYS - run.keys()}"
        assert run["preset"] == "seed"
        assert run["curve"][-1][0] >= run["timesteps"]
        assert str(run["timesteps"]) in run["command"]


def test_plot_rl_draws_the_stored_runs(tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "ppo.png"
    assert _plot_rl().main(["--out", str(out)]) == 0
    assert out.stat().st_size > 10_000


def test_plot_rl_reads_a_log_ending_with_the_json_line(tmp_path):
    log = tmp_path / "run.log"
    log.write_text('training...\n{"curve": [[2048, 0.1]], "ppo": 0.2}\n')
    assert _plot_rl().load(log)["ppo"] == 0.2
    log.write_text("no json here\n")
    with pytest.raises(SystemExit):
        _plot_rl().load(log)


def _rl_table():
    spec = importlib.util.spec_from_file_location("rl_table", BENCH / "rl_table.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_stored_ppo_baseline_runs_are_resumable_records():
    import hashlib
    import json

    root = BENCH / "data" / "rl" / "ppo"
    dirs = sorted(p.parent for p in root.glob("*/run.json"))
    assert dirs, "no PPO baseline run is stored"
    for d in dirs:
        run = json.loads((d / "run.json").read_text())
        assert run["command"].startswith("python benchmarks/rl_ppo.py ")
        assert f"--run-dir benchmarks/data/rl/ppo/{d.name}" in run["command"]
        assert d.name == f"{run['task']}-s{run['settings']['seed']}"
        steps = [t for t, _ in run["eval_curve"]]
        assert steps == sorted(steps) and steps[-1] == run["num_timesteps"]
        assert run["finished"] == (run["num_timesteps"] >= run["timesteps"]) == ("final" in run)
        assert len(run["baselines"]["sinusoid"]) == 1 and run["baselines"]["random"]
        # the committed checkpoint is the one the record describes, with the files it lists
        state = json.loads((d / "ckpt" / "state.json").read_text())
        assert state["num_timesteps"] == run["num_timesteps"]
        for name, digest in state["files"].items():
            assert hashlib.sha256((d / "ckpt" / name).read_bytes()).hexdigest() == digest, name


def test_rl_table_prints_every_task_and_draws_the_curves(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    mod = _rl_table()
    runs = mod.load_runs()
    out = tmp_path / "curves.png"
    assert mod.main(["--out", str(out)]) == 0
    text = capsys.readouterr().out
    for task in runs:
        assert f"| {task} | {len(runs[task])} |" in text
    assert out.stat().st_size > 10_000
    evolved = mod.evolved()
    assert evolved["flat"]["evolved_median"] == 4.56 and len(evolved) == 16
