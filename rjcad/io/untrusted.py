"""Untrusted input: every file a user gives rjcad (TOML, JSON, CSV) is read and parsed here, and checked.

What a reader gets from :func:`read_toml`, :func:`read_json` or :func:`read_text` is a regular file (a FIFO, a
device or a directory is refused before it is read: nothing blocks) that exists, is at most ``MAX_BYTES[kind]``
long (its size checked before it is read), is UTF-8 text (a BOM is dropped) without NUL bytes and, parsed, nests at
most ``MAX_DEPTH`` tables/arrays deep, holds no integer too large for a float and no NaN or infinity.
Anything else is one :class:`RjcadError` line naming the file (and the key): never a traceback, never the
file's content (only a short prefix of a value, :func:`rjcad.errors.quote`). Values are then checked by
their reader, with :func:`rjcad.validate.in_range` (a finite number in range; booleans are not numbers).

:func:`confined` resolves a file named inside another one (a campaign's CSV files) and keeps it inside
that file's folder.
"""

from __future__ import annotations

import json
import math
import os
import stat
import sys
import tomllib
from pathlib import Path
from typing import Any

from rjcad.errors import ParameterError, RjcadError, quote

#: Largest file read, by kind [bytes]: design, sweep and campaign TOML files are written by hand; a
#: manifest is a few kB; a campaign CSV holds up to a few million rows.
MAX_BYTES = {"TOML": 1 << 20, "JSON": 32 << 20, "CSV": 256 << 20, "text": 32 << 20, "mesh": 256 << 20}
#: A zip container (3MF) read: at most this many members, inflating to at most this many bytes in all, each
#: member at most MAX_ZIP_RATIO times its compressed size (a zip bomb is refused before anything is inflated).
MAX_ZIP_MEMBERS, MAX_ZIP_BYTES, MAX_ZIP_RATIO = 10_000, 256 << 20, 1000
#: Deepest nesting of tables and arrays (rjcad's own files nest at most 4 deep).
MAX_DEPTH = 32
#: Byte order marks of the encodings a user's editor may save in instead of UTF-8.
_BOMS = (
    (b"\xef\xbb\xbf", None),
    (b"\xff\xfe\x00\x00", "UTF-32"),
    (b"\x00\x00\xfe\xff", "UTF-32"),
    (b"\xff\xfe", "UTF-16"),
    (b"\xfe\xff", "UTF-16"),
)


def _size_text(n: int) -> str:
    return f"{n / (1 << 20):.0f} MB" if n >= 1 << 20 else f"{n} bytes"


def read_bytes(path: str | os.PathLike, kind: str = "text", name: str | None = None) -> bytes:
    """The bytes of the regular file ``path`` (at most ``MAX_BYTES[kind]``); RjcadError naming ``name`` (default: the
    path) if it is missing, a directory, a FIFO, a device or a socket, unreadable or too large. It is opened without
    blocking (a FIFO with no writer would wait for ever) and its type and size are checked before it is read."""
    p = Path(path)
    label = str(p) if name is None else name
    limit = MAX_BYTES[kind]
    flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(p, flags)
    except FileNotFoundError:
        raise RjcadError(f"{label}: file not found") from None
    except IsADirectoryError:
        raise RjcadError(f"{label}: is a directory, not a {kind} file") from None
    except (OSError, ValueError) as e:  # ValueError: a NUL byte in the name
        raise RjcadError(f"{label}: cannot read ({getattr(e, 'strerror', None) or type(e).__name__})") from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise RjcadError(f"{label}: is a directory, not a {kind} file")
        if not stat.S_ISREG(st.st_mode):
            raise RjcadError(f"{label}: not a regular file (a {_file_type(st.st_mode)}): give a {kind} file")
        if st.st_size > limit:
            raise RjcadError(f"{label}: too large: a {kind} file must be at most {_size_text(limit)}")
        with os.fdopen(os.dup(fd), "rb") as f:
            raw = f.read(limit + 1)
    except OSError as e:
        raise RjcadError(f"{label}: cannot read ({e.strerror or type(e).__name__})") from None
    finally:
        os.close(fd)
    if len(raw) > limit:
        raise RjcadError(f"{label}: too large: a {kind} file must be at most {_size_text(limit)}")
    return raw


def _file_type(mode: int) -> str:
    kinds = ((stat.S_ISFIFO, "FIFO"), (stat.S_ISCHR, "character device"), (stat.S_ISBLK, "block device"))
    return next((name for test, name in kinds if test(mode)), "socket" if stat.S_ISSOCK(mode) else "special file")


