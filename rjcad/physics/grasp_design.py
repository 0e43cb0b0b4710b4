"""Finger design for a set of cylinders (issue #40, point 5): stiffness ratios, joint ranges and link lengths that
make every target grasp enveloping and not ejected, the best worst-case Ferrari–Canny ε among them.

Geometry first (the template's straight pads, ``pad`` from each link's axis line): a cylinder of radius R touches
link i's pad where the link's axis line is tangent to the circle of radius ρ = R + pad about its centre. Wrapped
link by link from joint 1: link 1 tangent at θ1 = φ − asin(ρ/|c|) (c: the centre, φ its bearing from joint 1),
its tangent point s1 = √(|c|² − ρ²) along it; joint i+1 then sits d_i = L_i − s_i before the next tangent point,
so θ_{i+1} = 2·atan(d_i/ρ) and s_{i+1} = d_i. Every link touches if each θ ≤ its range − ANGLE_MARGIN and each
tangent point lies inside its link, EDGE_MARGIN from the ends. At the held position (tangent on link 1 half a
middle link before joint 2) θ2 = θ3 = 2·atan(L2/(2ρ)): L2 ≤ 2ρ·tan(θmax/2), so the smallest target bounds L2.
The wrapped contacts' normals give a predicted ε (``rjcad.physics.grasp_result.epsilon``) to rank candidates.

Search: the softest joint's stiffness K1 in SCALES, the ratios (K2/K1, K3/K1, …) in RATIOS, the distal joints'
range in ROTATIONS; for each, the shortest links the joint builder accepts (``FingerParams``), then middle links
from that shortest to the smallest target's bound. The candidates that wrap every target geometrically are
ranked by predicted (worst ε, mean ε) and confirmed with the contact solver (``close_on``), smallest target first;
the best confirmed (worst ε, then mean ε) wins. Moment arms: the builder's default, or a longer one on the distal
joints where the layout takes it (ARM_SETS): with contacts the statics depend on r_i, not only on K_i/r_i.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from rjcad import DEG
from rjcad.errors import InfeasibleDesign, ParameterError, RjcadError
from rjcad.physics.finger_model import FingerModel
from rjcad.physics.grasp import PAD_MM, held_position
from rjcad.physics.grasp_result import Contact, Grasp, epsilon
from rjcad.physics.objects import Cylinder
from rjcad.validate import in_range

ANGLE_MARGIN = 4 * DEG  # a wrapped joint stays this far from its stop [rad]
EDGE_MARGIN = 2.0  # a tangent point stays this far from its link's ends [mm]
SCALES = (5.2, 3.9, 2.6)  # the softest joint's stiffness [N·mm/rad]: the paper's, then softer (shorter springs)
RATIOS = ((1.5, 2.0), (1.0, 2.0), (1.0, 3.0), (1.0, 4.0), (1.5, 5.0))  # (K2/K1, K3/K1): the paper's first
ROTATIONS = (90 * DEG, 110 * DEG)  # the distal joints' range; 110°: the builder's largest
PRELOAD = 90 * DEG
ARM_MM = 6.0  # the joint builder's default moment arm [mm]
#: Moment arms tried beside the default, as (joint 1, the others) [mm], where the layout takes them: a longer arm
#: on the distal joints presses links 2 and 3 harder against the same tension (with contacts the statics depend
#: on r_i itself, not only on K_i/r_i), at the price of a larger joint.
ARM_SETS = ((ARM_MM, ARM_MM), (ARM_MM, 8.0))
L2_STEPS = 3  # middle-link lengths tried per candidate finger
#: Readings of each confirming closure: it asks only which links end up pressing (a fixed cylinder's frictionless end
#: state does not depend on the path; the solver's default is 40).
CONFIRM_STEPS = 20
MATERIAL, PRINTER = "absplus-p430", "generic-0.4"


@dataclass(frozen=True)
class Held:
    """A target cylinder at the held position of the finger being designed (``rjcad.physics.grasp``)."""

    diameter: float
    mu: float = 0.0
    free: bool = False
    mass_g: float = 0.0

    def __post_init__(self) -> None:
        in_range("cylinder diameter", self.diameter, 0.0, 1e4, lo_open=True, unit="mm")

    def place(self, model: FingerModel) -> Cylinder:
        """The cylinder where a user would hold it in ``model``."""
        x, y = held_position(model, self.diameter)
        return Cylinder(x, y, diameter=self.diameter, mu=self.mu, free=self.free, mass_g=self.mass_g)


Target = Cylinder | Held


def label(t: Target) -> str:
    """A target's name in messages: its diameter, and its centre if given."""
    if isinstance(t, Held):
        return f"{t.diameter:g} mm"
    return f"{t.diameter:g} mm at ({t.x:g}, {t.y:g})"


