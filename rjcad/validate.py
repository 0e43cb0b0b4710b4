"""One range check for every validator: a finite number within limits, or one ParameterError line."""

from __future__ import annotations

import math

from rjcad.errors import ParameterError


def _fmt(x: float, deg: bool) -> str:
    return f"{math.degrees(x):g}" if deg else f"{x:g}"


def default_limit(
    lo: float | None,
    hi: float | None,
    unit: str = "",
    *,
    deg: bool = False,
    lo_open: bool = False,
    hi_open: bool = False,
) -> str:
    """'must be in [lo, hi] unit', 'must be > lo unit', 'must be <= hi unit' … (bounds shown in deg if ``deg``)."""
    if lo is not None and hi is not None:
        text = f"must be in {'(' if lo_open else '['}{_fmt(lo, deg)}, {_fmt(hi, deg)}{')' if hi_open else ']'}"
    elif lo is not None:
        text = f"must be {'>' if lo_open else '>='} {_fmt(lo, deg)}"
    elif hi is not None:
        text = f"must be {'<' if hi_open else '<='} {_fmt(hi, deg)}"
    else:
        text = "must be a finite number"
    return f"{text} {unit}".strip()


def in_range(
    name: str,
    value,
    lo: float | None = None,
    hi: float | None = None,
    *,
    unit: str = "",
    limit: str | None = None,
    lo_open: bool = False,
    hi_open: bool = False,
    deg: bool = False,
    tol: float = 0.0,
    not_a_number: str | None = None,
) -> float:
    """``float(value)`` if it is a finite number with lo ≤ value ≤ hi (strict at an open end), within ``tol``.

    Otherwise ParameterError naming ``name`` with ``limit`` (default: the range in words).
    ``deg``: the value is in rad and shown in degrees. ``not_a_number``: the message for a value
    that is not a number at all (a string, a bool); default ``limit``. Booleans are not numbers.
    """
    text = limit if limit is not None else default_limit(lo, hi, unit, deg=deg, lo_open=lo_open, hi_open=hi_open)
    try:
        if isinstance(value, bool):
            raise TypeError
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(name, value, not_a_number or text) from None
    below = lo is not None and (v <= lo - tol if lo_open else v < lo - tol)
    above = hi is not None and (v >= hi + tol if hi_open else v > hi + tol)
    if not math.isfinite(v) or below or above:
        shown = math.degrees(v) if deg and math.isfinite(v) else v
        raise ParameterError(name, shown, text, unit="deg" if deg else unit)
    return v