def regular_or_absent(path: str | os.PathLike, name: str | None = None) -> bool:
    """True if ``path`` is a regular file (symlinks followed), False if nothing is there; RjcadError naming ``name``
    for a FIFO, a device, a socket or a directory (a reader that only looks whether a file exists)."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        return False
    except (OSError, ValueError) as e:
        raise RjcadError(f"{name or path}: cannot read ({getattr(e, 'strerror', None) or type(e).__name__})") from None
    if stat.S_ISREG(st.st_mode):
        return True
    what = "a directory" if stat.S_ISDIR(st.st_mode) else f"a {_file_type(st.st_mode)}"
    raise RjcadError(f"{name or path}: not a regular file ({what})")


def read_text(path: str | os.PathLike, kind: str = "text", name: str | None = None) -> str:
    """The UTF-8 text of ``path`` (:func:`read_bytes`, then :func:`decode`: a BOM dropped); RjcadError naming
    ``name`` (default: the path) if it is missing, not a regular file, unreadable, too large, not UTF-8 or holds
    NUL bytes."""
    label = str(path) if name is None else name
    return decode(read_bytes(path, kind, label), label, kind)


def check_zip(raw: bytes, label: str) -> None:
    """Refuse a zip container (a 3MF) before inflating it: not a zip, more than MAX_ZIP_MEMBERS members, more than
    MAX_ZIP_BYTES inflated in all, or a member inflating more than MAX_ZIP_RATIO-fold (RjcadError naming ``label``)."""
    import io
    import zipfile

    try:
        infos = zipfile.ZipFile(io.BytesIO(raw)).infolist()
    except (zipfile.BadZipFile, OSError, ValueError, EOFError) as e:
        raise RjcadError(f"{label}: not a readable zip container ({_one_line(e)})") from None
    if len(infos) > MAX_ZIP_MEMBERS:
        raise RjcadError(f"{label}: {len(infos)} zip members; at most {MAX_ZIP_MEMBERS} are read")
    total = sum(i.file_size for i in infos)
    if total > MAX_ZIP_BYTES:
        raise RjcadError(f"{label}: inflates to {_size_text(total)}; at most {_size_text(MAX_ZIP_BYTES)} are read")
    for i in infos:
        if i.file_size > (1 << 20) and i.file_size > MAX_ZIP_RATIO * max(i.compress_size, 1):
            raise RjcadError(
                f"{label}: zip member {quote(i.filename)} inflates {i.file_size // max(i.compress_size, 1)}-fold; "
                f"at most {MAX_ZIP_RATIO}-fold is read (a zip bomb)"
            )


def decode(raw: bytes, label: str, kind: str = "text") -> str:
    """``raw`` as UTF-8 text (BOM dropped, line ends as "\\n"); RjcadError naming ``label`` for another encoding
    or binary data."""
    for bom, encoding in _BOMS:
        if raw.startswith(bom):
            if encoding:
                raise RjcadError(f"{label}: {encoding} text; save the {kind} file as UTF-8")
            raw = raw[len(bom) :]
            break
    if b"\x00" in raw:
        raise RjcadError(f"{label}: holds NUL bytes: a binary file, not a {kind} file")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        line = raw.count(b"\n", 0, e.start) + 1
        raise RjcadError(f"{label}: not a UTF-8 text file (byte 0x{raw[e.start]:02x} on line {line})") from None
    return text.replace("\r\n", "\n").replace("\r", "\n") if "\r" in text else text  # universal newlines


def shown_path(path: str | os.PathLike) -> str:
    """``path`` as a user reads it best in a message: relative below the working folder, ``~/…`` below the home
    folder, else as it is (so that what rjcad prints does not depend on where a machine keeps its folders)."""
    if not str(path):
        return ""
    p = Path(path)
    for base, prefix in ((Path.cwd, ""), (Path.home, "~/")):
        try:
            return prefix + p.resolve().relative_to(base().resolve()).as_posix()
        except (ValueError, OSError, RuntimeError):  # not below it, or no such folder
            continue
    return str(p)


def read_toml(path: str | os.PathLike, name: str | None = None) -> dict[str, Any]:
    """The checked TOML document of ``path`` (see the module docstring); RjcadError naming the file."""
    label = str(path) if name is None else name
    return parse_toml(read_text(path, "TOML", label), label)


def parse_toml(text: str, label: str) -> dict[str, Any]:
    """``text`` parsed as TOML and checked (:func:`check_tree`); RjcadError naming ``label``."""
    try:
        data = tomllib.loads(text)
    except RecursionError:
        raise RjcadError(f"{label}: not valid TOML (nested deeper than {MAX_DEPTH} tables or arrays)") from None
    except ValueError as e:  # TOMLDecodeError is one; so is an integer of more than 4300 digits
        raise RjcadError(f"{label}: not valid TOML ({_one_line(e)})") from None
    return check_tree(data, label)


def read_json(path: str | os.PathLike, name: str | None = None) -> Any:
    """The checked JSON value of ``path`` (see the module docstring); RjcadError naming the file."""
    label = str(path) if name is None else name
    return parse_json(read_text(path, "JSON", label), label)


def parse_json(text: str, label: str) -> Any:
    """``text`` parsed as JSON and checked (:func:`check_tree`: NaN and Infinity refused, naming the key);
    RjcadError naming ``label``."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as e:
        raise RjcadError(f"{label}: not valid JSON ({e.msg} at line {e.lineno}, column {e.colno})") from None
    except RecursionError:
        raise RjcadError(f"{label}: not valid JSON (nested deeper than {MAX_DEPTH} objects or arrays)") from None
    except ValueError as e:
        raise RjcadError(f"{label}: not valid JSON ({_one_line(e)})") from None
    return check_tree(data, label)


