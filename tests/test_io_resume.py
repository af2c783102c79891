"""kill -9, a corrupt latest checkpoint, resume: each backend finishes as if never interrupted.

The run is killed with SIGKILL in a child process right after generation 2 is checkpointed;
that checkpoint is then truncated. Resuming (the run recorder loads through
:func:`softgym.io.load_latest_intact`) falls back to generation 1, says so in one line, and
redoes generation 2.
"""

import json
import logging
import os
import signal
import subprocess
import sys
import textwrap

import pytest

from evolvers.drivers.deap_runner import DeapRun
from evolvers.drivers.pymoo_runner import PymooRun
from evolvers.drivers.runner import EvolutionRun, population_summary
from evolvers.evaluation.experiments import get_experiment
from softgym.io import list_checkpoints

RUNS = {
    "native": ("evolvers.drivers.runner", "EvolutionRun", EvolutionRun, "controller-tournament"),
    "deap": ("evolvers.drivers.deap_runner", "DeapRun", DeapRun, "controller-tournament"),
    "pymoo": ("evolvers.drivers.pymoo_runner", "PymooRun", PymooRun, "controller-pareto"),
}
TINY = {"pop_size": 4, "seconds": 1.5, "shape": (4, 4, 4)}  # as tests/evolvers' tiny()


def _comparable(rows):
    # wall-clock columns differ between any two runs; everything else must match
    return [{k: v for k, v in r.items() if "wall" not in k} for r in rows]


