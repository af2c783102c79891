"""What a new user tripped over (issue 64): the kernel build shown, every flag checked before
anything is written, nothing silently ignored, options after ``run``, plain help, folders named.
"""

import ast
import json
import sys
import types
import warnings
from pathlib import Path

import pytest

from softgym_cli import main

TINY = ["--pop", "4", "--seconds", "1.2", "--shape", "3", "3", "3", "--quiet", "--no-gif"]
ROOT = Path(__file__).resolve().parents[1]


def _one_line(capsys, argv, command):
    assert main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"softgym {command}: "), captured.err
    assert captured.out == ""
    return lines[0]


@pytest.fixture(scope="module")
def evolve_run(tmp_path_factory):
    run = tmp_path_factory.mktemp("evolve") / "run"
    assert main(["evolve", "--out", str(run), "--generations", "0", "--no-figures", *TINY]) == 0
    return run


# ---------------------------------------------------------------------- 1, 2: kernel build
def test_info_and_version_print_the_kernel_build_in_use(capsys):
    from softgym.engine import available_kernels, kernel_build, openmp_enabled
    from softgym.engine._dispatch import installed_kernels

    assert main(["info"]) == 0
    text = capsys.readouterr().out
    assert f"kernel in use:     {kernel_build()}" in text
    assert f"kernels installed: {', '.join(installed_kernels())}" in text
    assert ("OpenMP:            on" if openmp_enabled() else "OpenMP:            off") in text
    assert main(["info", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["kernel"] == kernel_build() and info["this_cpu_runs"] == available_kernels()
    assert info["installed"] == installed_kernels() and info["openmp"] == openmp_enabled()
    assert "baseline" in info["installed"]
    with pytest.raises(SystemExit):
        main(["--version"])
    line = capsys.readouterr().out.splitlines()[1]
    assert line.startswith(f"kernel {kernel_build()}") and "OpenMP o" in line


def test_setup_warns_in_the_build_log_when_a_kernel_variant_is_dropped():
    tree = ast.parse((ROOT / "setup.py").read_text())
    func = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "_kernel_levels")
    host = {  # an x86-64 Linux build whose compiler takes -march=x86-64-v3 but not v4
        "os": types.SimpleNamespace(environ={"CC": "old-cc"}),
        "sys": types.SimpleNamespace(platform="linux"),
        "platform": types.SimpleNamespace(machine=lambda: "x86_64"),
        "sysconfig": types.SimpleNamespace(get_platform=lambda: "linux-x86_64",
                                           get_config_var=lambda name: "cc"),  # fmt: skip
        "warnings": warnings,
        "_compiler_takes": lambda flag: flag == "-march=x86-64-v3",
    }
    exec(compile(ast.Module([func], []), "setup.py", "exec"), host)
    with pytest.warns(UserWarning, match=r"x86-64-v4 are NOT built") as caught:
        assert host["_kernel_levels"]() == ["v3"]  # what is built is unchanged
    assert len(caught) == 1 and "old-cc" in str(caught[0].message)
    assert "x86-64-v3" not in str(caught[0].message).split("NOT built")[0].split("variant(s)")[1]
    host["_compiler_takes"] = lambda flag: True
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert host["_kernel_levels"]() == ["v3", "v4"]  # nothing dropped: no warning


# ---------------------------------------------------------------------- 3, 4: checked first
@pytest.mark.parametrize(
    ("command", "flags", "needle"),
    [
        ("evolve", ["--shape", "0", "0", "0"], "--shape (0, 0, 0): each side must lie in 1.."),
        ("evolve", ["--threads", "0"], "--threads must be an integer in 1..1024 (left out for all usable CPUs), got 0"),
        ("evolve", ["--seconds", "1"], "--seconds must be more than the 1 s settling time"),
        ("qd", ["--shape", "0", "0", "0"], "--shape (0, 0, 0)"),
        ("qd", ["--threads", "0"], "--threads must be an integer in 1..1024 (left out for all usable CPUs), got 0"),
        ("qd", ["--seconds", "0.5"], "--seconds must be more than the 1 s settling time"),
        ("poet", ["--shape", "0", "0", "0"], "--shape (0, 0, 0)"),
        ("poet", ["--threads", "0"], "--threads must be an integer in 1..1024 (left out for all usable CPUs), got 0"),
        ("poet", ["--seconds", "1"], "got 1"),
        ("study", ["--shape", "0", "0", "0", "--scenarios", "basic", "--seeds", "1"],
         "shape (--shape) (0, 0, 0): each side must lie in 1.."),
        ("study", ["--threads", "0", "--scenarios", "basic", "--seeds", "1"],
         "n_threads (--threads) must be an integer in 1..1024"),
        ("evolve", ["--max-evals", "0"], "--max-evals must be an integer >= 1"),
    ],
)  # fmt: skip
def test_bad_flags_are_refused_before_a_bar_or_a_file(tmp_path, capsys, command, flags, needle):
    out = tmp_path / "run"
    line = _one_line(capsys, [command, *flags, "--out", str(out)], command)  # no --quiet: no bar
    assert needle in line
    assert not out.exists()  # no .lock, config.json, identity.json, study.json


def test_no_figures_on_resume_draws_none_and_says_so(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["evolve", "--out", str(out), "--generations", "0", *TINY]) == 0
    capsys.readouterr()
    before = {p.name: p.stat().st_mtime_ns for p in (out / "figures").iterdir()}
    assert before
    argv = ["evolve", "--out", str(out), "--generations", "1", "--resume", "--no-figures", "-q"]
    assert main(argv) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["figures"] == []
    assert {p.name: p.stat().st_mtime_ns for p in (out / "figures").iterdir()} == before
    (line,) = captured.err.splitlines()
    assert line.startswith("softgym evolve: --no-figures: ") and "not redrawn" in line


def test_selection_with_the_pymoo_backend_warns_in_one_line(tmp_path, capsys):
    argv = ["evolve", "--backend", "pymoo", "--selection", "tournament", "--generations", "0",
            "--out", str(tmp_path / "run"), "--no-figures", *TINY]  # fmt: skip
    assert main(argv) == 0
    assert capsys.readouterr().err.splitlines() == [
        "softgym evolve: warning: --selection tournament is ignored with --backend pymoo "
        "(pymoo's nsga2 does its own survival)"
    ]
    assert main([*argv[:3], "--generations", "0", "--out", str(tmp_path / "n"), "--no-figures",
                 *TINY]) == 0  # fmt: skip
    assert capsys.readouterr().err == ""  # no --selection: no word


def test_study_seconds_at_the_settling_time_is_named(tmp_path, capsys):
    argv = ["study", "--scenarios", "basic", "--seeds", "1", "--seconds", "1", "--plan",
            "--out", str(tmp_path / "s")]  # fmt: skip
    assert main(argv) == 0
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("softgym study: warning: --seconds 1 is not more than the 1 s")


# ---------------------------------------------------------------------- 5: the parser
def _args(argv):
    from softgym_cli.parser import _parser

    return _parser()[0].parse_args(argv)


def test_options_go_before_or_after_run():
    for command, length in (("qd", "--generations"), ("poet", "--iterations")):
        dest = length.lstrip("-")
        after = _args([command, "run", length, "1", "--out", "x", "--threads", "2"])
        before = _args([command, length, "1", "--out", "x", "--threads", "2", "run"])
        for args in (after, before):
            assert getattr(args, dest) == 1 and args.out == "x" and args.threads == 2
        plain = _args([command, "run"])
        assert plain.out == f"runs/{command}" and plain.workers == 2 and not plain.resume
    args = _args(["study", "run", "--plan", "--seeds", "2"])
    assert args.plan and args.seeds == 2 and args.out == "runs/study"
    assert _args(["study", "--seeds", "2", "run"]).seeds == 2


@pytest.mark.parametrize("command", ["qd", "poet", "study"])
def test_run_help_lists_the_options_and_their_defaults(capsys, command):
    with pytest.raises(SystemExit):
        main([command, "run", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--out OUT" in text and "--seconds SECONDS" in text
    assert f"(default: runs/{command})" in text


def test_help_is_plain_text_and_each_command_says_what_q_and_v_do(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    text = capsys.readouterr().out
    assert "``" not in text and ":mod:" not in text and "The softgym command line" in text
    quiet = {}
    for command in ("evolve", "poet", "study", "replay"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        help_text = " ".join(capsys.readouterr().out.split())
        quiet[command] = help_text.split("-q, --quiet ")[1].split(" --")[0]
    assert quiet["evolve"] == "no progress bar"
    assert "no line per started and finished run" in quiet["study"]
    assert "draws no progress bar" in quiet["replay"]
    assert "study" not in quiet["evolve"] + quiet["poet"] + quiet["replay"]


# ---------------------------------------------------------------------- 6: folders, extras
def test_study_report_and_replay_say_what_a_folder_is(tmp_path, capsys, evolve_run):
    line = _one_line(capsys, ["study", "report", str(evolve_run)], "study report")
    assert f"{evolve_run} is an evolve run folder" in line
    assert f"softgym replay/view/compare {evolve_run}" in line
    assert not (evolve_run / "report").exists()
    poet = tmp_path / "poet"
    assert main(["poet", "--iterations", "0", "--pop", "3", "--seconds", "1.2", "--shape", "3",
                 "3", "3", "-q", "--no-figures", "--out", str(poet)]) == 0  # fmt: skip
    capsys.readouterr()
    line = _one_line(capsys, ["replay", str(poet)], "replay")
    assert f"{poet} is a POET run folder (softgym poet), which replay does not read" in line
    assert f"softgym view {poet}" in line and "is not a finished run folder" not in line
    assert not (poet / "replay").exists()


def test_missing_extra_hints_say_pypi_and_checkout(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # as if Dask were not installed
    out = tmp_path / "d"
    line = _one_line(capsys, ["evolve", "--dask", "local", "--out", str(out), *TINY], "evolve")
    assert 'pip install "softgym[distributed]", or pip install -e ".[distributed]" in a checkout' in line
    assert not out.exists()


def test_replay_video_checks_the_extra_before_simulating(evolve_run, capsys, monkeypatch):
    import importlib

    module = importlib.import_module("softgym.evaluate")  # softgym.evaluate is the function too
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # as if the extra were missing
    monkeypatch.setattr(module, "evaluate", lambda *a, **k: pytest.fail("simulated"))
    line = _one_line(capsys, ["replay", str(evolve_run), "--video", "--no-gif"], "replay")
    assert "--video needs imageio and imageio-ffmpeg" in line
    assert 'pip install "softgym[video]", or pip install -e ".[video]" in a checkout' in line
    assert not (evolve_run / "replay").exists()


# ---------------------------------------------------------------------- 7: study progress
def test_study_prints_a_line_per_started_and_finished_run(tmp_path, capsys):
    argv = ["study", "--scenarios", "basic", "--seeds", "2", "--generations", "0", "--pop", "4",
            "--seconds", "1.2", "--shape", "3", "3", "3", "--out", str(tmp_path / "s")]  # fmt: skip
    assert main(argv) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("basic") and "seed 0" in lines[0] and "started  [1/2]" in lines[0]
    assert "seed 0" in lines[1] and " ran " in lines[1] and "[1/2 done]" in lines[1]
    assert "started  [2/2]" in lines[2] and "[2/2 done]" in lines[3]
    assert lines[4] == "{"  # then the JSON summary
    assert main([*argv, "-q"]) == 0
    assert capsys.readouterr().out.startswith("{")  # -q: the summary alone
