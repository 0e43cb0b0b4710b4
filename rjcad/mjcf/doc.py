"""docs/mujoco.md, its plot and its numbers (docs/mujoco.json), every number computed by ``rjcad.mjcf.fit``.

Run: ``python -m rjcad.mjcf.doc [OUT_DIR]`` (``make mujoco-doc``).
"""

from __future__ import annotations

import json
import sys

import numpy as np

from rjcad.io.outputs import check_writable, write_set
from rjcad.mjcf.fit import PIN_LOAD_N, analyse
from rjcad.mjcf.spec import ACTUATOR_KP
from rjcad.plotting import png_bytes, pyplot

COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b")


def _panel(ax, cmp, title: str) -> None:
    ref, mj = cmp.rjcad, cmp.mujoco
    for i in range(ref.theta.shape[1]):
        c = COLOURS[i % len(COLOURS)]
        ax.plot(ref.tendon_mm, np.degrees(ref.theta[:, i]), color=c, lw=1.6, label=f"joint {i + 1} rjcad")
        ax.plot(mj.tendon_mm, np.degrees(mj.theta[:, i]), color=c, lw=1.0, ls="--", label=f"joint {i + 1} MuJoCo")
    ax.set_xlabel("tendon displacement [mm]")
    ax.set_ylabel("joint angle [deg]")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)


def plot(res: dict) -> bytes:
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    f, r = res["fitted"], res["fitted_without_capstan_and_gamma"]
    _panel(
        axes[0], f, f"rjcad's friction model vs MuJoCo, frictionloss fitted: RMS {f.rms_deg:.2f}°, max {f.max_deg:.1f}°"
    )
    _panel(axes[1], r, f"capstan and γ switched off in rjcad: RMS {r.rms_deg:.2f}°, max {r.max_deg:.2f}°")
    axes[0].legend(fontsize=7, ncol=2)
    fig.suptitle("The paper's finger, pull 0 → 25 mm and release (solid: rjcad; dashed: MuJoCo)", fontsize=10)
    fig.tight_layout()
    return png_bytes(fig, dpi=100)


#: The doc's section on the export (no numbers)
EXPORT = [
    "## Export",
    "",
    "`rjcad mjcf FINGER.json --out DIR` (or `rjcad finger --mjcf`, into `mjcf/` of the finger's folder) writes a "
    "folder laid out like the models of MuJoCo Menagerie: `finger.xml` (the model, SI units), `scene.xml` (the "
    "model over a floor, with lights: open this one) and `meshes/<body>.stl`. The model has one body per link, its "
    "frame at its joint's axis (the hinge at the body's origin), with its mass (the manifest's), centre of mass and "
    "inertia (from the mesh); `<default>` classes under `rjcad`: `joint` (hinges with stiff limits: `solreflimit` "
    "at two time steps, so that a spring's preload does not push its joint into the stop: MuJoCo's default "
    "softness lets it sink degrees in), `visual` (the meshes, group 2, no contact) and `collision` (a box around "
    "each body's mesh, group 3, touching the world but not the other links); one hinge per joint (`stiffness` K, `springref` "
    "= −preload so that the spring presses the joint on its extension stop with K·preload at the straight pose, "
    "`range` from the stop to the rotation limit), neighbouring links' contacts excluded, and two tendons: `path`, "
    "a spatial tendon through sites on the built tendon path (base channel, each fork face, each eye's groove as a "
    "wrap cylinder, each support slot, the distal anchor), and `tendon`, a fixed tendon of length −Σ r_i·q_i, "
    "rjcad's model of the groove (a constant moment arm). The `pull` actuator acts on `tendon` (`--pull path` "
    "moves it to the spatial tendon): its `ctrl` is the tendon pull in metres (rest length − length, positive "
    "pulls), `ctrlrange` from 0 to the pull that takes every joint to its rotation limit (Σ r_i·rotation_i; on "
    "`path` its own, longer travel), a "
    f"servo of {ACTUATOR_KP * 1e-3:g} N per mm of pull error that never pushes; its force is the tension. "
    "Sensors: each joint's angle, the pulled tendon's length, the tension; keyframe `home`: straight, ctrl 0. Gravity is MuJoCo's usual "
    "0 0 −9.81: `--gravity` turns the finger's base instead (palm down by default). When the springs cannot hold "
    "the finger straight against its weight in that orientation, `rjcad mjcf`, `rjcad finger --mjcf` and "
    "`rjcad simulate finger --gravity …` (either engine) say by how much, in one line. At the straight pose both "
    "tendons have the manifest's moment arms, and `path` its tendon length. With flexion the spatial path's "
    "straight runs between a fork face and the next support slot cut the corner (a bowstring): its moment arm "
    "(MuJoCo's `ten_J` on the exported file) grows with the angle, which rjcad's model, and the `tendon` MuJoCo "
    "is pulled by, do not have.",
    "",
    "`rjcad simulate finger FILE --engine mujoco` runs the same quasi-static pull and release in MuJoCo "
    "(the actuator made a stiff spring on the pull and its set point ramped slowly, the finger settled at each "
    "step; `--compare` overlays rjcad's).",
    "",
]


