"""Errors that the CLI turns into one line on stderr and exit code 2; ``quote`` shows a user's value in one."""

import math
import reprlib
from typing import Any

#: Longest value (and parameter name) an error line quotes: a prefix, then "…".
QUOTE_CHARS = 60


class _Short(reprlib.Repr):
    """reprlib with short strings, few items, shallow nesting, and integers of any length."""

    def __init__(self) -> None:
        super().__init__()
        self.maxlevel, self.maxlist, self.maxtuple, self.maxdict, self.maxset = 3, 6, 6, 6, 6
        self.maxstring = self.maxother = self.maxlong = 4 * QUOTE_CHARS

    def repr_int(self, x: int, level: int) -> str:
        bits = abs(x).bit_length()
        if bits <= 200:
            return repr(x)
        digits = int((bits - 1) * math.log10(2)) + 1  # Python refuses to print more than 4300 digits
        return f"<an integer of {digits + (abs(x) >= 10**digits)} digits>"


_SHORT = _Short()


def quote(value: Any, limit: int = QUOTE_CHARS, repr_: bool = True) -> str:
    """A user's value for an error line: its repr (``str`` if not ``repr_``) on one line, cut to ``limit``
    characters + "…"; a float as ``%g``; containers shortened (few items, shallow)."""
    if isinstance(value, float):
        return f"{value:g}"
    text = value[: 4 * limit] if isinstance(value, str) and not repr_ else _SHORT.repr(value)
    text = " ".join(text.split())
    return text if len(text) <= limit else text[:limit] + "…"


def _name(parameter: str, limit: int = 4 * QUOTE_CHARS) -> str:
    """A parameter's name for an error line, on one line: over ``limit`` characters, its middle is cut, so a
    name built as "file: experiment 2: key" keeps the key whole however long the path."""
    text, head = str(parameter), limit // 4
    if len(text) > limit:
        text = text[:head] + "…" + text[-(limit - head) :]
    return " ".join(text.split())


class RjcadError(Exception):
    """Base class: a user-facing problem with the input, never a bug."""


class ParameterError(RjcadError, ValueError):
    """A parameter is outside its allowed range.

    ``parameter`` names it as the user wrote it; ``limit`` states the range.
    """

    def __init__(self, parameter: str, value: Any, limit: str, unit: str = "") -> None:
        self.parameter = parameter
        self.value = value
        self.limit = limit
        self.unit = unit
        super().__init__(f"{_name(parameter)} = {quote(value)}{' ' + unit if unit else ''} is invalid: {limit}")


class InfeasibleDesign(RjcadError):
    """No design meets every constraint; ``constraint`` names the binding one."""

    def __init__(self, constraint: str, message: str) -> None:
        self.constraint = constraint
        super().__init__(message)


class BadInput(RjcadError):
    """An input file is unusable: a mesh (unreadable, empty, not matching its manifest), a missing
    installation's data, or a name that matches nothing."""


class MissingExtra(RjcadError, ImportError):
    """An optional package a command (or an API call) needs is not installed; the message names the extra that
    brings it."""


def optional_import(module: str, extra: str) -> Any:
    """The module ``module``, or MissingExtra naming ``pip install 'rjcad[extra]'``."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingExtra(f"{module} is not installed; this command needs it: pip install 'rjcad[{extra}]'") from None
