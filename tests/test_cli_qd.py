"""softgym qd: a tiny MAP-Elites run, its resume (a differing flag is named), and qd export."""

import json

import pytest

pytest.importorskip("ribs")

from softgym_cli import main  # noqa: E402

_TINY = ["--batch", "4", "--shape", "4", "4", "4", "--seconds", "1.2", "--cells", "8",
         "--no-figures", "--quiet"]  # fmt: skip


def test_qd_runs_resumes_and_exports(tmp_path, capsys):
    out = str(tmp_path / "qd")
    assert main(["qd", "--generations", "1", "--out", out, *_TINY]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["generations"] == 1 and summary["num_elites"] >= 1
    assert summary["archive"]["cells"] == [8, 8] and summary["export"].endswith(out)
    assert main(["qd", "--out", out, "--resume", "--generations", "2", "--quiet"]) == 0
    rows = [json.loads(line) for line in (tmp_path / "qd" / "log.jsonl").read_text().splitlines()]
    assert [r["generation"] for r in rows] == [0, 1, 2]
    assert all({"qd_score", "coverage", "qd_best"} <= r.keys() for r in rows)
    capsys.readouterr()
    assert main(["qd", "--out", out, "--resume", "--seed", "5"]) == 2
    assert "seed: 0 (recorded) != 5" in capsys.readouterr().err
    assert main(["qd", "export", out, "--top", "2"]) == 0
    assert "wrote 2 elites" in capsys.readouterr().out or rows[-1]["num_elites"] < 2
    assert len(list((tmp_path / "qd" / "elites").glob("*.vxa"))) == min(2, rows[-1]["num_elites"])
