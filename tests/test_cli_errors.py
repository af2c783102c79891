"""Bad input on the command line: one line on stderr and exit 2; ``--debug`` shows the traceback."""

import os
import sys

import pytest
from fuzzing import refused_in_child  # tests/fuzzing.py

from softgym.exceptions import CheckpointError, InvalidDesignError, SoftGymError
from softgym_cli import main

TINY = ["--pop", "4", "--seconds", "1.2", "--shape", "4", "4", "4", "--quiet", "--no-figures"]
#: One short generation of a few small robots per run command (what a refused input would
#: have started, had it been taken: never a long run, even on a softgym without the check).
SMALL = {
    "evolve": ["--generations", "0", "--no-gif", *TINY],
    "qd": ["--generations", "0", "--batch", "4", "--seconds", "1.2", "--shape", "4", "4", "4",
           "--quiet", "--no-figures", "--no-gif"],
    "poet": ["--iterations", "0", "--pop", "4", "--seconds", "1.2", "--shape", "4", "4", "4",
             "--quiet", "--no-figures"],
    "study": ["--generations", "0", "--pop", "4", "--seconds", "1.2", "--shape", "4", "4", "4",
              "--quiet"],
}  # fmt: skip


def _one_line_error(capsys, argv, command):
    assert main(argv) == 2
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"softgym {command}: ")
    assert "Traceback" not in err
    return lines[0]


def test_simulate_bad_design_and_seconds(tmp_path, capsys):
    missing = tmp_path / "missing.json"
    assert str(missing) in _one_line_error(
        capsys, ["simulate", "--design", str(missing)], "simulate"
    )
    bad = tmp_path / "bad.json"
    bad.write_text('{"grid": ')
    assert str(bad) in _one_line_error(capsys, ["simulate", "--design", str(bad)], "simulate")
    line = _one_line_error(
        capsys, ["simulate", "--seconds", "-1", "--out", str(tmp_path)], "simulate"
    )
    assert "seconds" in line
    with pytest.raises(InvalidDesignError):
        main(["--debug", "simulate", "--design", str(bad)])


