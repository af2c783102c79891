"""Atomic, versioned, pickle-free files: run checkpoints and JSON documents.

A checkpoint is a pair of files written into one folder::

    ckpt-000007.npz   numeric arrays (numpy's npz, loaded with allow_pickle=False)
    ckpt-000007.json  {"schema", "version", "step", "npz", "npz_sha256",
                       "identity", "state": {...}, "sha256"}

Both are written to a temporary file, flushed to disk and renamed into place,
the npz first: the JSON is the commit record, so a checkpoint exists only
once both halves are complete. The JSON holds the SHA-256 of the npz and of
its own state, so truncation or corruption of either file is detected and
raises :class:`~softgym.exceptions.CheckpointError` naming the file. The JSON's
``sha256`` covers every other field of it (the run's identity and the step
included: :func:`json_sha256`, the one digest of JSON data). The
previous ``keep - 1`` checkpoints stay on disk, so a bad latest checkpoint
never destroys the last good one: :func:`load_latest_intact` falls back to it
and says so in one logged line.

Reading never trusts the files: only regular files are opened (a FIFO or a
device is refused without blocking, :func:`read_capped`), each within a size
cap checked before it is read, numpy bit generators are named from an
allow-list (:data:`RNG_BIT_GENERATORS`), the array file must be an
uncompressed npz whose array headers match their data sizes (checked before
any array is allocated), and nothing is unpickled.

A checkpoint knows its run: :func:`save_checkpoint` can record the run's
identity (e.g. its id and the hash of its settings) and :func:`load_checkpoint`
refuses one whose identity differs or that records none, whatever its file
name (a deleted identity breaks the checksum; a re-signed one without it is
still refused); a checkpoint
whose name disagrees with the step it records is refused too, so the newest
checkpoint is always the one with the highest recorded step. :class:`RunLock`
gives one writer at a time a run folder.
"""

from __future__ import annotations

import errno
import hashlib
import io
import json
import logging
import math
import os
import re
import socket
import stat
import sys
import time
import zipfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from softgym.exceptions import CheckpointError, InvalidParameterError, RunFolderLockedError
from softgym.validate import show

__all__ = [
    "CHECKPOINT_SCHEMA",
    "CHECKPOINT_VERSION",
    "RNG_BIT_GENERATORS",
    "IntactCheckpoint",
    "MAX_CHECKPOINT_BYTES",
    "MAX_JSON_BYTES",
    "MAX_PATH_DEPTH",
    "RunLock",
    "atomic_write_bytes",
    "atomic_write_json",
    "atomic_write_text",
    "check_path_depth",
    "latest_checkpoint",
    "list_checkpoints",
    "load_checkpoint",
    "load_latest_intact",
    "json_sha256",
    "loads_json",
    "read_capped",
    "read_json",
    "read_json_lines",
    "read_json_records",
    "remove_stale_temp_files",
    "rng_from_state",
    "rng_state",
    "python_random_state",
    "set_python_random_state",
    "save_checkpoint",
    "temp_file_target",
]

#: ``"schema"`` field of a checkpoint's JSON half.
CHECKPOINT_SCHEMA = "softgym.checkpoint"
#: Newest checkpoint version this softgym writes and reads (1: the checksum covered
#: the state alone; 2: ``sha256`` covers the whole record, identity included).
CHECKPOINT_VERSION = 2

_NAME = re.compile(r"^ckpt-(\d{6,})\.json$")
_NPZ_NAME = re.compile(r"^ckpt-\d{6,}\.npz$")

#: The numpy bit generators a checkpoint may name, by name. Anything else in a
#: checkpoint is refused: a name is never looked up in ``numpy.random``.
RNG_BIT_GENERATORS: dict[str, type[np.random.BitGenerator]] = {
    "MT19937": np.random.MT19937,
    "PCG64": np.random.PCG64,
    "PCG64DXSM": np.random.PCG64DXSM,
    "Philox": np.random.Philox,
    "SFC64": np.random.SFC64,
}

#: Largest JSON document :func:`read_json` reads (bytes): a run's state of the
#: biggest study population is under 1 MiB.
MAX_JSON_BYTES = 64 * 2**20
#: Most folders a path softgym writes may have (Python creates missing folders one
#: call per level: a path thousands of folders deep would exhaust the recursion limit).
MAX_PATH_DEPTH = 256
#: Largest array file of a checkpoint :func:`load_checkpoint` reads (bytes).
MAX_CHECKPOINT_BYTES = 2 * 2**30

logger = logging.getLogger(__name__)

#: How :func:`atomic_write_bytes` names its temporary file: ``.NAME.tmpPID`` beside the target.
_TEMP_PREFIX, _TEMP_INFIX = ".", ".tmp"
_TEMP_NAME = re.compile(r"^\.(.+)\.tmp(\d+)$")


