"""Checkpoints under tampering: allow-listed generators, npz checks, fallback to the newest intact one."""

import hashlib
import io
import json
import logging
import os
import subprocess
import sys
import zipfile

import numpy as np
import pytest
from fuzzing import FUZZ, fifo_code, outcome, refused_in_child  # tests/fuzzing.py
from hypothesis import given
from hypothesis import strategies as st

from softgym import io as sio
from softgym.exceptions import CheckpointError, InvalidParameterError, RunFolderLockedError


def _save_three(directory):
    rng = np.random.default_rng(7)
    for step in range(3):
        state = {"generation": step, "rng": sio.rng_state(rng), "values": rng.random(3).tolist()}
        sio.save_checkpoint(directory, step, state, {"x": np.arange(step + 2.0)})
    return sio.list_checkpoints(directory)


def _rewrite(path, mutate):
    """Apply ``mutate`` to a checkpoint JSON and fix its checksums, so deeper checks run."""
    doc = json.loads(path.read_text())
    mutate(doc)
    _resign(doc)
    path.write_text(json.dumps(doc))


def _resign(doc):
    """Fix a checkpoint record's checksum after tampering (what a forger can always do)."""
    doc["sha256"] = sio.json_sha256({k: v for k, v in doc.items() if k != "sha256"})


def _set_npz(json_path, npz_bytes):
    npz = json_path.with_suffix(".npz")
    npz.write_bytes(npz_bytes)
    _rewrite(json_path, lambda d: d.update(npz_sha256=hashlib.sha256(npz_bytes).hexdigest()))


# ------------------------------------------------------------------ RNG names: an allow-list


def test_a_tampered_rng_name_never_reaches_numpy_random(monkeypatch):
    called = []
    for attr in ("seed", "default_rng", "RandomState"):
        monkeypatch.setattr(np.random, attr, lambda *a, attr=attr, **k: called.append(attr))
    for name in ["seed", "default_rng", "Generator", "__class__", "RandomState", "", 5, None]:
        with pytest.raises(CheckpointError, match="unknown numpy bit generator"):
            sio.rng_from_state({"bit_generator": name, "state": {}})
    assert called == []  # the old getattr(numpy.random, name)() called numpy.random.seed()


@pytest.mark.parametrize("name", sorted(sio.RNG_BIT_GENERATORS))
def test_every_allowed_generator_round_trips(name):
    rng = np.random.Generator(sio.RNG_BIT_GENERATORS[name](3))
    rng.random(5)
    back = sio.rng_from_state(json.loads(json.dumps(sio.rng_state(rng))))
    assert back.random(4).tolist() == rng.random(4).tolist()


@pytest.mark.parametrize(
    "state",
    [5, [], {"bit_generator": "PCG64", "state": 3}, {"bit_generator": "MT19937", "state": {}}],
)
def test_malformed_rng_states_raise_checkpoint_errors(state):
    with pytest.raises(CheckpointError):
        sio.rng_from_state(state)


@pytest.mark.parametrize("state", [5, [1, 2], [3, [0] * 624, None], [3, [0] * 625, "x"]])
def test_malformed_python_random_states_raise_checkpoint_errors(state):
    with pytest.raises(CheckpointError, match="python random state"):
        sio.set_python_random_state(state)


def test_saving_refuses_bad_steps_and_non_json_state(tmp_path):
    for step in (-1, 1.5, True, "3"):
        with pytest.raises(InvalidParameterError, match="step"):
            sio.save_checkpoint(tmp_path, step, {})
    with pytest.raises(InvalidParameterError, match="plain JSON"):
        sio.save_checkpoint(tmp_path, 0, {"x": object()})


# ------------------------------------------------------------------ npz and file checks


def test_npz_name_cannot_point_elsewhere(tmp_path):
    latest = _save_three(tmp_path)[-1]
    for name in ["../ckpt-000000.npz", "/etc/passwd", "ckpt-000000.npz/..", 7]:
        _rewrite(latest, lambda d, name=name: d.update(npz=name))
        with pytest.raises(CheckpointError, match="invalid array file name"):
            sio.load_checkpoint(latest)


