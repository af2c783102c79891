"""softgym evolve / qd --controller: network runs on every backend, fixed bodies, CMA-ES, resume, bad input."""

import json

import pytest

from softgym.design import default_walker
from softgym.design.robot import RobotDesign
from softgym_cli import main

_TINY = ["--pop", "4", "--seconds", "1.5", "--quiet", "--no-figures", "--no-gif"]


def _small_body(path):
    w = default_walker()
    grid = w.grid[1:5, :4, :4].copy()
    grid[:, :, 3] = 1
    RobotDesign(grid, palette=w.palette, controller=w.controller).save(path)
    return str(path)


def _config(out):
    return json.loads((out / "config.json").read_text())


@pytest.mark.parametrize(
    "backend",
    [
        ["--backend", "native"],
        ["--backend", "deap"],
        ["--backend", "pymoo", "--algorithm", "nsga2"],
    ],
)
def test_evolve_a_network_on_each_backend_and_resume(tmp_path, capsys, backend):
    out = tmp_path / "run"
    argv = ["evolve", "--out", str(out), "--generations", "1", "--shape", "4", "4", "4",
            "--controller", "distributed", "--hidden", "4", "--signals", "2", *backend, *_TINY]  # fmt: skip
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["controller"] == "distributed" and summary["generations"] == 1
    exp = _config(out)["experiment"]
    assert (exp["controller"], exp["hidden"], exp["signals"], exp["body"]) == (
        "distributed",
        4,
        2,
        None,
    )
    best = json.loads((out / "best_design.json").read_text())
    assert best["brain"]["kind"] == "distributed" and best["brain"]["hidden"] == 4
    assert main(["evolve", "--out", str(out), "--resume", "--generations", "2", "--quiet",
                 "--no-figures", "--no-gif"]) == 0  # fmt: skip
    assert json.loads(capsys.readouterr().out)["generations"] == 2
    assert (
        main(["evolve", "--out", str(out), "--resume", "--controller", "central", "--quiet"]) == 2
    )
    assert "--controller distributed, not central" in capsys.readouterr().err


def test_evolve_cmaes_on_a_fixed_body_records_it_and_resumes(tmp_path, capsys):
    out = tmp_path / "cma"
    body = _small_body(tmp_path / "body.json")
    argv = ["evolve", "--out", str(out), "--generations", "1", "--backend", "pymoo",
            "--algorithm", "cmaes", "--controller", "distributed", "--body", body, *_TINY]  # fmt: skip
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["fixed_body"] and summary["controller"] == "distributed"
    cfg = _config(out)
    assert cfg["algorithm"] == "cmaes" and cfg["experiment"]["shape"] == [4, 4, 4]
    assert RobotDesign.from_dict(cfg["experiment"]["body"]) == RobotDesign.load(body)
    assert main(["evolve", "--out", str(out), "--resume", "--generations", "2", "--body", body,
                 "--quiet", "--no-figures", "--no-gif"]) == 0  # fmt: skip
    assert json.loads(capsys.readouterr().out)["generations"] == 2
    assert main(["evolve", "--out", str(out), "--resume", "--body", "walker", "--quiet"]) == 2
    assert "--body its own body, not walker" in capsys.readouterr().err


def test_qd_with_a_network(tmp_path, capsys):
    pytest.importorskip("ribs")
    out = tmp_path / "qd"
    assert main(["qd", "--out", str(out), "--generations", "1", "--batch", "4", "--shape", "4", "4",
                 "4", "--seconds", "1.5", "--cells", "4", "--controller", "central",
                 "--no-figures", "--quiet"]) == 0  # fmt: skip
    summary = json.loads(capsys.readouterr().out)
    assert summary["controller"] == "central" and summary["num_elites"] >= 1
    assert _config(out)["experiment"]["controller"] == "central"
    assert main(["qd", "--out", str(out), "--resume", "--generations", "2", "--quiet",
                 "--no-figures"]) == 0  # fmt: skip


def _bad_body_file(tmp_path):
    p = tmp_path / "bad.json"
    p.write_text('{"grid": ')
    return str(p)


@pytest.mark.parametrize(
    "flags, word",
    [
        (["--controller", "lstm"], "--controller"),
        (["--controller", "central", "--signals", "2"], "--signals"),
        (["--signals", "2"], "--signals"),
        (["--hidden", "4"], "--hidden"),
        (["--controller", "central", "--hidden", "-1"], "hidden"),
        (["--controller", "distributed", "--control-dt", "0"], "control_dt"),
        (["--controller", "central", "--body", "BAD"], "--body"),
        (["--controller", "central", "--body", "MISSING"], "--body"),
        (["--controller", "central", "--body", "walker", "--shape", "4", "4", "4"], "shape"),
        (["--body", "walker", "--backend", "pymoo", "--algorithm", "cmaes"], "network"),
        (["--experiment", "materials", "--backend", "pymoo", "--algorithm", "cmaes"], "genes"),
        (["--experiment", "materials", "--controller", "central", "--body", "walker"], "materials"),
    ],
)
def test_bad_controller_input_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys, flags, word):
    flags = [_bad_body_file(tmp_path) if f == "BAD" else str(tmp_path / "no.json") if f == "MISSING"
             else f for f in flags]  # fmt: skip
    for command in (["evolve"], ["qd"]):
        if command == ["qd"] and ("--backend" in flags or "--experiment" in flags):
            continue
        out = tmp_path / "run"
        assert main([*command, "--out", str(out), *flags, "--quiet"]) == 2
        err = capsys.readouterr().err
        lines = err.splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"softgym {command[0]}: "), err
        assert word in lines[0] and "Traceback" not in err
        assert not out.exists()