def _pid_alive(pid: int) -> bool:
    """Whether a process ``pid`` runs on this host (True when that cannot be told)."""
    if pid == os.getpid():
        return False  # ours: this process writes no file while it cleans
    if sys.platform == "win32":  # pragma: no cover - no signal 0 there
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, OSError):
        return True
    return True


def temp_file_target(name: str) -> str | None:
    """The file name a temporary file of :func:`atomic_write_bytes` named ``name`` was
    being written to (``.NAME.tmpPID`` gives ``NAME``), or None if ``name`` is not one.
    """
    m = _TEMP_NAME.match(name)
    return m.group(1) if m else None


def remove_stale_temp_files(directory: str | os.PathLike[str], recursive: bool = True) -> list[Path]:
    """Remove the temporary files of :func:`atomic_write_bytes` left in ``directory`` by a
    process that was killed mid-write (``.NAME.tmpPID`` whose process no longer runs).

    Called by a run that holds its folder's :class:`RunLock` (no other writer), on
    resume: a file of a process that still runs is kept. Links and anything
    that is not a regular file are left alone.

    Returns
    -------
    list of Path
        The files removed.
    """
    root = Path(directory)
    removed: list[Path] = []
    if not root.is_dir():
        return removed
    folders = [root]
    while folders:
        folder = folders.pop()
        try:
            entries = list(os.scandir(folder))
        except OSError:
            continue
        for entry in entries:
            if entry.is_dir(follow_symlinks=False):
                if recursive:
                    folders.append(Path(entry.path))
                continue
            m = _TEMP_NAME.match(entry.name)
            if not m or not entry.is_file(follow_symlinks=False) or _pid_alive(int(m.group(2))):
                continue
            try:
                os.unlink(entry.path)
            except OSError:
                continue
            removed.append(Path(entry.path))
    return removed


def read_capped(
    path: str | os.PathLike[str],
    cap: int,
    what: str,
    error: type[Exception] = CheckpointError,
) -> bytes:
    """The bytes of the regular file ``path``, refused beyond ``cap`` bytes.

    The file is opened without blocking and checked to be a regular file
    before a byte is read: a FIFO, a device or a socket given as a path is
    refused at once instead of waiting for a writer forever. Its size is
    checked against ``cap`` before it is read (and the read stops at
    ``cap + 1`` bytes, should it grow meanwhile).

    Parameters
    ----------
    path : path
        The file.
    cap : int
        Largest accepted size (bytes).
    what : str
        What the file is, for the message ("design", "checkpoint"...).
    error : type
        The :class:`~softgym.exceptions.SoftGymError` subclass to raise.

    Raises
    ------
    error
        Naming the file, if it is missing, a folder or another non-regular
        file, unreadable, or larger than ``cap``.
    """
    name = os.fspath(path)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(name, flags)
    except FileNotFoundError:
        raise error(f"{what} file {name!r} does not exist") from None
    except IsADirectoryError:
        raise error(f"{what} file {name!r} is a folder, not a file") from None
    except OSError as exc:
        raise error(f"{what} file {name!r} cannot be read: {exc.strerror or exc}") from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise error(f"{what} file {name!r} is a folder, not a file")
        if not stat.S_ISREG(st.st_mode):
            raise error(
                f"{what} file {name!r} is not a regular file (a FIFO, device or socket); "
                f"only regular files are read"
            )
        if st.st_size > cap:
            raise error(
                f"{what} file {name!r} has {st.st_size} bytes, more than the cap of {cap}"
            )
        chunks = []
        n = 0
        while n <= cap:
            chunk = os.read(fd, min(1 << 20, cap + 1 - n))
            if not chunk:
                break
            chunks.append(chunk)
            n += len(chunk)
    except OSError as exc:
        raise error(f"{what} file {name!r} cannot be read: {exc.strerror or exc}") from None
    finally:
        os.close(fd)
    if n > cap:
        raise error(f"{what} file {name!r} is larger than the cap of {cap} bytes")
    return b"".join(chunks)


def loads_json(text: str | bytes, what: str, error: type[Exception] = CheckpointError) -> Any:
    """Parse JSON text; anything that is not valid JSON raises ``error`` naming ``what``.

    Covers text that is not UTF-8, malformed JSON, integers too long to
    convert, and documents nested too deeply for the parser (a RecursionError
    in :func:`json.loads`): never a bare builtin exception or a traceback.
    """
    try:
        if not isinstance(text, str):
            text = bytes(text).decode("utf-8")
        return json.loads(text)
    except UnicodeDecodeError as exc:
        raise error(f"{what}: not UTF-8 text ({exc!s:.120})") from None
    except RecursionError:
        raise error(f"{what}: JSON nested too deeply to be read") from None
    except ValueError as exc:  # JSONDecodeError, an integer of more than 4300 digits
        raise error(f"{what}: corrupt or truncated JSON ({exc!s:.200})") from None


