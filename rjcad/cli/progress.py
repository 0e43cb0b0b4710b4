"""Progress lines on a terminal: one line on stderr, redrawn in place by tqdm, while a long command works.

Shown only when stderr is a terminal and ``--quiet`` was not given (``rjcad.cli.main`` sets ``QUIET``): a pipe,
a file or a test's capture gets nothing, so stderr keeps its promise (an error line, a note, nothing else).
The library never writes to the terminal: a command passes ``report`` (``rjcad.progress.Progress``) to the
functions that take ``progress=``, and the line shows what runs now, a count where there is one, and the time
since the command started, ticking while a step runs silently (PrusaSlicer, a fit). The line is erased when the
command's work is done, before it prints its result.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

from rjcad.progress import Progress

#: ``--quiet`` was given (anywhere on the command line): no progress line.
QUIET = False
#: Seconds between redraws of a step that reports nothing (its elapsed time ticks).
TICK_S = 0.5
#: The line of a step without a count, of one with a count, and of one with a count and the time left (a sweep's
#: designs: the one count whose items take about alike).
PLAIN = "{desc}  {elapsed}"
COUNTED = "{desc}  {n_fmt}/{total_fmt} |{bar:16}| {elapsed}"
RATED = "{desc}  {n_fmt}/{total_fmt} |{bar:16}| {elapsed}<{remaining}"


def shown() -> bool:
    """True when a progress line is shown: stderr is a terminal and ``--quiet`` was not given."""
    if QUIET:
        return False
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):  # a replaced or closed stream
        return False


def _width() -> int:
    """The terminal's width, less one column (a line as wide as the terminal wraps on some); 80 when it says 0
    (a pseudo-terminal nobody sized)."""
    import os

    try:
        cols = os.get_terminal_size(sys.stderr.fileno()).columns
    except (OSError, AttributeError, ValueError):
        cols = 0
    return (cols or 80) - 1


@contextmanager
def progress_line(command: str, rated: bool = False) -> Iterator[Progress | None]:
    """A ``Progress`` function that draws ``command: what`` on stderr, for the ``with`` block; None (nothing to
    call) when no line is shown. ``rated``: a count also shows the time left."""
    if not shown():
        yield None
        return
    from tqdm import tqdm

    tqdm.monitor_interval = 0  # no monitor thread of tqdm's own: the ticker below redraws
    # nrows: a pseudo-terminal nobody sized says -1 rows, and tqdm then draws nothing
    bar = tqdm(total=None, desc=command, file=sys.stderr, leave=False, ncols=_width(), nrows=100, bar_format=PLAIN)
    lock = threading.Lock()
    stop = threading.Event()

    def report(what: str, done: int | None = None, total: int | None = None) -> None:
        with lock:
            bar.set_description_str(f"{command}: {what}", refresh=False)
            if total:
                bar.bar_format, bar.total, bar.n = RATED if rated else COUNTED, total, done or 0
            else:
                bar.bar_format, bar.total, bar.n = PLAIN, None, 0
            bar.ncols = _width()
            bar.refresh()

    def tick() -> None:
        while not stop.wait(TICK_S):
            with lock:
                bar.ncols = _width()
                bar.refresh()

    ticker = threading.Thread(target=tick, name="rjcad-progress", daemon=True)
    ticker.start()
    try:
        yield report
    finally:
        stop.set()
        ticker.join()
        bar.close()
