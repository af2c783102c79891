"""Writes that stay inside the run folder (issue 61, items 5, 6 and 9): the run lock is never
followed through a link, an atomic write never replaces a device or a FIFO, and the temporary
files a killed write leaves are removed by the next holder of the folder."""

import os
import re
import subprocess
import sys

import pytest
from fuzzing import refused_in_child  # tests/fuzzing.py

from softgym import io as sio
from softgym.exceptions import CheckpointError

posix = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs and links of POSIX")


@posix
def test_run_lock_never_follows_a_link_out_of_the_run_folder(tmp_path):
    victim = tmp_path / "victim"
    victim.write_text("precious")
    run = tmp_path / "r"
    run.mkdir()
    (run / ".lock").symlink_to("../victim")
    with pytest.raises(CheckpointError, match=r"\.lock.*symbolic link"):
        sio.RunLock(run).acquire()
    assert victim.read_text() == "precious"  # not truncated nor written
    (run / ".lock").unlink()
    os.link(victim, run / ".lock")  # a hard link shares the victim's data
    with pytest.raises(CheckpointError, match=r"\.lock.*2 hard links"):
        sio.RunLock(run).acquire()
    assert victim.read_text() == "precious"


@posix
def test_run_lock_refuses_a_fifo_at_once(tmp_path):
    os.mkfifo(tmp_path / ".lock")
    code = (f"from softgym.io import RunLock\nfrom softgym.exceptions import CheckpointError\n"
            f"try:\n    RunLock({str(tmp_path)!r}).acquire()\n"
            f"except CheckpointError as e:\n    print('REFUSED', e)\n")  # fmt: skip
    assert "not a regular file" in refused_in_child(code, timeout=30)


@posix
def test_an_atomic_write_never_replaces_a_device_or_a_fifo(tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(CheckpointError, match="not a regular file"):
        sio.atomic_write_text(fifo, "x")
    assert os.path.exists(fifo) and not fifo.is_file()  # still the FIFO
    link = tmp_path / "to-null"  # (never /dev/null itself: a softgym without the fix, run as
    link.symlink_to("/dev/null")  # root, would replace the machine's /dev/null)
    with pytest.raises(CheckpointError, match="not a regular file"):
        sio.atomic_write_json(link, {"a": 1})
    assert not [p for p in tmp_path.iterdir() if ".tmp" in p.name]  # nothing left behind
    sio.atomic_write_text(tmp_path / "plain.txt", "ok")  # a regular file is replaced as before
    sio.atomic_write_text(tmp_path / "plain.txt", "ok2")
    assert (tmp_path / "plain.txt").read_text() == "ok2"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc refuses new files")
def test_a_failed_write_names_the_target_not_the_temporary_file():
    with pytest.raises(CheckpointError) as err:
        sio.atomic_write_text("/proc/softgym-note.txt", "x")
    assert "/proc/softgym-note.txt" in str(err.value) and ".tmp" not in str(err.value)


def test_stale_temporary_files_are_removed_and_live_ones_kept(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()  # fmt: skip
    (tmp_path / "checkpoints").mkdir()
    stale = [tmp_path / f".log.csv.tmp{dead}", tmp_path / "checkpoints" / f".ckpt-000001.npz.tmp{dead}"]
    for p in stale:
        p.write_bytes(b"half")
    live = tmp_path / f".config.json.tmp{os.getppid()}"  # a process that still runs
    live.write_text("{")
    user = tmp_path / "notes.tmp123"  # not a temporary name of softgym's
    user.write_text("mine")
    removed = sio.remove_stale_temp_files(tmp_path)
    assert sorted(removed) == sorted(stale) and not any(p.exists() for p in stale)
    assert live.exists() and user.exists()
    assert sio.temp_file_target(stale[0].name) == "log.csv"
    assert sio.temp_file_target("log.csv") is None


def test_a_run_files_records_are_a_non_empty_list_of_objects(tmp_path):
    # one reader for pairs.json and best_designs.json (the key and the file named)
    import json

    from softgym.exceptions import CheckpointError
    from softgym.io import read_json_records

    path = tmp_path / "f.json"
    for doc, needle in (({"x": []}, "'x' must be a non-empty list of things, got []"),
                        ({"y": [1]}, "'x' must be a non-empty list of things, got None"),
                        ([1, 2], "'x' must be a non-empty list of things"),
                        ({"x": [{}, 3]}, "'x'[1] must be an object, got 3")):  # fmt: skip
        path.write_text(json.dumps(doc))
        with pytest.raises(CheckpointError, match=re.escape(f"{path}: {needle}")):
            read_json_records(path, "x", "things")
    path.write_text(json.dumps({"x": [{"a": 1}]}))
    assert read_json_records(path, "x", "things") == [{"a": 1}]
