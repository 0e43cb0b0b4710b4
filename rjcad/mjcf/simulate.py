"""The quasi-static pull/release of a finger run in MuJoCo, read like rjcad's solver (a ``Closure``).

The tendon is pulled by the file's ``pull`` actuator, made a pulling-only spring of stiffness ``KP`` on the pull
p = L_rest − L of its tendon (tension KP·(ctrl − p), never pushing: a released tendon goes slack, as in rjcad;
whatever the file's gear and bias, as the export writes it: ctrl = the pull [m]). At tendon displacement t_d the set
point is t_d + T/KP with T the last tension (so that the pull comes out at t_d); it moves there from the previous
point in ``RAMP_STEPS`` time steps (``RAMP_CHUNKS`` equal moves: a slow, steady pull or pay-out), MuJoCo runs
``SETTLE_STEPS`` more, the set point is corrected by the remaining pull error (``CORRECTIONS`` times, and once more
per ``LONG_STEP_MM`` of the step's displacement: a coarse path settles longer; ``SETTLE_STEPS`` each), then qpos
and the tension are read. A spring, not a hard length limit: moving a hard limit lets the tendon go slack for an
instant at each move, and a joint that friction should hold then slips. To settle fast without changing the
statics, the run (on a copy of the model):

* scales every body's mass and inertia down by ``MASS_SCALE`` and gravity up by it (the weights are kept);
* gives each hinge an armature K·``ARMATURE_S``² and a damping K·``SETTLE_S`` (implicit in the integrator):
  neither acts at rest;
* makes joint limits and friction stiff (time constant 2·dt, impedance 0.9999) and turns contacts off
  (self-contact is no part of rjcad's model).

The file's joint ``frictionloss`` and ``stiffness``/``springref``/``range`` are used as they are. The first reading
(t_d = 0, the tendon slack if the weight flexes the finger) is the settled rest pose: ``rest_pose``.
"""

from __future__ import annotations

import itertools

import numpy as np

from rjcad.errors import RjcadError, optional_import
from rjcad.physics.finger import Closure

DT = 5e-4  # time step [s]
RAMP_STEPS = 32  # time steps over which the set point moves from one point to the next
RAMP_CHUNKS = 8  # in this many equal moves
SETTLE_STEPS = 24  # then time steps before a correction and before the reading
CORRECTIONS = 1  # set point corrections by the length error
KP = 1e4  # the pulling actuator's stiffness in the run [N/m]
SETTLE_S = 0.02  # damping / stiffness [s]
ARMATURE_S = 0.01  # sqrt(armature / stiffness) [s]: 1 / the hinges' own frequency
MASS_SCALE = 1e6
SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
LONG_STEP_MM = 0.15  # one more correction and settle per this much tendon displacement in a step [mm]
FIRST_SETTLE = 400  # time steps at t_d = 0 before the first reading


#: MuJoCo's warnings since the last ``quiet_mujoco()``: kept here instead of printed and logged to MUJOCO_LOG.TXT
#: in the current folder (MuJoCo's default handler).
WARNINGS: list[str] = []


def quiet_mujoco():
    """The ``mujoco`` module with its warnings sent to WARNINGS (emptied): nothing printed, no log file."""
    mujoco = optional_import("mujoco", "mujoco")
    mujoco.set_mju_user_warning(WARNINGS.append)
    WARNINGS.clear()
    return mujoco


def raise_warnings(source: str) -> None:
    """RjcadError naming ``source`` with MuJoCo's first warning, if it gave one (its run is not to be trusted)."""
    if WARNINGS:
        first = " ".join(WARNINGS[0].split())
        raise RjcadError(f"{source}: MuJoCo warned: {first} (the model is not one it can simulate)")


def load(xml: str, assets: dict[str, bytes] | None = None):
    """A MuJoCo model from MJCF text and its mesh files (name → bytes)."""
    mujoco = quiet_mujoco()

    return mujoco.MjModel.from_xml_string(xml, assets or {})


def _driven_tendon(model) -> int:
    mujoco = optional_import("mujoco", "mujoco")

    for a in range(model.nu):
        if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_TENDON:
            return int(model.actuator_trnid[a, 0])
    if model.ntendon:
        return 0
    from rjcad.errors import RjcadError

    raise RjcadError("the MJCF has no tendon to pull (no tendon, no actuator on a tendon)")


def _prepare(model):
    """The settling set-up described in the module docstring, in place."""
    mujoco = optional_import("mujoco", "mujoco")

    model.opt.timestep = DT
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    model.body_mass[:] /= MASS_SCALE
    model.body_inertia[:] /= MASS_SCALE
    model.opt.gravity[:] *= MASS_SCALE
    tc = (2 * DT, 1.0)
    for j in range(model.njnt):
        d = model.jnt_dofadr[j]
        k = max(float(model.jnt_stiffness[j]), 1e-6)
        model.dof_armature[d] = k * ARMATURE_S**2
        model.dof_damping[d] = k * SETTLE_S
        model.jnt_solref[j], model.jnt_solimp[j] = tc, SOLIMP
        model.dof_solref[d], model.dof_solimp[d] = tc, SOLIMP
    model.tendon_solref_lim[:] = tc
    model.tendon_solimp_lim[:] = SOLIMP


