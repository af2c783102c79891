"""scripts/study_state.py: a study saved on one machine resumes exactly on another."""

import importlib.util
import json
from pathlib import Path

from softgym_cli import main

ROOT = Path(__file__).resolve().parents[3]
_spec = importlib.util.spec_from_file_location("study_state", ROOT / "scripts" / "study_state.py")
study_state = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(study_state)

STUDY = ["study", "--scenarios", "basic", "--seeds", "1", "--pop", "4", "--seconds", "1",
         "--shape", "3", "3", "3", "--quiet"]  # fmt: skip


def _rows(run: Path) -> list[dict]:
    rows = [json.loads(x) for x in (run / "log.jsonl").read_text().splitlines()]
    return [{k: v for k, v in r.items() if "wall" not in k and "time" not in k} for r in rows]


def test_saved_study_resumes_exactly_elsewhere(tmp_path):
    first, saved, second, straight = (tmp_path / n for n in ("a", "saved", "b", "straight"))
    assert main([*STUDY, "--generations", "1", "--out", str(first)]) == 0
    assert main([*STUDY, "--generations", "2", "--out", str(first)]) == 0  # 3 checkpoints now
    # a complete run keeps its log and designs, not its checkpoints (the study skips it)
    study_state.save(first, tmp_path / "complete")
    done = tmp_path / "complete" / "basic" / "seed-0"
    assert (done / "final_population.json").is_file() and not (done / "checkpoints").exists()
    # a run killed before its end (no final_population.json yet, as after a kill -9)
    (first / "basic" / "seed-0" / "final_population.json").unlink()
    # only what resuming needs: the newest checkpoint, no figures, no .vxa
    print(study_state.save(first, saved))
    run = saved / "basic" / "seed-0"
    ckpts = sorted(p.name for p in (run / "checkpoints").iterdir())
    assert ckpts == ["ckpt-000002.json", "ckpt-000002.npz"]
    assert not list(saved.rglob("*.png")) and not list(saved.rglob("*.vxa"))
    assert (saved / "basic" / "scenario.json").is_file() and (run / "log.jsonl").is_file()
    # saving again writes nothing (a committed copy only changes where the study moved on)
    assert study_state.save(first, saved).endswith("0 files written, 0 removed")

    assert "restored 1 run folders" in study_state.restore(saved, second)
    assert main([*STUDY, "--generations", "4", "--out", str(second)]) == 0
    assert main([*STUDY, "--generations", "4", "--out", str(straight)]) == 0
    assert _rows(second / "basic" / "seed-0") == _rows(straight / "basic" / "seed-0")
    assert len(_rows(straight / "basic" / "seed-0")) == 5
    # restore never moves a run back; saving the now complete run drops its checkpoint
    assert "left 1 alone" in study_state.restore(saved, second)
    assert _rows(second / "basic" / "seed-0") == _rows(straight / "basic" / "seed-0")
    assert "2 removed" in study_state.save(second, saved)
    assert not list((run / "checkpoints").glob("*")) and (run / "final_population.json").is_file()
    # a scenario moved aside in the run root (e.g. renamed when its settings changed) leaves
    # the saved copy too, and its new name arrives
    (second / "basic").rename(second / "basic-old")
    n_files = sum(f.is_file() for f in (saved / "basic").rglob("*"))  # with scenario.json
    msg = study_state.save(second, saved)  # without --prune: kept, and the line says so
    assert "1 run folders in" in msg and "--prune removes them" in msg
    assert (saved / "basic" / "seed-0" / "log.jsonl").is_file()
    msg = study_state.save(second, saved, prune=True)
    assert msg.endswith(f"pruned 1 run folders {second} no longer has ({n_files} files)")
    assert not (saved / "basic").exists()
    assert (saved / "basic-old" / "seed-0" / "log.jsonl").is_file()


def test_missing_folders_are_one_line_and_exit_2(tmp_path, capsys):
    assert study_state.main(["restore", str(tmp_path / "nothing"), str(tmp_path / "runs")]) == 2
    assert study_state.main(["save", str(tmp_path / "nothing"), str(tmp_path / "saved")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and all(e.startswith("study_state: ") for e in err)
    assert not (tmp_path / "runs").exists() and not (tmp_path / "saved").exists()