def check_path_depth(path: str | os.PathLike[str], what: str = "path") -> Path:
    """``path`` as a Path, if it has at most :data:`MAX_PATH_DEPTH` parts.

    Raises
    ------
    CheckpointError
        Naming ``what`` and the depth, for a deeper path.
    """
    p = Path(path)
    if len(p.parts) > MAX_PATH_DEPTH:
        raise CheckpointError(
            f"{what} {str(p)[:60]!r}... is {len(p.parts)} folders deep, more than the "
            f"{MAX_PATH_DEPTH} softgym writes into; give a shorter path"
        )
    return p


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file, fsync and rename.

    A reader sees either the old file or the complete new one, never a part;
    on failure the temporary file is removed. A folder at ``path``, or
    anything else there that is not a regular file (a device, a FIFO, a
    socket: the rename would replace it), raises :class:`CheckpointError`
    naming it, as does a write that fails (naming ``path``, not the
    temporary file).
    """
    path = check_path_depth(path, "file")
    if path.is_dir():
        raise CheckpointError(f"{path} is a folder: cannot write a file there")
    try:
        st = os.stat(path)
    except (FileNotFoundError, NotADirectoryError):
        st = None  # nothing there yet (or a dangling link, which the rename replaces)
    except OSError as exc:
        raise CheckpointError(f"cannot write {path}: {exc.strerror or exc}") from None
    if st is not None and not stat.S_ISREG(st.st_mode):
        raise CheckpointError(
            f"{path} exists and is not a regular file (a device, FIFO or socket): "
            f"it is never replaced; write to another path"
        )
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f"{_TEMP_PREFIX}{path.name}{_TEMP_INFIX}{os.getpid()}")
    try:
        try:
            tmp.unlink()  # a temporary file left by a killed process of the same pid
        except FileNotFoundError:
            pass
        # a new file, never through a link someone left at the temporary name
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
                     | getattr(os, "O_BINARY", 0), 0o644)  # fmt: skip
        with open(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        # never leave the temporary file behind (a full disk, a folder in the way...)
        try:
            tmp.unlink()
        except OSError:
            pass
        if isinstance(exc, OSError) and not isinstance(exc, CheckpointError):
            raise CheckpointError(f"cannot write {path}: {exc.strerror or exc}") from None
        raise
    try:  # make the rename durable (best effort: not every filesystem allows it)
        fd = os.open(path.parent, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError:  # pragma: no cover - platform dependent
        pass


def atomic_write_text(path: str | os.PathLike[str], text: str) -> None:
    """Atomic UTF-8 text write (see :func:`atomic_write_bytes`)."""
    atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_json(path: str | os.PathLike[str], obj: Any, indent: int | None = 1) -> None:
    """Atomic JSON write; floats are written with ``repr`` so they read back exactly."""
    atomic_write_text(path, json.dumps(obj, indent=indent, allow_nan=True) + "\n")


def read_json(path: str | os.PathLike[str], cap: int = MAX_JSON_BYTES) -> Any:
    """Read a JSON file; a missing, non-regular, oversized or malformed file raises
    :class:`CheckpointError` naming it (see :func:`read_capped`, :func:`loads_json`).
    """
    path = Path(path)
    data = read_capped(path, cap, "JSON")
    return loads_json(data, str(path))


def read_json_records(path: str | os.PathLike[str], key: str, what: str) -> list[dict[str, Any]]:
    """The non-empty list of objects under ``key`` of a JSON file's top-level object (a run
    folder's ``best_designs.json``, ``pairs.json``...), through :func:`read_json`.

    Parameters
    ----------
    path : path
    key : str
        The top-level key.
    what : str
        What an entry is, for the message (``"pairs"``, ``"entries"``).

    Raises
    ------
    CheckpointError
        Naming the file and the key, if the file is missing, not a regular file,
        oversized or malformed, or ``key`` is not a non-empty list of objects.
    """
    path = Path(path)
    doc = read_json(path)
    items = doc.get(key) if isinstance(doc, dict) else None
    if not isinstance(items, list) or not items:
        raise CheckpointError(f"{path}: {key!r} must be a non-empty list of {what}, got {show(items)}")
    for i, item in enumerate(items):
        if not isinstance(item, dict):
            raise CheckpointError(f"{path}: {key!r}[{i}] must be an object, got {show(item)}")
    return items


def read_json_lines(path: str | os.PathLike[str], cap: int = MAX_JSON_BYTES) -> list[dict[str, Any]]:
    """The JSON objects of a JSON-lines file (a run's ``log.jsonl``, ``notes.jsonl``), one
    per line, blank lines skipped; through :func:`read_capped`, so a FIFO or an oversized
    file is refused without blocking.

    Raises
    ------
    CheckpointError
        Naming the file (and the line), if it is missing, not a regular file, larger
        than ``cap``, not UTF-8, or holds a line that is not a JSON object.
    """
    path = Path(path)
    data = read_capped(path, cap, "JSON lines")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise CheckpointError(f"{path}: not UTF-8 text ({exc!s:.120})") from None
    rows = []
    for n, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        row = loads_json(line, f"{path}: line {n}")
        if not isinstance(row, dict):
            raise CheckpointError(f"{path}: line {n} is not a JSON object")
        rows.append(row)
    return rows


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def json_sha256(obj: Any) -> str:
    """The SHA-256 (hex) of plain JSON data, keys sorted: the one digest of JSON data
    (a checkpoint's record, a run's settings in its ``identity.json``).

    Raises
    ------
    InvalidParameterError
        If ``obj`` is not plain JSON data or is nested too deeply to be written.
    """
    try:
        text = json.dumps(obj, sort_keys=True, allow_nan=True)
    except (TypeError, ValueError, RecursionError) as exc:
        raise InvalidParameterError(f"not plain JSON data: {exc!s:.200}") from None
    return _sha256(text.encode("utf-8"))


def _record_digest(doc: Mapping[str, Any]) -> str:
    """The checksum of a version-2 checkpoint record: every field but ``sha256``."""
    return json_sha256({k: v for k, v in doc.items() if k != "sha256"})


def list_checkpoints(directory: str | os.PathLike[str]) -> list[Path]:
    """Checkpoint JSON files of ``directory``, oldest first (by step number)."""
    directory = Path(directory)
    if not directory.is_dir():
        return []
    found = []
    for p in directory.iterdir():
        m = _NAME.match(p.name)
        if m:
            found.append((int(m.group(1)), p))
    return [p for _, p in sorted(found)]


def latest_checkpoint(directory: str | os.PathLike[str]) -> Path | None:
    """The newest checkpoint JSON of ``directory``, or None."""
    ckpts = list_checkpoints(directory)
    return ckpts[-1] if ckpts else None


def save_checkpoint(
    directory: str | os.PathLike[str],
    step: int,
    state: Mapping[str, Any],
    arrays: Mapping[str, np.ndarray] | None = None,
    keep: int = 3,
    identity: Mapping[str, Any] | None = None,
) -> Path:
    """Write checkpoint ``step`` atomically and prune old ones.

    Parameters
    ----------
    directory : path
        Folder of the checkpoints (created if needed).
    step : int
        Checkpoint number (a generation), >= 0; names the files.
    state : mapping
        Plain-JSON data (dicts, lists, str, int, float, bool, None). Random
        generator states belong here (:func:`rng_state`).
    arrays : mapping of str to ndarray, optional
        Numeric arrays, stored in the npz (no object arrays: no pickle).
    keep : int
        Checkpoints kept on disk after this one is written (>= 2 keeps the
        previous good one).
    identity : mapping, optional
        Plain-JSON data naming the run the checkpoint belongs to (e.g. its
        run id and the hash of its settings), covered by the checksum;
        :func:`load_checkpoint` given an identity refuses a checkpoint that
        records another one or none.

    Returns
    -------
    Path
        The JSON file of the new checkpoint.
    """
    if isinstance(step, bool) or not isinstance(step, (int, np.integer)) or step < 0:
        raise InvalidParameterError(f"checkpoint step must be an integer >= 0, got {step!r}")
    if isinstance(keep, bool) or not isinstance(keep, (int, np.integer)) or keep < 1:
        raise InvalidParameterError(f"checkpoint keep must be an integer >= 1, got {keep!r}")
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    stem = f"ckpt-{int(step):06d}"
    buf = io.BytesIO()
    arrays = dict(arrays or {})
    for k, v in arrays.items():
        if np.asarray(v).dtype == object:
            raise CheckpointError(f"array {k!r} has dtype object; checkpoints never pickle")
    np.savez(buf, **{k: np.asarray(v) for k, v in arrays.items()})
    npz_bytes = buf.getvalue()
    doc = {
        "schema": CHECKPOINT_SCHEMA,
        "version": CHECKPOINT_VERSION,
        "step": int(step),
        "npz": f"{stem}.npz",
        "npz_sha256": _sha256(npz_bytes),
        "identity": None if identity is None else _to_json(dict(identity)),
        "state": dict(state),
    }
    try:
        doc["sha256"] = _record_digest(doc)
    except InvalidParameterError as exc:
        raise InvalidParameterError(f"checkpoint state or identity is {exc}") from None
    atomic_write_bytes(directory / f"{stem}.npz", npz_bytes)
    path = directory / f"{stem}.json"
    atomic_write_json(path, doc, indent=None)
    ckpts = list_checkpoints(directory)
    for old in ckpts[: max(0, len(ckpts) - max(1, int(keep)))]:
        for p in (old, old.with_suffix(".npz")):
            try:
                p.unlink()
            except FileNotFoundError:
                pass
    return path


def load_checkpoint(
    path: str | os.PathLike[str],
    identity: Mapping[str, Any] | None = None,
    settings_sha256: str | None = None,
) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """Read and verify a checkpoint written by :func:`save_checkpoint`.

    Parameters
    ----------
    path : path
        The checkpoint's JSON file (or a folder: its latest checkpoint).
    identity : mapping, optional
        The run's identity: a checkpoint that records another identity, or
        none, is refused, whatever its file name (None: no identity is
        checked, for a run folder written before runs had identities).
    settings_sha256 : str, optional
        For a run folder without a recorded identity (``identity`` None): the
        digest of its settings. A checkpoint that records an identity must
        record these settings (it is then the run's own, written before a kill
        left the folder without its identity file), and one that records none
        must be a version-1 record, written before runs had identities; any
        other is refused.

    Returns
    -------
    state : dict
        The JSON state, with ``"step"`` added.
    arrays : dict of str to ndarray

    Raises
    ------
    CheckpointError
        Naming the file, if either half is missing, not a regular file,
        larger than :data:`MAX_CHECKPOINT_BYTES`, truncated, corrupt, of
        another schema or of a newer version, if its name disagrees with the
        step it records, or if it belongs to another run or (``identity``
        given) records no run.
    """
    path = Path(path)
    if path.is_dir():
        latest = latest_checkpoint(path)
        if latest is None:
            raise CheckpointError(f"{path}: no checkpoint (ckpt-*.json) in this folder")
        path = latest
    doc = read_json(path)
    if not isinstance(doc, dict) or doc.get("schema") != CHECKPOINT_SCHEMA:
        raise CheckpointError(
            f"{path}: not a softgym checkpoint (schema {CHECKPOINT_SCHEMA!r} expected)"
        )
    version = doc.get("version")
    if not isinstance(version, int) or version < 1:
        raise CheckpointError(f"{path}: invalid checkpoint version {version!r}")
    if version > CHECKPOINT_VERSION:
        raise CheckpointError(
            f"{path}: checkpoint version {version} is newer than this softgym reads "
            f"(up to {CHECKPOINT_VERSION})"
        )
    state = doc.get("state")
    if version >= 2:  # the checksum covers the whole record: identity and step included
        try:
            intact = doc.get("sha256") == _record_digest(doc)
        except InvalidParameterError:
            intact = False
        if not intact or not isinstance(state, dict):
            raise CheckpointError(f"{path}: checkpoint record is corrupt (checksum mismatch)")
    elif not isinstance(state, dict) or _v1_state_digest(state) != doc.get("state_sha256"):
        raise CheckpointError(f"{path}: checkpoint state is corrupt (checksum mismatch)")
    step = doc.get("step")
    if isinstance(step, bool) or not isinstance(step, int) or step < 0:
        raise CheckpointError(f"{path}: invalid checkpoint step {step!r:.40}")
    named = _NAME.match(path.name)
    if named and int(named.group(1)) != step:
        # a copy renamed to look newer (or older) than it is
        raise CheckpointError(
            f"{path}: its name says step {int(named.group(1))} but it records step {step}; "
            f"a renamed checkpoint is not resumed"
        )
    recorded = doc.get("identity")
    if identity is not None and recorded is None:
        # its identity deleted (a version-1 record, or one re-signed without it): a
        # checkpoint copied from another run would become this run's history
        raise CheckpointError(
            f"{path}: records no run identity, and this run ({_describe(dict(identity))}) "
            f"resumes only its own checkpoints; it is not resumed"
        )
    if identity is not None and recorded != _to_json(dict(identity)):
        raise CheckpointError(
            f"{path}: belongs to another run (it records {_describe(recorded)}, "
            f"this run is {_describe(dict(identity))}); it is not resumed"
        )
    if identity is None and settings_sha256 is not None:
        if recorded is None and version >= 2:
            # every version-2 writer records the run: one without is another run's,
            # re-signed after its identity was deleted
            raise CheckpointError(
                f"{path}: records no run identity; in a folder without one, only a "
                f"checkpoint written before runs had identities (version 1) resumes "
                f"without it; it is not resumed"
            )
        if recorded is not None and (
            not isinstance(recorded, dict) or recorded.get("config_sha256") != settings_sha256
        ):
            raise CheckpointError(
                f"{path}: belongs to another run (it records {_describe(recorded)}, whose "
                f"settings are not this folder's config.json); it is not resumed"
            )
    npz_name = doc.get("npz")
    if not isinstance(npz_name, str) or not _NPZ_NAME.match(npz_name):
        # a plain ckpt-NNNNNN.npz beside the JSON: never a path to somewhere else
        raise CheckpointError(f"{path}: invalid array file name {npz_name!r:.80}")
    npz_path = path.with_name(npz_name)
    if not npz_path.exists():
        raise CheckpointError(f"{npz_path}: array file of checkpoint {path.name} is missing")
    npz_bytes = read_capped(npz_path, MAX_CHECKPOINT_BYTES, "checkpoint array")
    if _sha256(npz_bytes) != doc.get("npz_sha256"):
        raise CheckpointError(f"{npz_path}: corrupt or truncated array file (checksum mismatch)")
    _check_npz(npz_bytes, npz_path)
    try:
        with np.load(io.BytesIO(npz_bytes), allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as exc:
        raise CheckpointError(f"{npz_path}: unreadable array file ({exc!s:.200})") from None
    state = dict(state)
    state["step"] = step
    return state, arrays


def _v1_state_digest(state: Any) -> str:
    """A version-1 checkpoint's checksum: its state alone."""
    try:
        return json_sha256(state)
    except InvalidParameterError:
        return ""


def _describe(identity: Any) -> str:
    """A short description of a checkpoint's identity for a message."""
    if not isinstance(identity, dict):
        return "no run identity"
    return ", ".join(f"{k} {str(v)[:16]}" for k, v in sorted(identity.items())) or "no run identity"


def _check_npz(npz_bytes: bytes, npz_path: Path) -> None:
    """Refuse an npz whose members are compressed, pickled or claim more data than they hold.

    Runs before :func:`numpy.load`, which allocates an array of the size its header
    claims before reading the data.
    """
    try:
        with zipfile.ZipFile(io.BytesIO(npz_bytes)) as zf:
            for info in zf.infolist():
                where = f"{npz_path}: member {info.filename!r:.60}"
                if info.compress_type != zipfile.ZIP_STORED or not info.filename.endswith(".npy"):
                    raise CheckpointError(f"{where} is not an uncompressed .npy array")
                if info.file_size > len(npz_bytes):
                    raise CheckpointError(f"{where} claims more bytes than the file holds")
                with zf.open(info) as fh:
                    version = np.lib.format.read_magic(fh)
                    if version == (1, 0):
                        shape, _, dtype = np.lib.format.read_array_header_1_0(fh)
                    elif version == (2, 0):
                        shape, _, dtype = np.lib.format.read_array_header_2_0(fh)
                    else:
                        raise CheckpointError(f"{where} has npy format {version}, not 1.0 or 2.0")
                    header = fh.tell()
                if dtype.hasobject:
                    raise CheckpointError(f"{where} holds Python objects; checkpoints never pickle")
                nbytes = math.prod(int(n) for n in shape) * dtype.itemsize
                if nbytes != info.file_size - header:
                    raise CheckpointError(
                        f"{where}: header says {nbytes} bytes of data, the member holds "
                        f"{info.file_size - header}"
                    )
    except CheckpointError:
        raise
    except (zipfile.BadZipFile, ValueError, OSError, EOFError, KeyError, TypeError) as exc:
        raise CheckpointError(f"{npz_path}: unreadable array file ({exc!s:.200})") from None


class IntactCheckpoint(NamedTuple):
    """What :func:`load_latest_intact` found.

    Attributes
    ----------
    state : dict
        The JSON state, with ``"step"`` added (as :func:`load_checkpoint`).
    arrays : dict of str to ndarray
    path : Path
        The checkpoint JSON that was loaded.
    skipped : list of (Path, str)
        Newer checkpoints that were corrupt, newest first, with the reason.
    """

    state: dict[str, Any]
    arrays: dict[str, np.ndarray]
    path: Path
    skipped: list[tuple[Path, str]]

    @property
    def message(self) -> str | None:
        """One line saying which checkpoints were skipped and which one was used; None if none."""
        if not self.skipped:
            return None
        names = ", ".join(p.name for p, _ in self.skipped)
        return (
            f"skipped corrupt checkpoint(s) {names} ({self.skipped[0][1]}); "
            f"resuming from {self.path.name} (step {self.state['step']})"
        )


def load_latest_intact(
    directory: str | os.PathLike[str],
    identity: Mapping[str, Any] | None = None,
    settings_sha256: str | None = None,
) -> IntactCheckpoint:
    """The newest checkpoint of ``directory`` that verifies, skipping corrupt newer ones.

    Each checkpoint holds the whole run state (generator states included), so
    resuming from an older intact one and redoing the lost steps finishes
    exactly like an uninterrupted run. When a newer checkpoint had to be
    skipped, one line says so (logged as a warning on ``softgym.io``, and in
    :attr:`IntactCheckpoint.message`). Nothing is deleted: the corrupt files
    are overwritten when their step is saved again.

    Parameters
    ----------
    directory : path
        A folder of checkpoints written by :func:`save_checkpoint`.
    identity : mapping, optional
        The run's identity (see :func:`load_checkpoint`). A checkpoint of
        another run, or one renamed to a step it does not record, is skipped
        like a corrupt one (and named in the message); a folder with none of
        the run's own raises.
    settings_sha256 : str, optional
        For a folder without a recorded identity (see :func:`load_checkpoint`).

    Returns
    -------
    IntactCheckpoint
        ``(state, arrays, path, skipped)``.

    Raises
    ------
    CheckpointError
        If the folder holds no checkpoint, or none of them is intact (the
        message names each one and why).
    """
    directory = Path(directory)
    ckpts = list_checkpoints(directory)
    if not ckpts:
        raise CheckpointError(f"{directory}: no checkpoint (ckpt-*.json) in this folder")
    skipped: list[tuple[Path, str]] = []
    for path in reversed(ckpts):
        try:
            state, arrays = load_checkpoint(path, identity, settings_sha256)
        except CheckpointError as exc:
            skipped.append((path, str(exc)))
            continue
        found = IntactCheckpoint(state, arrays, path, skipped)
        if skipped:
            logger.warning("%s", found.message)
        return found
    reasons = "; ".join(reason for _, reason in skipped)
    raise CheckpointError(f"{directory}: no intact checkpoint among {len(ckpts)}: {reasons}")


class RunLock:
    """An exclusive lock on a run folder: one writer at a time.

    Used as a context manager around everything that writes a run folder. The
    lock is an OS file lock (``fcntl.flock``; ``msvcrt.locking`` on Windows) on
    ``<folder>/.lock``, released by the OS when the holder exits or is killed,
    so a crashed run never leaves the folder locked. The file records the
    holder (pid, host, start time) for the message a second writer gets.

    Parameters
    ----------
    directory : path
        The run folder (created if needed).

    Raises
    ------
    RunFolderLockedError
        On entry, if another process holds the folder; the message names it.
    CheckpointError
        On entry, if ``.lock`` is a symbolic link or not a regular file (it is
        never followed nor written through), naming it.
    """

    #: The lock file's name in the run folder.
    FILE_NAME = ".lock"

    def __init__(self, directory: str | os.PathLike[str]) -> None:
        self.directory = Path(directory)
        self.path = self.directory / self.FILE_NAME
        self._fd: int | None = None

    def __enter__(self) -> RunLock:
        self.acquire()
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    def acquire(self) -> None:
        """Take the lock or raise :class:`RunFolderLockedError` naming the holder."""
        check_path_depth(self.directory, "run folder")
        self.directory.mkdir(parents=True, exist_ok=True)
        # never through a symbolic link (it could truncate a file outside the run folder),
        # never a FIFO or device (opened without blocking, then refused)
        flags = os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
        try:
            fd = os.open(self.path, flags, 0o644)
        except OSError as exc:
            if os.path.islink(self.path) or exc.errno == errno.ELOOP:
                raise CheckpointError(
                    f"lock file {str(self.path)!r} is a symbolic link, not a regular file; "
                    f"remove it (the run folder's lock is never followed elsewhere)"
                ) from None
            raise
        try:
            st = os.fstat(fd)
            if not stat.S_ISREG(st.st_mode):
                raise CheckpointError(
                    f"lock file {str(self.path)!r} is not a regular file (a FIFO, device or "
                    f"socket); remove it"
                )
            if st.st_nlink > 1:  # a hard link to a file elsewhere: writing the holder would change it
                raise CheckpointError(
                    f"lock file {str(self.path)!r} has {st.st_nlink} hard links (another file "
                    f"shares it); remove it"
                )
            if hasattr(os, "set_blocking"):
                os.set_blocking(fd, True)
        except BaseException:
            os.close(fd)
            raise
        try:
            _lock_fd(fd)
        except OSError:
            try:
                holder = os.read(fd, 4096).decode("utf-8", "replace").strip() or "another process"
            finally:
                os.close(fd)
            raise RunFolderLockedError(
                f"run folder {str(self.directory)!r} is in use by {holder}; wait for it to "
                f"finish or choose another --out"
            ) from None
        info = (f"pid {os.getpid()} on {socket.gethostname()} since "
                f"{time.strftime('%Y-%m-%d %H:%M:%S')}")  # fmt: skip
        os.ftruncate(fd, 0)
        os.lseek(fd, 0, os.SEEK_SET)
        os.write(fd, info.encode("utf-8"))
        os.lseek(fd, 0, os.SEEK_SET)
        self._fd = fd

    def release(self) -> None:
        """Give the lock back (the file stays: removing it could race a new holder)."""
        if self._fd is not None:
            try:
                _unlock_fd(self._fd)
            finally:
                os.close(self._fd)
                self._fd = None


if sys.platform == "win32":  # pragma: no cover - exercised on Windows only
    import msvcrt

    def _lock_fd(fd: int) -> None:
        os.lseek(fd, 0, os.SEEK_SET)
        msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)

    def _unlock_fd(fd: int) -> None:
        os.lseek(fd, 0, os.SEEK_SET)
        msvcrt.locking(fd, msvcrt.LK_UNLCK, 1)

