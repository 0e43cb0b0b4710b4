"""The paper's finger: what the design-time model gets wrong, and which changes explain the measurement.

Measured (paper Sec. V): tendon displacement 0 → 25 mm ends at θ = (65°, 50°, 50°);
the proximal joint moves first, joints 2 and 3 start almost together.
Design: K = 5.2·[1, 1.5, 2] N·mm/rad, preload 90°, range 90°, moment arm r.
"""

from __future__ import annotations

import math
import tempfile
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from rjcad import DEG
from rjcad.design.params import JointParams
from rjcad.errors import ParameterError
from rjcad.io import console
from rjcad.io.outputs import check_writable, write_set
from rjcad.paper import FINGER, JOINT
from rjcad.physics.finger import (
    Closure,
    FingerModel,
    load_finger_model,
    onset_tendon,
    simulate_angles,
    simulate_path,
    simulate_stroke,
)
from rjcad.physics.uncertainty import parameter_std
from rjcad.plotting import png_bytes, pyplot

MEASURED_DEG = np.array(FINGER.measured_end_deg)
STROKE = FINGER.stroke
K_DESIGN = FINGER.designed_stiffness
#: A candidate's parameter vector: the solver's array, or a list of fitted values.
Params = Sequence[float] | np.ndarray
#: A candidate family's model builder from its parameter vector.
Builder = Callable[[Params], FingerModel]
ANGLE_SIGMA_DEG = 2.0  # assumed 1-σ error of the vision-tracked end angles
PAPER_MU_FN = JOINT.mu_j * JOINT.normal_load  # N·mm: the paper's joint, μ_j under F_n (for scale only)


def design_model(arm: float | list[float] = 6.0, **kw: Any) -> FingerModel:
    arms = tuple(arm) if isinstance(arm, (list, tuple)) else (arm,) * 3
    return FingerModel(K_DESIGN, (90 * DEG,) * 3, (90 * DEG,) * 3, arms, **kw)


def end_and_onset(m: FingerModel, steps: int = 200) -> tuple[np.ndarray, np.ndarray, Closure]:
    """End angles [deg] and onsets [mm] of the pull 0 → STROKE (the measurement has no release)."""
    c = simulate_path(m, np.linspace(0.0, STROKE, steps + 1))
    return np.degrees(c.theta[steps]), onset_tendon(c), c


@dataclass
class Explanation:
    name: str
    cause: str
    params: dict[str, float]
    std: dict[str, float]
    end_deg: list[float]
    onset_mm: list[float]
    rms_deg: float
    n_params: int
    why: dict[str, str] | None = None  # per parameter: "" (identified), or why it has no interval
    scale: float = 1.0  # √(χ²/dof) the Jacobian σ was multiplied by (1 when χ²/dof ≤ 1 or dof ≤ 0)

    @property
    def sequence_ok(self) -> bool:
        o = self.onset_mm
        return bool(o[0] < min(o[1], o[2]) and abs(o[1] - o[2]) <= 0.25 * STROKE)


def _fit(
    name: str,
    cause: str,
    names: Sequence[str],
    starts: Sequence[Sequence[float]],
    lb: Sequence[float],
    ub: Sequence[float],
    build: Builder,
) -> Explanation:
    """Bounded least squares from several starts (the stops make the problem non-smooth). The residuals take the
    end angles of a 120-step pull (``simulate_angles``); what is reported is the closure's on 200 steps."""
    path = np.linspace(0.0, STROKE, 121)

    def resid(x: np.ndarray) -> np.ndarray:
        theta, _ = simulate_angles(build(x), path)
        r: np.ndarray = (np.degrees(theta[-1]) - MEASURED_DEG) / ANGLE_SIGMA_DEG
        return r

    best = None
    for x0 in starts:
        res = least_squares(resid, x0, bounds=(lb, ub), diff_step=1e-3, max_nfev=300)
        if best is None or res.cost < best.cost:
            best = res
    assert best is not None, "no starts"
    end, onset, _ = end_and_onset(build(best.x))
    std, why = parameter_std(best.jac, best.x, np.asarray(lb, float), np.asarray(ub, float), names)
    dof = len(MEASURED_DEG) - int(np.isfinite(std).sum())
    chi2 = 2.0 * float(best.cost)
    scale = math.sqrt(chi2 / dof) if dof > 0 and chi2 > dof else 1.0
    return Explanation(
        name,
        cause,
        dict(zip(names, map(float, best.x))),
        dict(zip(names, map(float, std * scale))),
        list(map(float, end)),
        list(map(float, onset)),
        float(np.sqrt(np.mean((end - MEASURED_DEG) ** 2))),
        len(best.x),
        dict(zip(names, why)),
        scale,
    )


