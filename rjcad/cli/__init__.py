"""Command line: parse, call, print. Degrees here, radians inside.

Every user-facing error is one line on stderr and exit code 2; ``--debug``
adds the traceback. Python warnings are not printed (``--debug`` prints them): stderr holds the error
line and nothing else. User files are read through ``rjcad.io.untrusted``.

One module per command group, each thin (parse, call the library, print) with
its printers beside it: ``spring``, ``build`` (joint, finger), ``check``,
``sweep``, ``simulate`` (simulate joint|finger, finger-design, paper-finger),
``life``, ``identify`` (bench, identify); ``options`` holds what several share
(the design options of ``rjcad.fields`` as click options, the table printer).
``joint`` and ``finger`` read their input through the Python API (``rjcad.api``).
A new command: a ``click.command`` in its group's module (or a new module),
registered by name in ``COMMANDS`` below; the group imports a command's module only
when that command runs. Heavy imports (CAD, matplotlib, scipy, VTK, identify) stay
inside the command functions, so each command imports only what it needs.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import re
import signal
import sys
import threading
import traceback
import warnings

import click

from rjcad.errors import RjcadError

#: Command name → ``module:attribute`` in rjcad.cli; a command's module is imported only when it runs
#: (or when ``--help`` lists them all), so a command pays only for its own imports.
COMMANDS = {
    "spring": "spring:spring",
    "joint": "build:joint",
    "finger": "build:finger",
    "view": "view:view",
    "sweep": "sweep:sweep",
    "check": "check:check",
    "simulate": "simulate:simulate",
    "finger-design": "finger_design:finger_design",
    "paper-finger": "simulate:paper_finger",
    "life": "life:life",
    "bench": "identify:bench",
    "identify": "identify:identify",
    "mjcf": "mjcf:mjcf",
    "urdf": "urdf:urdf",
    "profiles": "profiles:profiles",
}


class StdoutClosed(Exception):
    """The reader of stdout went away (``rjcad spring | head -1``); not an OSError, so that click passes it on."""


def _stdout_gone() -> bool:
    """True if fd 1 is a pipe or socket whose reader has closed it (poll says POLLERR), so that a BrokenPipeError
    from a helper process's pipe is not taken for it."""
    import select

    try:
        poller = select.poll()
        poller.register(sys.stdout.fileno(), select.POLLOUT)
        return any(ev & (select.POLLERR | select.POLLHUP) for _, ev in poller.poll(0))
    except (OSError, AttributeError, ValueError):  # stdout is no file (a test's capture)
        return False


class LazyGroup(click.Group):
    """A click group that imports a command's module on first use (``COMMANDS``)."""

    def invoke(self, ctx: click.Context):
        try:
            return super().invoke(ctx)
        except BrokenPipeError as e:  # click would exit 1 on it; main exits quietly with 0
            if _stdout_gone():
                raise StdoutClosed() from e
            raise

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(COMMANDS)

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        if name not in COMMANDS:
            return None
        module, attr = COMMANDS[name].split(":")
        return getattr(importlib.import_module(f"rjcad.cli.{module}"), attr)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--debug", is_flag=True, help="Show tracebacks (and Python warnings) on errors; accepted anywhere.")
@click.option("--quiet", is_flag=True, help="No progress line on the terminal; accepted anywhere.")
@click.version_option(package_name="rjcad")
def cli(debug: bool, quiet: bool) -> None:
    """Design, build and check 3D-printable elastic joints for robotic fingers."""


#: Longest error line printed (a safety net: messages quote at most a short prefix of a value, rjcad.errors.quote).
MAX_ERROR_CHARS = 1000


LONG_WORD = 120


