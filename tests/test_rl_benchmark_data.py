"""The stored PPO runs (benchmarks/data/rl/) and the scripts that draw them (issues 13, 33).

The scripts run as a user runs them (child processes): tests import nothing from
benchmarks/. The stored records are read here as the JSON files they are.
"""

import hashlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"
DATA = BENCH / "data" / "rl"
KEYS = {"command", "preset", "timesteps", "train_seconds", "wall_seconds", "actuation",
        "control_dt", "curve", "ppo", "ppo_sampled", "random", "sinusoid"}  # fmt: skip


def _script(name, *args, check=True):
    res = subprocess.run([sys.executable, str(BENCH / name), *map(str, args)],
                         capture_output=True, text=True, timeout=300)  # fmt: skip
    if check:
        assert res.returncode == 0, res.stderr[-3000:]
    return res


def test_stored_rl_runs_are_complete():
    paths = sorted(DATA.glob("*.json"))
    assert len(paths) >= 2
    for path in paths:
        run = json.loads(path.read_text())
        assert KEYS <= run.keys(), f"{path.name} lacks {KEYS - run.keys()}"
        assert run["preset"] == "seed"
        assert run["curve"][-1][0] >= run["timesteps"]
        assert str(run["timesteps"]) in run["command"]


def test_plot_rl_draws_the_stored_runs(tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "ppo.png"
    _script("plot_rl.py", "--out", out)
    assert out.stat().st_size > 10_000


def test_plot_rl_reads_a_log_ending_with_the_json_line(tmp_path):
    pytest.importorskip("matplotlib")
    run = json.loads(sorted(DATA.glob("*.json"))[0].read_text())
    log = tmp_path / "run.log"
    log.write_text("training...\n" + json.dumps(run) + "\n")
    out = tmp_path / "one.png"
    _script("plot_rl.py", log, "--out", out)
    assert out.stat().st_size > 10_000
    log.write_text("no json here\n")
    res = _script("plot_rl.py", log, "--out", tmp_path / "none.png", check=False)
    assert res.returncode != 0
    assert "the last line is not rl_ppo.py's JSON" in res.stderr
    assert not (tmp_path / "none.png").exists()


def test_stored_ppo_baseline_runs_are_resumable_records():
    root = DATA / "ppo"
    dirs = sorted(p.parent for p in root.glob("*/run.json"))
    assert dirs, "no PPO baseline run is stored"
    for d in dirs:
        run = json.loads((d / "run.json").read_text())
        assert run["command"].startswith("python benchmarks/rl_ppo.py ")
        assert f"--run-dir benchmarks/data/rl/ppo/{d.name}" in run["command"]
        sensing = "-sensing" if run["settings"].get("observe") == "sensing" else ""
        shaped = "-shaped" if run["settings"].get("shaping") else ""
        assert d.name == f"{run['task']}{sensing}{shaped}-s{run['settings']['seed']}"
        steps = [t for t, _ in run["eval_curve"]]
        assert steps == sorted(steps) and steps[-1] == run["num_timesteps"]
        assert run["finished"] == (run["num_timesteps"] >= run["timesteps"]) == ("final" in run)
        assert len(run["baselines"]["sinusoid"]) == 1 and run["baselines"]["random"]
        # the committed checkpoint is the one the record describes, with the files it lists
        state = json.loads((d / "ckpt" / "state.json").read_text())
        assert state["num_timesteps"] == run["num_timesteps"]
        for name, digest in state["files"].items():
            assert hashlib.sha256((d / "ckpt" / name).read_bytes()).hexdigest() == digest, name


def test_rl_table_prints_every_task_and_draws_the_curves(tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "curves.png"
    text = _script("rl_table.py", "--out", out).stdout
    by_task = {}
    for d in (DATA / "ppo").glob("*/run.json"):
        run = json.loads(d.read_text())
        settings = run["settings"]
        tags = ["sensing"] if settings.get("observe") == "sensing" else []
        tags += ["shaped"] if settings.get("shaping") else []
        task = run["task"] + (f" ({', '.join(tags)})" if tags else "")
        by_task[task] = by_task.get(task, 0) + 1
    for task, n in by_task.items():
        assert f"| {task} | {n} |" in text
    assert out.stat().st_size > 10_000
    # the evolved column: bench_tasks.py's controllers, 3 s episodes (flat 4.56 [4.45, 4.73])
    assert "| flat | 3 |" in text and "4.56 [4.45, 4.73]" in text
    evolved = json.loads((DATA / "baselines" / "evolved_controllers.json").read_text())
    assert len(evolved["tasks"]) == 16 and evolved["tasks"]["flat"]["evolved_median"] == 4.56
    # swim's actions; on flat the sampled sinusoid (2.91, all 3 seeds above it) beside the
    # engine's continuous drive (4.38, 2 of 3 above it)
    assert "| swim | 1 | temperature (symmetric) |" in text
    assert "| flat | 3 | contraction |" in text and "| 3/3 | 2.91 | 2/3 | 4.38 |" in text
    # the engine of each run: its commit, or the commits that stored it
    for d in (DATA / "ppo").glob("*/run.json"):
        assert f"  {d.parent.name}: " in text