def _k(scale2: float, scale3: float) -> tuple[float, float, float]:
    return (K_DESIGN[0], K_DESIGN[1] * scale2, K_DESIGN[2] * scale3)


def _arm_common(x: Params) -> FingerModel:
    return design_model(float(x[0]))


def _arm_friction(x: Params) -> FingerModel:
    return design_model(float(x[0]), friction=tuple(map(float, x[1:])))


def _arm_capstan_base(x: Params) -> FingerModel:
    return design_model(float(x[0]), wrap=(float(x[1]), 0.0, 0.0), mu_t=1.0)


def _arm_capstan_along(x: Params) -> FingerModel:
    return design_model(float(x[0]), wrap=(0.0, float(x[1]), float(x[1])), mu_t=1.0)


def _arms_per_joint(x: Params) -> FingerModel:
    return design_model(list(x))


def _arm_springs_softer(x: Params) -> FingerModel:
    return FingerModel(_k(float(x[1]), float(x[2])), (90 * DEG,) * 3, (90 * DEG,) * 3, (float(x[0]),) * 3)


def _arm_preloads_lower(x: Params) -> FingerModel:
    return FingerModel(K_DESIGN, (90 * DEG, float(x[1]) * DEG, float(x[2]) * DEG), (90 * DEG,) * 3, (float(x[0]),) * 3)


FRICTION = "moment arm + pin friction at every joint"
CAPSTAN_BASE = "moment arm + capstan in the base"
CAPSTAN_ALONG = "moment arm + capstan along the finger"
#: name → (cause, parameter names, starts, lower, upper, model builder)
FAMILIES: dict[str, tuple[str, list[str], list[list[float]], list[float], list[float], Builder]] = {
    "moment arm (common)": (
        "the tendon runs farther from the axes than designed",
        ["r_mm"],
        [[7.0], [9.0], [12.0]],
        [3.0],
        [15.0],
        _arm_common,
    ),
    FRICTION: (
        "a longer arm and Coulomb friction bands in the pins",
        ["r_mm", "f1_nmm", "f2_nmm", "f3_nmm"],
        [[9.0, 10.0, 2.0, 2.0], [8.7, 5.0, 0.5, 0.5]],
        [3.0, 0.0, 0.0, 0.0],
        [15.0, 40.0, 40.0, 40.0],
        _arm_friction,
    ),
    CAPSTAN_BASE: (
        "a longer arm and tendon friction in the base channel (the tension reaching every joint drops alike)",
        ["r_mm", "mu_alpha"],
        [[8.0, 0.2], [10.0, 0.5]],
        [3.0, 0.0],
        [15.0, 2.0],
        _arm_capstan_base,
    ),
    CAPSTAN_ALONG: (
        "a longer arm and tendon friction in the channels of joints 2 and 3 (μ_t·α each)",
        ["r_mm", "mu_alpha"],
        [[8.0, 0.2], [10.0, 0.5]],
        [3.0, 0.0],
        [15.0, 2.0],
        _arm_capstan_along,
    ),
    "moment arms per joint": (
        "each joint's tendon path sits at its own distance from the axis (distal arms longer)",
        ["r1_mm", "r2_mm", "r3_mm"],
        [[6.0, 9.0, 12.0], [8.0, 8.0, 8.0], [10.0, 10.0, 10.0]],
        [3.0] * 3,
        [15.0] * 3,
        _arms_per_joint,
    ),
    "moment arm + distal springs softer": (
        "the printed springs of joints 2 and 3 are softer than designed (K scale factors)",
        ["r_mm", "k2_scale", "k3_scale"],
        [[8.7, 0.8, 0.6], [10.0, 1.0, 1.0]],
        [3.0, 0.2, 0.2],
        [15.0, 2.0, 2.0],
        _arm_springs_softer,
    ),
    "moment arm + distal preloads lower": (
        "the springs of joints 2 and 3 hold less preload than 90° (hooking, relaxation)",
        ["r_mm", "preload2_deg", "preload3_deg"],
        [[8.7, 60.0, 30.0], [10.0, 80.0, 80.0]],
        [3.0, 0.0, 0.0],
        [15.0, 120.0, 120.0],
        _arm_preloads_lower,
    ),
}


def explanations() -> list[Explanation]:
    """Fit each candidate family of physically plausible changes to the measured end angles."""
    return [_fit(name, *spec) for name, spec in FAMILIES.items()]