@pytest.mark.parametrize("backend", sorted(RUNS))
def test_kill9_then_corrupt_latest_resumes_identically(tmp_path, backend, caplog):
    module, cls_name, cls, exp_name = RUNS[backend]
    exp = get_experiment(exp_name, **TINY)
    ref = cls(exp, tmp_path / "ref", seed=5, generations=3, figures=False)
    ref_pop = ref.run()

    child = textwrap.dedent(
        f"""
        import os, signal
        from evolvers.evaluation.experiments import get_experiment
        from {module} import {cls_name}

        def kill9(run, row):
            if row["generation"] == 2:
                os.kill(os.getpid(), signal.SIGKILL)

        exp = get_experiment({exp_name!r}, **{TINY!r})
        {cls_name}(exp, {str(tmp_path / "b")!r}, seed=5, generations=3,
                   figures=False, on_generation=kill9).run()
        """
    )
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    proc = subprocess.run([sys.executable, "-c", child], env=env, capture_output=True, timeout=300)
    assert proc.returncode == -signal.SIGKILL, proc.stderr.decode()[-2000:]

    ckpts = list_checkpoints(tmp_path / "b" / "checkpoints")
    assert ckpts[-1].name == "ckpt-000002.json"
    text = ckpts[-1].read_text()
    ckpts[-1].write_text(text[: len(text) // 2])  # the newest checkpoint is corrupt

    with caplog.at_level(logging.WARNING, logger="softgym.io"):
        resumed = cls(exp, tmp_path / "b", seed=5, generations=3, figures=False)
        pop = resumed.run(resume=True)
    [line] = [r.getMessage() for r in caplog.records if r.name == "softgym.io"]
    assert "ckpt-000002.json" in line and "resuming from ckpt-000001.json" in line

    assert population_summary(pop) == population_summary(ref_pop)
    assert _comparable(resumed.rows) == _comparable(ref.rows)
    assert [r["generation"] for r in resumed.rows] == [0, 1, 2, 3]
    logged = [json.loads(x) for x in (tmp_path / "b" / "log.jsonl").read_text().splitlines()]
    assert _comparable(logged) == _comparable(ref.rows)


def test_resume_removes_the_temporary_files_of_a_killed_write(tmp_path):
    # issue 61, item 9: a kill mid-write left .NAME.tmpPID files that no resume removed
    exp = get_experiment("controller-tournament", **TINY)
    out = tmp_path / "run"
    EvolutionRun(exp, out, seed=0, generations=0, figures=False, progress=False).run()
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()  # fmt: skip
    stale = [out / f".log.csv.tmp{dead}", out / "checkpoints" / f".ckpt-000001.npz.tmp{dead}"]
    for p in stale:
        p.write_bytes(b"half a file")
    run = EvolutionRun(exp, out, seed=0, generations=1, figures=False, progress=False)
    run.run(resume=True)
    assert run.generation == 1
    assert not any(p.exists() for p in stale)
    assert not list(out.rglob("*.tmp*"))


@pytest.mark.parametrize(
    ("array", "state"),
    [
        ({"pop_traces": [0.0]}, None),
        ({"cache_traces": []}, None),
        ({"cache_metrics": [0.5] * 10}, None),
        ({"pop_traces": [[0.0] * 7] * 3}, None),
        (None, {"rows": [1]}),
        (None, {"hall_of_fame": [{}]}),
        (None, {"hall_of_fame": [5]}),
    ],
)  # fmt: skip
def test_a_re_signed_checkpoint_of_wrong_shapes_is_a_checkpoint_error(tmp_path, array, state):
    # issue 61, item 11: a checkpoint re-signed (checksums fixed) with arrays of other shapes or
    # entries of other types was an IndexError, TypeError or KeyError traceback on resume
    import hashlib
    import io

    import numpy as np

    from softgym.exceptions import CheckpointError
    from softgym.io import json_sha256

    exp = get_experiment("controller-tournament", **{**TINY, "seconds": 0.5})
    out = tmp_path / "run"
    EvolutionRun(exp, out, seed=1, generations=0, figures=False, gif=False, progress=False).run()
    ckpt = list_checkpoints(out / "checkpoints")[-1]
    doc = json.loads(ckpt.read_text())
    if array is not None:
        with np.load(ckpt.with_suffix(".npz")) as z:
            arrays = {k: z[k] for k in z.files}
        arrays.update({k: np.asarray(v) for k, v in array.items()})
        buf = io.BytesIO()
        np.savez(buf, **arrays)
        ckpt.with_suffix(".npz").write_bytes(buf.getvalue())
        doc["npz_sha256"] = hashlib.sha256(buf.getvalue()).hexdigest()
    doc["state"].update(state or {})
    doc["sha256"] = json_sha256({k: v for k, v in doc.items() if k != "sha256"})
    ckpt.write_text(json.dumps(doc))
    run = EvolutionRun(exp, out, seed=1, generations=1, figures=False, gif=False, progress=False)
    with pytest.raises(CheckpointError, match="checkpoint content is invalid|checkpoint is damaged"):
        run.run(resume=True)


def _mutations(arrays, state):
    """Wrong shapes and types for every array and every list, dict or count of a checkpoint."""
    import numpy as np

    out = []
    for k, v in arrays.items():
        out.append((f"{k} as a scalar", {k: np.asarray(0.0)}, {}))
        if v.ndim >= 2:
            out.append((f"{k} one column short", {k: v[..., :-1]}, {}))
    for k, v in state.items():
        if isinstance(v, list):
            out.append((f"{k} [5]", {}, {k: [5]}))
        elif isinstance(v, dict):
            out.append((f"{k} a list", {}, {k: [1]}))
        elif isinstance(v, (int, float)) and not isinstance(v, bool):
            out.append((f"{k} a string", {}, {k: "x"}))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("backend", [*sorted(RUNS), "qd"])
def test_every_backend_resumes_a_re_signed_checkpoint_to_a_typed_error_or_a_run(tmp_path, backend):
    # a checkpoint re-signed (checksums fixed) with each array of another shape and each
    # list, object or count of another type: a typed error or a run, never a traceback,
    # on every backend (a negative count is refused: it would corrupt the budgets)
    import hashlib
    import io
    import shutil

    import numpy as np

    from softgym.exceptions import CheckpointError, SoftGymError
    from softgym.io import json_sha256

    if backend == "qd":
        pytest.importorskip("ribs")
        from evolvers.drivers.qd import QDRun

        cls, exp_name, kw = QDRun, "controller-tournament", {"figures": False, "progress": False}
    else:
        cls, exp_name = RUNS[backend][2], RUNS[backend][3]
        kw = {"figures": False, "gif": False, "progress": False}
    exp = get_experiment(exp_name, **{**TINY, "seconds": 0.5})
    src = tmp_path / "src"
    cls(exp, src, seed=1, generations=1, **kw).run()
    ckpt = list_checkpoints(src / "checkpoints")[-1]
    with np.load(ckpt.with_suffix(".npz")) as z:
        arrays = {k: z[k] for k in z.files}
    state = json.loads(ckpt.read_text())["state"]
    typed = 0
    for label, new_arrays, new_state in [*_mutations(arrays, state),
                                         ("evaluations_total -1", {}, {"evaluations_total": -1})]:  # fmt: skip
        out = tmp_path / "m"
        shutil.rmtree(out, ignore_errors=True)
        shutil.copytree(src, out)
        ckpts = list_checkpoints(out / "checkpoints")
        for old in ckpts[:-1]:
            old.unlink()
            old.with_suffix(".npz").unlink()
        doc = json.loads(ckpts[-1].read_text())
        if new_arrays:
            buf = io.BytesIO()
            np.savez(buf, **{**arrays, **new_arrays})
            ckpts[-1].with_suffix(".npz").write_bytes(buf.getvalue())
            doc["npz_sha256"] = hashlib.sha256(buf.getvalue()).hexdigest()
        doc["state"].update(new_state)
        doc["sha256"] = json_sha256({k: v for k, v in doc.items() if k != "sha256"})
        ckpts[-1].write_text(json.dumps(doc))
        try:
            cls(exp, out, seed=1, generations=2, **kw).run(resume=True)
        except SoftGymError:
            typed += 1
        except Exception as exc:  # pragma: no cover - the failure this test exists for
            pytest.fail(f"{backend}, {label}: {type(exc).__name__}: {exc}")
        if label == "evaluations_total -1":
            with pytest.raises(CheckpointError, match="counts .* must be finite and >= 0"):
                cls(exp, out, seed=1, generations=2, **kw).run(resume=True)
    assert typed > 0
