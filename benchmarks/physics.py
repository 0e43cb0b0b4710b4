"""Physics benchmark: a 1000-step pull+release stroke of a 3-joint finger (target < 0.5 s) and
joint-model throughput (target >= 1e6 samples/s), with a plain-numpy ceiling and the optional
effects measured in the same run; the default finger's pull+release in MuJoCo (target <= 1 s) next to the
built-in solver's. Prints one JSON object (medians after a warm-up).
Run: .venv/bin/python benchmarks/physics.py [--n 1000000] [--steps 500] [--repeats 5] [--quick]
"""

from __future__ import annotations

import argparse

import numpy as np
from _timing import emit, median_time, parse_args, target

from rjcad import DEG
from rjcad.paper import FINGER
from rjcad.physics.finger import FingerModel, simulate_path, simulate_stroke, unbalanced_readings
from rjcad.physics.inverse import design_finger
from rjcad.physics.joint import PAPER_JOINT, Setup, motion_direction, simulate


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1_000_000, help="joint-model samples per evaluation")
    ap.add_argument("--steps", type=int, default=500, help="finger steps each way (500: 1001 in all)")
    ap.add_argument("--repeats", type=int, default=5)
    args = parse_args(ap, quick={"n": 2000, "steps": 20, "repeats": 1})
    # the paper's finger, full model: capstan, pin friction with the tendon-induced part, gravity on the links
    m = FingerModel(
        FINGER.designed_stiffness,
        (90 * DEG,) * 3,
        (90 * DEG,) * 3,
        (6.0,) * 3,
        wrap=(0.45, 0, 0),
        mu_t=0.2,
        friction=(2.0,) * 3,
        gamma=(1.0,) * 3,
        link_mass=(17.6, 14.4, 9.8),
        gravity=(0.0, -1.0),
    )
    t_finger, c = median_time(lambda: simulate_stroke(m, FINGER.stroke, steps=args.steps), args.repeats)
    # the same stroke with each joint's own slope of the weight only (the coupled step's fallback, and the
    # solver before it): the readings that are not equilibria, and the time, in the same run
    td, phase = c.tendon_mm, c.phase
    t_own, c_own = median_time(lambda: simulate_path(m, td, phase, coupled=False), args.repeats)
    n = args.n
    t = np.linspace(0, 100, n)
    th = 0.8 + 0.7 * np.sin(t)
    setup = Setup("tendon", 1.5, routed=True)
    s = motion_direction(th)
    t_joint = median_time(lambda: simulate(PAPER_JOINT, setup, th), args.repeats)[0]
    t_joint_dir = median_time(lambda: simulate(PAPER_JOINT, setup, th, direction=s), args.repeats)[0]
    # ceiling: the same arithmetic written as bare numpy (no direction finding, no checks)
    j = PAPER_JOINT
    k, th0, f = j.stiffness, j.preload, j.mu_j * 1.5

    def plain():
        x = th + th0
        gamma = np.where(s > 0, j.gamma_pos * x, -j.gamma_neg * x)
        return np.maximum((k * x + s * f + gamma) * np.where(s > 0, j.beta_pos, j.beta_neg), 0) / j.pulley_radius

    t_plain = median_time(plain, args.repeats)[0]
    # all optional effects on, with non-uniform sample times (measured data)
    rng = np.random.default_rng(0)
    tt = np.cumsum(rng.uniform(0.5, 1.5, n)) * (100.0 / n)
    full = PAPER_JOINT.with_(viscous=0.05, cubic=0.3, relaxation_stiffness=1.0, relaxation_time=2.0)
    t_full = median_time(lambda: simulate(full, setup, th, tt), args.repeats)[0]
    target_deg = list(FINGER.measured_end_deg)
    t_design = median_time(lambda: design_finger(target_deg, FINGER.stroke, "proximal-first"), args.repeats)[0]
    out = {
        **mujoco_stroke(args),
        "finger_steps": len(c.tendon_mm),
        "finger_1000_step_stroke_s": t_finger * 1000 / len(c.tendon_mm),
        "finger_own_slope_only_1000_step_stroke_s": t_own * 1000 / len(c.tendon_mm),
        "finger_coupled_speedup": t_own / t_finger,
        "finger_readings_not_equilibria": unbalanced_readings(m, c),
        "finger_own_slope_only_readings_not_equilibria": unbalanced_readings(m, c_own),
        "joint_samples_per_s": n / t_joint,
        "joint_given_direction_samples_per_s": n / t_joint_dir,
        "joint_numpy_ceiling_samples_per_s": n / t_plain,
        "joint_vs_numpy_ceiling": t_plain / t_joint,
        "joint_all_effects_nonuniform_t_samples_per_s": n / t_full,
        "inverse_design_s": t_design,
        "n": n,
        "repeats": args.repeats,
    }
    out["targets"] = {
        "finger_1000_step_stroke_s": target(out["finger_1000_step_stroke_s"], at_most=0.5),
        "joint_samples_per_s": target(out["joint_samples_per_s"], at_least=1e6),
        "mujoco_default_finger_stroke_s": target(out["mujoco_default_finger_stroke_s"], at_most=1.0),
    }
    emit(out)


def mujoco_stroke(args) -> dict:
    """The default finger (templates/finger.toml: capsule links, no meshes, no gravity) pulled 0 → 25 mm and
    released in MuJoCo (rjcad.mjcf.simulate), and by the built-in solver, in ``args.steps`` steps each way."""
    from rjcad.io.templates import DEFAULT_FINGER
    from rjcad.mjcf.model import spec_from_model
    from rjcad.mjcf.simulate import load, run_stroke
    from rjcad.mjcf.spec import to_xml
    from rjcad.physics.finger import model_from_template

    m = model_from_template(DEFAULT_FINGER)
    model = load(to_xml(spec_from_model(m)))
    t_mj, c_mj = median_time(lambda: run_stroke(model, FINGER.stroke, args.steps), max(1, min(args.repeats, 3)))
    t_rj, c_rj = median_time(lambda: simulate_stroke(m, FINGER.stroke, args.steps), args.repeats)
    return {
        "mujoco_default_finger_stroke_s": t_mj,
        "rjcad_default_finger_stroke_s": t_rj,
        "mujoco_over_rjcad": t_mj / t_rj,
        "mujoco_steps": len(c_mj.tendon_mm),
        "mujoco_vs_rjcad_max_deg": float(np.degrees(np.abs(c_mj.theta - c_rj.theta)).max()),
    }


if __name__ == "__main__":
    main()
