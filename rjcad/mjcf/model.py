"""An MJCF spec from a ``FingerModel`` alone (no meshes): capsule links, point-like masses where rjcad puts
them, the tendon on the groove line y = r. For the physics cross-checks and the fit; ``export`` builds the
spec of a built finger from its manifest and meshes."""

from __future__ import annotations

import numpy as np

from rjcad.mjcf.spec import BodySpec, FingerSpec, JointSpec, rod_inertia
from rjcad.physics.finger import FingerModel

#: The base link of a model-only finger: length [mm] and mass [g] (it does not move: neither matters)
BASE_MM, BASE_G = 30.0, 10.0
#: Capsule radius [mm]; the smallest link mass MuJoCo is given [g] (a massless link has no dynamics to settle)
RADIUS_MM, MIN_G = 5.0, 1e-3
#: Sites on the groove line either side of each axis [mm]
SITE_OFFSET_MM = 2.0


def gravity_vector(direction: tuple[float, float] | None, g: float = 9.81) -> tuple[float, float, float]:
    """MuJoCo's gravity [m/s²] for rjcad's in-plane unit direction (None: along −z, no torque on the joints)."""
    if direction is None:
        return (0.0, 0.0, -g)
    return (g * direction[0], g * direction[1], 0.0)


def spec_from_model(
    m: FingerModel, frictionloss=None, damping=None, armature=None, gravity: tuple[float, float, float] | None = None
) -> FingerSpec:
    """Capsule finger of ``m``: joint i's axis at x_i = Σ L_<i along +X, its child's mass at ``link_com``.

    ``frictionloss`` [N·mm], ``damping`` [N·mm·s/rad], ``armature`` [g·mm²] per joint (default 0);
    gravity: ``m.gravity`` (in-plane, rjcad's direction) unless given [m/s²].
    """
    n = m.n
    xs = np.concatenate([[0.0], np.cumsum(m.link_length)])
    fl = np.zeros(n) if frictionloss is None else np.asarray(frictionloss, float)
    dm = np.zeros(n) if damping is None else np.asarray(damping, float)
    ar = np.zeros(n) if armature is None else np.asarray(armature, float)
    r = RADIUS_MM * 1e-3
    bodies = [
        BodySpec(
            "base",
            BASE_G * 1e-3,
            (-BASE_MM / 2e3, 0.0, 0.0),
            rod_inertia(BASE_G * 1e-3, (-BASE_MM * 1e-3, 0, 0), (0, 0, 0), r),
            capsule=((-BASE_MM * 1e-3, 0.0, 0.0), (0.0, 0.0, 0.0), r),
        )
    ]
    names = ["base"] + [f"link{i + 1}" for i in range(n - 1)] + ["distal"]
    joints = []
    for i in range(n):
        a, b = xs[i] * 1e-3, xs[i + 1] * 1e-3
        mass = max(m.link_mass[i], MIN_G) * 1e-3
        cx, cy = m.link_com[i]
        bodies.append(
            BodySpec(
                names[i + 1],
                mass,
                ((xs[i] + cx) * 1e-3, cy * 1e-3, 0.0),
                rod_inertia(mass, (a, 0, 0), (b, 0, 0), r),
                capsule=((a, 0.0, 0.0), (b, 0.0, 0.0), r),
            )
        )
        joints.append(
            JointSpec(
                names[i],
                names[i + 1],
                (a, 0.0, 0.0),
                (0.0, 0.0, 1.0),
                m.stiffness[i] * 1e-3,
                m.preload[i],
                m.rotation[i],
                m.moment_arm[i] * 1e-3,
                dm[i] * 1e-3,
                fl[i] * 1e-3,
                ar[i] * 1e-9,
            )
        )
    sites = [("base", (-BASE_MM * 1e-3, m.moment_arm[0] * 1e-3, 0.0))]
    for i in range(n):
        y = m.moment_arm[i] * 1e-3
        sites.append((names[i], ((xs[i] - SITE_OFFSET_MM) * 1e-3, y, 0.0)))
        sites.append((names[i + 1], ((xs[i] + SITE_OFFSET_MM) * 1e-3, y, 0.0)))
    sites.append((names[-1], ((xs[-1] - SITE_OFFSET_MM) * 1e-3, m.moment_arm[-1] * 1e-3, 0.0)))
    grav = gravity if gravity is not None else gravity_vector(m.gravity) if any(m.link_mass) else (0.0, 0.0, 0.0)
    return FingerSpec(
        tuple(bodies),
        tuple(joints),
        tuple(sites),
        gravity=grav,
        notes=("rjcad finger model (capsules, no meshes): SI units, m kg N·m rad",),
    )
