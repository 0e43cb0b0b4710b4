"""Progress reports from library code, with no terminal I/O here: the caller passes a function, default None.

``progress(what, done, total)``: ``what`` names the step now running ("slicing", "building link2"), ``done``
and ``total`` count it where it is one of several (``None`` otherwise). The CLI shows it as a progress line on
a terminal (``rjcad.cli.progress``); a script may pass its own function, or nothing.
"""

from __future__ import annotations

from collections.abc import Callable

#: A progress function: (what is running now, how many of ``total`` are done or None, total or None).
Progress = Callable[[str, "int | None", "int | None"], None]


def report(progress: Progress | None, what: str, done: int | None = None, total: int | None = None) -> None:
    """Tell ``progress`` (if any) that ``what`` runs now (``done`` of ``total``)."""
    if progress is not None:
        progress(what, done, total)