def test_npz_header_claiming_a_huge_array_is_refused_before_allocation(tmp_path):
    latest = _save_three(tmp_path)[-1]
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        with zf.open("x.npy", "w") as fh:
            np.lib.format.write_array_header_1_0(
                fh, {"descr": "<f8", "fortran_order": False, "shape": (10**12,)}
            )
            fh.write(b"\0" * 64)
    _set_npz(latest, buf.getvalue())
    with pytest.raises(CheckpointError, match="header says 8000000000000 bytes"):
        sio.load_checkpoint(latest)


def test_compressed_or_pickled_npz_members_are_refused(tmp_path):
    latest = _save_three(tmp_path)[-1]
    buf = io.BytesIO()
    np.savez_compressed(buf, x=np.zeros(10))
    _set_npz(latest, buf.getvalue())
    with pytest.raises(CheckpointError, match="not an uncompressed .npy array"):
        sio.load_checkpoint(latest)
    buf = io.BytesIO()
    np.savez(buf, x=np.array([{"a": 1}], dtype=object))
    _set_npz(latest, buf.getvalue())
    with pytest.raises(CheckpointError, match="Python objects"):
        sio.load_checkpoint(latest)


def test_unreadable_checkpoint_paths_raise_checkpoint_errors(tmp_path):
    (tmp_path / "ckpt-000009.json").mkdir()
    with pytest.raises(CheckpointError, match="ckpt-000009.json"):
        sio.load_checkpoint(tmp_path / "ckpt-000009.json")
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100000 + "]" * 100000)
    with pytest.raises(CheckpointError, match="nested too deeply"):
        sio.read_json(deep)
    (tmp_path / "bad.json").write_text('{"a": ')
    with pytest.raises(CheckpointError, match="corrupt or truncated JSON"):
        sio.read_json(tmp_path / "bad.json")
    big = tmp_path / "big.json"
    big.write_text("[" + "0," * 600 + "0]")
    with pytest.raises(CheckpointError, match="more than the cap of 1000"):
        sio.read_json(big, cap=1000)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this platform")
def test_a_fifo_is_refused_at_once_not_waited_on(tmp_path):
    # a FIFO with no writer blocks a plain open() forever; read_capped refuses it
    # without opening it for a blocking read (run in a child with a timeout so a
    # regression fails instead of hanging the suite)
    fifo = tmp_path / "ckpt-000001.json"
    os.mkfifo(fifo)
    out = refused_in_child(fifo_code("from softgym import io", "io.read_json", str(fifo),
                                     "CheckpointError"))  # fmt: skip
    assert "not a regular file" in out


def test_a_renamed_checkpoint_is_refused_not_taken_as_newest(tmp_path):
    ckpts = _save_three(tmp_path)
    # a copy of the oldest, renamed to look like the newest
    newest = tmp_path / "ckpt-999999.json"
    newest.write_text(ckpts[0].read_text())
    with pytest.raises(CheckpointError, match="name says step 999999 but it records step"):
        sio.load_checkpoint(tmp_path)
    # the newest by recorded step is resumed, and the message names the skipped copy
    found = sio.load_latest_intact(tmp_path)
    assert found.path == ckpts[-1]
    assert "ckpt-999999.json" in found.message and "renamed" in found.message


def test_a_checkpoint_of_another_run_is_refused(tmp_path):
    mine = {"run_id": "abc", "config_sha256": "1" * 64}
    sio.save_checkpoint(tmp_path, 1, {"x": 1}, identity=mine)
    state, _ = sio.load_checkpoint(tmp_path, identity=mine)
    assert state["x"] == 1 and state["step"] == 1
    other = {"run_id": "xyz", "config_sha256": "2" * 64}
    with pytest.raises(CheckpointError, match="belongs to another run"):
        sio.load_checkpoint(tmp_path, identity=other)
    with pytest.raises(CheckpointError, match="no intact checkpoint.*belongs to another run"):
        sio.load_latest_intact(tmp_path, identity=other)
    # a foreign checkpoint copied in beside the run's own is skipped, never resumed
    sio.save_checkpoint(tmp_path, 2, {"x": 2}, identity=other)
    found = sio.load_latest_intact(tmp_path, identity=mine)
    assert found.state["step"] == 1 and "belongs to another run" in found.message
    # a checkpoint that records no identity is read only where no identity is asked for
    # (a run folder from before runs had identities)
    sio.save_checkpoint(tmp_path / "old", 1, {"x": 1})
    assert sio.load_checkpoint(tmp_path / "old")[0]["x"] == 1
    with pytest.raises(CheckpointError, match="records no run identity"):
        sio.load_checkpoint(tmp_path / "old", identity=mine)


