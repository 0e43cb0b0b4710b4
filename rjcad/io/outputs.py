"""Output places and output sets: a write that cannot happen is one error line, and a set of files is whole.

An output set (a joint's STL, 3MF, STEP, PNG and JSON; a report and its plots; a sweep's results) is
written whole or not at all: every file goes into a temporary directory inside the output directory (the
same filesystem), then each is renamed into place. The files it replaces are set aside until the last
rename and put back if one fails, so an earlier run's files are left byte for byte, mtime for mtime.
Single files: ``rjcad.io.config.write_atomic`` (temporary file + rename), with the same error.
"""

from __future__ import annotations

import errno
import os
import re
import shutil
import signal
import stat
import sys
import tempfile
import threading
from collections.abc import Iterator, Mapping
from contextlib import contextmanager, suppress
from pathlib import Path

from rjcad.errors import RjcadError

#: Inside a stage: the files a commit replaces, until it is done.
_ASIDE = ".replaced"
#: True once this process has put an output set or file in place. A signal after that is answered by finishing
#: the command (``rjcad.cli`` ignores it): a run never ends "terminated" with its new files in place.
PLACED = False


def stage_prefix() -> str:
    """The start of this process's temporary names (short: any legal output name fits beside them; with the pid,
    so that a later run can tell a killed run's leftovers from a live run's)."""
    return f".rjcad-{os.getpid()}-"


def _hold() -> set | None:
    """Hold SIGINT and SIGTERM back (pending) in the main thread; the mask before (None: not the main thread)."""
    if threading.current_thread() is not threading.main_thread():
        return None
    return signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})


def _release(old: set | None) -> None:
    """Deliver what ``_hold`` held back (its handler runs now)."""
    if old is not None:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


@contextmanager
def signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM held back (left pending) while files are renamed into place, in the main thread."""
    old = _hold()
    try:
        yield
    finally:
        _release(old)


def clear_stale(out: Path) -> None:
    """Remove the temporary files and stages a killed run left in ``out`` (named with a pid no longer running)."""
    with suppress(OSError):
        for entry in out.iterdir():
            m = re.fullmatch(r"\.rjcad-(\d+)-[^/]*\.tmp", entry.name)
            if m and int(m.group(1)) != os.getpid() and not _alive(int(m.group(1))):
                if entry.is_dir() and not entry.is_symlink():
                    shutil.rmtree(entry, ignore_errors=True)
                else:
                    entry.unlink(missing_ok=True)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


class OutputError(RjcadError):
    """An output path that cannot be written: ``path`` and the system's ``reason``."""

    def __init__(self, path: str | os.PathLike, reason: str):
        self.path, self.reason = Path(path), reason
        super().__init__(f"{path}: cannot write: {reason}")

    def __reduce__(self):  # raised in a sweep worker, it crosses to the main process
        return OutputError, (self.path, self.reason)


class TemporaryWriteError(OSError):
    """A file an output is made through (OpenCASCADE's STEP, read back) could not be written in the temporary
    folder: a full disk, a file size limit. Reported against the output directory (``OutputError``)."""


def cannot_write(path: str | os.PathLike, err: OSError) -> OutputError:
    """The ``OutputError`` for ``path`` from the OSError that stopped its write (names a file in the way)."""
    path = Path(path)
    if isinstance(err, (NotADirectoryError, FileExistsError)):
        block = next((a for a in (path, *path.parents) if a.exists() or a.is_symlink()), None)
        if block is not None and not block.is_dir():
            return OutputError(path, "not a directory" if block == path else f"{block} is not a directory")
    return OutputError(path, err.strerror or str(err))


def refuse_special(path: str | os.PathLike) -> None:
    """OutputError if ``path`` is a symbolic link, a FIFO, a device or a socket: rjcad never writes through a link
    and never replaces one, nor such a file (a directory or a regular file, or nothing, passes)."""
    try:
        mode = os.lstat(path).st_mode
    except (OSError, ValueError):
        return  # absent, or a name the write itself will refuse
    if stat.S_ISLNK(mode):
        raise OutputError(path, "is a symbolic link: rjcad never writes through a link nor replaces one")
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        kind = "FIFO" if stat.S_ISFIFO(mode) else "device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode) else "socket"
        raise OutputError(path, f"is a {kind}, not a regular file: rjcad does not replace it")