# ------------------------------------------------------------------ geometry


@dataclass(frozen=True)
class Wrap:
    """The geometric wrap of one cylinder: joint angles θ [rad], each tangent point's distance from its link's
    axis [mm], and why not every link can touch (None if every one can)."""

    theta: np.ndarray
    along: np.ndarray
    reason: str | None


def wrap(lengths: Sequence[float], rotation: Sequence[float], centre: Sequence[float], radius: float,
         pad: float = PAD_MM) -> Wrap:  # fmt: skip
    """Angles at which every link is tangent to the cylinder (see the module), and the first reason it fails."""
    n, rho = len(lengths), radius + pad
    theta, along = np.zeros(n), np.zeros(n)
    dist, phi = math.hypot(centre[0], centre[1]), math.atan2(centre[1], centre[0])
    if dist <= rho:
        return Wrap(theta, along, "it covers joint 1")
    theta[0] = phi - math.asin(rho / dist)
    s = math.sqrt(dist * dist - rho * rho)
    if theta[0] < -1e-9:
        return Wrap(theta, along, "it overlaps the open finger")
    for i in range(n):
        along[i] = s
        if i and theta[i] > rotation[i] - ANGLE_MARGIN:
            return Wrap(theta, along, _stop_reason(i, theta[i], rotation[i], rho))
        if i == 0 and theta[0] > rotation[0] - ANGLE_MARGIN:
            return Wrap(theta, along, f"joint 1 must turn {math.degrees(theta[0]):.0f}° to reach it")
        if s < EDGE_MARGIN:
            return Wrap(theta, along, f"link {i + 1} would touch it at its joint, not on its pad")
        if s > lengths[i] - EDGE_MARGIN:
            return Wrap(theta, along, _reach_reason(i, s, lengths, n))
        if i + 1 < n:
            s = lengths[i] - s
            theta[i + 1] = 2 * math.atan(s / rho)
    return Wrap(theta, along, None)


def _stop_reason(i: int, th: float, rot: float, rho: float) -> str:
    fits = rho * math.tan((rot - ANGLE_MARGIN) / 2)
    return (
        f"joint {i + 1} must turn {math.degrees(th):.0f}° to wrap it, beyond its {math.degrees(rot):.0f}° range "
        f"less {math.degrees(ANGLE_MARGIN):g}°: link {i}'s contact lies {rho * math.tan(th / 2):.1f} mm before "
        f"joint {i + 1}, at most {fits:.1f} mm would do ((R + pad)·tan(θ/2))"
    )


def _reach_reason(i: int, s: float, lengths: Sequence[float], n: int) -> str:
    if i == n - 1:
        return f"link {n} ({lengths[i]:g} mm) ends before it can touch it ({s + EDGE_MARGIN:.1f} mm needed)"
    return f"link {i + 1} ({lengths[i]:g} mm) would touch it past joint {i + 2}: it lies beyond the link"


def l2_bound(diameter: float, rotation: float, pad: float = PAD_MM) -> float:
    """Longest middle link that wraps a held cylinder with joints 2 and 3 within ``rotation`` [mm]:
    2ρ·tan((θmax − ANGLE_MARGIN)/2), ρ = D/2 + pad."""
    return 2 * (diameter / 2 + pad) * math.tan((rotation - ANGLE_MARGIN) / 2)


def predicted_contacts(lengths: Sequence[float], w: Wrap, pad: float = PAD_MM) -> list[Contact]:
    """Each link's contact at its tangent point (unit normal force), from the wrap's angles."""
    out, axis, heading = [], np.zeros(2), 0.0
    for i, L in enumerate(lengths):
        heading += w.theta[i]
        d = np.array([math.cos(heading), math.sin(heading)])
        n = np.array([-d[1], d[0]])  # towards the palm: into the object
        p = axis + w.along[i] * d + pad * n
        out.append(Contact(f"link{i + 1}", 1, (float(p[0]), float(p[1])), (float(n[0]), float(n[1])), 1.0))
        axis = axis + L * d
    return out