else:
    import fcntl

    def _lock_fd(fd: int) -> None:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)

    def _unlock_fd(fd: int) -> None:
        fcntl.flock(fd, fcntl.LOCK_UN)


def _to_json(obj: Any) -> Any:
    if isinstance(obj, tuple):
        return [_to_json(v) for v in obj]
    if isinstance(obj, list):
        return [_to_json(v) for v in obj]
    if isinstance(obj, dict):
        return {k: _to_json(v) for k, v in obj.items()}
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return obj


def rng_state(rng: np.random.Generator) -> dict[str, Any]:
    """JSON-ready state of a numpy Generator (its bit generator's ``state`` dict).

    Raises
    ------
    InvalidParameterError
        If the bit generator is not one of :data:`RNG_BIT_GENERATORS` (it could
        not be restored).
    """
    if not isinstance(rng, np.random.Generator):
        raise InvalidParameterError(f"expected a numpy Generator, got {type(rng).__name__}")
    name = type(rng.bit_generator).__name__
    if RNG_BIT_GENERATORS.get(name) is not type(rng.bit_generator):
        raise InvalidParameterError(
            f"bit generator {name} cannot be checkpointed; use one of {sorted(RNG_BIT_GENERATORS)}"
        )
    return _to_json(rng.bit_generator.state)


