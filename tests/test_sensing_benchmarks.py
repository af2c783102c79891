"""benchmarks/closed_loop.py, one_brain.py and bench_sensing.py as a user runs them, on toy budgets.

The scripts run in child processes: tests import nothing from benchmarks/.
"""

import json
import subprocess
import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


def _run(script, argv):
    res = subprocess.run([sys.executable, str(BENCH / script), *argv], capture_output=True,
                         text=True, timeout=600)  # fmt: skip
    assert res.returncode == 0, res.stderr[-3000:]
    return res.stdout


def test_closed_loop_runs_are_stored_resumed_and_reported(tmp_path):
    argv = ["--tasks", "gap", "--seeds", "1", "--evals", "8", "--pop", "4", "--out", str(tmp_path)]
    out = _run("closed_loop.py", argv)
    assert "gap      open" in out and "gap      distributed" in out
    runs = sorted((tmp_path / "runs").glob("*.json"))
    assert [p.name for p in runs] == ["gap-distributed-1.json", "gap-open-1.json"]
    rec = json.loads(runs[0].read_text())
    assert rec["evals"] >= 8 and len(rec["curve"]) == rec["evals"] and rec["design"]["brain"]
    assert rec["curve"] == sorted(rec["curve"])  # best so far
    assert _run("closed_loop.py", argv) == ""  # finished runs are skipped
    table = _run("closed_loop.py", ["--out", str(tmp_path), "--report",
                                    "--figure", str(tmp_path / "f.png")])  # fmt: skip
    assert "| gap |" in table and (tmp_path / "f.png").stat().st_size > 1000


def test_one_brain_generalist_and_specialists(tmp_path):
    argv = ["--train", "1", "--held-out", "2", "--candidates", "4", "--pop", "4", "--out", str(tmp_path)]
    _run("one_brain.py", argv)
    g = json.loads((tmp_path / "generalist.json").read_text())
    assert len(g["held_out_scores"]) == 2 and g["brain"]["kind"] == "distributed"
    assert sorted(p.name for p in tmp_path.glob("specialist-*.json")) == [
        "specialist-00.json", "specialist-01.json"]
    table = _run("one_brain.py", ["--out", str(tmp_path), "--report"])
    assert "ratio of medians" in table


def test_bench_sensing_prints_the_control_steps_share():
    out = _run("bench_sensing.py", ["--batch", "2", "--tasks", "flat", "--control-dt", "0.1",
                                    "--steps", "2", "--threads", "1", "--no-append"])  # fmt: skip
    rows = [line for line in out.splitlines() if line.startswith("| flat")]
    assert len(rows) == 3 and rows[1].rstrip().endswith("% |")
