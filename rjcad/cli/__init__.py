"""Command line: parse, call, print. Degrees here, radians inside.

Every user-facing error is one line on stderr and exit code 2; ``--debug``
adds the traceback. Python warnings are not printed (``--debug`` prints them): stderr holds the error
line and nothing else. User files are read through ``rjcad.untrusted``.

One module per command group, each thin (parse, call the library, print) with
its printers beside it: ``spring``, ``build`` (joint, finger), ``check``,
``sweep``, ``simulate`` (simulate joint|finger, finger-design, paper-finger),
``life``, ``identify`` (bench, identify); ``options`` holds what several share
(design options and their TOML keys, ``--config`` merging, the table printer).
A new command: a ``click.command`` in its group's module (or a new module),
registered in ``COMMANDS`` below. Heavy imports (CAD, matplotlib, scipy,
identify) stay inside the command functions, so ``rjcad spring`` starts fast.
"""

from __future__ import annotations

import sys
import traceback
import warnings

import click

from rjcad.cli import build, check, identify, life, simulate, spring, sweep
from rjcad.errors import RjcadError


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--debug", is_flag=True, help="Show tracebacks on errors.")
@click.version_option(package_name="rjcad")
def cli(debug: bool) -> None:
    """Design, build and check 3D-printable elastic joints for robotic fingers."""


COMMANDS = (spring.spring, build.joint, build.finger, sweep.sweep, check.check, simulate.simulate,
            simulate.finger_design, simulate.paper_finger, life.life, identify.bench, identify.identify)
for _command in COMMANDS:
    cli.add_command(_command)


#: Longest error line printed (a safety net: messages quote at most a short prefix of a value, rjcad.errors.quote).
MAX_ERROR_CHARS = 1000


def _line(text: str) -> str:
    """``text`` on one line, cut to MAX_ERROR_CHARS (click quotes a bad option value whole)."""
    text = " ".join(text.split()) if "\n" in text or "\r" in text else text
    return text if len(text) <= MAX_ERROR_CHARS else text[:MAX_ERROR_CHARS] + "…"


def main(argv: list[str] | None = None) -> None:
    """Console entry point: run the CLI, turn user errors into one line and exit 2."""
    args = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in args
    args = [a for a in args if a != "--debug"]  # accepted anywhere on the line
    try:
        with warnings.catch_warnings():
            if not debug:   # a stray library warning is not the user's business; --debug shows it
                warnings.simplefilter("ignore")
            rv = cli.main(args=args, prog_name="rjcad", standalone_mode=False)
    except RjcadError as e:
        if debug:
            traceback.print_exc()
        click.echo(f"rjcad: error: {_line(str(e))}", err=True)
        sys.exit(2)
    except click.exceptions.Abort:
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
    main()
