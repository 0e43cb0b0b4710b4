"""``--friction bearing`` of ``rjcad simulate finger``: each joint's band from its bearing, and its printed lines."""

from __future__ import annotations

from typing import Any

import click

#: ``--friction`` and ``--mu`` of the commands that run a finger's closure (simulate finger, view).
FRICTION_HELP = "The joints' friction: none, or each joint's band from its own bearing model (docs/bearing.md)."
MU_HELP = (
    "With --friction bearing: the printed material's friction on itself [default: the one the manifest's bearing "
    "block assumes, for dry plastic]."
)


def friction_options(f: Any) -> Any:
    """The ``--friction`` and ``--mu`` options (a decorator)."""
    f = click.option("--mu", type=float, default=None, help=MU_HELP)(f)
    return click.option(
        "--friction", type=click.Choice(["none", "bearing"]), default="none", show_default=True, help=FRICTION_HELP
    )(f)


def bearing_mu(friction: str, mu: float | None) -> float | None:
    """The μ of ``--friction bearing`` (its default: the block's), None for ``--friction none``; ``--mu`` alone
    refused."""
    from rjcad.validate import in_range

    if friction == "none":
        if mu is not None:
            raise click.BadParameter("only with --friction bearing", param_hint="--mu")
        return None
    from rjcad.physics.bearing_block import MU_ASSUMED

    mu = MU_ASSUMED if mu is None else mu
    in_range("--mu", mu, 0.0, 2.0)
    return mu


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
        raise e.parameter_error("--mu", mu) from None


def echo_bands(bands: list) -> None:
    """One line per joint: its band and how far the band is off the bearing it was fitted to."""
    for i, b in enumerate(bands, start=1):
        click.echo(
            f"joint {i}: bearing band at μ {b.mu:g}: f0 {b.f0:.2f} N·mm, γ⁺ {b.gamma_pos:.2f} / γ⁻ {b.gamma_neg:.2f} "
            f"N·mm/rad (off the bearing by {b.rms:.2f} RMS, {b.largest:.2f} at most, of {b.largest_friction:.1f} N·mm)"
        )