def _line(text: str) -> str:
    """``text`` on one line: a word over LONG_WORD characters (click quotes a bad value whole) keeps its
    first and last 50 (a long path keeps its file name); the whole cut to MAX_ERROR_CHARS."""
    text = " ".join(text.split()) if "\n" in text or "\r" in text else text
    text = re.sub(rf"\S{{{LONG_WORD + 1},}}", lambda m: m.group(0)[:50] + "…" + m.group(0)[-50:], text)
    return text if len(text) <= MAX_ERROR_CHARS else text[:MAX_ERROR_CHARS] + "…"


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread: a command stops as on Ctrl-C (its clean-up runs, finished work is
    kept: a sweep writes the rows it has), then exits 143 (128 + SIGTERM) where Ctrl-C exits 130."""


def _on_sigterm(signum, frame):
    """SIGTERM stops the command, unless its output is already in place: it then finishes (exit 0)."""
    from rjcad.io import outputs

    if not outputs.PLACED:
        raise Terminated()


def _on_sigint(signum, frame):
    """Ctrl-C stops the command, unless its output is already in place: it then finishes (exit 0)."""
    from rjcad.io import outputs

    if not outputs.PLACED:
        raise KeyboardInterrupt()


def main(argv: list[str] | None = None) -> None:
    """Console entry point: run the CLI, turn user errors into one line and exit 2 (SIGINT 130, SIGTERM 143)."""
    args = list(sys.argv[1:] if argv is None else argv)
    environment()
    debug = "--debug" in args
    from rjcad.cli import progress

    progress.QUIET = "--quiet" in args
    args = [a for a in args if a not in ("--debug", "--quiet")]  # accepted anywhere on the line
    on_main = threading.current_thread() is threading.main_thread()
    from rjcad.io import outputs

    outputs.PLACED = False
    previous = {}
    if on_main:
        previous = {signal.SIGTERM: signal.signal(signal.SIGTERM, _on_sigterm)}
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # not where Ctrl-C is ignored
            previous[signal.SIGINT] = signal.signal(signal.SIGINT, _on_sigint)
    try:
        _run(args, debug)
    finally:
        for s, h in previous.items():
            if PROGRAM and outputs.PLACED:  # the program is leaving with its output in place: it exits 0
                signal.signal(s, signal.SIG_IGN)
            elif h is not None:
                signal.signal(s, h)


#: True in the ``rjcad`` program itself (``entry``), False where ``main`` is called in another program's
#: process (tests, a notebook): only the program forks helper processes (``rjcad.cad.process``).
PROGRAM = False


#: The ``rjcad`` program's BLAS threads, unless the environment sets them: its linear algebra is small problems
#: (the rod model, the fits), where OpenBLAS's extra threads only spin on the core that the program's other
#: process needs (the CAD process of ``rjcad joint``, PrusaSlicer in ``rjcad check --slicer``).
BLAS_THREADS = "1"


def entry() -> None:
    """The ``rjcad`` program (console script and ``python -m rjcad``): ``main()`` with ``PROGRAM`` set, and one
    BLAS thread unless ``OPENBLAS_NUM_THREADS`` is set (read when NumPy loads, which is later)."""
    global PROGRAM
    PROGRAM = True
    os.environ.setdefault("OPENBLAS_NUM_THREADS", BLAS_THREADS)
    main()


#: rjcad's symbols as ASCII, for a terminal whose encoding lacks them (a non-UTF-8 locale).
ASCII = {
    "→": "->", "←": "<-", "↔": "<->", "°": " deg", "·": "*", "×": "x", "≤": "<=", "≥": ">=", "±": "+/-",
    "−": "-", "–": "-", "—": "-", "…": "...", "≈": "~", "²": "^2", "³": "^3", "√": "sqrt", "µ": "u", "μ": "mu",
    "θ": "theta", "τ": "tau", "σ": "sigma", "γ": "gamma", "β": "beta", "α": "alpha", "Δ": "d", "ω": "omega",
    "φ": "phi", "ρ": "rho", "κ": "kappa", "λ": "lambda", "ε": "eps", "⁺": "+", "⁻": "-", "₀": "0", "₁": "1",
    "₂": "2", "₃": "3", "✓": "ok", "✗": "x", "“": '"', "”": '"', "‘": "'", "’": "'",
}  # fmt: skip


def _as_ascii(err: UnicodeError) -> tuple[str, int]:
    """The ``rjcad-ascii`` error handler: ASCII stand-ins for what the stream cannot encode ("?" at worst)."""
    import unicodedata

    if not isinstance(err, UnicodeEncodeError):
        raise err
    text = err.object[err.start : err.end]
    plain = (ASCII.get(c) or unicodedata.normalize("NFKD", c).encode("ascii", "ignore").decode() or "?" for c in text)
    return "".join(plain), err.end


def environment() -> None:
    """Streams that cannot encode rjcad's symbols (a non-UTF-8 locale) write them as ASCII (``ASCII``: "->",
    " deg"); Matplotlib's environment is set where it is imported (``rjcad.plotting.pyplot``)."""
    import codecs

    codecs.register_error("rjcad-ascii", _as_ascii)
    for stream in (sys.stdout, sys.stderr):
        try:
            "".join(ASCII).encode(getattr(stream, "encoding", None) or "ascii")
        except (UnicodeEncodeError, LookupError):
            with contextlib.suppress(AttributeError, ValueError):  # not a TextIOWrapper (a test's capture)
                stream.reconfigure(errors="rjcad-ascii")  # type: ignore[union-attr]


def _quiet_stdout() -> None:
    """The reader of stdout is gone (``rjcad spring | head -1``): point fd 1 at /dev/null, so that nothing more
    fails on it, not even the interpreter's last flush."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, AttributeError, ValueError):  # stdout is no file (a test's capture)
        pass


def _run(args: list[str], debug: bool) -> None:
    """Run the command line ``args``; exit with its code."""
    try:
        with warnings.catch_warnings():
            if not debug:  # a stray library warning is not the user's business; --debug shows it
                warnings.simplefilter("ignore")
            rv = cli.main(args=args, prog_name="rjcad", standalone_mode=False)
        sys.stdout.flush()  # here, where a closed pipe can still be told from an error
    except (StdoutClosed, BrokenPipeError) as e:  # the reader stopped reading (`| head`): it has what it wanted
        if isinstance(e, BrokenPipeError) and not _stdout_gone():
            raise
        _quiet_stdout()
        sys.exit(0)
    except RjcadError as e:
        if debug:
            traceback.print_exc()
        click.echo(f"rjcad: error: {_line(str(e))}", err=True)
        sys.exit(2)
    except OSError as e:  # a file the command was given cannot be read (name too long, a device, …)
        if debug:
            traceback.print_exc()
        where = f"{e.filename}: " if e.filename else ""
        click.echo(f"rjcad: error: {_line(where + (e.strerror or str(e)))}", err=True)
        sys.exit(2)
    except click.exceptions.Abort as e:
        if isinstance(e.__cause__, Terminated):
            click.echo("rjcad: terminated", err=True)
            sys.exit(143)
        click.echo("rjcad: aborted", err=True)
        sys.exit(130)
    except getattr(click.exceptions, "NoArgsIsHelpError", ()) as e:
        click.echo(e.format_message())
        sys.exit(0)
    except click.ClickException as e:
        if debug:
            traceback.print_exc()
        ctx = getattr(e, "ctx", None)
        where = f" (see '{ctx.command_path} --help')" if ctx is not None and ctx.info_name != "rjcad" else ""
        click.echo(f"rjcad: error: {_line(e.format_message())}{where}", err=True)
        sys.exit(2)
    sys.exit(rv if isinstance(rv, int) else 0)


if __name__ == "__main__":  # pragma: no cover
    entry()