def rng_from_state(state: Mapping[str, Any]) -> np.random.Generator:
    """A Generator restored from :func:`rng_state` (same bit generator kind).

    The bit generator is named from :data:`RNG_BIT_GENERATORS` only.

    Raises
    ------
    CheckpointError
        If the state is not a mapping, names a bit generator outside the
        allow-list, or does not fit that bit generator.
    """
    if not isinstance(state, Mapping):
        raise CheckpointError(f"random generator state must be an object, got {state!r:.80}")
    name = state.get("bit_generator")
    bitgen_cls = RNG_BIT_GENERATORS.get(name) if isinstance(name, str) else None
    if bitgen_cls is None:
        raise CheckpointError(
            f"unknown numpy bit generator {name!r:.80} in checkpoint "
            f"(expected one of {sorted(RNG_BIT_GENERATORS)})"
        )
    bg = bitgen_cls()
    try:
        bg.state = dict(state)
    except (TypeError, ValueError, KeyError, IndexError, OverflowError) as exc:
        raise CheckpointError(f"invalid {name} state in checkpoint: {exc!s:.200}") from None
    return np.random.Generator(bg)


def python_random_state(rnd: Any = None) -> list[Any]:
    """JSON-ready ``random.getstate()`` (of the module, or of a ``random.Random``)."""
    import random

    st = (rnd or random).getstate()
    return [st[0], list(st[1]), st[2]]


def set_python_random_state(state: list[Any], rnd: Any = None) -> None:
    """Inverse of :func:`python_random_state`.

    Raises
    ------
    CheckpointError
        If ``state`` is not ``[version, [625 ints], gauss_next]`` as
        :func:`python_random_state` writes it.
    """
    import random

    ok = (
        isinstance(state, (list, tuple))
        and len(state) == 3
        and isinstance(state[1], (list, tuple))
        and len(state[1]) == 625
        and all(type(v) is int and 0 <= v < 2**32 for v in state[1])
        and (state[2] is None or type(state[2]) is float)
    )
    if not ok:
        raise CheckpointError(
            "python random state in checkpoint must be [version, [625 ints], gauss_next]"
        )
    try:
        (rnd or random).setstate((state[0], tuple(state[1]), state[2]))
    except (TypeError, ValueError, OverflowError) as exc:
        raise CheckpointError(f"invalid python random state in checkpoint: {exc}") from None
