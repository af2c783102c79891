import csv
import json
import logging

import pytest
from evolver_helpers import tiny

from evolvers.drivers.runner import EvolutionRun, population_summary
from softgym.design import CompositionRules
from softgym.exceptions import CheckpointError
from softgym.io import list_checkpoints, load_checkpoint


class Crash(RuntimeError):
    pass


def _crash_after(gen):
    def cb(run, row):
        if row["generation"] == gen:
            raise Crash

    return cb


def test_run_folder_contents(tmp_path):
    exp = tiny("controller-pareto")
    run = EvolutionRun(exp, tmp_path / "r", seed=2, generations=2, figures=False)
    pop = run.run()
    out = tmp_path / "r"
    assert len(pop) == exp.pop_size
    cfg = json.loads((out / "config.json").read_text())
    assert cfg["experiment"]["name"] == "controller-pareto" and cfg["seed"] == 2
    rows = list(csv.DictReader((out / "log.csv").open()))
    assert [int(r["generation"]) for r in rows] == [0, 1, 2]
    for col in (
        "norm_final_dist_best",
        "norm_final_dist_median",
        "norm_final_dist_mean",
        "norm_final_dist_worst",
        "n_muscle_best",
        "evaluations",
        "wall_time",
    ):
        assert col in rows[0]
    assert int(rows[1]["evaluations"]) <= exp.pop_size + 1  # parents come from the cache
    assert [p.name for p in list_checkpoints(out / "checkpoints")] == [
        "ckpt-000000.json",
        "ckpt-000001.json",
        "ckpt-000002.json",
    ]
    best = json.loads((out / "best_designs.json").read_text())["best"]
    assert best[0]["objectives"]["norm_final_dist"] == max(
        b["objectives"]["norm_final_dist"] for b in best
    )
    assert (out / "best_design.json").exists() and (out / "final_population.json").exists()


@pytest.mark.parametrize("name", ["obstacles", "novelty-archive", "materials-t1"])
def test_interrupted_run_resumes_to_the_identical_result(tmp_path, name):
    exp = tiny(name, rules=CompositionRules.seed())  # no bone required: keeps the test fast
    ref = EvolutionRun(exp, tmp_path / "ref", seed=5, generations=3, figures=False).run()
    broken = EvolutionRun(
        exp, tmp_path / "b", seed=5, generations=3, figures=False, on_generation=_crash_after(1)
    )
    with pytest.raises(Crash):
        broken.run()
    resumed = EvolutionRun(exp, tmp_path / "b", seed=5, generations=3, figures=False)
    pop = resumed.run(resume=True)
    assert population_summary(pop) == population_summary(ref)
    assert [r["generation"] for r in resumed.rows] == [0, 1, 2, 3]