def test_evolve_out_that_cannot_be_a_run_folder(tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("not a folder")
    for out in (afile, afile / "run"):  # an existing file, a path under a file
        line = _one_line_error(capsys, ["evolve", "--out", str(out), *TINY], "evolve")
        assert str(out) in line
    assert afile.read_text() == "not a folder"
    with pytest.raises(OSError):
        main(["--debug", "evolve", "--out", str(afile / "run"), *TINY])


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc refuses new folders")
def test_evolve_out_in_an_unwritable_place(capsys):
    out = "/proc/softgym-run"  # even root cannot create a folder here
    assert out in _one_line_error(capsys, ["evolve", "--out", out, *TINY], "evolve")


@pytest.mark.skipif(
    not hasattr(os, "geteuid") or os.geteuid() == 0, reason="root ignores folder permissions"
)
def test_evolve_out_in_a_read_only_folder(tmp_path, capsys):
    ro = tmp_path / "ro"
    ro.mkdir(mode=0o500)
    try:
        out = ro / "run"
        assert str(out) in _one_line_error(capsys, ["evolve", "--out", str(out), *TINY], "evolve")
    finally:
        ro.chmod(0o700)


def test_compare_reads_config_through_read_json(tmp_path, capsys):
    line = _one_line_error(capsys, ["compare", str(tmp_path / "nonexistent")], "compare")
    assert str(tmp_path / "nonexistent" / "config.json") in line and "does not exist" in line
    run = tmp_path / "run"
    run.mkdir()
    (run / "config.json").write_text('{"experiment": ')
    assert str(run / "config.json") in _one_line_error(capsys, ["compare", str(run)], "compare")
    (run / "config.json").write_text("[1, 2]")  # JSON, but not a run config
    line = _one_line_error(capsys, ["compare", str(run)], "compare")
    assert str(run / "config.json") in line and "not a softgym run config" in line
    with pytest.raises(CheckpointError, match="config.json"):
        main(["--debug", "compare", str(run)])


def test_debug_flag_leaves_success_alone(capsys):
    assert main(["--debug", "experiments"]) == 0
    assert "controller-tournament" in capsys.readouterr().out
    assert issubclass(CheckpointError, SoftGymError)


def test_resume_of_a_folder_without_a_run_refuses(tmp_path, capsys):
    for command in ("evolve", "qd", "poet"):
        out = tmp_path / command
        line = _one_line_error(capsys, [command, "--out", str(out), "--resume", "-q"], command)
        assert str(out) in line and "no run to resume" in line
        assert not out.exists()  # nothing was started
    with pytest.raises(CheckpointError):
        main(["--debug", "evolve", "--out", str(tmp_path / "x"), "--resume"])


def test_version_and_global_flags_on_either_side(capsys):
    from importlib.metadata import version

    with pytest.raises(SystemExit) as exit_:
        main(["--version"])
    assert exit_.value.code == 0
    first, kernel = capsys.readouterr().out.strip().splitlines()
    assert first == f"softgym {version('softgym')}"
    assert kernel.startswith("kernel ") and "installed: baseline" in kernel and "OpenMP" in kernel
    import softgym

    assert softgym.__version__ == version("softgym")  # one source: pyproject.toml
    for argv in (["-v", "-q", "experiments"], ["experiments", "-v", "--quiet"]):
        assert main(argv) == 0
        assert "controller-tournament" in capsys.readouterr().out


def test_the_library_does_not_import_the_cli_or_the_evolvers():
    import ast
    from pathlib import Path

    import softgym

    root = Path(softgym.__file__).parent
    for path in root.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])  # fmt: skip
            for name in names:
                top = name.split(".")[0]
                assert top not in ("evolvers", "softgym_cli"), f"{path} imports {name}"


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        # issue 31: each of these hung, tracebacked or allocated gigabytes
        (["evolve", "--pop", "100000000"], "pop_size must be an integer in [2, 100000]"),
        (["qd", "--cells", "20000", "20000"], "more than 1000000"),
        (["evolve", "--dask", "local", "--workers", "0"], "n_workers >= 1"),
    ],
)  # fmt: skip
def test_sizes_that_would_hang_or_exhaust_memory_are_refused_in_one_line(tmp_path, capsys,
                                                                         argv, needle):  # fmt: skip
    line = _one_line_error(capsys, [*argv, "--out", str(tmp_path / "run")], argv[0])
    assert needle in line


def test_compare_into_a_format_matplotlib_cannot_write_is_one_line(tmp_path, capsys):
    line = _one_line_error(capsys, ["compare", str(tmp_path), "--out", str(tmp_path / "c.xyz")],
                           "compare")  # fmt: skip
    assert "c.xyz" in line and "not a format matplotlib writes" in line