#: Linux's FS_IOC_GETFLAGS (``lsattr``), and its append-only and immutable flags.
_GETFLAGS, _APPEND_ONLY, _IMMUTABLE = 0x80086601, 0x20, 0x10


def refuse_append_only(folder: str | os.PathLike) -> None:
    """OutputError if ``folder`` is append-only or immutable (``chattr +a``/``+i``): a file written there could not
    be renamed into place nor its temporary removed, so nothing is written (Linux; elsewhere nothing is checked)."""
    try:
        import fcntl

        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except (OSError, ImportError, ValueError):
        return
    try:
        flags = int.from_bytes(fcntl.ioctl(fd, _GETFLAGS, bytes(8))[:4], sys.byteorder)
    except OSError:
        return  # a file system without these flags
    finally:
        os.close(fd)
    if flags & (_APPEND_ONLY | _IMMUTABLE):
        kind = "append-only" if flags & _APPEND_ONLY else "immutable"
        raise OutputError(
            folder, f"the folder is {kind} (chattr): rjcad writes by renaming into place, which it forbids"
        )


def check_writable(out_dir: str | os.PathLike) -> Path:
    """Refuse, before a long computation, an output directory that cannot be made or written; creates nothing.

    A full disk shows only when writing (``output_set`` then leaves the directory as it was).
    """
    out = Path(out_dir)
    near = next(a for a in (out, *out.parents, Path(".")) if a.exists() or a.is_symlink())
    if not near.is_dir():
        raise OutputError(out, "not a directory" if near == out else f"{near} is not a directory")
    refuse_append_only(near)
    if not os.access(near, os.W_OK | os.X_OK):
        read_only = bool(os.statvfs(near).f_flag & getattr(os, "ST_RDONLY", 1))
        raise OutputError(out, os.strerror(errno.EROFS if read_only else errno.EACCES))
    return out


@contextmanager
def output_set(out_dir: str | os.PathLike, remove: tuple[str, ...] = ()) -> Iterator[Path]:
    """Stage an output set: yield a fresh directory inside ``out_dir`` to write the set's files into.

    On a clean exit every file (or folder) staged there moves into ``out_dir``, replacing earlier ones (a folder
    replaces the earlier folder whole; the names in ``remove`` that this set does not write are removed too, a name
    ending in "/" a folder, so a set never mixes runs). On any error or
    interrupt ``out_dir`` is left as it was (and removed if this call made it). Write errors are
    ``OutputError``s naming the file in ``out_dir``, never the stage.
    """
    out = Path(out_dir)
    made = make_dirs(out)
    held = _hold()  # until the clean-up below is armed: a signal in between would leave the stage behind
    try:
        refuse_append_only(out)
        clear_stale(out)
        times = os.stat(out)
        stage = Path(tempfile.mkdtemp(dir=out, prefix=stage_prefix(), suffix=".tmp"))
    except OSError as e:
        _release(held)
        unmake(made)
        raise cannot_write(out, e) from None
    except BaseException:
        _release(held)
        unmake(made)
        raise
    done = False
    try:
        _release(held)
        yield stage
        _commit(stage, out, remove)
        done = True
    except OutputError as e:
        raise OutputError(_target(e.path, stage, out), e.reason) from None
    except OSError as e:
        raise cannot_write(_target(Path(e.filename or out), stage, out), e) from None
    finally:
        aside = stage / _ASIDE
        if done or not (aside.is_dir() and any(aside.iterdir())):  # else: earlier files that could not go back
            shutil.rmtree(stage, ignore_errors=True)
        if not done:
            unmake(made)
            restore_times(out, times)


