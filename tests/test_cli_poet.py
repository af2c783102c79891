"""softgym poet: a tiny run, its resume (a differing flag is named), compare, view, bad input."""

import json

from softgym_cli import main

_TINY = ["--pop", "3", "--seconds", "1.2", "--shape", "3", "3", "3", "--reproduce-every", "1",
         "--transfer-every", "1", "--no-figures", "--quiet"]  # fmt: skip


def test_poet_runs_resumes_and_compares(tmp_path, capsys):
    out = str(tmp_path / "p")
    assert main(["poet", "--iterations", "1", "--out", out, *_TINY]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["iterations"] == 1 and summary["generator"] == "mutate"
    assert main(["poet", "--out", out, "--resume", "--iterations", "2", "--quiet",
                 "--no-figures"]) == 0  # fmt: skip
    rows = [json.loads(x) for x in (tmp_path / "p" / "log.jsonl").read_text().splitlines()]
    assert [r["generation"] for r in rows] == [0, 1, 2]
    assert all(
        {"annecs", "terrains", "admitted", "rejected", "transfers"} <= r.keys() for r in rows
    )
    capsys.readouterr()
    assert main(["poet", "--out", out, "--resume", "--max-active", "5"]) == 2
    assert "poet.max_active: 8 (recorded) != 5" in capsys.readouterr().err
    fig = tmp_path / "annecs.png"
    assert main(["poet", "compare", out, "--out", str(fig)]) == 0
    assert fig.is_file() and "POET: 1 run(s)" in capsys.readouterr().out
    # softgym view shows the best robot of the pairs, on its own terrain
    assert main(["view", out, "--seconds", "0.3", "--fps", "2"]) == 0
    assert "best robot (POET pair" in (tmp_path / "p" / "view.html").read_text()


def test_poet_bad_input_is_one_line_and_exit_2(tmp_path, capsys):
    assert main(["poet", "--out", str(tmp_path / "x"), "--mc-low", "9", "--mc-high", "4"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("softgym poet: the minimal-criterion band") and "\n" not in err
    bad = tmp_path / "g.json"
    bad.write_text(json.dumps({"fence_height": 7}))
    assert main(["poet", "--out", str(tmp_path / "y"), "--start-terrain", str(bad)]) == 2
    assert "fence_height = 7 is outside [0, 2]" in capsys.readouterr().err
    assert main(["poet", "compare", str(tmp_path / "nope")]) == 2
