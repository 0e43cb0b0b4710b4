"""Executing sweep tasks: on this process, a local process pool or a Dask cluster, with a progress display."""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time
from collections.abc import Callable


class DesignCounter:
    """Counts the finished designs and tells them on: to ``report`` (a ``rjcad.progress.Progress``: the CLI's
    progress line on a terminal) each one, or else as a plain line on ``stream`` at most every ``every_s``
    seconds and at the end; with neither, to no one. The library itself writes to no terminal."""

    def __init__(self, total: int, stream=None, every_s: float = 5.0, report=None, what: str = "designs"):
        self.total, self.done, self.t0 = total, 0, time.perf_counter()
        self.stream, self.report, self.what = stream, report, what
        self.every_s, self.last = every_s, 0.0

    def start(self, what: str) -> None:
        """Name what runs now (the count so far stays)."""
        self.what = what
        if self.report is not None:
            self.report(what, self.done, self.total)

    def update(self, n: int = 1) -> None:
        self.done += n
        if self.report is not None:
            self.report(self.what, self.done, self.total)
            return
        now = time.perf_counter()
        if self.stream is not None and (now - self.last >= self.every_s or self.done == self.total):
            self.last = now
            el = now - self.t0
            rate = self.done / el if el > 0 else 0.0
            eta = (self.total - self.done) / rate if rate > 0 else float("inf")
            self.stream.write(f"sweep: {self.done}/{self.total} designs, {rate:.1f}/s, ETA {eta:.0f} s\n")
            self.stream.flush()


def run_tasks(
    fn: Callable,
    points: list[dict],
    workers: int,
    scheduler: str | None,
    progress: DesignCounter,
    on_row: Callable[[dict], None],
    **kw,
) -> None:
    """Run ``fn(point, **kw)`` for every point on a local process pool or a Dask cluster."""
    if not points:
        return
    if scheduler:
        from dask.distributed import Client, as_completed

        with Client(scheduler) as client:
            futures = [client.submit(fn, pt, pure=False, **kw) for pt in points]
            for fut in as_completed(futures):
                on_row(fut.result())
                progress.update()
        return
    if workers == 0:  # in this process (debugging, tests)
        for pt in points:
            on_row(fn(pt, **kw))
            progress.update()
        return
    _pool_tasks(fn, points, workers, progress, on_row, **kw)


#: The -W option that keeps the resource tracker's leaked-semaphore warning off stderr.
TRACKER_QUIET = "ignore::UserWarning:multiprocessing.resource_tracker"


def _pool_tasks(
    fn: Callable, points: list[dict], workers: int, progress: DesignCounter, on_row: Callable[[dict], None], **kw
) -> None:
    """Run the tasks on a local process pool whose workers never outlive this process.

    Each worker holds the read end of a pipe whose only write end is here (its lifeline): when this process
    dies, even by SIGKILL, the pipe closes and the workers exit at once; then the forkserver and the resource
    tracker, which wait only for them, exit too. On an interrupt or error the lifeline is closed on purpose:
    the running designs are dropped (``--resume`` redoes them), the queued ones cancelled.
    """
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures import as_completed as done
    from multiprocessing.context import BaseContext

    # forkserver where the platform has it: a clean server process imports rjcad's build modules once and
    # forks the workers from there, so they start at once; plain fork could inherit locked thread pools
    if "forkserver" in mp.get_all_start_methods():
        forkserver = mp.get_context("forkserver")
        forkserver.set_forkserver_preload(["rjcad.cad.build", "rjcad.sweep"])
        ctx: BaseContext = forkserver
    else:
        ctx = mp.get_context("spawn")
    # the resource tracker starts with this interpreter's -W options: after a SIGKILL it still unlinks the pool's
    # semaphores, without its "leaked semaphore objects" warning on the user's terminal
    if TRACKER_QUIET not in sys.warnoptions:
        sys.warnoptions.append(TRACKER_QUIET)
    lifeline_r, lifeline_w = ctx.Pipe(duplex=False)
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_worker_start, initargs=(lifeline_r,))
    try:
        futs = [pool.submit(fn, pt, **kw) for pt in points]
        for fut in done(futs):
            on_row(fut.result())
            progress.update()
    except BaseException:
        lifeline_w.close()
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    finally:
        pool.shutdown(wait=True)
        lifeline_w.close()
        lifeline_r.close()


def _worker_start(lifeline) -> None:
    """In each worker: leave Ctrl-C to the main process, and exit as soon as the lifeline closes."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)

    def watch() -> None:
        with contextlib.suppress(EOFError, OSError):
            lifeline.recv_bytes()  # nothing is ever sent: returns only by EOF, when the main process is gone
        os._exit(1)

    threading.Thread(target=watch, name="rjcad-lifeline", daemon=True).start()
