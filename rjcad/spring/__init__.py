"""Spiral torsion spring (STS): formulas, requirement and design.

- :mod:`rjcad.spring.formulas`: the pure, vectorised model (stiffness, stresses, spiral geometry).
- :mod:`rjcad.spring.design`: :class:`SpringRequirement` (validated input) and :class:`SpringDesign`.
- :mod:`rjcad.spring.optimise`: the optimiser (``design_spring``, ``optimise_arrays``, ``CONSTRAINTS`` …).

This package re-exports the first two only. Import the optimiser from ``rjcad.spring.optimise``:
it imports ``rjcad.life`` (the life constraint), and ``rjcad.life`` computes Table I's stresses with
``rjcad.spring.formulas``, so a re-export here would make ``rjcad.spring`` and ``rjcad.life``
import each other.

Units: mm, N, N·mm, rad, MPa (= N/mm²). ``K`` is the torsional stiffness of one spring; a joint has
two springs in parallel, so a joint of stiffness ``K_joint`` uses springs of ``K_joint/2``.
rjcad's default outer end is ``pinned``: the paper's springs hook on a cylindrical protrusion of the
moving link. Wind-up (preload + joint rotation) *tightens* the spiral; the linear law holds until
coils touch, so the optimiser keeps the wound coil gap ≥ the printer's minimum gap.
"""

from rjcad.spring.design import (
    MIN_RADIUS_TO_THICKNESS,
    MIN_WIDTH_TO_THICKNESS,
    STIFFNESS_TOLERANCE,
    SpringDesign,
    SpringRequirement,
    check_end,
)
from rjcad.spring.formulas import (
    DEFAULT_END,
    END_CONDITIONS,
    TWO_PI,
    approx_length,
    archimedean_length,
    coil_gap,
    end_factors,
    length_for_stiffness,
    outer_radius,
    peak_stress,
    stiffness,
    stress_amplitude,
    turns_for_length,
    windup_stress,
    wound_pitch,
)

__all__ = [
    "DEFAULT_END", "END_CONDITIONS", "MIN_RADIUS_TO_THICKNESS", "MIN_WIDTH_TO_THICKNESS", "STIFFNESS_TOLERANCE",
    "SpringDesign", "SpringRequirement", "TWO_PI", "approx_length", "archimedean_length", "check_end", "coil_gap",
    "end_factors", "length_for_stiffness", "outer_radius", "peak_stress", "stiffness", "stress_amplitude",
    "turns_for_length", "windup_stress", "wound_pitch",
]