def model_of(e: Explanation) -> FingerModel:
    """The fitted model of an explanation."""
    names, build = FAMILIES[e.name][1], FAMILIES[e.name][5]
    return build([e.params[n] for n in names])


def baseline(arm: float = 6.0) -> tuple[np.ndarray, np.ndarray, Closure]:
    end, onset, closure = end_and_onset(design_model(arm))
    return end, onset, closure


def builder_arms(manifest: str | None = None) -> tuple[tuple[float, ...], str]:
    """Moment arms of the design model: a finger manifest's measured ones, else the joint builder's design arm."""
    if manifest is not None:
        m = load_finger_model(manifest)
        if m.n != 3:
            raise ParameterError("manifest", m.n, "the paper's finger has 3 joints")
        return tuple(m.moment_arm), f"moment arms measured on the built finger ({manifest})"
    a = JointParams().moment_arm
    return (a,) * 3, f"equal arms of {a:g} mm (the joint builder's design arm)"


def _fmt_param(e: Explanation, k: str) -> str:
    sd, why = e.std[k], (e.why or {}).get(k, "")
    if math.isfinite(sd):
        return f"{k} = {e.params[k]:.3g} ± {sd:.2g}" + (f" (σ ×{e.scale:.3g})" if e.scale > 1 else "")
    if why == "at its bound":
        return f"{k} = {e.params[k]:.3g} (rejected by the data: at its bound)"
    if why == "no effect":  # the fit leaves it wherever its start and the solver's path put it: no number to give
        return f"{k}: any value (not identified: no effect on the end angles)"
    return f"{k} = {e.params[k]:.3g} (not identified: {why or 'no interval'})"