def contact_forces(c: Candidate, w: Wrap, tension: float, pad: float = PAD_MM) -> np.ndarray:
    """Each link's normal force [N] in the wrapped pose at ``tension`` [N], from the joints' balance
    Σ_{j≥i} N_j·((p_j − a_i) × n_j)_z = r_i·T − K_i·(θ_i + θ0_i) (solved distal first); negative: it lifts off."""
    contacts = predicted_contacts(c.link_length, w, pad)
    axes, heading = [np.zeros(2)], 0.0
    for th, L in zip(w.theta, c.link_length):
        heading += th
        axes.append(axes[-1] + L * np.array([math.cos(heading), math.sin(heading)]))
    n = len(contacts)
    A = np.zeros((n, n))
    for i in range(n):
        for j in range(i, n):
            arm, nj = np.asarray(contacts[j].point_mm) - axes[i], contacts[j].normal
            A[i, j] = arm[0] * nj[1] - arm[1] * nj[0]
    K, th0, r = (np.asarray(v) for v in (c.stiffness, c.preload, c.moment_arm))
    out: np.ndarray = np.linalg.solve(A, r * tension - K * (w.theta + th0))
    return out


def predicted_epsilon(lengths: Sequence[float], w: Wrap, target: Cylinder, pad: float = PAD_MM) -> float:
    """Ferrari–Canny ε of the wrapped contacts (as ``Grasp.verdict`` takes it)."""
    return epsilon(predicted_contacts(lengths, w, pad), target.centre, target.radius, target.mu, target.mu > 0)


# ------------------------------------------------------------------ candidates


@dataclass(frozen=True)
class Candidate:
    """One finger: per joint K [N·mm/rad], θ0, θmax [rad], r and L [mm]; the base [mm]."""

    stiffness: tuple[float, ...]
    preload: tuple[float, ...]
    rotation: tuple[float, ...]
    moment_arm: tuple[float, ...]
    link_length: tuple[float, ...]
    base_length: float

    def model(self) -> FingerModel:
        return FingerModel(self.stiffness, self.preload, self.rotation, self.moment_arm, link_length=self.link_length)

    def template_dict(self, material: str = MATERIAL, printer: str = PRINTER) -> dict[str, Any]:
        """The finger template's tables (what ``rjcad finger`` builds)."""
        return {
            "material": material,
            "printer": printer,
            "base_length_mm": self.base_length,
            "joint": [
                {"stiffness_nmm_per_rad": round(k, 4), "preload_deg": round(p / DEG, 3),
                 "rotation_deg": round(r / DEG, 3), "tendon_moment_arm_mm": a, "link_length_mm": L}
                for k, p, r, a, L in zip(self.stiffness, self.preload, self.rotation, self.moment_arm,
                                         self.link_length)
            ],
        }  # fmt: skip


@lru_cache(maxsize=128)
def shortest_links(stiffness: tuple[float, ...], rotation: tuple[float, ...], material: str, printer: str,
                   arms: tuple[float, ...] | None = None) -> tuple[float, tuple[float, ...]] | str:  # fmt: skip
    """(base, links): the shortest whole-mm lengths the finger builder accepts for these joints, or its error."""
    from rjcad.design.finger_lengths import base_length_min, link_length_min, whole_mm
    from rjcad.design.finger_params import FingerParams

    data = {"material": material, "printer": printer,
            "joint": [{"stiffness_nmm_per_rad": k, "rotation_deg": r / DEG, "preload_deg": PRELOAD / DEG,
                       "tendon_moment_arm_mm": a}
                      for k, r, a in zip(stiffness, rotation, arms or (ARM_MM,) * len(stiffness))]}  # fmt: skip
    try:
        js = FingerParams.from_dict(data).joints
    except RjcadError as e:
        return str(e)
    links = tuple(whole_mm(link_length_min(p, js[i + 1] if i + 1 < len(js) else None)) for i, p in enumerate(js))
    return whole_mm(base_length_min(js[0]), 25.0), links


def _grid(n: int) -> list[tuple[float, ...]]:
    """The stiffnesses tried [N·mm/rad], softest finger (smallest ΣK) first."""
    out = [(k1, *[k1 * r[min(i, len(r) - 1)] for i in range(n - 1)]) for k1 in SCALES for r in RATIOS]
    return sorted(out, key=sum)


