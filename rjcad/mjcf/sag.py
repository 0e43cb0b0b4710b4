"""The finger's sag at rest: where its own weight takes it with the tendon slack (no pull), by rjcad's statics or
as MuJoCo settles it, and the one-line note when its springs cannot hold it straight."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from rjcad import DEG

#: A joint that rests more than this off its extension stop [deg] sags: its spring's preload cannot hold it
SAG_DEG = 1.0


def rjcad_rest_pose(man, gravity: Sequence[float]) -> np.ndarray:
    """Joint angles at rest [rad] by rjcad's statics: the manifest's finger under gravity [m/s², finger frame; its
    in-plane part torques the joints], the tendon slack, settled from straight (``simulate_path`` at t_d = 0)."""
    from rjcad.mjcf.export import G
    from rjcad.physics.finger import model_from_manifest, simulate_path

    gx, gy = float(gravity[0]) / G, float(gravity[1]) / G
    if gx == 0.0 and gy == 0.0:
        return np.zeros(len(man.joints))
    return simulate_path(model_from_manifest(man, gravity=(gx, gy)), [0.0]).theta[0]


def sag_note(theta: ArrayLike, orientation: str, by: str) -> str | None:
    """``rjcad: note: ...`` naming each joint more than SAG_DEG off its extension stop at rest and its angle [deg],
    under gravity as ``orientation`` says (e.g. "--gravity horizontal-palm-down"), settled by ``by``; None when
    every spring holds its joint."""
    deg = np.asarray(theta, dtype=float) / DEG
    sags = [f"joint {i + 1} sags {a:.1f}°" for i, a in enumerate(deg) if abs(a) > SAG_DEG]
    if not sags:
        return None
    return (
        f"rjcad: note: the springs cannot hold the finger straight under gravity ({orientation}): at rest, tendon "
        f"slack, {', '.join(sags)} ({by})"
    )