def _plot(c0: Closure, best: Explanation, arm_source: str) -> bytes:
    """PNG of the closure curves: the design model (left) and the best explanation (right) against the measurement."""
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(13, 5))
    c1 = simulate_stroke(model_of(best), STROKE, steps=200)
    for ax, c, title in (
        (axes[0], c0, f"design-time model, frictionless\n({arm_source})"),
        (axes[1], c1, f"best explanation: {best.name}"),
    ):
        for i in range(3):
            ax.plot(c.tendon_mm, np.degrees(c.theta[:, i]), color=f"C{i}", label=f"θ{i + 1} model")
            ax.plot([STROKE], [MEASURED_DEG[i]], "o", color=f"C{i}", ms=8, label=f"θ{i + 1} measured")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("tendon displacement t_d [mm]")
        ax.set_ylabel("joint angle [deg]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    return png_bytes(fig, dpi=100)


def _f(v: Iterable[float]) -> str:
    return ", ".join(f"{x:.1f}" for x in v)


def _design_section(arms: Sequence[float], arm_source: str, end0: np.ndarray, onset0: np.ndarray) -> list[str]:
    """The measurement, the design-time model's end angles and why they cannot match (tendon constraint)."""
    sum_meas = math.radians(MEASURED_DEG.sum())
    with tempfile.TemporaryDirectory(prefix="rjcad-paper-finger-doc-") as work:
        closure = console.block("rjcad simulate finger", work)
    lines = [
        "# The paper's finger: what the design model gets wrong",
        "",
        "You built a finger, pulled its tendon, and it did not close the way the design model said. Which "
        "change to the model explains what you measured, and which explanations can your measurement not tell "
        "apart? This page answers it for the one finger whose closure is published, the paper's: the design "
        f"model, {len(FAMILIES)} candidate explanations fitted to the measured end angles, and what the data "
        "cannot decide. For a finger of your own, measure its closure and let `rjcad identify` do the same "
        "([identify.md](identify.md)).",
        "",
        "Generated by `rjcad paper-finger` (`make paper-finger`); every number, every verdict and every output "
        "below is computed, none typed.",
        "",
        "## The design model against the measurement",
        "",
        "`rjcad simulate finger` without a finger closes the paper's, as designed, by pulling its tendon "
        f"{STROKE:g} mm:",
        "",
        *closure,
        "",
        "**Measurement** (paper Sec. V): pulling the tendon 0 → 25 mm closes the finger to "
        f"θ = ({_f(MEASURED_DEG)})°; the proximal joint moves first, joints 2 and 3 start almost together.",
        "",
        f"**Design-time model**: K = ({_f(K_DESIGN)}) N·mm/rad, preload 90°, range 90°, {arm_source}, "
        "no friction (rjcad.physics.finger).",
        "",
        "| joint | measured [deg] | design model [deg] | error [deg] | starts at t_d [mm] |",
        "|---|---|---|---|---|",
    ]
    for i in range(3):
        lines.append(
            f"| {i + 1} | {MEASURED_DEG[i]:.0f} | {end0[i]:.1f} | {end0[i] - MEASURED_DEG[i]:+.1f} | {onset0[i]:.2f} |"
        )
    at_stop = [i + 1 for i in range(3) if end0[i] >= 90 - 1e-6]
    lines += [
        "",
        f"The tendon constraint Σ r·θ = {STROKE:g} mm with these arms asks for Σθ = "
        f"{math.degrees(STROKE / np.mean(arms)):.0f}° (mean arm {np.mean(arms):.2f} mm), but the measured angles "
        f"add up to {MEASURED_DEG.sum():.0f}°: the design model closes the finger "
        f"{'too far' if end0.sum() > MEASURED_DEG.sum() else 'too little'}"
        + (
            f" (joint{'s' if len(at_stop) > 1 else ''} {', '.join(map(str, at_stop))} on the 90° stop)"
            if at_stop
            else ""
        )
        + f". An inextensible tendon on the measured angles needs a mean arm of {STROKE / sum_meas:.2f} mm, "
        "or the tendon must lose displacement on the way.",
    ]
    return lines


def _candidates_section(exps: list[Explanation]) -> list[str]:
    """The table of fitted candidate explanations."""
    lines = [
        "",
        "## Candidate explanations, fitted to the three end angles",
        "",
        f"Least squares on the end angles with an assumed ±{ANGLE_SIGMA_DEG:g}° (1σ) tracking error; "
        "± is the 1σ parameter uncertainty from the fit's Jacobian, multiplied by √(χ²/dof) when the fit leaves "
        "more error than the assumed tracking error explains (shown as σ ×factor: the interval of a fit that "
        "does not fit is wide). *Rejected by the data*: the fit pushed the parameter onto its bound (the values "
        "inside fit worse). *Not identified*: the end angles do not change with it (no effect), or it trades off "
        "exactly with another parameter (three angles cannot pin more than three numbers).",
        "",
        "| explanation | cause | fitted parameters | end angles [deg] | RMS error [deg] | onset t_d [mm] | "
        "order as measured |",
        "|---|---|---|---|---|---|---|",
    ]
    for e in exps:
        ps = "; ".join(_fmt_param(e, k) for k in e.params)
        lines.append(
            f"| {e.name} | {e.cause} | {ps} | {_f(e.end_deg)} | {e.rms_deg:.2f} | {_f(e.onset_mm)} | "
            f"{'yes' if e.sequence_ok else 'no'} |"
        )
    return lines


def _names(es: Iterable[Explanation]) -> str:
    return ", ".join(f"*{e.name}*" for e in es) or "none"


def _first(e: Explanation) -> int:
    return int(np.argmin(e.onset_mm)) + 1


def _verdict_section(exps: list[Explanation]) -> list[str]:
    """What the end angles and the order of motion can and cannot tell apart."""
    by = {e.name: e for e in exps}
    fits = [e for e in exps if e.rms_deg < 0.5]
    ordered = [e for e in fits if e.sequence_ok]
    common = by["moment arm (common)"]
    cap, along = by[CAPSTAN_BASE], by[CAPSTAN_ALONG]
    need = [k * math.radians(m + 90) for k, m in zip(K_DESIGN, MEASURED_DEG)]
    misfits = [e for e in exps if e.rms_deg >= 0.5]
    lines = [
        "",
        "![closure curves](paper-finger.png)",
        "",
        "## What the data can and cannot tell",
        "",
        "- With one tension T, each joint sits where r_i·T = K_i·(θ_i + θ0_i) (± its friction). With equal arms "
        "and preloads the measured angles need K_i·(θ_i + θ0_i) equal at the three joints; it is "
        f"({_f(need)}) N·mm: joint 3 would need {need[2] / need[0]:.2f}× joint 1's torque from the same tension. "
        f"One common arm scales all three alike: its best fit leaves {common.rms_deg:.1f}° RMS, with joint 1 at "
        f"{common.end_deg[0]:.1f}°.",
        "- Do not fit (RMS ≥ 0.5°): " + "; ".join(f"*{e.name}* {e.rms_deg:.1f}°" for e in misfits) + ".",
    ]
    if abs(cap.rms_deg - common.rms_deg) < 0.05:
        lines.append(
            f"- A capstan in the base changes nothing ({cap.rms_deg:.1f}° RMS, as the common arm alone): it "
            "lowers the tension at every joint by the same factor, which the tendon constraint cancels, so "
            "its μ_t·α is not identified by the end angles."
        )
    if along.rms_deg >= 0.5:
        at_bound = (along.why or {}).get("mu_alpha") == "at its bound"
        lines.append(
            "- Capstan along the finger lowers the tension reaching the distal joints, the wrong way for "
            "this measurement: "
            + (
                "its fit pushes μ_t·α onto its bound 0, so the data reject it"
                if at_bound
                else f"its fit puts μ_t·α at {along.params['mu_alpha']:.2g}"
            )
            + f" ({along.rms_deg:.1f}° RMS)."
        )
    lines += [
        f"- {len(fits)} of the {len(exps)} families fit the three end angles within 0.5° RMS: {_names(fits)}, with "
        f"{', '.join(str(e.n_params) for e in fits)} parameters for 3 numbers. The end angles alone cannot tell "
        "them apart.",
        f"- The order of motion separates some: keeping the measured order (proximal first, 2 and 3 together): "
        f"{_names(ordered)}; against it: "
        + (", ".join(f"*{e.name}* (joint {_first(e)} starts first)" for e in fits if not e.sequence_ok) or "none")
        + ".",
    ]
    if by[FRICTION].rms_deg < 0.5:
        lines.append(_friction_verdict(by[FRICTION]))
    if len(ordered) > 1:
        lines.append(
            "- What is left cannot be separated by this data: it needs the joint torques (a bench test of "
            "each printed spring, as in the paper's joint experiments), the tendon force during the "
            "closure, or a measured moment arm on the printed links."
        )
    return lines


def _friction_verdict(fric: Explanation) -> str:
    """Why pin friction, though it fits the end angles, does or does not keep the measured order."""
    kth = [k * math.radians(m) for k, m in zip(K_DESIGN, MEASURED_DEG)]
    return (
        f"- Pin friction fits the end angles ({fric.n_params} parameters for 3 numbers, so the bands "
        f"trade off; the solution found has f1 = {fric.params['f1_nmm']:.1f} N·mm at joint 1, for "
        f"scale: the paper's bar test gives μ_j·F_n = {PAPER_MU_FN:.2f} N·mm under 1.5 N); on a pull a "
        "friction band acts like extra preload torque, so it delays the joints it holds back: "
        + (
            "the measured order is kept."
            if fric.sequence_ok
            else f"joint {_first(fric)} starts first, against the measurement. This holds for all friction "
            "(or preload) values that fit: with equal arms joint i starts K_i·θ_i/r below the end "
            f"tension, and K_i·θ_i = ({_f(kth)}) N·mm at the measured angles is largest at joint "
            f"{int(np.argmax(kth)) + 1}."
        )
    )


def wrote(out_dir: str | Path, n_explanations: int) -> str:
    """What ``rjcad paper-finger`` prints when it has written the page into ``out_dir``."""
    return f"wrote {out_dir}/paper-finger.md and paper-finger.png ({n_explanations} explanations fitted)"


def _regenerate_section(n_explanations: int) -> list[str]:
    """How to write this page again (the command's line is ``wrote``'s: running it here would recurse)."""
    return [
        "",
        "## Write this page again",
        "",
        "`rjcad paper-finger --out DIR` computes all of the above and writes it, with its plot, into DIR "
        "(`--manifest FINGER.json` takes the design model's moment arms from a finger you built):",
        "",
        "```console",
        "$ rjcad paper-finger --out out/paper",
        wrote("out/paper", n_explanations),
        "```",
    ]


def write_doc(out_dir: str | Path, manifest: str | None = None) -> list[Explanation]:
    """docs/paper-finger.md and its plot, every number and every verdict computed here; nothing written on error."""
    out = check_writable(out_dir)  # before the fits, not after them
    arms, arm_source = builder_arms(manifest)
    end0, onset0, c0 = end_and_onset(design_model(list(arms)))
    exps = explanations()
    best = min(exps, key=lambda e: (not e.sequence_ok, round(e.rms_deg, 1), e.n_params))
    png = _plot(c0, best, arm_source)
    lines = (
        _design_section(arms, arm_source, end0, onset0)
        + _candidates_section(exps)
        + _verdict_section(exps)
        + _regenerate_section(len(exps))
    )
    write_set(out, {"paper-finger.png": png, "paper-finger.md": "\n".join(lines) + "\n"})
    return exps
