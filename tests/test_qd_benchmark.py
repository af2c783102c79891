"""benchmarks/bench_qd.py: stored runs, resume, curves and the figure (issue 17)."""

import importlib.util
import json
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


def _bench_qd():
    pytest.importorskip("ribs")
    sys.path.insert(0, str(BENCH))  # the script imports results_log from its folder
    spec = importlib.util.spec_from_file_location("bench_qd", BENCH / "bench_qd.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_runs_are_stored_with_curves_and_skipped_when_run_again(tmp_path, capsys):
    bench = _bench_qd()
    data, fig = tmp_path / "qd.json", tmp_path / "qd.png"
    argv = ["--quick", "--seeds", "1", "--budget", "10", "--batch", "5", "--seconds", "0.3",
            "--methods", "map-elites", "nsga2", "--data", str(data), "--figure", str(fig),
            "--no-append"]  # fmt: skip
    assert bench.main(argv) == 0
    store = json.loads(data.read_text())
    assert set(store["runs"]) == {"map-elites/0", "nsga2/0"}
    for run in store["runs"].values():
        curve = run["curve"]
        assert len(curve) == bench.CURVE_POINTS and curve[-1][0] == 10
        qd = [p[1] for p in curve]
        assert qd == sorted(qd)  # the archive only gains
        assert curve[-1][1:] == [run["qd_score"], run["coverage"], run["best"]]
    assert fig.stat().st_size > 10_000
    capsys.readouterr()
    assert bench.main(argv) == 0  # everything stored: nothing is simulated again
    assert capsys.readouterr().out.count("(stored in") == 2
    with pytest.raises(SystemExit, match="holds runs of"):
        bench.main([*argv[:4], "12", *argv[5:]])  # another budget, same file
