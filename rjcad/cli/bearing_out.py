"""``--friction bearing`` of ``rjcad simulate finger``: each joint's band from its bearing, and its printed lines."""

from __future__ import annotations

from typing import Any

import click

from rjcad.errors import ParameterError


def with_bearing(model: Any, source: str | None, mu: float | None) -> tuple[Any, list]:
    """``model`` with its joints' bearing bands at ``mu`` (the designs of ``source``), and the bands; unchanged
    with none where ``mu`` is None. A joint that locks is ``--mu``'s one error line."""
    if mu is None:
        return model, []
    from rjcad.physics.bearing_band import JointLocked, with_bearing_friction
    from rjcad.physics.finger_sources import load_finger_designs

    try:
        return with_bearing_friction(model, load_finger_designs(source), mu)
    except JointLocked as e:
        raise ParameterError("--mu", mu, f"too high for this finger: {e}") from None


def echo_bands(bands: list) -> None:
    """One line per joint: its band and how far the band is off the bearing it was fitted to."""
    for i, b in enumerate(bands, start=1):
        click.echo(
            f"joint {i}: bearing band at μ {b.mu:g}: f0 {b.f0:.2f} N·mm, γ⁺ {b.gamma_pos:.2f} / γ⁻ {b.gamma_neg:.2f} "
            f"N·mm/rad (off the bearing by {b.rms:.2f} RMS, {b.largest:.2f} at most, of {b.largest_friction:.1f} N·mm)"
        )
