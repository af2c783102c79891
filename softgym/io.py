"""Atomic, versioned, pickle-free files: run checkpoints and JSON documents.

A checkpoint is a pair of files written into one folder::

    ckpt-000007.npz   numeric arrays (numpy's npz, loaded with allow_pickle=False)
    ckpt-000007.json  {"schema", "version", "step", "npz", "npz_sha256",
                       "state_sha256", "state": {...}}

Both are written to a temporary file, flushed to disk and renamed into place,
the npz first: the JSON is the commit record, so a checkpoint exists only
once both halves are complete. The JSON holds the SHA-256 of the npz and of
its own state, so truncation or corruption of either file is detected and
raises :class:`~softgym.exceptions.CheckpointError` naming the file. The
previous ``keep - 1`` checkpoints stay on disk, so a bad latest checkpoint
never destroys the last good one.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from softgym.exceptions import CheckpointError

__all__ = [
    "CHECKPOINT_SCHEMA",
    "CHECKPOINT_VERSION",
    "atomic_write_bytes",
    "atomic_write_json",
    "atomic_write_text",
    "latest_checkpoint",
    "list_checkpoints",
    "load_checkpoint",
    "read_json",
    "rng_from_state",
    "rng_state",
    "python_random_state",
    "set_python_random_state",
    "save_checkpoint",
]

#: ``"schema"`` field of a checkpoint's JSON half.
CHECKPOINT_SCHEMA = "softgym.checkpoint"
#: Newest checkpoint version this softgym writes and reads.
CHECKPOINT_VERSION = 1

_NAME = re.compile(r"^ckpt-(\d{6,})\.json$")


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file, fsync and rename.

    A reader sees either the old file or the complete new one, never a part.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    with open(tmp, "wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)
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


def read_json(path: str | os.PathLike[str]) -> Any:
    """Read a JSON file; a missing or malformed file raises :class:`CheckpointError` naming it."""
    path = Path(path)
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise CheckpointError(f"{path}: file not found") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise CheckpointError(f"{path}: corrupt or truncated JSON ({exc})") from exc


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _state_digest(state: Any) -> str:
    return _sha256(json.dumps(state, sort_keys=True, allow_nan=True).encode("utf-8"))


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

    Returns
    -------
    Path
        The JSON file of the new checkpoint.
    """
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
    atomic_write_bytes(directory / f"{stem}.npz", npz_bytes)
    state = dict(state)
    doc = {
        "schema": CHECKPOINT_SCHEMA,
        "version": CHECKPOINT_VERSION,
        "step": int(step),
        "npz": f"{stem}.npz",
        "npz_sha256": _sha256(npz_bytes),
        "state_sha256": _state_digest(state),
        "state": state,
    }
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


def load_checkpoint(path: str | os.PathLike[str]) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """Read and verify a checkpoint written by :func:`save_checkpoint`.

    Parameters
    ----------
    path : path
        The checkpoint's JSON file (or a folder: its latest checkpoint).

    Returns
    -------
    state : dict
        The JSON state, with ``"step"`` added.
    arrays : dict of str to ndarray

    Raises
    ------
    CheckpointError
        Naming the file, if either half is missing, truncated, corrupt, of
        another schema or of a newer version.
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
    if not isinstance(state, dict) or _state_digest(state) != doc.get("state_sha256"):
        raise CheckpointError(f"{path}: checkpoint state is corrupt (checksum mismatch)")
    npz_path = path.with_name(str(doc.get("npz")))
    try:
        npz_bytes = npz_path.read_bytes()
    except FileNotFoundError:
        raise CheckpointError(
            f"{npz_path}: array file of checkpoint {path.name} is missing"
        ) from None
    if _sha256(npz_bytes) != doc.get("npz_sha256"):
        raise CheckpointError(f"{npz_path}: corrupt or truncated array file (checksum mismatch)")
    try:
        with np.load(io.BytesIO(npz_bytes), allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (ValueError, OSError) as exc:  # pragma: no cover - the checksum catches this first
        raise CheckpointError(f"{npz_path}: unreadable array file ({exc})") from exc
    state = dict(state)
    state["step"] = int(doc["step"])
    return state, arrays


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
    """JSON-ready state of a numpy Generator (its bit generator's ``state`` dict)."""
    return _to_json(rng.bit_generator.state)


def rng_from_state(state: Mapping[str, Any]) -> np.random.Generator:
    """A Generator restored from :func:`rng_state` (same bit generator kind)."""
    name = state["bit_generator"]
    bitgen_cls = getattr(np.random, name, None)
    if bitgen_cls is None:
        raise CheckpointError(f"unknown numpy bit generator {name!r} in checkpoint")
    bg = bitgen_cls()
    bg.state = dict(state)
    return np.random.Generator(bg)


def python_random_state(rnd: Any = None) -> list[Any]:
    """JSON-ready ``random.getstate()`` (of the module, or of a ``random.Random``)."""
    import random

    st = (rnd or random).getstate()
    return [st[0], list(st[1]), st[2]]


def set_python_random_state(state: list[Any], rnd: Any = None) -> None:
    """Inverse of :func:`python_random_state`."""
    import random

    (rnd or random).setstate((state[0], tuple(state[1]), state[2]))