def candidates(targets: Sequence[Target], n: int, material: str, printer: str) -> list[Candidate]:
    """Every finger of the grid (see the module) that the builder accepts, middle links from the shortest to the
    smallest held target's bound (a fixed target bounds nothing here: the wrap decides). Where even the softest
    finger's middle link is over that bound, the range is skipped: stiffer springs are no shorter."""
    from rjcad.physics.inverse import arm_range

    held = [t.diameter for t in targets if isinstance(t, Held)]
    lo, hi = arm_range(material, printer)
    arm_sets = [(a1, *[a] * (n - 1)) for a1, a in ARM_SETS if lo <= min(a1, a) and max(a1, a) <= hi]
    out = []
    for rot, arms in itertools.product(ROTATIONS, arm_sets):
        top = min((l2_bound(d, rot) for d in held), default=150.0)
        rots = (90 * DEG, *[rot] * (n - 1))
        for ks in _grid(n):
            got = shortest_links(ks, rots, material, printer, arms)
            if isinstance(got, str):
                continue
            base, links = got
            if top < links[1]:
                if ks == _grid(n)[0]:
                    break
                continue
            for L2 in _middle_lengths(links[1], top):
                L = list(links)
                L[1] = L2
                L[0] = max(L[0], math.ceil(L2 / 2 + 2 * EDGE_MARGIN))  # held: tangent on link 1
                out.append(Candidate(ks, (PRELOAD,) * n, rots, arms, tuple(L), base))
    return out


def _middle_lengths(shortest: float, top: float) -> list[float]:
    """Up to L2_STEPS whole-mm middle links from ``shortest`` to ``top`` (none if top < shortest)."""
    if top < shortest:
        return []
    return sorted({float(round(v)) for v in np.linspace(shortest, math.floor(top), L2_STEPS) if v >= shortest})


def _lengthen_distal(c: Candidate, places: list[Cylinder]) -> Candidate:
    """The last link long enough to reach every target's tangent point (+ EDGE_MARGIN beyond it)."""
    L = list(c.link_length)
    for p in places:
        w = wrap(L[:-1] + [1e4], c.rotation, (p.x, p.y), p.radius)
        if w.reason is None:
            L[-1] = max(L[-1], float(math.ceil(w.along[-1] + 2 * EDGE_MARGIN)))
    return Candidate(c.stiffness, c.preload, c.rotation, c.moment_arm, tuple(L), c.base_length)


# ------------------------------------------------------------------ the search

Solver = Callable[..., Grasp]
MAX_CONFIRMED = 3  # designs confirmed by the solver before the best is taken
BUDGET_S = 90.0  # the solver's share of the search [s]


@dataclass
class GraspDesign:
    """The chosen finger, its targets where they were placed, and the solver's grasp of each."""

    candidate: Candidate
    targets: list[Target]
    places: list[Cylinder]
    grasps: list[Grasp]
    searched: dict[str, Any] = field(default_factory=dict)

    @property
    def worst_epsilon(self) -> float:
        return min(g.verdict().epsilon for g in self.grasps)

    def template(self, material: str = MATERIAL, printer: str = PRINTER) -> str:
        """The finger template (TOML), the targets listed in a comment as ``--object`` specs."""
        data = self.candidate.template_dict(material, printer)
        lines = ["# Generated by rjcad finger-design for these target cylinders (base frame, mm):"]
        lines += [f"#   {_spec(p)}" for p in self.places]
        lines += [f'material = "{material}"', f'printer = "{printer}"', f"base_length_mm = {data['base_length_mm']:g}"]
        for j in data["joint"]:
            lines += ["", "[[joint]]", *(f"{k} = {v:g}" for k, v in j.items())]
        return "\n".join(lines) + "\n"

    def report(self) -> dict[str, Any]:
        """The design (per joint) and each target's grasp verdict and touch order."""
        c = self.candidate
        return {
            "stiffness_nmm_per_rad": list(c.stiffness),
            "preload_deg": [p / DEG for p in c.preload],
            "rotation_deg": [r / DEG for r in c.rotation],
            "tendon_moment_arm_mm": list(c.moment_arm),
            "link_length_mm": list(c.link_length),
            "base_length_mm": c.base_length,
            "worst_epsilon": self.worst_epsilon,
            "targets": [
                {
                    "object": p.to_dict(),
                    "held": isinstance(t, Held),
                    **g.verdict().to_dict(),
                    "touch_order": [f"link{i}" for i in g.touch_order],
                }
                for t, p, g in zip(self.targets, self.places, self.grasps)
            ],
            "search": self.searched,
        }