def _fl(x) -> str:
    return ", ".join(f"{v:.2f}" for v in x)


def markdown(res: dict) -> str:
    m, none, f, r = res["model"], res["frictionless_mujoco"], res["fitted"], res["fitted_without_capstan_and_gamma"]
    ft, rt = res["fitted_to_tension"], res["fitted_to_tension_without_capstan_and_gamma"]
    pj = ", ".join(f"{v:.1f}°" for v in f.per_joint_release_max_deg)
    return "\n".join(
        [
            "# The finger in MuJoCo: what its joint friction cannot say",
            "",
            "Generated by `make mujoco-doc` (`python -m rjcad.mjcf.doc docs`): every number below is computed by "
            "`rjcad.mjcf.fit` and stored in `mujoco.json`; `tests/test_mujoco.py` checks that they are what the code "
            "measures.",
            "",
            *EXPORT,
            "## What MuJoCo misses, and by how much",
            "",
            f"The finger: the paper's (K = {_fl(m['stiffness_nmm_per_rad'])} N·mm/rad, moment arms "
            f"{_fl(m['moment_arm_mm'])} mm, 90° preload and range), {m['stroke_mm']:g} mm of tendon pulled and released "
            f"in {m['steps_each_way']} steps each way, no gravity. rjcad's friction model: a constant pin friction "
            f"{m['pin_friction_nmm']:.2f} N·mm (μ_j·F_n, F_n = {PIN_LOAD_N} N, a link's weight), the tendon-induced pin "
            f"friction γ⁺ = {m['gamma_pos_nmm_per_rad']} / γ⁻ = {m['gamma_neg_nmm_per_rad']} N·mm/rad "
            "(it grows with the "
            f"load), and the capstan in the base (β⁺ = {m['capstan_beta_pos']}: the tension reaching the joints is "
            "lower than the actuator's while pulling, higher while releasing).",
            "",
            "MuJoCo's joint `frictionloss` is a constant, and a tendon has one tension along its length. The constant "
            "frictionloss, the same on every joint, that brings MuJoCo's joint angles closest to rjcad's (least RMS "
            f"over the whole stroke) is **{f.frictionloss_nmm[0]:.2f} N·mm**; the one that brings its actuator tension "
            f"closest is {ft.frictionloss_nmm[0]:.2f} N·mm. What remains:",
            "",
            "| MuJoCo against rjcad | frictionloss [N·mm] | RMS [deg] | max [deg] | release RMS [deg] | release max [deg] "
            "| tension RMS [N] |",
            "|---|---|---|---|---|---|---|",
            *[
                f"| {name} | {_fl(c.frictionloss_nmm)} | {c.rms_deg:.2f} | {c.max_deg:.2f} | {c.release_rms_deg:.2f} | "
                f"{c.release_max_deg:.2f} | {c.tension_rms_n:.2f} |"
                for name, c in (
                    ("frictionless MJCF", none),
                    ("frictionloss fitted to the angles", f),
                    ("frictionloss fitted to the tension", ft),
                    ("fitted to the angles, rjcad without capstan and γ", r),
                    ("fitted to the tension, rjcad without capstan and γ", rt),
                )
            ],
            "",
            "![rjcad against MuJoCo](mujoco.png)",
            "",
            "In plain words:",
            "",
            f"- **The capstan and the load-dependent friction are what MuJoCo misses.** With them, no constant "
            f"frictionloss gets MuJoCo closer than {f.rms_deg:.1f}° RMS; the release is worst ({f.release_max_deg:.1f}° "
            f"at most; per joint {pj}): in rjcad the friction grows with each spring's torque "
            "(γ⁻ > γ⁺, so each joint "
            "opens along its own, softer line) and the tension reaching the joints rises along the base channel while "
            "releasing; MuJoCo's joints follow one tension and one stiffness both ways, so its release retraces its pull.",
            f"- **A constant frictionloss hardly helps the angles** ({none.rms_deg:.2f}° RMS frictionless, "
            f"{f.rms_deg:.2f}° fitted): while every joint slips, equal constant frictions shift the tension, not the "
            f"angles. It does help the tension: {none.tension_rms_n:.2f} N RMS frictionless, {f.tension_rms_n:.2f} N "
            f"with the angles' value; the tension's own best ({ft.frictionloss_nmm[0]:.2f} N·mm, "
            f"{ft.tension_rms_n:.2f} N) costs angle ({ft.rms_deg:.2f}° RMS, {ft.max_deg:.1f}° at most).",
            f"- **Without capstan and γ, MuJoCo says what rjcad says**: the same fit leaves {r.rms_deg:.2f}° RMS and "
            f"{r.max_deg:.2f}° at most, within the 1° of the frictionless comparison; fitted to the tension, the "
            f"frictionloss comes out at {rt.frictionloss_nmm[0]:.2f} N·mm against rjcad's pin friction of "
            f"{m['pin_friction_nmm']:.2f} N·mm, and MuJoCo's angles stay within {rt.max_deg:.2f}°.",
            "",
            "## What to set in MJCF to get closest",
            "",
            f"- `frictionloss` = {f.frictionloss_nmm[0] * 1e-3:.2g} N·m ({f.frictionloss_nmm[0]:.2f} N·mm) on every "
            "joint for this finger: the angles as close as a constant gets them, and the tension much closer than "
            "frictionless; for another finger, run `rjcad.mjcf.fit.fit_frictionloss(model)` on its rjcad model, or "
            "give `rjcad mjcf` an identify result (`--identified`), whose per-joint pin friction it writes as "
            "`frictionloss`;",
            "- `damping`: any value. The pull/release is quasi-static; damping exerts no torque at rest, so these "
            "data cannot fit it (the export states its default, K·0.02 s, for dynamic runs);",
            "- no MJCF setting gives a tension that changes along the tendon or a friction that grows with the load: "
            "where they matter (the release above), simulate the finger in rjcad, or treat MuJoCo's angles as good to "
            "the errors in the table.",
            "",
        ]
    )


def write_doc(out_dir="docs") -> dict:
    """Compute the numbers and write mujoco.md, mujoco.png and mujoco.json into ``out_dir`` (one set)."""
    check_writable(out_dir)
    res = analyse()
    numbers = {"model": res["model"], **{k: v.to_dict() for k, v in res.items() if k != "model"}}
    write_set(
        out_dir,
        {"mujoco.md": markdown(res), "mujoco.png": plot(res), "mujoco.json": json.dumps(numbers, indent=2) + "\n"},
    )
    return numbers


if __name__ == "__main__":
    write_doc(sys.argv[1] if len(sys.argv) > 1 else "docs")