def write_set(
    out_dir: str | os.PathLike[str], files: Mapping[str, bytes | str], remove: tuple[str, ...] = ()
) -> list[Path]:
    """Write ``files`` (name → bytes, or text as UTF-8) into ``out_dir`` as one set (``output_set``). A name is a
    plain file name or a relative path ("mjcf/meshes/base.stl"): its top folder is then the set's, written whole."""
    out = Path(out_dir)
    for name in files:
        parts = name.split("/")
        if any(not p or p.startswith(".") or Path(p).name != p for p in parts):
            raise ValueError(f"output set member {name!r}: must be a plain file name or a relative path of them")
    with output_set(out, remove) as stage:
        for name, data in files.items():
            try:
                (stage / name).parent.mkdir(parents=True, exist_ok=True)
                (stage / name).write_bytes(data.encode("utf-8") if isinstance(data, str) else data)
            except OSError as e:
                raise cannot_write(out / name, e) from None
    return [out / name for name in files]


def make_dirs(out: Path) -> list[Path]:
    """Make ``out`` and its missing parents; return the ones made, deepest first."""
    missing = []
    for d in (out, *out.parents):
        if d.exists() or d.is_symlink():
            break
        missing.append(d)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        unmake(missing)
        raise cannot_write(out, e) from None
    return missing


def unmake(made: list[Path]) -> None:
    """Remove the directories ``make_dirs`` made, if still empty."""
    for d in made:
        with suppress(OSError):
            d.rmdir()


def restore_times(out: Path, st: os.stat_result) -> None:
    """Give ``out`` back the times it had before a temporary file or stage came and went (best effort)."""
    with suppress(OSError):
        os.utime(out, ns=(st.st_atime_ns, st.st_mtime_ns))


def _target(path: Path, stage: Path, out: Path) -> Path:
    """Where a staged path goes in ``out`` (errors name the target, never the stage)."""
    try:
        parts = Path(path).relative_to(stage).parts
    except ValueError:
        return Path(path)
    if parts and parts[0] == _ASIDE:
        parts = parts[1:]
    return out.joinpath(*parts)


def _commit(stage: Path, out: Path, remove: tuple[str, ...]) -> None:
    """Move the staged files (and folders) into ``out``, each one they replace set aside first; undo all on a
    failure. An earlier directory is replaced only by a staged folder or a ``remove`` name ending in "/"."""
    new = sorted(p.name for p in stage.iterdir())
    for n in dict.fromkeys([*new, *(r.rstrip("/") for r in remove)]):
        refuse_special(out / n)
    folders = {n for n in new if (stage / n).is_dir()} | {n.rstrip("/") for n in remove if n.endswith("/")}
    old = [n for n in dict.fromkeys([*new, *(r.rstrip("/") for r in remove)]) if os.path.lexists(out / n)]
    for n in old:
        if (out / n).is_dir() and not (out / n).is_symlink() and n not in folders:
            raise OutputError(out / n, os.strerror(errno.EISDIR))
    aside = stage / _ASIDE
    aside.mkdir()
    saved: list[str] = []
    moved: list[str] = []
    current = out
    global PLACED
    try:
        with signals_held():  # a signal waits until the whole set is in place (or back as it was)
            for n in old:
                current = out / n
                os.replace(out / n, aside / n)
                saved.append(n)
            for n in new:
                current = out / n
                os.replace(stage / n, out / n)
                moved.append(n)
            PLACED = True
    except BaseException as e:
        if not _undo(stage, out, moved, saved):
            raise OutputError(
                current, f"{getattr(e, 'strerror', None) or e!r}; earlier files kept in {aside}"
            ) from None
        if isinstance(e, OSError):
            raise cannot_write(current, e) from None
        raise


def _undo(stage: Path, out: Path, moved: list[str], saved: list[str]) -> bool:
    """Put the earlier files back after a failed commit; False if one could not be restored."""
    ok = True
    for n in reversed(moved):
        try:
            os.replace(out / n, stage / n)
        except OSError:
            ok = False
    for n in reversed(saved):
        try:
            os.replace(stage / _ASIDE / n, out / n)
        except OSError:
            ok = False
    return ok