def check_tree(data: Any, label: str) -> Any:
    """``data`` if it nests at most MAX_DEPTH deep, and every number in it is finite and fits a float.

    Walked without recursion; otherwise RjcadError (ParameterError for a number) naming ``label`` and the key
    path (``a.b[2].c``).
    """
    stack = [(data, "", 1)]
    while stack:
        value, where, depth = stack.pop()
        if isinstance(value, (dict, list)):
            if depth > MAX_DEPTH:
                raise RjcadError(f"{label}: {_key(where)} nests deeper than {MAX_DEPTH} tables or arrays")
            items = value.items() if isinstance(value, dict) else enumerate(value)
            for k, v in items:
                key = f"{where}[{k + 1}]" if isinstance(value, list) else (f"{where}.{k}" if where else str(k))
                stack.append((v, key, depth + 1))
        elif isinstance(value, bool):
            continue
        elif isinstance(value, int) and not _fits_float(value):
            raise ParameterError(f"{label}: {_key(where)}", value, f"must fit a float (|x| < {sys.float_info.max:.3g})")
        elif isinstance(value, float) and not math.isfinite(value):
            raise ParameterError(f"{label}: {_key(where)}", value, "must be a finite number")
    return data


def _fits_float(i: int) -> bool:
    try:
        float(i)
    except OverflowError:
        return False
    return True


def parse_json_lines(text: str, label: str) -> list[Any]:
    """Each non-blank line of ``text`` parsed as JSON (:func:`parse_json`: the same depth and number checks), or None
    for a line that is not valid JSON (a reader of a log drops those)."""
    out: list[Any] = []
    for k, line in enumerate(text.split("\n"), 1):
        if line.strip():
            try:
                out.append(parse_json(line, f"{label}: line {k}"))
            except RjcadError:
                out.append(None)
    return out


def _key(where: str) -> str:
    return quote(where, 80, repr_=False) if where else "the document"


def _one_line(e: Exception) -> str:
    return quote(" ".join(str(e).split()), 120, repr_=False)


def confined(folder: Path, name: str, label: str, allow_outside: bool = False) -> Path:
    """``folder / name``; unless ``allow_outside``, RjcadError naming ``label`` when it resolves (symlinks
    followed) outside ``folder``: ``../../etc/passwd``, an absolute path, a link out of the folder."""
    path = folder / name
    if allow_outside:
        return path
    try:
        base, real = folder.resolve(), path.resolve()
    except (OSError, ValueError, RuntimeError) as e:  # a NUL byte, a name too long, a symlink loop (RuntimeError)
        why = getattr(e, "strerror", None) or e
        raise RjcadError(f"{label}: file {quote(name)} cannot be opened ({why})") from None
    if base not in real.parents:
        raise RjcadError(
            f"{label}: file {quote(name)} is outside {base} (symlinks followed): data files must lie "
            "in the folder of the file that names them (or pass --allow-outside)"
        )
    return path
