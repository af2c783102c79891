"""The researcher's workflow on the command line: resume from the folder, compare, Ctrl-C,
--help defaults, view, convert (issue 13)."""

import argparse
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from softgym_cli import main

TINY = ["--pop", "4", "--seconds", "1.5", "--shape", "4", "4", "4", "--quiet", "--no-gif"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("runs")
    for name, extra in (("a0", ["--seed", "0"]), ("a1", ["--seed", "1"]),
                        ("o", ["--experiment", "obstacles"])):  # fmt: skip
        assert main(["evolve", "--generations", "1", "--out", str(root / name), *TINY, *extra]) == 0
    return root


def test_resume_reads_the_settings_from_the_run_folder(runs, capsys):
    capsys.readouterr()
    # the obstacles run resumes without --experiment, --pop...; it goes on to generation 2
    assert main(["evolve", "--out", str(runs / "o"), "--resume", "--generations", "2",
                 "--quiet", "--no-gif"]) == 0  # fmt: skip
    summary = json.loads(capsys.readouterr().out)
    assert summary["experiment"] == "obstacles" and summary["generations"] == 2
    assert main(["evolve", "--out", str(runs / "o"), "--resume", "--pop", "5"]) == 2
    err = capsys.readouterr().err.strip()
    assert "started with --pop 4, not 5" in err and len(err.splitlines()) == 1 and len(err) < 200


def test_help_shows_every_default(capsys):
    import softgym_cli as cli

    parser_holder = {}
    real = argparse.ArgumentParser.parse_args

    def grab(self, *a, **k):
        parser_holder["p"] = self
        raise SystemExit(0)

    argparse.ArgumentParser.parse_args = grab
    try:
        with pytest.raises(SystemExit):
            cli.main(["experiments"])
    finally:
        argparse.ArgumentParser.parse_args = real
    sub = next(a for a in parser_holder["p"]._actions if isinstance(a, argparse._SubParsersAction))
    for name, p in sub.choices.items():
        if name not in ("simulate", "evolve", "replay", "compare", "view", "convert"):
            continue
        text = p.format_help()
        for action in p._actions:
            if not action.option_strings or action.dest == "help":
                continue
            assert action.help, f"softgym {name} {action.option_strings[0]} has no help"
            if isinstance(action, argparse._StoreTrueAction) or action.default is not None:
                continue
            assert "default" in action.help, f"softgym {name} {action.option_strings[0]}"
        if name == "evolve":
            assert "(default: 10)" in text and "seed of the run's random generator" in text


def test_compare_groups_seeds_and_explains_a_missing_metric(runs, tmp_path, capsys):
    out = tmp_path / "c.png"
    assert main(["compare", str(runs / "a0"), str(runs / "a1"), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "2 run(s)" in printed and out.stat().st_size > 5000
    # a flat run and an obstacle run on one axis: the obstacle run's fittest robot's distance
    assert main(["compare", str(runs / "a0"), str(runs / "o"), "--out", str(out)]) == 0
    assert "(top_norm_final_dist) stands in" in capsys.readouterr().err
    assert main(["compare", str(runs / "a0"), str(runs / "o"), "--stat", "median",
                 "--out", str(out)]) == 2  # fmt: skip
    err = capsys.readouterr().err
    assert "did not record 'norm_final_dist'" in err and "--metric" in err
    # a mix of experiments compares on a metric both record
    assert main(["compare", str(runs / "a0"), str(runs / "o"), "--metric", "n_muscle",
                 "--out", str(out)]) == 0  # fmt: skip
    # a damaged log is one line naming the file and line, exit 2
    import shutil

    bad = tmp_path / "bad"
    shutil.copytree(runs / "a1", bad)
    lines = (bad / "log.jsonl").read_text().splitlines()
    (bad / "log.jsonl").write_text("\n".join([lines[0], lines[1][:20], *lines[2:]]) + "\n")
    capsys.readouterr()
    assert main(["compare", str(runs / "a0"), str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "log.jsonl: line 2: corrupt or truncated JSON" in err


def test_convert_both_ways_and_view(runs, tmp_path, capsys):
    from softgym.design import RobotDesign

    src = runs / "a0" / "best_design.json"
    assert (runs / "a0" / "best_design.vxa").is_file()
    assert main(["convert", str(src), str(tmp_path / "d.vxa")]) == 0
    assert main(["convert", str(tmp_path / "d.vxa"), str(tmp_path / "d.json")]) == 0
    a, b = RobotDesign.load(src), RobotDesign.load(tmp_path / "d.json")
    assert (a.grid == b.grid).all() and a.controller == b.controller
    assert main(["convert", str(src), str(tmp_path / "d.txt")]) == 2
    assert main(["view", str(tmp_path / "d.vxa"), "--seconds", "0.3", "--fps", "5"]) == 0
    assert (tmp_path / "d.html").stat().st_size > 1_000_000  # plotly.js inlined
    assert main(["view", str(runs / "o"), "--seconds", "0.3", "--fps", "5"]) == 0
    html = (runs / "o" / "view.html").read_text()
    assert "best robot (obstacles)" in html


@pytest.mark.skipif(os.name != "posix", reason="needs POSIX signals")
def test_ctrl_c_stops_fast_and_prints_the_resume_command(tmp_path):
    out = tmp_path / "run"
    cmd = [sys.executable, "-m", "softgym_cli", "evolve", "--out", str(out), "--generations",
           "50", "--pop", "6", "--seconds", "3", "--shape", "4", "4", "4", "--no-gif",
           "--no-figures"]  # fmt: skip
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.time() + 240
        while not (out / "checkpoints" / "ckpt-000000.json").exists():
            assert p.poll() is None and time.time() < deadline
            time.sleep(0.05)
        time.sleep(0.5)  # inside generation 1's simulations
        t0 = time.perf_counter()
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=60)
        took = time.perf_counter() - t0
    finally:
        p.kill()
    assert p.returncode == 130
    assert took < 5.0  # a fraction of a second plus interpreter exit, on a loaded 2-core box
    assert "Traceback" not in err
    assert f"resume with: softgym evolve --out {out} --resume" in err
    assert "checkpointed in" in err
    assert err.count("interrupted") == 1, err  # one message, not the log's and the CLI's
