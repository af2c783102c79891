"""benchmarks/rl_ppo.py at a tiny budget: it trains, stores the run, and resumes exactly (issue 33)."""

import io
import json
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3", reason="the rl extra (stable-baselines3, torch) is not installed")
torch = pytest.importorskip("torch", reason="the rl extra (torch) is not installed")

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "rl_ppo.py"
TINY = ["--timesteps", "24", "--n-envs", "2", "--episode-seconds", "0.2", "--net-arch", "8",
        "--checkpoint-every", "8", "--eval-episodes", "2"]  # fmt: skip


def _run(*args):
    res = subprocess.run([sys.executable, str(SCRIPT), *TINY, *args], capture_output=True,
                         text=True, timeout=300)  # fmt: skip
    assert res.returncode == 0, res.stderr[-3000:]
    return res


def _params(run_dir):
    with zipfile.ZipFile(run_dir / "ckpt" / "model.zip") as z:
        return torch.load(io.BytesIO(z.read("policy.pth")))


def test_a_run_interrupted_and_resumed_ends_as_an_uninterrupted_one(tmp_path):
    whole, parts = tmp_path / "whole", tmp_path / "parts"
    _run("--run-dir", str(whole))
    _run("--run-dir", str(parts), "--pause-at", "10")  # stops at its checkpoint at 16 steps
    paused = json.loads((parts / "run.json").read_text())
    assert paused["num_timesteps"] == 16 and not paused["finished"] and "final" not in paused
    res = _run("--run-dir", str(parts), "--json")
    assert "resuming" in res.stderr
    a, b = json.loads((whole / "run.json").read_text()), json.loads((parts / "run.json").read_text())
    assert a["finished"] and b["finished"] and a["num_timesteps"] == b["num_timesteps"] == 24
    assert a["final"] == b["final"] and a["curve"] == b["curve"]
    assert json.loads(res.stdout.splitlines()[-1])["final"] == b["final"]
    pa, pb = _params(whole), _params(parts)
    assert pa.keys() == pb.keys() and all(torch.equal(pa[k], pb[k]) for k in pa)
    # the stored record: the command (without --pause-at), baselines, curves
    assert b["command"].startswith("python benchmarks/rl_ppo.py --timesteps 24")
    assert "--pause-at" not in b["command"]
    assert len(b["baselines"]["random"]) == 2 and len(b["baselines"]["sinusoid"]) == 1
    assert [t for t, _ in b["eval_curve"]] == [8, 16, 24]
    assert b["action_mode"] == "contraction" and b["preset"] == "seed"
    assert not (parts / "ckpt.new").exists() and not (parts / "ckpt.old").exists()


@pytest.mark.slow
def test_a_stored_run_resumes_only_with_its_settings_and_its_own_files(tmp_path):
    _run("--run-dir", str(tmp_path), "--pause-at", "8")
    res = subprocess.run([sys.executable, str(SCRIPT), *TINY, "--lr", "0.001", "--run-dir",
                          str(tmp_path)], capture_output=True, text=True, timeout=300)  # fmt: skip
    assert res.returncode != 0 and "other settings" in res.stderr and "'lr'" in res.stderr
    (tmp_path / "ckpt" / "vecnormalize.npz").write_bytes(b"not mine")
    res = subprocess.run([sys.executable, str(SCRIPT), *TINY, "--run-dir", str(tmp_path)],
                         capture_output=True, text=True, timeout=300)  # fmt: skip
    assert res.returncode != 0 and "checksum mismatch" in res.stderr


def test_a_finished_run_keeps_its_final_policy_lean(tmp_path):
    _run("--run-dir", str(tmp_path))
    with zipfile.ZipFile(tmp_path / "ckpt" / "model.zip") as z:
        names = z.namelist()
    assert "policy.pth" in names and "policy.optimizer.pth" not in names
    again = _run("--run-dir", str(tmp_path), "--json")  # finished: nothing trained or rewritten
    assert "finished" in again.stderr
    assert json.loads(again.stdout.splitlines()[-1]) == json.loads((tmp_path / "run.json").read_text())
