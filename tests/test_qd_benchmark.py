"""benchmarks/bench_qd.py: stored runs, resume, curves and the figure (issue 17).

The script runs as a user runs it (a child process): tests import nothing from benchmarks/.
"""

import json
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_qd.py"


def _bench_qd(argv):
    return subprocess.run([sys.executable, str(SCRIPT), *argv], capture_output=True, text=True)


def test_runs_are_stored_with_curves_and_skipped_when_run_again(tmp_path):
    pytest.importorskip("ribs")
    data, fig = tmp_path / "qd.json", tmp_path / "qd.png"
    argv = ["--quick", "--seeds", "1", "--budget", "10", "--batch", "5", "--seconds", "0.3",
            "--methods", "map-elites", "nsga2", "--data", str(data), "--figure", str(fig),
            "--no-append"]  # fmt: skip
    first = _bench_qd(argv)
    assert first.returncode == 0, first.stderr
    store = json.loads(data.read_text())
    assert set(store["runs"]) == {"map-elites/0", "nsga2/0"}
    for run in store["runs"].values():
        curve = run["curve"]
        assert len(curve) == 10 and curve[-1][0] == 10  # CURVE_POINTS marks of the 10 robots
        qd = [p[1] for p in curve]
        assert qd == sorted(qd)  # the archive only gains
        assert curve[-1][1:] == [run["qd_score"], run["coverage"], run["best"]]
    assert fig.stat().st_size > 10_000
    again = _bench_qd(argv)  # everything stored: nothing is simulated again
    assert again.returncode == 0 and again.stdout.count("(stored in") == 2
    other = _bench_qd([*argv[:4], "12", *argv[5:]])  # another budget, same file
    assert other.returncode != 0 and "holds runs of" in other.stderr