def hinge_addresses(model) -> np.ndarray:
    mujoco = optional_import("mujoco", "mujoco")

    return np.array(
        [model.jnt_qposadr[j] for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE], dtype=int
    )


def _actuator(model, t: int) -> tuple[int, float]:
    """The actuator on tendon ``t`` (its index and gear g), made a spring of stiffness KP [N/m] on the pull, pulling
    only, no damping. Its force F pulls the tendon with T = −g·F over the actuator length g·L; with the pull
    p = L_rest − L, T = KP·(ctrl − p) is F = −KP/g·ctrl + KP·L_rest/g − KP/g²·(g·L)."""
    mujoco = optional_import("mujoco", "mujoco")

    for a in range(model.nu):
        if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_TENDON and model.actuator_trnid[a, 0] == t:
            g = float(model.actuator_gear[a, 0])
            if g == 0.0:
                break
            model.actuator_gaintype[a] = mujoco.mjtGain.mjGAIN_FIXED
            model.actuator_biastype[a] = mujoco.mjtBias.mjBIAS_AFFINE
            model.actuator_gainprm[a, :3] = (-KP / g, 0.0, 0.0)
            model.actuator_biasprm[a, :3] = (KP * float(model.tendon_length0[t]) / g, -KP / g**2, 0.0)
            model.actuator_ctrllimited[a] = 0
            model.actuator_forcelimited[a] = 1
            model.actuator_forcerange[a] = (0.0, 1e6) if g < 0 else (-1e6, 0.0)
            model.actuator_dyntype[a] = mujoco.mjtDyn.mjDYN_NONE
            return a, g
    from rjcad.errors import RjcadError

    raise RjcadError("the MJCF has no actuator on its tendon")


def run_path(model, tendon_mm, phase: list[str] | None = None) -> Closure:
    """Joint angles and tension along a tendon-displacement path [mm], quasi-static, in MuJoCo.

    ``model`` is a loaded ``MjModel``; it is copied, never changed.
    """
    import copy

    mujoco = optional_import("mujoco", "mujoco")

    m = copy.copy(model)
    _prepare(m)
    d = mujoco.MjData(m)
    mujoco.mj_setConst(m, d)  # constraint scales for the new masses (it leaves d at the spring pose)
    mujoco.mj_resetData(m, d)
    t = _driven_tendon(m)
    a, gear = _actuator(m, t)
    mujoco.mj_forward(m, d)
    rest = float(m.tendon_length0[t])
    d.ctrl[a] = 0.0
    td = np.asarray(tendon_mm, dtype=float)
    q = hinge_addresses(m)
    theta = np.zeros((len(td), len(q)))
    tension = np.zeros(len(td))
    mujoco.mj_step(m, d, nstep=FIRST_SETTLE)
    last = 0.0
    for k, x in enumerate(td):
        goal = x * 1e-3
        start, aim = float(d.ctrl[a]), goal - gear * float(d.actuator_force[a]) / KP  # feed-forward: the last tension
        for s in range(1, RAMP_CHUNKS + 1):
            d.ctrl[a] = start + (aim - start) * s / RAMP_CHUNKS
            mujoco.mj_step(m, d, nstep=RAMP_STEPS // RAMP_CHUNKS)
        mujoco.mj_step(m, d, nstep=SETTLE_STEPS)
        for _ in range(CORRECTIONS + int(abs(x - last) / LONG_STEP_MM)):  # a long step settles longer
            err = goal - (rest - float(d.ten_length[t]))
            if not (-gear * d.actuator_force[a] > 0 or err > 0):
                break  # slack (and pulled as far as asked, or further): nothing to correct
            d.ctrl[a] += err  # taut (or short of the goal): the pull error moves the set point
            mujoco.mj_step(m, d, nstep=SETTLE_STEPS)
        last = x
        theta[k] = d.qpos[q]
        tension[k] = -gear * float(d.actuator_force[a])
    if phase is None:
        phase = ["pull"] + ["pull" if b > a else ("release" if b < a else "hold") for a, b in itertools.pairwise(td)]
    moved = np.diff(theta, axis=0, prepend=theta[:1])
    state = np.sign(np.where(np.abs(moved) > 1e-9, moved, 0.0))
    return Closure(td, list(phase), theta, tension, np.repeat(tension[:, None], len(q), axis=1), state, tension <= 1e-9)


def rest_pose(model) -> np.ndarray:
    """The joint angles [rad] the finger settles at with ctrl 0 (no pull; the weight may flex it, the tendon then
    slack), quasi-static as ``run_path``'s readings."""
    return run_path(model, [0.0]).theta[0]


def run_stroke(model, stroke: float, steps: int = 500, hold: int = 0) -> Closure:
    """Pull 0 → ``stroke`` mm and release back, ``steps`` steps each way (as ``simulate_stroke``)."""
    up = np.linspace(0.0, stroke, steps + 1)
    td = np.concatenate([up, np.full(hold, stroke), up[-2::-1]])
    phase = ["pull"] * (steps + 1) + ["hold"] * hold + ["release"] * steps
    return run_path(model, td, phase)