def test_a_checkpoint_whose_identity_was_deleted_is_refused(tmp_path):
    # issue 61, item 4: a checkpoint copied from another run with its "identity" key
    # deleted resumed silently; the checksum covers the identity now, and a checkpoint
    # re-signed without one is refused all the same
    mine = {"run_id": "abc", "config_sha256": "1" * 64}
    path = sio.save_checkpoint(tmp_path, 1, {"x": 1}, identity=mine)
    doc = json.loads(path.read_text())
    del doc["identity"]
    path.write_text(json.dumps(doc))
    with pytest.raises(CheckpointError, match="ckpt-000001.json: checkpoint record is corrupt"):
        sio.load_checkpoint(path, identity=mine)
    with pytest.raises(CheckpointError, match="checksum mismatch"):
        sio.load_checkpoint(path)  # whoever reads it
    _rewrite(path, lambda d: None)  # re-signed without the identity
    with pytest.raises(CheckpointError, match="ckpt-000001.json: records no run identity"):
        sio.load_checkpoint(path, identity=mine)
    # the step is covered too (the name check aside)
    path = sio.save_checkpoint(tmp_path / "s", 2, {"x": 1}, identity=mine)
    doc = json.loads(path.read_text())
    doc["identity"]["run_id"] = "xyz"
    path.write_text(json.dumps(doc))
    with pytest.raises(CheckpointError, match="checksum mismatch"):
        sio.load_checkpoint(path)


def test_run_lock_refuses_a_second_writer_naming_the_holder(tmp_path):
    with sio.RunLock(tmp_path / "run"):
        with pytest.raises(RunFolderLockedError, match=f"in use by pid {os.getpid()}"):
            with sio.RunLock(tmp_path / "run"):
                pass
    # released on exit: a new writer gets it
    with sio.RunLock(tmp_path / "run"):
        pass


def test_run_lock_is_released_when_its_holder_is_killed(tmp_path):
    code = (
        "import sys, time; from softgym import io\n"
        f"lock = io.RunLock({str(tmp_path)!r}); lock.acquire()\n"
        "print('HELD', flush=True); time.sleep(60)\n"
    )
    child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == "HELD"
        with pytest.raises(RunFolderLockedError, match=f"pid {child.pid}"):
            sio.RunLock(tmp_path).acquire()
    finally:
        child.kill()
        child.wait()
    with sio.RunLock(tmp_path):  # the OS released the dead holder's lock
        pass


# ------------------------------------------------------------------ fallback to the newest intact