def _one_line_error_in_child(argv, command, timeout=60, cwd=None):
    """``softgym ARGV`` in a child process (a hang fails the test by ``timeout``): one line, exit 2."""
    import subprocess

    res = subprocess.run([sys.executable, "-m", "softgym_cli", *argv], capture_output=True,
                         text=True, timeout=timeout, cwd=cwd)  # fmt: skip
    lines = res.stderr.splitlines()
    assert res.returncode == 2 and len(lines) == 1, res.stderr[-2000:]
    assert lines[0].startswith(f"softgym {command}: ") and "Traceback" not in res.stderr
    return lines[0]


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        # issue 61, hang 3: these ran (or planned) for ever; capped like the population
        (["evolve", "--generations", "999999999999999999999"],
         "generations must be an integer in [0, 1000000]"),
        (["poet", "--iterations", "99999999999"], "iterations must be an integer in [0, 1000000]"),
        (["study", "--seeds", "1000000000", "--plan"], "seeds must be an integer in [1, 10000]"),
        (["study", "--generations", "99999999999", "--plan"],
         "generations must be an integer in [0, 1000000]"),
        # issue 61, hang 1: NSGA-III's reference directions never ended on one objective
        (["evolve", "--backend", "pymoo", "--algorithm", "nsga3"],
         "'nsga3' needs at least 2 objectives"),
    ],
)  # fmt: skip
def test_counts_and_algorithms_that_would_run_for_ever_are_refused_in_one_line(tmp_path, argv,
                                                                                needle):  # fmt: skip
    out = tmp_path / "run"
    line = _one_line_error_in_child([*argv, "--out", str(out)], argv[0])
    assert needle in line
    assert not out.exists()  # nothing was written


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        # issue 61, item 11: each was a traceback
        (["evolve", "--seed", "-1"], "seed must be an integer in [0, 4294967295], got -1"),
        (["qd", "--seed", "-1"], "seed must be an integer in [0, 4294967295], got -1"),
        (["poet", "--seed", "-1"], "seed must be an integer in [0, 4294967295], got -1"),
        (["study", "--first-seed", "-1", "--plan"], "first_seed must be an integer in [0, "),
        (["study", "--first-seed", "4294967295", "--seeds", "2", "--plan"], "at most 4294967295"),
        (["evolve", "--dask", "garbage"], "--dask"),
        (["evolve", "--backend", "pymoo", "--algorithm", "sms-emoa"],
         "'sms-emoa' needs at least 2 objectives"),
        (["evolve", "--backend", "pymoo", "--algorithm", "nsga3", "--experiment", "novelty"],
         "'nsga3' needs at least 2 objectives"),
    ],
)  # fmt: skip
def test_bad_seeds_addresses_and_algorithms_are_one_line_before_anything_is_written(
    tmp_path, capsys, argv, needle
):
    out = tmp_path / "run"
    line = _one_line_error(capsys, [*argv, *SMALL[argv[0]], "--out", str(out)], argv[0])
    assert needle in line
    assert not out.exists()


@pytest.mark.parametrize("command", ["evolve", "qd", "poet", "study"])
def test_an_empty_out_is_refused_not_taken_as_the_current_folder(tmp_path, monkeypatch, capsys,
                                                                 command):  # fmt: skip
    monkeypatch.chdir(tmp_path)
    extra = ["--plan", "--seeds", "1"] if command == "study" else []
    line = _one_line_error(capsys, [command, *SMALL[command], "--out", "", *extra], command)
    assert "--out" in line and "''" in line
    assert list(tmp_path.iterdir()) == []  # nothing written into the current folder


def test_a_folder_of_a_users_files_is_refused_not_overwritten(tmp_path, capsys):
    # issue 61, item 7: a folder without config.json counted as fresh; its log.csv was replaced
    out = tmp_path / "mine"
    out.mkdir()
    (out / "log.csv").write_text("my data\n")
    for command in ("evolve", "qd", "poet"):
        line = _one_line_error(capsys, [command, *SMALL[command], "--out", str(out)], command)
        assert str(out) in line and "log.csv" in line and "holds no run" in line
        assert "another --out" in line
    assert sorted(p.name for p in out.iterdir() if p.name != ".lock") == ["log.csv"]
    assert (out / "log.csv").read_text() == "my data\n"


def test_replay_shorter_than_the_settling_time_and_of_a_fifo_is_one_line(tmp_path, capsys):
    # issue 61: replay --seconds 0.5 was an IndexError in plot_trajectory (no trace sample
    # after the 1 s settling); a FIFO config.json blocked replay for ever (read_text)
    run = tmp_path / "run"
    assert main(["evolve", "--out", str(run), "--generations", "0", "--no-gif", *TINY]) == 0
    capsys.readouterr()
    line = _one_line_error(capsys, ["replay", str(run), "--seconds", "0.5", "--no-gif",
                                    "--out", str(tmp_path / "replay")], "replay")  # fmt: skip
    assert "--seconds must be more than the 1 s settling time" in line and "0.5" in line
    assert not (tmp_path / "replay").exists()
    if hasattr(os, "mkfifo"):
        (run / "config.json").unlink()
        os.mkfifo(run / "config.json")
        code = ("from softgym_cli import main\n"
                f"print('REFUSED' if main(['replay', {str(run)!r}, '--no-gif']) == 2 else 'RAN')\n")  # fmt: skip
        refused_in_child(code, timeout=60)


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory):
    """A finished tiny evolve run (one generation), copied by each test that damages it."""
    run = tmp_path_factory.mktemp("finished") / "run"
    assert main(["evolve", "--out", str(run), "--generations", "0", "--no-gif", *TINY]) == 0
    return run


