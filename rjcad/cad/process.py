"""A second process for the CAD work of ``rjcad joint``: it imports OCP (OpenCASCADE) while this process designs
the spring and imports the mesh side (trimesh, VTK), then builds the joint and hands back plain numbers.

Importing OCP's library is about 1.0 s and nothing in it can start before the design is known; the design,
trimesh and VTK take another 1.3 s that do not need OCP. Forked before either, the child pays the first while
the parent pays the second, on two cores (``benchmarks/cli.py`` measures what it saves against one process).
The child runs ``rjcad.cad.measure.LocalJoint`` (the in-process builder itself) and sends its three stages
as they are ready: the shape (triangles, tendon, axis), the measurements, the STEP file. The parent meshes
and renders the first while the child measures and writes STEP. The arrays cross the pipe pickled, bit for
bit: the files are the ones an in-process build writes (``tests/test_cad_process.py``). Building the two
bodies in two processes as well was tried and gave nothing (OCCT's booleans already use both cores): the
bodies are built here one after the other.

Used only by the ``rjcad`` program itself (``rjcad.cli.entry``), where fork is the platform's way to start a
process, before any thread or OCP exists in it, and unless ``RJCAD_CAD_PROCESS=0``. An error in the
child is raised again in the parent (its traceback is a note, printed with ``--debug``). The child ignores
Ctrl-C and SIGTERM's handler (the parent handles both and ends it), and ends when the parent's end of the
pipe closes.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import pickle
import signal
import sys
import threading
import traceback

#: Set to 0 to build in the ``rjcad`` program's own process.
ENV = "RJCAD_CAD_PROCESS"


class CadProcessError(RuntimeError):
    """The CAD process ended without an answer (it crashed or was killed)."""


def usable() -> bool:
    """True if a forked CAD process would help and is safe: fork is available (Linux), this process has one
    thread and no OpenCASCADE (OCP) yet, and ``RJCAD_CAD_PROCESS`` is not 0."""
    return (
        os.environ.get(ENV, "1") != "0"
        and sys.platform.startswith("linux")
        and "fork" in multiprocessing.get_all_start_methods()
        and threading.active_count() == 1
        and "OCP" not in sys.modules
    )


class CadProcess:
    """The forked CAD process (a context manager: leaving it ends the process). ``joint(p)`` asks it for the
    joint of ``p``; the answer's ``shape()``, ``measures()`` and ``step(name)`` are ``LocalJoint``'s."""

    def __init__(self):
        ctx = multiprocessing.get_context("fork")
        for stream in (sys.stdout, sys.stderr):  # the child inherits the buffers; nothing may be written twice
            stream.flush()
        self._conn, child = ctx.Pipe()
        self._proc = ctx.Process(target=_serve, args=(child, self._conn), name="rjcad-cad", daemon=True)
        self._proc.start()
        child.close()
        self._asked = False

    def __enter__(self) -> CadProcess:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """End the child (at once if it is still working) and reap it."""
        self._conn.close()
        if self._proc.is_alive():
            self._proc.kill()
        self._proc.join()

    def joint(self, p) -> RemoteJoint:
        """Send ``p`` (a validated ``JointParams``) to be built; one joint per process."""
        if self._asked:
            raise RuntimeError("a CAD process builds one joint")
        self._asked = True
        with contextlib.suppress(OSError):  # the child is gone: say so where its answer is read
            self._conn.send(p)
        return RemoteJoint(self, p)

    def _receive(self):
        """The child's next answer, or its error raised here."""
        try:
            kind, value = self._conn.recv()
        except (EOFError, OSError):  # closed, or reset by a child that died
            self._proc.join(5)
            raise CadProcessError(
                f"the CAD process ended without an answer (exit code {self._proc.exitcode})"
            ) from None
        if kind == "error":
            exc, text = value
            exc.add_note(f"in the CAD process:\n{text}")
            raise exc
        return value


class RemoteJoint:
    """The joint the CAD process builds: ``LocalJoint``'s three stages, each received once, in order."""

    #: The bodies stay in the child.
    solids = None

    def __init__(self, cad: CadProcess, p):
        self._cad = cad
        self._got: list = []

    def _stage(self, i: int):
        while len(self._got) <= i:
            self._got.append(self._cad._receive())
        return self._got[i]

    def shape(self):
        return self._stage(0)

    def measures(self):
        return self._stage(1)

    def step(self, name: str = "joint") -> bytes:
        if name != "joint":
            raise ValueError(f"the CAD process writes the STEP assembly 'joint', not {name!r}")
        return self._stage(2)


def _serve(conn, parent_end) -> None:
    """The child: import the builder, wait for the parameters, send the three stages (or the error)."""
    parent_end.close()
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C reaches the whole group: the parent answers it
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    failure: BaseException | None = None
    try:
        from rjcad.cad.measure import LocalJoint  # OpenCASCADE: the reason for this process
    except BaseException as e:
        failure = e
    try:
        p = conn.recv()
        if failure is not None:
            raise failure
        source = LocalJoint(p)
        conn.send(("ok", source.shape()))
        conn.send(("ok", source.measures()))
        conn.send(("ok", source.step("joint")))
    except EOFError:  # the parent stopped before asking
        pass
    except (BrokenPipeError, ConnectionResetError):  # the parent stopped listening: nobody to tell
        pass
    except BaseException as e:
        with contextlib.suppress(OSError):
            conn.send(("error", (_picklable(e), traceback.format_exc())))
    finally:
        conn.close()


def _picklable(e: BaseException) -> BaseException:
    """``e`` if it survives pickling as itself, else a RuntimeError naming it."""
    try:
        back = pickle.loads(pickle.dumps(e))
        if type(back) is type(e) and str(back) == str(e):
            return e
    except Exception:
        pass
    return RuntimeError(f"{type(e).__name__}: {e}")
