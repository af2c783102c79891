"""benchmarks/profile_engine.py --modes: the reference robot's links by mode (issue 29).

Run as a user runs it (a child process). The instruction and cycle profiles need valgrind
or a probed build of a copy of the tree (minutes) and are not run here.
"""

import json
import subprocess
import sys
from pathlib import Path

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
