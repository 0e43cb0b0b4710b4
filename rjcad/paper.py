"""The paper's measured and designed values, in one table (rjcad units: N·mm/rad, mm, N, rad).

Source: "Modeling, Design, and Experimental Evaluation of Rotational Elastic Joints for
Underactuated Robotic Fingers" (shared/seed-paper.txt); conventions in shared/paper-notes.md.
"""

from __future__ import annotations

from dataclasses import dataclass

from rjcad import DEG


@dataclass(frozen=True)
class PaperJoint:
    """The measured joint (paper Eq. 3-7; the bar- and tendon-driven experiments A-E)."""

    designed_stiffness: float = 5.2  # N·mm/rad, designed with K = E·b·t³/(12·L)
    stiffness: float = 5.19  # N·mm/rad, measured K_s
    preload: float = 70 * DEG  # rad, θ_0 of the measured joint (the design text says 90°)
    normal_load: float = 1.5  # N, F_n of experiments A-C
    mu_j: float = 6.92  # mm, generalised pin friction (10.39 N·mm / 1.5 N)
    gamma_pos: float = 1.89  # N·mm/rad, tendon-induced friction while pulling
    gamma_neg: float = 3.15  # N·mm/rad, while releasing
    beta_pos: float = 1.24  # capstan factor while pulling, e^{μ_t·α}
    beta_neg: float = 0.67  # while releasing
    pulley_radius: float = 6.0  # mm, tendon moment arm of the test joint


@dataclass(frozen=True)
class PaperFinger:
    """The measured finger (paper Sec. V)."""

    designed_stiffness: tuple[float, ...] = (5.2, 7.8, 10.4)  # N·mm/rad, K1, 1.5·K1, 2·K1
    link_length: float = 40.0  # mm, every link
    stroke: float = 25.0  # mm of tendon displacement
    measured_end_deg: tuple[float, ...] = (65.0, 50.0, 50.0)  # joint angles at the end of the stroke


JOINT = PaperJoint()
FINGER = PaperFinger()
