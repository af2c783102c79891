"""softgym evolve / qd / poet budgets: --max-evals, --max-robot-seconds, --max-wall-seconds,
--target-score stop a run, the summary says which, --resume counts on; bad values are one
line, exit 2, nothing written.
"""

import json

import pytest

from softgym_cli import main

_SIZES = ["--seconds", "1.5", "--shape", "4", "4", "4", "--no-figures", "--quiet"]
_TINY = {
    "evolve": ["evolve", "--pop", "4", "--no-gif", *_SIZES],
    "qd": ["qd", "--batch", "4", "--cells", "4", "--no-gif", *_SIZES],
    "poet": ["poet", "--pop", "3", "--reproduce-every", "1", "--transfer-every", "1", *_SIZES],
}
_LENGTH = {"evolve": "--generations", "qd": "--generations", "poet": "--iterations"}


def _summary(capsys):
    return json.loads(capsys.readouterr().out)


def _rows(out):
    return [json.loads(x) for x in (out / "log.jsonl").read_text().splitlines()]


@pytest.mark.parametrize("command", sorted(_TINY))
def test_max_evals_stops_the_run_and_resume_counts_on(tmp_path, capsys, command):
    if command == "qd":
        pytest.importorskip("ribs")
    out = tmp_path / "r"
    assert main([*_TINY[command], _LENGTH[command], "40", "--max-evals", "5", "--out", str(out)]) == 0
    s = _summary(capsys)
    assert s["stopped_by"] == "max_evals"
    assert s["budget"]["limits"] == {"generations": 40, "max_evals": 5}
    used = s["budget"]["used"]
    assert used["evaluations"] >= 5 and used["generation"] < 40
    assert used["robot_seconds"] == pytest.approx(used["evaluations"] * 1.5)
    rows = _rows(out)
    assert rows[-1]["evaluations_total"] == used["evaluations"]
    assert all(r["evaluations_total"] < 5 for r in rows[:-1])
    assert json.loads((out / "config.json").read_text())["budget"] == {"max_evals": 5}
    # --resume without budget flags keeps the recorded budget: spent, nothing more runs
    assert main([command, "--out", str(out), "--resume", "--quiet", "--no-figures"]) == 0
    assert _summary(capsys)["stopped_by"] == "max_evals" and len(_rows(out)) == len(rows)
    # a larger budget goes on from the checkpoint's counts
    assert main([command, "--out", str(out), "--resume", "--quiet", "--no-figures",
                 "--max-evals", "12"]) == 0  # fmt: skip
    s = _summary(capsys)
    assert s["stopped_by"] == "max_evals" and s["budget"]["used"]["evaluations"] >= 12
    assert len(_rows(out)) > len(rows)


def test_each_budget_flag_stops_evolve(tmp_path, capsys):
    base = [*_TINY["evolve"], "--generations", "40"]
    assert main([*base, "--max-robot-seconds", "9", "--out", str(tmp_path / "a")]) == 0
    s = _summary(capsys)
    assert s["stopped_by"] == "max_robot_seconds" and s["budget"]["used"]["robot_seconds"] >= 9
    assert main([*base, "--max-wall-seconds", "0.001", "--out", str(tmp_path / "b")]) == 0
    s = _summary(capsys)
    assert s["stopped_by"] == "max_wall_seconds" and s["generations"] == 0
    assert main([*base, "--target-score", "-1000000", "--out", str(tmp_path / "c")]) == 0
    s = _summary(capsys)
    assert s["stopped_by"] == "target_score" and s["generations"] == 0
    assert main([*_TINY["evolve"], "--generations", "1", "--out", str(tmp_path / "d")]) == 0
    assert _summary(capsys)["stopped_by"] == "generations"


@pytest.mark.parametrize("command", sorted(_TINY))
@pytest.mark.parametrize(
    "flag, value, message",
    [
        ("--max-evals", "0", "--max-evals must be an integer >= 1 (simulations), got 0"),
        ("--max-evals", "2.5", "--max-evals must be an integer >= 1"),
        ("--max-evals", "many", "--max-evals must be an integer >= 1 (simulations), got 'many'"),
        ("--max-robot-seconds", "-3", "--max-robot-seconds must be a finite number of seconds > 0"),
        ("--max-wall-seconds", "nan", "--max-wall-seconds must be a finite number of seconds > 0"),
        ("--max-wall-seconds", "0", "--max-wall-seconds must be a finite number of seconds > 0"),
        ("--target-score", "inf", "--target-score must be a finite number, got inf"),
    ],
)  # fmt: skip
def test_bad_budget_is_one_line_exit_2_and_nothing_written(tmp_path, capsys, command, flag,
                                                           value, message):  # fmt: skip
    out = tmp_path / "r"
    assert main([command, "--out", str(out), flag, value, "--quiet"]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert err == f"softgym {command}: {err.split(': ', 1)[1]}" and "\n" not in err
    assert message in err and captured.out == ""
    assert not out.exists()


def test_a_bad_budget_on_resume_leaves_the_run_untouched(tmp_path, capsys):
    out = tmp_path / "r"
    assert main([*_TINY["evolve"], "--generations", "1", "--out", str(out)]) == 0
    capsys.readouterr()
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    assert main(["evolve", "--out", str(out), "--resume", "--max-evals", "-2"]) == 2
    assert "--max-evals must be an integer >= 1" in capsys.readouterr().err
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before
