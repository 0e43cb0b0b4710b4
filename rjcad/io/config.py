"""TOML design files: load, check keys, and write outputs atomically."""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from rjcad.errors import ParameterError
from rjcad.io import outputs
from rjcad.io.outputs import OutputError, cannot_write, make_dirs, refuse_special, restore_times, unmake
from rjcad.io.untrusted import read_toml

#: Known keys and the type (or types) each takes.
KeyTypes = Mapping[str, type | tuple[type, ...]]


def load_toml(path: str | os.PathLike[str], allowed: KeyTypes) -> dict[str, Any]:
    """Read a TOML file (rjcad.io.untrusted: size, depth, finite numbers) and check every top-level key against
    ``allowed`` (key → type)."""
    p = Path(path)
    data = read_toml(p)
    for key, value in data.items():
        check_key(f"{p.name}: ", key, value, allowed)
    return data


def check_key(where: str, key: str, value: Any, allowed: KeyTypes) -> Any:
    """``value`` if ``key`` is known and of its type; else ParameterError naming ``where + key``."""
    if key not in allowed:
        raise ParameterError(f"{where}{key}", value, f"unknown key; known keys: {', '.join(allowed)}")
    want = allowed[key]
    if isinstance(value, bool) or not isinstance(value, want):
        names = " or ".join(t.__name__ for t in (want if isinstance(want, tuple) else (want,)))
        raise ParameterError(f"{where}{key}", value, f"must be a {names}")
    return value


def write_atomic(path: str | os.PathLike, data: bytes | str) -> Path:
    """Write ``data`` to a temporary file beside ``path`` (a short name, so that any name the file system allows
    works), then rename it into place.

    A path that cannot be written is an ``OutputError`` naming it and the system's reason; a symbolic link, a FIFO
    or a device at ``path`` is refused (never written through, never replaced); nothing is left, not even the
    folders it made.
    """
    path = Path(path)
    raw = data.encode("utf-8") if isinstance(data, str) else data
    refuse_special(path)
    made = make_dirs(path.parent)
    try:
        outputs.refuse_append_only(path.parent)
    except OutputError:
        unmake(made)
        raise
    try:
        parent = os.stat(path.parent)  # its times come back if the write fails: an earlier run untouched
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=outputs.stage_prefix(), suffix=".tmp")
    except OSError as e:
        unmake(made)
        raise cannot_write(path, e) from None
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(raw)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        refuse_special(path)  # a link made while the data was written
        with outputs.signals_held():
            os.replace(tmp, path)
            outputs.PLACED = True
    except BaseException as e:
        Path(tmp).unlink(missing_ok=True)
        restore_times(path.parent, parent)
        unmake(made)
        if isinstance(e, OSError):
            raise cannot_write(path, e) from None
        raise
    return path


def write_json(path: str | os.PathLike, obj: Any) -> Path:
    """Atomically write ``obj`` as indented JSON."""
    return write_atomic(path, json.dumps(obj, indent=2, sort_keys=False) + "\n")
