"""What a joint's build hands to its writer, as plain numbers (``rjcad.cad.measure`` makes them; they cross
from the CAD process to the ``rjcad`` program pickled, so this module imports neither OCP nor trimesh)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rjcad.io.manifest import BodyEntry


@dataclass
class JointShape:
    """The built joint's shape: each body's triangles (unmerged, ``export.triangulate``), the tendon at rest
    [mm], the joint axis (point [mm], direction)."""

    triangles: dict[str, tuple[np.ndarray, np.ndarray]]
    tendon: np.ndarray
    axis_point: list[float]
    axis_dir: list[float]
    timings: dict[str, float] = field(default_factory=dict)


@dataclass
class JointMeasures:
    """Measured on the built solids: tendon moment arm [mm] and wrap angle [rad] (``export.measure_*``), each
    body's entry, the free spring strips' volume [mm³]."""

    moment_arm: float
    wrap_angle: float
    bodies: list[BodyEntry]
    strip_volume: float
    timings: dict[str, float] = field(default_factory=dict)
