"""``rjcad sweep``: run a design sweep (analytic, or built and checked), print a one-line summary."""

from __future__ import annotations

from pathlib import Path

import click

from rjcad.cli.options import OutDir


@click.command()
@click.argument("sweep_file", type=click.Path(dir_okay=False))
@click.option(
    "--out",
    "out_dir",
    type=OutDir(),
    default="out/sweep",
    show_default=True,
    help="The folder to write the results into.",
)
@click.option(
    "--workers",
    type=click.IntRange(0, 256),
    help="Local worker processes (default: the cores; 0 runs in this process).",
)
@click.option("--scheduler", help="Dask distributed scheduler address, e.g. tcp://host:8786.")
@click.option("--build", is_flag=True, help="Build and check the joint of every feasible design.")
@click.option("--keep-meshes", is_flag=True, help="With --build: keep each design's STL in OUT/meshes.")
@click.option(
    "--resume",
    is_flag=True,
    help="Keep the intact rows of an earlier run in OUT (results.csv, and the "
    "log of an interrupted build) and compute the other designs.",
)
def sweep(sweep_file, out_dir, workers, scheduler, build, keep_meshes, resume):
    """Sweep design parameters (analytic by default; --build for CAD + checks)."""
    import sys

    from rjcad.cli import progress as line
    from rjcad.sweep import SweepSpec, run_sweep

    spec = SweepSpec.from_toml(sweep_file)
    # on a terminal the progress line; otherwise a plain line on stdout every few seconds (none with --quiet)
    stream = None if line.QUIET else sys.stdout
    try:
        with line.progress_line("sweep", rated=True) as progress:
            res = run_sweep(
                spec,
                out_dir,
                build=build,
                workers=workers,
                scheduler=scheduler,
                resume=resume,
                keep_meshes=keep_meshes,
                stream=stream,
                progress=progress,
            )
    except KeyboardInterrupt:  # Ctrl-C or SIGTERM: the earlier outputs are untouched
        if build:
            click.echo(_stopped(Path(out_dir) / "results.partial.jsonl"))
        raise
    print_sweep(res, out_dir)


def _stopped(log: Path) -> str:
    """The line a stopped build sweep prints: how many designs its log keeps for --resume (none: no log left)."""
    try:
        kept = log.is_file() and not log.is_symlink() and log.stat().st_size > 0
        rows = sum(_whole_row(line) for line in log.open(encoding="utf-8", errors="replace")) if kept else 0
    except OSError:
        rows = 0
    if not rows:
        return "sweep: stopped before any design was built: nothing to resume"
    return f"sweep: stopped; {rows} design{'s' if rows > 1 else ''} built so far in {log}: --resume continues from them"


def _whole_row(line: str) -> bool:
    """A log line that holds a whole row (a JSON object): the stop may have cut the last one."""
    import json

    try:
        return isinstance(json.loads(line), dict)
    except ValueError:
        return False


def print_sweep(res, out_dir: str) -> None:
    """What --resume kept and dropped, designs computed and resumed, the time, the count per status, the files."""
    for note in res.notes:
        click.echo(f"sweep: {note}")
    status: dict[str, int] = {}
    for r in res.rows:
        status[r.get("status", "")] = status.get(r.get("status", ""), 0) + 1
    click.echo(
        f"sweep: {len(res.rows)} designs ({res.computed} computed, {res.skipped} resumed) in "
        f"{res.seconds:.2f} s; " + ", ".join(f"{k}: {v}" for k, v in sorted(status.items()))
    )
    click.echo(f"wrote {out_dir}/results.csv, pareto.png, summary.md")
