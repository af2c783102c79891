"""benchmarks/compare_builds.py: builds timed in turn, each from its own tree (issue 29).

The script runs as a user runs it (a child process): tests import nothing from benchmarks/.
"""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "benchmarks" / "compare_builds.py"


def _compare(*argv):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, argv)], capture_output=True,
                          text=True)  # fmt: skip


def test_two_turns_of_the_same_tree_report_minima_medians_and_ratios():
    res = _compare(ROOT, ROOT, "--rounds", 2, "--runs", 1, "--seconds", 0.02, "--json")
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert out["rounds"] == 2 and len(out["builds"]) == 2
    first, second = out["builds"]
    assert first["speedup_min"] == 1.0 and first["speedup_median"] == 1.0
    for b in out["builds"]:
        assert 0.0 < b["min_s"] <= b["median_s"]
    assert second["speedup_min"] == first["min_s"] / second["min_s"]
    assert sum(line.startswith("round") for line in res.stdout.splitlines()) == 2


def test_the_corotational_preset_is_timed_on_request():
    res = _compare(ROOT, ROOT, "--rounds", 1, "--runs", 1, "--seconds", 0.02, "--model",
                   "corotational", "--json")  # fmt: skip
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout.strip().splitlines()[-1])["model"] == "corotational"
    bad = _compare(ROOT, ROOT, "--rounds", 1, "--model", "stiff")
    assert bad.returncode == 2 and "--model" in bad.stderr


def test_the_fence_as_terrain_boxes_is_timed_on_request():
    res = _compare(ROOT, ROOT, "--rounds", 1, "--runs", 1, "--seconds", 0.02, "--box-fence",
                   "--json")  # fmt: skip
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert out["box_fence"] is True and len(out["builds"]) == 2


def test_a_tree_without_softgym_is_refused_with_the_reason(tmp_path):
    # softgym would come from the installed checkout, not from the tree asked for
    (tmp_path / "benchmarks").mkdir()
    (tmp_path / "benchmarks" / "bench_engine.py").write_text(
        (ROOT / "benchmarks" / "bench_engine.py").read_text()
    )
    (tmp_path / "benchmarks" / "results_log.py").write_text(
        (ROOT / "benchmarks" / "results_log.py").read_text()
    )
    res = _compare(ROOT, tmp_path, "--rounds", 1, "--runs", 1, "--seconds", 0.02)
    assert res.returncode != 0
    assert f"the run in {tmp_path.resolve()} imported" in res.stderr


def test_one_tree_is_a_usage_error():
    res = _compare(ROOT, "--rounds", 1)
    assert res.returncode == 2 and "two or more trees" in res.stderr