def _copy(run, tmp_path, name="run"):
    import shutil

    shutil.copytree(run, tmp_path / name, ignore=shutil.ignore_patterns(".lock"))
    return tmp_path / name


def _edit_json(path, edit):
    import json

    doc = json.loads(path.read_text())
    edit(doc)
    path.write_text(json.dumps(doc))


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs")
def test_study_report_plan_and_resume_over_fifos_never_block(tmp_path, capsys):
    # issue 61, hang 2: study report read config.json, best_designs.json and scenario.json
    # with read_text, and --plan / a resume read log.jsonl and config.json so: a FIFO there
    # blocked for ever. Every run-folder read goes through the capped reader now.
    import shutil

    argv = ["study", "--scenarios", "basic", "--seeds", "1", *SMALL["study"]]
    argv.remove("--quiet")  # each run's line names why it failed
    root = tmp_path / "a"
    assert main([*argv, "--out", str(root)]) == 0
    capsys.readouterr()
    shutil.copytree(root, tmp_path / "b")
    shutil.copytree(root, tmp_path / "c")
    for name, files in (("a", ["basic/seed-0/config.json"]), ("b", ["basic/seed-0/log.jsonl"]),
                        ("c", ["basic/seed-0/best_designs.json", "basic/scenario.json"])):  # fmt: skip
        for f in files:
            (tmp_path / name / f).unlink()
            os.mkfifo(tmp_path / name / f)
    calls = []
    for name in "abc":
        out = str(tmp_path / name)
        calls += [["study", "report", out, "--out", str(tmp_path / f"report-{name}")]]
        if name != "c":
            calls += [[*argv, "--out", out, "--plan"], [*argv, "--out", out]]
    code = ("import contextlib, io\nfrom softgym_cli import main\n"
            f"for argv in {calls!r}:\n"
            "    err, out = io.StringIO(), io.StringIO()\n"
            "    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):\n"
            "        rc = main(argv)\n"
            "    print('REFUSED' if 'Traceback' not in err.getvalue() else 'TRACEBACK', rc,\n"
            "          repr(err.getvalue() + out.getvalue()))\n")  # fmt: skip
    lines = refused_in_child(code, timeout=120).splitlines()
    assert len(lines) == len(calls) and all(line.startswith("REFUSED") for line in lines), lines
    report_a, plan_a, run_a, report_b, plan_b, run_b, report_c = lines
    assert report_a.startswith("REFUSED 2") and report_b.startswith("REFUSED 2")  # the run skipped
    assert plan_a.startswith("REFUSED 0") and plan_b.startswith("REFUSED 0")
    assert run_a.startswith("REFUSED 1") and "config.json" in run_a and "not a regular file" in run_a
    assert run_b.startswith("REFUSED 0")  # the checkpoint resumed: the log is not read
    assert report_c.startswith("REFUSED 0")  # the run reported; its best robot left out
    assert (tmp_path / "report-c" / "README.md").is_file()