def _spec(c: Cylinder) -> str:
    extra = f",mu={c.mu:g}" if c.mu else ""
    extra += f",free,mass={c.mass_g:g}" if c.free else ""
    return f"cylinder:diameter={c.diameter:g},x={c.x:.2f},y={c.y:.2f}{extra}"


def design_for_targets(
    targets: Sequence[Target],
    *,
    joints: int = 3,
    max_tension_n: float = 10.0,
    steps: int = CONFIRM_STEPS,
    material: str = MATERIAL,
    printer: str = PRINTER,
    budget_s: float = BUDGET_S,
    solve: Solver | None = None,
) -> GraspDesign:
    """The finger whose closure on each target (alone, by ``close_on``) is enveloping and not ejected, with the best
    worst-case ε (then mean ε); ``InfeasibleDesign`` naming the binding target if none is."""
    if solve is None:
        from rjcad.physics import grasp

        run: Solver = grasp.close_on
    else:
        run = solve
    if not targets:
        raise ParameterError("targets", [], "give at least one cylinder")
    if not 2 <= joints <= 6:
        raise ParameterError("joints", joints, "a finger to design has 2 to 6 joints")
    in_range("max_tension_n", max_tension_n, 0.0, 1e3, lo_open=True, unit="N")
    order = sorted(range(len(targets)), key=lambda i: targets[i].diameter)  # the smallest binds most often
    ranked, failures = _rank(targets, joints, material, printer, max_tension_n)
    if not ranked:
        raise InfeasibleDesign("grasp", _geometric_binding(targets, failures, joints, material, printer))
    start, runs = time.monotonic(), 0
    best: tuple[tuple[float, float], GraspDesign] | None = None
    solver_fail: dict[int, tuple[Candidate, Grasp]] = {}
    confirmed = 0
    for _score, cand, places in ranked:
        if confirmed >= MAX_CONFIRMED or (time.monotonic() - start > budget_s and best is not None):
            break
        model = cand.model()
        grasps: list[Grasp | None] = [None] * len(targets)
        for i in order:
            runs += 1
            g = run(model, [places[i]], max_tension_n=max_tension_n, steps=steps)
            v = g.verdict()
            if not v.enveloping or v.ejected:
                solver_fail.setdefault(i, (cand, g))
                break
            grasps[i] = g
        else:
            confirmed += 1
            d = GraspDesign(cand, list(targets), places, [g for g in grasps if g is not None])
            # to 0.001: a nearer tie keeps the prediction's order (the solver's last digits decide nothing)
            key = (round(d.worst_epsilon, 3), round(float(np.mean([g.verdict().epsilon for g in d.grasps])), 3))
            if best is None or key > best[0]:
                best = (key, d)
        if time.monotonic() - start > 2 * budget_s:
            break
    if best is None:
        raise InfeasibleDesign("grasp", _solver_binding(targets, solver_fail))
    d = best[1]
    d.searched = {"candidates": len(ranked) + sum(len(v) for v in failures.values()),
                  "wrap_every_target": len(ranked), "confirmed": confirmed, "solver_runs": runs,
                  "solver_seconds": round(time.monotonic() - start, 2)}  # fmt: skip
    return d


def _rank(targets: Sequence[Target], n: int, material: str, printer: str, tension: float
          ) -> tuple[list[tuple[tuple[float, float, float], Candidate, list[Cylinder]]], dict[int, list[str]]]:  # fmt: skip
    """The candidates that wrap every target with every contact pressing, best predicted (worst ε, then the
    smallest contact force [N] over the targets, then mean ε) first; per target, why the others do not."""
    ranked: list[tuple[tuple[float, float, float], Candidate, list[Cylinder]]] = []
    failures: dict[int, list[str]] = {}
    for cand in candidates(targets, n, material, printer):
        places = [t.place(cand.model()) if isinstance(t, Held) else t for t in targets]
        cand = _lengthen_distal(cand, places)
        places = [t.place(cand.model()) if isinstance(t, Held) else t for t in targets]
        eps, grip, bad = [], [], False
        for i, p in enumerate(places):
            w = wrap(cand.link_length, cand.rotation, (p.x, p.y), p.radius)
            if w.reason is not None:
                failures.setdefault(i, []).append(w.reason)
                bad = True
                continue
            N = contact_forces(cand, w, tension)
            if np.any(N <= 0):
                k = int(np.argmin(N))
                failures.setdefault(i, []).append(
                    f"link {k + 1} lifts off at {tension:g} N (its balance needs {N[k]:.2f} N of contact): "
                    "the distal joints' springs are too soft against the tendon"
                )
                bad = True
                continue
            eps.append(predicted_epsilon(cand.link_length, w, p))
            grip.append(float(N.min()))
        if not bad:
            ranked.append(((min(eps), min(grip), float(np.mean(eps))), cand, places))
    ranked.sort(key=lambda r: r[0], reverse=True)
    return ranked, failures