def test_corrupt_checkpoint_names_the_file_and_keeps_the_previous(tmp_path, caplog):
    # a corrupt newest checkpoint: resume falls back to the previous intact one, says so in
    # one line naming both files, redoes the lost generation and ends as an uninterrupted run
    exp = tiny()
    ref = EvolutionRun(exp, tmp_path / "ref", seed=1, generations=2, figures=False).run()
    EvolutionRun(exp, tmp_path / "r", seed=1, generations=1, figures=False).run()
    ckpts = list_checkpoints(tmp_path / "r" / "checkpoints")
    text = ckpts[-1].read_text()
    ckpts[-1].write_text(text[: len(text) // 2])  # truncated
    with caplog.at_level(logging.WARNING, logger="softgym.io"):
        run = EvolutionRun(exp, tmp_path / "r", seed=1, generations=2, figures=False)
        pop = run.run(resume=True)
    [line] = [r.getMessage() for r in caplog.records if r.name == "softgym.io"]
    assert "ckpt-000001.json" in line and "resuming from ckpt-000000.json" in line
    assert population_summary(pop) == population_summary(ref)
    assert [r["generation"] for r in run.rows] == [0, 1, 2]
    # a corrupt npz is named too; with no intact checkpoint left the resume stops, naming each
    ckpts = list_checkpoints(tmp_path / "r" / "checkpoints")
    npz = ckpts[0].with_suffix(".npz")
    npz.write_bytes(npz.read_bytes()[:100])
    with pytest.raises(CheckpointError, match="ckpt-000000.npz"):
        load_checkpoint(ckpts[0])
    for path in ckpts[1:]:
        path.write_text("{")
    with pytest.raises(CheckpointError, match="no intact checkpoint") as info:
        EvolutionRun(exp, tmp_path / "r", seed=1, generations=3, figures=False).run(resume=True)
    assert all(path.name in str(info.value) for path in ckpts[1:])
    assert "ckpt-000000.npz" in str(info.value)


def test_resume_refuses_another_experiment(tmp_path):
    EvolutionRun(tiny(), tmp_path / "r", seed=1, generations=0, figures=False).run()
    with pytest.raises(CheckpointError, match="seed"):
        EvolutionRun(tiny(), tmp_path / "r", seed=2, generations=1, figures=False).run(resume=True)
    with pytest.raises(CheckpointError, match="already holds a run"):
        EvolutionRun(tiny(), tmp_path / "r", seed=1, generations=1, figures=False).run()


def test_a_checkpoint_copied_in_from_another_run_is_never_resumed(tmp_path):
    # issue 31: a checkpoint of another run (here: the same settings, another folder)
    # copied into a run folder was resumed without a word, whatever its name
    import shutil

    a, b = tmp_path / "a", tmp_path / "b"
    EvolutionRun(tiny(), a, seed=1, generations=1, figures=False).run()
    EvolutionRun(tiny(), b, seed=1, generations=0, figures=False, gif=False).run()
    ids = {json.loads((d / "identity.json").read_text())["run_id"] for d in (a, b)}
    assert len(ids) == 2  # each run has its own identity
    newest_a = list_checkpoints(a / "checkpoints")[-1]
    for suffix in (".json", ".npz"):
        shutil.copy(newest_a.with_suffix(suffix), b / "checkpoints" / f"ckpt-000001{suffix}")
    run = EvolutionRun(tiny(), b, seed=1, generations=1, figures=False, gif=False)
    assert run.resume()
    assert run.generation == 0  # b's own checkpoint, not a's generation 1
    for p in (b / "checkpoints").glob("ckpt-0*"):
        if not p.name.startswith("ckpt-000001"):
            p.unlink()
    with pytest.raises(CheckpointError, match="belongs to another run"):
        EvolutionRun(tiny(), b, seed=1, generations=1, figures=False).run(resume=True)


def test_a_copied_checkpoint_without_identity_and_an_edited_config_are_refused(tmp_path):
    # issue 61, item 4: a's checkpoint with its identity deleted (and re-signed) resumed
    # as b's history; an edited population size in config.json resumed as the same run
    import shutil

    from softgym.io import json_sha256

    a, b = tmp_path / "a", tmp_path / "b"
    EvolutionRun(tiny(), a, seed=1, generations=1, figures=False, gif=False).run()
    EvolutionRun(tiny(), b, seed=1, generations=0, figures=False, gif=False).run()
    for p in (b / "checkpoints").glob("ckpt-*"):
        p.unlink()
    newest_a = list_checkpoints(a / "checkpoints")[-1]
    shutil.copy(newest_a.with_suffix(".npz"), b / "checkpoints" / "ckpt-000001.npz")
    doc = json.loads(newest_a.read_text())
    del doc["identity"]
    doc["sha256"] = json_sha256({k: v for k, v in doc.items() if k != "sha256"})
    (b / "checkpoints" / "ckpt-000001.json").write_text(json.dumps(doc))
    log = (b / "log.jsonl").read_text()
    with pytest.raises(CheckpointError, match="records no run identity"):
        EvolutionRun(tiny(), b, seed=1, generations=2, figures=False).run(resume=True)
    assert (b / "log.jsonl").read_text() == log  # a's history never became b's

    cfg = json.loads((a / "config.json").read_text())
    cfg["experiment"]["pop_size"] = 6
    (a / "config.json").write_text(json.dumps(cfg))
    before = sorted(p.name for p in a.rglob("*"))
    with pytest.raises(CheckpointError, match="config.json was changed after the run started"):
        EvolutionRun(tiny(pop_size=6), a, seed=1, generations=2, figures=False).run(resume=True)
    assert sorted(p.name for p in a.rglob("*")) == before  # nothing written


def _as_version_1(path):
    """Rewrite a checkpoint as a version-1 record of before run identities."""
    from softgym.io import _v1_state_digest

    doc = json.loads(path.read_text())
    doc.pop("sha256")
    doc.update(version=1, identity=None, state_sha256=_v1_state_digest(doc["state"]))
    path.write_text(json.dumps(doc))


def test_a_run_from_before_identities_resumes_and_gets_one(tmp_path):
    out = tmp_path / "r"
    EvolutionRun(tiny(), out, seed=1, generations=0, figures=False, gif=False).run()
    (out / "identity.json").unlink()
    for path in list_checkpoints(out / "checkpoints"):  # as a checkpoint of then
        _as_version_1(path)
    run = EvolutionRun(tiny(), out, seed=1, generations=1, figures=False, gif=False)
    run.run(resume=True)
    assert run.generation == 1
    ident = json.loads((out / "identity.json").read_text())
    assert json.loads(list_checkpoints(out / "checkpoints")[-1].read_text())["identity"] == ident
    EvolutionRun(tiny(), out, seed=1, generations=2, figures=False, gif=False).run(resume=True)


def test_a_folder_without_its_identity_resumes_only_its_own_checkpoints(tmp_path):
    # a kill between a run's first checkpoint and identity.json: the run resumes and keeps
    # its identity; a version-2 checkpoint re-signed without one, or one of a run with other
    # settings, copied into such a folder is refused (it would become this run's history)
    import shutil

    from softgym.io import json_sha256

    out, ref = tmp_path / "r", tmp_path / "ref"
    EvolutionRun(tiny(), ref, seed=1, generations=2, figures=False, gif=False).run()
    EvolutionRun(tiny(), out, seed=1, generations=1, figures=False, gif=False).run()
    ident = json.loads((out / "identity.json").read_text())
    (out / "identity.json").unlink()
    run = EvolutionRun(tiny(), out, seed=1, generations=2, figures=False, gif=False)
    run.run(resume=True)
    assert json.loads((out / "identity.json").read_text()) == ident  # the same run
    def fitness(d):
        return [(r["generation"], r["norm_final_dist_best"], r["norm_final_dist_median"])
                for r in map(json.loads, (d / "log.jsonl").read_text().splitlines())]  # fmt: skip

    assert fitness(out) == fitness(ref)  # as if never interrupted

    other = tmp_path / "other"
    EvolutionRun(tiny(pop_size=6), other, seed=3, generations=1, figures=False, gif=False).run()
    (out / "identity.json").unlink()
    for p in (out / "checkpoints").glob("ckpt-*"):
        p.unlink()
    newest = list_checkpoints(other / "checkpoints")[-1]
    for suffix in (".json", ".npz"):
        shutil.copy(newest.with_suffix(suffix), out / "checkpoints" / f"ckpt-000001{suffix}")
    log = (out / "log.jsonl").read_text()
    with pytest.raises(CheckpointError, match="whose settings are not this folder's config.json"):
        EvolutionRun(tiny(), out, seed=1, generations=3, figures=False).run(resume=True)
    doc = json.loads(newest.read_text())
    doc["identity"] = None
    doc["sha256"] = json_sha256({k: v for k, v in doc.items() if k != "sha256"})
    (out / "checkpoints" / "ckpt-000001.json").write_text(json.dumps(doc))
    with pytest.raises(CheckpointError, match="only a checkpoint written before runs had identities"):
        EvolutionRun(tiny(), out, seed=1, generations=3, figures=False).run(resume=True)
    assert (out / "log.jsonl").read_text() == log  # nothing of the other run became this one's


def test_a_second_writer_of_a_run_folder_is_refused_naming_the_first(tmp_path):
    import os

    from softgym.exceptions import RunFolderLockedError
    from softgym.io import RunLock

    with RunLock(tmp_path / "r"):  # another process's run, as far as the folder can tell
        with pytest.raises(RunFolderLockedError, match=f"in use by pid {os.getpid()}"):
            EvolutionRun(tiny(), tmp_path / "r", seed=4, generations=0, figures=False).run()
    assert not (tmp_path / "r" / "config.json").exists()  # nothing was written
