"""benchmarks/profile_engine.py --modes and --perf (issue 29).

Run as a user runs it (a child process). The instruction and cycle profiles need valgrind
or a probed build of a copy of the tree (minutes) and are not run here; --perf runs where
perf can sample (skipped elsewhere).
"""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "benchmarks" / "profile_engine.py"


def _modes(*argv):
    res = subprocess.run([sys.executable, str(SCRIPT), "--modes", "--json", *map(str, argv)],
                         capture_output=True, text=True)  # fmt: skip
    assert res.returncode == 0, res.stderr
    lines = res.stdout.strip().splitlines()
    return lines[0], json.loads(lines[-1])


def test_the_actuated_robot_bends_links_into_large_angle_mode():
    line, m = _modes("--seconds", 2.0)
    assert m["links"] == 540 and m["samples"] == 40 and m["block"] == 16
    # the two muscle groups bend the body: a good share of its links leave small-angle mode
    assert 0.2 < m["large_angle_share"] < 0.9
    # a block all in small-angle mode holds only small-angle links
    small = 1.0 - m["large_angle_share"]
    assert 0.0 <= m["all_small_block_share"] <= small + 16 / 540
    assert "% of the links in large-angle mode" in line


def test_a_short_run_keeps_a_robot_at_rest_in_small_angle_mode():
    # links start in small-angle mode; 0.05 s after the start the body has barely moved
    _, m = _modes("--seconds", 0.05)
    assert m["samples"] == 1
    assert m["large_angle_share"] < 0.05



def _perf_works(tmp_path):
    if shutil.which("perf") is None or shutil.which("objdump") is None:
        return False
    res = subprocess.run(["perf", "record", "-q", "-o", str(tmp_path / "probe.data"), "true"],
                         capture_output=True, text=True)  # fmt: skip
    return res.returncode == 0


def test_perf_splits_the_engine_functions_at_their_loops(tmp_path):
    # --perf: perf's samples of the engine's hottest functions, each split into its
    # innermost loops and the rest (the step's glue); skipped where perf cannot sample
    if not _perf_works(tmp_path):
        pytest.skip("needs a working perf and objdump")
    res = subprocess.run([sys.executable, str(SCRIPT), "--perf", "--json", "--seconds", "0.5"],
                         capture_output=True, text=True)  # fmt: skip
    assert res.returncode == 0, res.stderr
    lines = res.stdout.strip().splitlines()
    got = json.loads(lines[-1])
    funcs = got["functions"]
    assert 1 <= len(funcs) <= 8 and "outside its innermost loops" in lines[0]
    shares = [f["share"] for f in funcs]
    assert shares == sorted(shares, reverse=True) and 0.0 < sum(shares) <= 1.0 + 1e-9
    assert all(0.0 <= f["outside"] <= 1.0 for f in funcs)
    # the seed step's link passes are among the hottest, and mostly in their loops
    geom = [f for f in funcs if f["symbol"].startswith("softgym_seed_geom")]
    assert geom and geom[0]["outside"] < 0.6
    for f in funcs:
        for pct, addr, fn, text in f["hottest_outside"]:
            assert pct >= 0.0 and addr > 0 and fn and text
