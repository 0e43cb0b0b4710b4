"""Spiral torsion spring (STS): formulas, requirement and design.

- :mod:`rjcad.spring.formulas`: the pure, vectorised model (stiffness, stresses, spiral geometry).
- :mod:`rjcad.spring.design`: :class:`SpringRequirement` (validated input) and :class:`SpringDesign`.
- :mod:`rjcad.spring.optimise`: the optimiser (``design_spring``, ``optimise_arrays``, ``CONSTRAINTS`` …).
- :mod:`rjcad.spring.rod`, :mod:`~rjcad.spring.surrogate`, :mod:`~rjcad.spring.factors`, :mod:`~rjcad.spring.verify`:
  the rod model, its table, the lookups the search uses, its verdict on a design.

This package re-exports the first two (formulas, design types) only. Import the optimiser from ``rjcad.spring.optimise``:
it imports ``rjcad.life`` (the life constraint), and ``rjcad.life`` computes Table I's stresses with
``rjcad.spring.factors``, so a re-export here would make ``rjcad.spring`` and ``rjcad.life``
import each other.

Units: mm, N, N·mm, rad, MPa (= N/mm²). ``K`` is the torsional stiffness of one spring; a joint has
two springs in parallel, so a joint of stiffness ``K_joint`` uses springs of ``K_joint/2``.
rjcad's default outer end is ``clamped`` (the paper's measured stiffness says its hooks behaved
clamped) and the joint loads its springs *unwinding* (``rjcad.spring.factors.JOINT_SENSE``). The
physics of a design is the large-rotation rod model's (``rjcad.spring.rod``, judged by
``rjcad.spring.verify``): no coil contact and the printer's minimum gap over the whole wind-up.
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
    "DEFAULT_END",
    "END_CONDITIONS",
    "MIN_RADIUS_TO_THICKNESS",
    "MIN_WIDTH_TO_THICKNESS",
    "STIFFNESS_TOLERANCE",
    "TWO_PI",
    "SpringDesign",
    "SpringRequirement",
    "approx_length",
    "archimedean_length",
    "check_end",
    "coil_gap",
    "end_factors",
    "length_for_stiffness",
    "outer_radius",
    "peak_stress",
    "stiffness",
    "stress_amplitude",
    "turns_for_length",
    "windup_stress",
    "wound_pitch",
]
