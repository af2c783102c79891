"""benchmarks/leaderboard.py as a user runs it, on a toy budget: cells stored, skipped, refused
on another budget; the documented command for a new optimiser runs it under the reference's
budget and seeds and prints its row beside the references; the report's page and figures.

The script runs in child processes: tests import nothing from benchmarks/.
"""

import json
import re
import shlex
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "benchmarks" / "leaderboard.py"
TOY = ["--tasks", "flat", "--seeds", "1", "--evals", "8", "--pop", "4", "--seconds", "1.5"]


def _run(argv, cwd=None, ok=True):
    res = subprocess.run([sys.executable, str(SCRIPT), *argv], capture_output=True, text=True,
                         timeout=900, cwd=cwd)  # fmt: skip
    if ok:
        assert res.returncode == 0, res.stderr[-3000:]
    return res


def _reference(tmp_path):
    ref = tmp_path / "ref"
    _run(["--out", str(ref), "--optimizers", "random", "tournament", *TOY])
    return ref


def _documented_command():
    """The page's command that adds an optimiser (the console block with --optimizer)."""
    page = (ROOT / "docs" / "leaderboard.md").read_text()
    blocks = re.findall(r"```console\n(.*?)```", page, re.S)
    mine = [b for b in blocks if "--optimizer" in b and "--reference" in b]
    assert len(mine) == 1, blocks
    return shlex.split(mine[0].replace("\\\n", " "))


def test_cells_are_stored_skipped_and_a_second_budget_refused(tmp_path):
    ref = _reference(tmp_path)
    plan = json.loads((ref / "plan.json").read_text())
    assert plan["evals"] == 8 and plan["seeds"] == [1] and plan["tasks"] == ["flat"]
    assert set(plan["optimizers"]) == {"random", "tournament"}
    for name in ("random", "tournament"):
        cell = json.loads((ref / "cells" / "flat" / name / "seed-1.json").read_text())
        assert cell["evals"] <= 8 <= cell["evals_run"] and cell["cpu_seconds"] > 0
        assert "--max-evals 8" in cell["command"] and "--task flat" in cell["command"]
        best = [b for _, b in cell["curve"]]
        assert best == sorted(best) and cell["best_score"] in best
        assert cell["design"]["grid"]["shape"] == [6, 6, 6]
        assert (ref / "runs" / "flat" / name / "seed-1" / "checkpoints").is_dir()
    again = _run(["--out", str(ref), "--optimizers", "random", "tournament", *TOY])
    assert "2 finished, 0 to run" in again.stdout and "[1/" not in again.stdout
    other = _run(["--out", str(ref), "--optimizers", "random", *TOY[:-6], "--evals", "9"], ok=False)
    assert other.returncode == 2 and "planned with --evals 8" in other.stderr
    bad = _run(["--out", str(tmp_path / "x"), "--optimizer", "mine=softgym evolve {nope}", *TOY],
               ok=False)  # fmt: skip
    assert bad.returncode == 2 and "unknown placeholder {nope}" in bad.stderr
    clash = _run(["--out", str(tmp_path / "y"), "--reference", str(ref), "--optimizer",
                  "random=softgym evolve --experiment codesign {run_flags}"], ok=False)  # fmt: skip
    assert clash.returncode == 2 and "give this command another name" in clash.stderr


def test_the_documented_command_adds_an_optimiser_beside_the_references(tmp_path):
    ref = _reference(tmp_path)
    argv = _documented_command()
    assert argv[:2] == ["python", "benchmarks/leaderboard.py"]
    argv = argv[2:]
    # the page's paths, here: the toy reference and a scratch folder
    argv[argv.index("--reference") + 1] = str(ref)
    argv[argv.index("--out") + 1] = str(tmp_path / "mine")
    name = argv[argv.index("--optimizer") + 1].split("=")[0]
    out = _run(argv, cwd=tmp_path).stdout
    cell = json.loads((tmp_path / "mine" / "cells" / "flat" / name / "seed-1.json").read_text())
    assert "--max-evals 8" in cell["command"] and "--seconds 1.5" in cell["command"]
    assert cell["evals"] <= 8 <= cell["evals_run"]  # the reference's budget and seeds
    header = next(line for line in out.splitlines() if line.startswith("| task |"))
    assert header.split("|")[2:5] == [" random ", " tournament ", f" {name} "]
    rows = {line.split("|")[1].strip(): line for line in out.splitlines() if line.startswith("| ")}
    assert rows[name].split("|")[5].strip() == "1"  # its one run, in the optimisers' table
    assert {"random", "tournament"} <= set(rows)
    # a Driver class as an optimiser, beside the same references
    py = _run(["--reference", str(ref), "--out", str(tmp_path / "py"), "--optimizer",
               "deap=py:evolvers.drivers.deap_runner:DeapRun"]).stdout  # fmt: skip
    assert "| deap |" in py
    # the report: the page's block, the curves and the gallery
    page = tmp_path / "page.md"
    page.write_text("# p\n\n<!-- leaderboard:start -->\nSTALE\n<!-- leaderboard:end -->\n")
    _run(["--out", str(tmp_path / "mine"), "--reference", str(ref), "--report", "--doc", str(page),
          "--figures", str(tmp_path / "fig")])  # fmt: skip
    text = page.read_text()
    assert "STALE" not in text and f"| {name} |" in text and "3 of 3 runs finished" in text
    for figure in ("leaderboard_curves.png", "leaderboard_gallery.png"):
        assert (tmp_path / "fig" / figure).stat().st_size > 5000


def test_an_interrupted_cell_resumes_from_its_run_folder(tmp_path):
    out = tmp_path / "lb"
    run_dir = out / "runs" / "flat" / "random" / "seed-1"
    partial = ["evolve", "--experiment", "codesign", "--backend", "random", "--pop", "4", "--task",
               "flat", "--seed", "1", "--seconds", "1.5", "--max-evals", "4", "--generations",
               "100000", "--threads", "1", "--out", str(run_dir), "--no-figures", "--no-gif", "-q"]  # fmt: skip
    subprocess.run([sys.executable, "-m", "softgym_cli", *partial], check=True, capture_output=True)
    run_id = json.loads((run_dir / "identity.json").read_text())["run_id"]
    _run(["--out", str(out), "--optimizers", "random", *TOY])
    cell = json.loads((out / "cells" / "flat" / "random" / "seed-1.json").read_text())
    assert json.loads((run_dir / "identity.json").read_text())["run_id"] == run_id  # went on
    assert "--resume" in cell["command"] and [e for e, _ in cell["curve"]] == [4, 8]