@pytest.mark.parametrize(
    ("file", "edit", "needle"),
    [
        ("config.json", lambda d: d["experiment"].update(objectives=5), "'objectives'"),
        ("config.json", lambda d: d["experiment"].pop("name"), "'name' is missing"),
        ("config.json", lambda d: d.update(seed="x"), "'seed' must be an integer"),
        ("config.json", lambda d: d.pop("backend"), "'backend' must be a string"),
        ("best_designs.json", lambda d: d.update(best=[5]), "'best'[0] must be an object, got 5"),
    ],
)  # fmt: skip
def test_malformed_run_files_are_one_line_in_view_compare_replay_and_resume(
    finished_run, tmp_path, capsys, file, edit, needle
):
    # issue 61, item 11: a malformed key was a KeyError or TypeError traceback
    run = _copy(finished_run, tmp_path)
    _edit_json(run / file, edit)
    before = sorted(p.name for p in run.rglob("*"))
    commands = [["replay", str(run), "--no-gif"]]
    if file == "config.json":
        commands += [["view", str(run)], ["compare", str(run), "--out", str(tmp_path / "c.png")],
                     ["evolve", "--out", str(run), "--resume", "--no-figures", "--quiet"]]  # fmt: skip
    for argv in commands:
        line = _one_line_error(capsys, argv, argv[0])
        assert needle in line and str(run / file) in line, line
    assert sorted(p.name for p in run.rglob("*")) == before  # nothing written


def test_malformed_logs_and_pairs_are_one_line_in_compare_view_and_poet_compare(
    finished_run, tmp_path, capsys
):
    import json

    run = _copy(finished_run, tmp_path)
    log = run / "log.jsonl"
    log.write_text(log.read_text() + json.dumps({"generation": 1}) + "\n")  # no metrics
    line = _one_line_error(capsys, ["compare", str(run), "--out", str(tmp_path / "c.png")], "compare")
    assert str(log) in line and "line 2 has no number" in line
    # a POET run's pairs.json with a pair that lacks its score
    _edit_json(run / "config.json", lambda d: d.update(poet={"generator": "mutate"}))
    (run / "pairs.json").write_text(json.dumps({"pairs": [{"id": 0}]}))
    line = _one_line_error(capsys, ["view", str(run)], "view")
    assert str(run / "pairs.json") in line and "'pairs'[0]['score'] must be a number" in line
    line = _one_line_error(capsys, ["poet", "compare", str(run), "--out", str(tmp_path / "p.png")],
                           "poet")  # fmt: skip
    assert str(log) in line and "'annecs'" in line
    _edit_json(run / "config.json", lambda d: d.update(poet=5))
    line = _one_line_error(capsys, ["poet", "compare", str(run), "--out", str(tmp_path / "p.png")],
                           "poet")  # fmt: skip
    assert "'generator'" in line
    # a figure format matplotlib cannot write, refused before any run is read
    line = _one_line_error(capsys, ["poet", "compare", str(tmp_path / "none"), "--out",
                                    str(tmp_path / "a.xyz")], "poet")  # fmt: skip
    assert "a.xyz" in line and "not a format matplotlib writes" in line
    assert not (tmp_path / "a.xyz").exists() and not (tmp_path / "p.png").exists()


def test_an_edited_config_is_refused_on_resume_in_one_line(finished_run, tmp_path, capsys):
    # issue 61, item 4: an edited population size resumed as the same run
    run = _copy(finished_run, tmp_path)
    _edit_json(run / "config.json", lambda d: d["experiment"].update(pop_size=6))
    line = _one_line_error(capsys, ["evolve", "--out", str(run), "--resume", "--no-figures",
                                    "--quiet"], "evolve")  # fmt: skip
    assert "config.json was changed after the run started" in line and "identity.json" in line


def test_an_out_path_thousands_of_folders_deep_is_one_line(tmp_path, monkeypatch, capsys):
    # issue 61, item 11: a RecursionError traceback (folders are created one call per level)
    monkeypatch.chdir(tmp_path)
    deep = "a/" * 2000
    for argv in (["evolve", *SMALL["evolve"]], ["compare", str(tmp_path)], ["view", str(tmp_path)]):
        line = _one_line_error(capsys, [*argv, "--out", deep], argv[0])
        assert "2000 folders deep, more than the 256" in line
    assert list(tmp_path.iterdir()) == []
