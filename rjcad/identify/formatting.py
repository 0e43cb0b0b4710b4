"""Numbers and units as the identification report writes them (shared by the text and the plots)."""

from __future__ import annotations

import math

#: measured quantity → (name, unit)
QUANTITY = {"torque_nmm": ("torque", "N·mm"), "tendon_force_n": ("tendon force", "N")}
#: JSON name suffix → unit, longest first
_SUFFIX_UNITS = (
    ("_nmm_s_per_rad", "N·mm·s/rad"),
    ("_nmm_per_rad3", "N·mm/rad³"),
    ("_nmm_per_rad", "N·mm/rad"),
    ("_deg", "deg"),
    ("_nmm", "N·mm"),
    ("_mm", "mm"),
    ("_n", "N"),
    ("_s", "s"),
)


def fmt(x, sig: int = 4) -> str:
    """``x`` with ``sig`` significant digits; integers from 10⁴ on, scientific below 10⁻³; '—' for None."""
    if x is None:
        return "—"
    x = float(x)
    if not math.isfinite(x):
        return "—"
    if x == 0:
        return "0"
    if 1e4 <= abs(x) < 1e12:
        return f"{x:.0f}"
    if abs(x) < 1e-3:
        return f"{x:.{max(sig - 1, 1)}e}"
    return f"{x:.{sig}g}"


def unit_of(name: str) -> str:
    """Unit of a JSON parameter from its name (``mu_j_mm`` → mm); '–' for a ratio such as beta_pos."""
    for suffix, unit in _SUFFIX_UNITS:
        if name.endswith(suffix):
            return unit
    return "–"


def quantity_unit(quantity: str) -> str:
    """N·mm for torque_nmm, N for tendon_force_n."""
    return QUANTITY.get(quantity, (quantity, ""))[1]