def test_corrupt_latest_falls_back_to_the_previous_with_one_line(tmp_path, caplog):
    ckpts = _save_three(tmp_path)
    text = ckpts[-1].read_text()
    ckpts[-1].write_text(text[: len(text) // 2])
    with pytest.raises(CheckpointError, match="ckpt-000002.json"):
        sio.load_checkpoint(tmp_path)  # the strict loader still refuses
    with caplog.at_level(logging.WARNING, logger="softgym.io"):
        found = sio.load_latest_intact(tmp_path)
    state, arrays, path, skipped = found
    assert path == ckpts[1] and state["step"] == 1 and state["generation"] == 1
    assert arrays["x"].tolist() == [0.0, 1.0, 2.0]
    assert [p for p, _ in skipped] == [ckpts[2]]
    assert len(caplog.records) == 1 and "\n" not in caplog.records[0].getMessage()
    assert caplog.records[0].getMessage() == found.message
    assert "ckpt-000002.json" in found.message and "resuming from ckpt-000001.json" in found.message


def test_fallback_skips_several_and_reports_when_none_is_intact(tmp_path):
    ckpts = _save_three(tmp_path)
    ckpts[2].with_suffix(".npz").write_bytes(b"garbage")
    _rewrite(ckpts[1], lambda d: d["state"].update(rng={"bit_generator": "seed"}))
    _rewrite(ckpts[1], lambda d: d.update(step=-4))
    found = sio.load_latest_intact(tmp_path)
    assert found.path == ckpts[0] and [p.name for p, _ in found.skipped] == [
        "ckpt-000002.json",
        "ckpt-000001.json",
    ]
    assert found.state["rng"]["bit_generator"] == "PCG64"
    ckpts[0].write_text("{")
    with pytest.raises(CheckpointError, match="no intact checkpoint among 3"):
        sio.load_latest_intact(tmp_path)
    with pytest.raises(CheckpointError, match="no checkpoint"):
        sio.load_latest_intact(tmp_path / "empty")


def test_an_intact_latest_is_loaded_without_a_message(tmp_path):
    ckpts = _save_three(tmp_path)
    found = sio.load_latest_intact(tmp_path)
    assert found.path == ckpts[-1] and found.skipped == [] and found.message is None


# ------------------------------------------------------------------ properties

SCALARS = (
    st.none()
    | st.booleans()
    | st.integers(min_value=-(2**70), max_value=2**70)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=10)
)
JSON_VALUES = st.recursive(
    SCALARS,
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=3)
    ),
    max_leaves=12,
)


@pytest.fixture(scope="module")
def pristine(tmp_path_factory):
    d = tmp_path_factory.mktemp("pristine")
    _save_three(d)
    return {p.name: p.read_bytes() for p in d.iterdir()}


def _fresh(tmp_path_factory, pristine):
    d = tmp_path_factory.mktemp("ck")
    for name, data in pristine.items():
        (d / name).write_bytes(data)
    return d


@FUZZ
@given(
    key=st.sampled_from(["schema", "version", "step", "npz", "npz_sha256", "state", "rng", "x"]),
    value=JSON_VALUES,
    fix_checksum=st.booleans(),
)
def test_tampered_checkpoint_json_loads_or_raises_checkpoint_error(
    tmp_path_factory, pristine, key, value, fix_checksum
):
    d = _fresh(tmp_path_factory, pristine)
    latest = d / "ckpt-000002.json"
    doc = json.loads(latest.read_text())
    if key == "rng":
        doc["state"]["rng"] = value
    elif key == "x":
        doc["state"]["values"] = value
    else:
        doc[key] = value
    if fix_checksum:
        _resign(doc)
    latest.write_text(json.dumps(doc, allow_nan=True))

    def load_and_restore():
        state, _ = sio.load_checkpoint(latest)
        sio.rng_from_state(state.get("rng"))  # a missing state is the runner's KeyError

    outcome("checkpoint: tampered JSON field", load_and_restore)
    found = sio.load_latest_intact(d)  # an intact older one is always there
    assert found.path.name in ("ckpt-000002.json", "ckpt-000001.json")


@FUZZ
@given(data=st.binary(max_size=400), prefix_len=st.integers(0, 600))
def test_tampered_npz_bytes_load_or_raise_checkpoint_error(
    tmp_path_factory, pristine, data, prefix_len
):
    d = _fresh(tmp_path_factory, pristine)
    latest = d / "ckpt-000002.json"
    good = pristine["ckpt-000002.npz"]
    _set_npz(latest, good[:prefix_len] + data)  # checksum fixed: the npz checks must catch it
    outcome("checkpoint: tampered npz bytes", sio.load_checkpoint, latest)


@FUZZ
@given(JSON_VALUES)
def test_arbitrary_rng_states_restore_or_raise_checkpoint_error(state):
    outcome("checkpoint: rng state", sio.rng_from_state, state)
    outcome(
        "checkpoint: python random state",
        sio.set_python_random_state,
        state,
        __import__("random").Random(),
    )
