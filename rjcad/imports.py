"""Importing the large extension packages (OCP, VTK, trimesh's) without the cyclic garbage collector.

pybind11 (OCP) and VTK create tens of thousands of type and function objects as they import; every few
hundred allocations the collector walks the young ones, and now and then all of them: a fifth of
``import OCP``'s time in a profile (perf: ``gc_collect_main`` and the traversals it calls). None of it is
garbage. ``collector_paused()`` turns the collector off for a block and then freezes what survived
(``gc.freeze``: later collections skip it), so that the program pays neither now nor later; ``load(name)``
imports a module that way the first time only (freezing again on every call would keep a long-running
caller's later garbage forever). Measured: the CAD process's import of CadQuery 1.85 → 1.61 s (median of 15).
"""

from __future__ import annotations

import gc
import importlib
import sys
from contextlib import contextmanager
from types import ModuleType


@contextmanager
def collector_paused():
    """Run the block with the cyclic garbage collector off, then freeze every object tracked so far and turn
    the collector back on (if it was on). For code that runs once per process."""
    was_on = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if was_on:
            gc.enable()


def load(name: str) -> ModuleType:
    """The module ``name``, imported with the collector paused if this process has not imported it yet."""
    module = sys.modules.get(name)
    if module is not None:
        return module
    with collector_paused():
        return importlib.import_module(name)
