"""Candidate causes of Table I's scatter: each a term c·x(data) added to the mean log10 life."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from rjcad.life.table import LifeData

#: Road (extrusion) width assumed for the paper's printer (Stratasys Dimension Elite) [mm].
ROAD_WIDTH = 0.5


@dataclass(frozen=True)
class Effect:
    """A candidate cause: in words, its feature x = feature(LifeData), its coefficient's name and what that means."""

    cause: str
    feature: Callable[[LifeData], np.ndarray]
    param: str
    unit: str


EFFECTS = {
    "pin_backlash": Effect(
        "pin backlash lets the spring take secondary (out-of-plane, impact) loads",
        lambda d: (np.asarray(d.backlash) - 0.25) / 0.5,
        "c_backlash",
        "log10 cycles from 0.25 to 0.75 mm backlash",
    ),
    "thin_strip": Effect(
        "a strip of one or two extrusion roads: a surface flaw or a weak road bond is a large part of the section",
        lambda d: ROAD_WIDTH / np.asarray(d.thickness),
        "c_thin",
        f"log10 cycles per unit of road width / t (road {ROAD_WIDTH} mm)",
    ),
}