def _geometric_binding(targets: Sequence[Target], failures: dict[int, list[str]], n: int, material: str,
                       printer: str) -> str:  # fmt: skip
    """Which target no candidate can wrap, and why (the reason it fails with most)."""
    if not failures:  # no candidate at all: the held targets' bound is under every buildable middle link
        shortest, ks = _shortest_middle(n, material, printer)
        small = min((t for t in targets if isinstance(t, Held)), key=lambda t: t.diameter)
        top = l2_bound(small.diameter, ROTATIONS[-1])
        return (
            f"{label(small)}: link 2 must be <= {top:.1f} mm to wrap it within joints 2 and 3's "
            f"{math.degrees(ROTATIONS[-1]):.0f}° ranges (2·(R + pad)·tan((range − "
            f"{math.degrees(ANGLE_MARGIN):g}°)/2), pad {PAD_MM:g} mm), but the joint builder's shortest middle link, "
            f"with the softest springs tried (K {', '.join(f'{k:g}' for k in ks)} N·mm/rad), is {shortest:g} mm "
            f"({material}, {printer})"
        )
    i = max(failures, key=lambda k: len(failures[k]))
    reasons = failures[i]
    common = max(set(reasons), key=reasons.count)
    return f"{label(targets[i])}: no candidate finger wraps it with every link touching: {common}"


def _shortest_middle(n: int, material: str, printer: str) -> tuple[float, tuple[float, ...]]:
    """The softest finger of the grid at the largest range: its middle link [mm] (inf if not buildable), its K."""
    ks = _grid(n)[0]
    got = shortest_links(ks, (90 * DEG, *[ROTATIONS[-1]] * (n - 1)), material, printer)
    return (math.inf if isinstance(got, str) else got[1][1]), ks


def _solver_binding(targets: Sequence[Target], fails: dict[int, tuple[Candidate, Grasp]]) -> str:
    """Which target the solver never saw enveloped, and what it saw instead, on the best-ranked finger."""
    i = min(fails, key=lambda k: targets[k].diameter)
    cand, g = fails[i]
    v = g.verdict()
    if v.ejected:
        why = f"it is pushed away at reading {g.ejected_at}"
    else:
        th = g.theta[-1] if g.theta else np.zeros(len(cand.stiffness))
        stops = [k + 1 for k in range(len(th)) if th[k] >= cand.rotation[k] - 1e-6]
        missing = [k for k in range(1, len(cand.stiffness) + 1) if k not in v.phalanges_in_contact]
        why = f"link(s) {', '.join(map(str, missing))} never touch it (touch order {g.touch_order or 'none'}"
        why += f"; joint(s) {', '.join(map(str, stops))} at the stop" if stops else ""
        why += f"; {v.max_tension_n:.1f} N tension)"
    ks = ", ".join(f"{k:.2f}" for k in cand.stiffness)
    Ls = ", ".join(f"{L:g}" for L in cand.link_length)
    return f"{label(targets[i])}: on the best-ranked finger (K {ks} N·mm/rad, links {Ls} mm) {why}"


def parse_diameters(text: str) -> list[float]:
    """Diameters [mm] from ``START:STOP:STEP`` (STOP included when the steps land on it: ``25:55:10`` = 25, 35,
    45, 55) or a list ``25,40,55``."""
    name = "--cylinders"
    limit = "must be START:STOP:STEP (e.g. 25:55:10) or a list (e.g. 25,40,55) of diameters in mm"
    parts = str(text).split(":")
    if len(parts) == 1:
        values = [in_range(name, v.strip(), 0.0, 1e4, lo_open=True, limit=limit) for v in parts[0].split(",")]
    elif len(parts) == 3:
        a, b, step = (in_range(name, v.strip(), limit=limit) for v in parts)
        if not (0 < a <= b <= 1e4 and step > 0) or (b - a) / step > 50:
            raise ParameterError(name, text, "needs 0 < START <= STOP and STEP > 0, at most 50 steps")
        values = list(np.arange(a, b + 1e-9 * max(1.0, b), step))
    else:
        raise ParameterError(name, text, limit)
    return [float(v) for v in values]
