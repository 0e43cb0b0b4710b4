"""A finger closing on objects in its flexion plane, quasi-static: unilateral contacts with Coulomb friction,
solved together with the springs, the bearings' friction, the tendon's capstan losses and gravity.

Frame: the base's, in mm; the straight finger along +x from joint 1 at the origin, flexion about +z (towards +y,
the palm). Link i runs from axis i to axis i + 1 (the tip for the last); its outline is a polyline in its own frame
(x along the link from axis i, y towards the palm): the surface that touches objects (``template_outlines``: a
straight pad PAD_MM from the axis line; a built finger's manifest has the measured ones). Objects: cylinders and
boxes (``rjcad.physics.objects``), fixed, or free in the plane (x, y, turn) with a mass.

Drive: the tendon's tension T, ramped from 0 to ``max_tension_n``. Joint i feels T·c_i, c_i = exp(−μ_t Σ_{k≤i} α_k)
(the capstan while pulling). The state q (angles, free objects' poses) at each reading minimises, from the last
state q⁻, the incremental potential

    Φ(q) = Σ ½K_i(θ_i + θ0_i)² − T Σ c_i r_i θ_i + V_g(q) + Σ_j w_j |a_j·(q − q⁻)|

subject to every gap ≥ 0 and the joints' ranges. V_g: the links' and free objects' weight. The last sum is the
work of friction on the step (rate-independent, Coulomb): for each joint, its bearing band
w = f0_i + γ±_i(θ_i + θ0_i) on Δθ_i; for each touching contact, μ·N on its tangential slip t·(J_A − J_B)(q − q⁻),
N the normal force of the last state. Its stationary point is the equilibrium: a joint sticks within its band, a
contact within its cone, and slips at the band's or cone's edge. The normal forces are the gap constraints'
Lagrange multipliers, the friction forces those of the slips' definitions. Each move turns a joint by at most
TURN_RAD and moves an object by at most MOVE_MM, so that a link sweeps onto an object and never jumps through it.

A free object is ejected when it is pushed out of the finger's reach (its centre farther from joint 1 than the
links' length, the outlines' depth and its radius), when under gravity it has left its place by more than its
radius and nothing touches it (it falls; the closure then goes on without it), or when at the end it is farther
than its radius from where it was placed and no link presses it (pushed, and not held).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from rjcad.errors import ParameterError
from rjcad.physics import grasp_geometry as geo
from rjcad.physics.finger_model import FingerModel, G
from rjcad.physics.grasp_result import PRESS_N, Contact, Grasp, let_go, out_of_reach, reach
from rjcad.physics.objects import Box, Cylinder, Object
from rjcad.validate import in_range

__all__ = ["Box", "Cylinder", "Grasp", "close_on", "held_position", "template_outlines"]

#: Offset of a link's palmar surface from its axis line in a template's outline [mm].
PAD_MM = 5.0
#: The held cylinder's clearance above the open finger [mm].
CLEAR_MM = 0.01
#: A contact is active when its gap is below this [mm].
TOUCH_MM = 1e-4
#: Default largest tension [N] and readings of a closure.
MAX_TENSION_N, STEPS = 10.0, 40
#: Largest turn of a joint or an object [rad] and move of an object [mm] per move of the minimiser; moves per reading.
TURN_RAD, MOVE_MM, MAX_MOVES = 0.03, 3.0, 200
#: A free object's drag on a move [N/mm, N·mm/rad]: it moves only as far as it is pushed (without it, an object
#: that nothing holds may sit anywhere it does not block a link, and the minimiser takes any of those places).
DRAG = 1e-3
#: Pairs whose bounding circles are farther apart than this [mm] take that distance as their gap (more than any
#: move: TURN_RAD × the finger's length, a few mm).
FAR_MM = 20.0
#: Solves of one move at most, friction's weights taken again at its end each time.
FIXED_POINT = 10
#: A move's end that changes less than this between solves has settled [rad, mm].
SETTLED = 1e-8


def template_outlines(m: FingerModel, pad: float = PAD_MM) -> list[np.ndarray]:
    """Per link, the straight palmar pad from (0, pad) to (L_i, pad) in its own frame [mm]."""
    return [np.array([[0.0, pad], [float(L), pad]]) for L in m.link_length]


def link_outlines(m: FingerModel, outlines: Sequence[np.ndarray] | None) -> list[np.ndarray]:
    """``outlines`` checked (one per link, each k ≥ 2 finite (x, y) points [mm]) as float arrays; the template's
    pads where None. Both engines take the outlines through here."""
    lines = template_outlines(m) if outlines is None else list(outlines)
    if len(lines) != m.n:
        raise ParameterError("outlines", len(lines), f"needs one per link ({m.n})")
    out = []
    for i, o in enumerate(lines, start=1):
        a = np.asarray(o, dtype=float)
        if a.ndim != 2 or a.shape[1] != 2 or len(a) < 2 or not np.all(np.isfinite(a)):
            raise ParameterError(f"outline {i}", a.shape, "must be (k >= 2, 2) finite points [mm]")
        out.append(a)
    return out


def check_run(max_tension_n: float, stroke: float | None, steps: int) -> None:
    """A closure's drive, for either engine: 0 < max_tension_n ≤ 1e4 N, 0 < stroke ≤ 1e4 mm (or None), 2 to
    100000 readings."""
    in_range("max_tension_n", max_tension_n, 0.0, 1e4, lo_open=True, unit="N")
    if stroke is not None:
        in_range("stroke", stroke, 0.0, 1e4, lo_open=True, unit="mm")
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or not 2 <= steps <= 100000:
        raise ParameterError("steps", steps, "must be an integer from 2 to 100000")


def held_position(
    m: FingerModel,
    diameter: float,
    outlines: Sequence[np.ndarray] | None = None,
    base_outline: np.ndarray | None = None,
) -> tuple[float, float]:
    """Where the docs hold a cylinder of ``diameter`` [mm]: its centre half of link 2 before joint 2,
    x = L1 − L2/2 (the middle of link 1 for one link), resting on the open finger: as low as the outlines of the
    links (and of the base, if given) let it, plus CLEAR_MM. With straight pads the closed finger then wraps it
    evenly: links 2 and 3 reach it at the same turn when every link touches."""
    lines = template_outlines(m) if outlines is None else [np.asarray(o, dtype=float) for o in outlines]
    L = np.asarray(m.link_length, dtype=float)
    x = float(L[0] - L[1] / 2 if m.n > 1 else L[0] / 2)
    shapes = [line + [start, 0.0] for line, start in zip(lines, np.r_[0.0, np.cumsum(L)[:-1]])]
    if base_outline is not None:
        shapes.append(np.asarray(base_outline, dtype=float))
    R, top = diameter / 2, -np.inf
    for line in shapes:  # the lowest centre above each segment: sampled every 0.05 mm along it
        for a, b in itertools.pairwise(line):
            k = max(2, math.ceil(float(np.hypot(*(b - a))) / 0.05) + 1)
            pts = a + np.linspace(0.0, 1.0, k)[:, None] * (b - a)
            near = np.abs(pts[:, 0] - x) < R
            if near.any():
                top = max(top, float(np.max(pts[near, 1] + np.sqrt(R**2 - (pts[near, 0] - x) ** 2))))
    return x, (top if math.isfinite(top) else R) + CLEAR_MM


@dataclass
class _Pair:
    """A pair that may touch: body A (a link, or an object) and object B (never both fixed)."""

    a_link: int | None  # link index (0-based) or None
    a_obj: int | None  # object index (0-based) or None
    b_obj: int
    mu: float
    a_base: bool = False  # A is the base (fixed): a_link and a_obj are None

    @property
    def body(self) -> str:
        if self.a_base:
            return "base"
        return f"link{self.a_link + 1}" if self.a_link is not None else f"object{(self.a_obj or 0) + 1}"


class _Scene:
    """The finger and the objects as functions of the state q = (θ_1…θ_n, then x, y, turn of each free object)."""

    def __init__(
        self,
        m: FingerModel,
        objects: Sequence[Object],
        outlines: Sequence[np.ndarray],
        base_outline: np.ndarray | None = None,
    ) -> None:
        self.m, self.objects = m, list(objects)
        self.outlines = [np.asarray(o, dtype=float) for o in outlines]
        self.base = None if base_outline is None else np.asarray(base_outline, dtype=float)
        self.n = m.n
        self.free = [k for k, o in enumerate(self.objects) if o.free]
        self.slot = {k: self.n + 3 * i for i, k in enumerate(self.free)}
        self.nq = self.n + 3 * len(self.free)
        self.gone: set[int] = set()  # ejected objects
        self.pairs = [_Pair(i, None, k, o.mu) for k, o in enumerate(self.objects) for i in range(self.n)]
        if self.base is not None:
            self.pairs += [_Pair(None, None, k, o.mu, a_base=True) for k, o in enumerate(self.objects) if o.free]
        for k, o in enumerate(self.objects):
            for j, p in enumerate(self.objects[:k]):
                if o.free or p.free:
                    a, b = (k, j) if p.free and not o.free else (j, k)
                    self.pairs.append(_Pair(None, a, b, max(o.mu, p.mu)))
        self.weights = np.asarray(m.link_mass, dtype=float) * G
        self.link_circles = []
        for line in self.outlines + ([self.base] if self.base is not None else []):
            mid = (line.min(axis=0) + line.max(axis=0)) / 2
            self.link_circles.append((mid, float(np.hypot(*(line - mid).T).max())))
        self.g = np.asarray(m.gravity if m.gravity is not None else (0.0, 0.0), dtype=float)

    def start(self) -> np.ndarray:
        q = np.zeros(self.nq)
        for k in self.free:
            o = self.objects[k]
            q[self.slot[k] : self.slot[k] + 3] = (o.x, o.y, o.angle)
        return q

    def pose(self, q: np.ndarray, k: int) -> tuple[float, float, float]:
        if k in self.slot:
            s = self.slot[k]
            return float(q[s]), float(q[s + 1]), float(q[s + 2])
        o = self.objects[k]
        return o.x, o.y, o.angle

    def frames(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Axes a_i (n + 1, 2) [mm] (the last: the tip) and the links' absolute angles (n,) [rad]."""
        ang = np.cumsum(q[: self.n])
        d = np.column_stack([np.cos(ang), np.sin(ang)])
        a = np.vstack([np.zeros(2), np.cumsum(d * np.asarray(self.m.link_length)[:, None], axis=0)])
        return a, ang

    def outline(self, q: np.ndarray, i: int, frames: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        a, ang = frames
        c, s = math.cos(ang[i]), math.sin(ang[i])
        out: np.ndarray = a[i] + self.outlines[i] @ np.array([[c, s], [-s, c]])
        return out

    def _bound(self, q: np.ndarray, p: _Pair, frames: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, float]:
        """A circle [mm] about A: centre and radius."""
        if p.a_base:
            return self.link_circles[-1]
        if p.a_link is not None:
            centre, radius = self.link_circles[p.a_link]
            a, ang = frames
            c, s = math.cos(ang[p.a_link]), math.sin(ang[p.a_link])
            return a[p.a_link] + np.array([c * centre[0] - s * centre[1], s * centre[0] + c * centre[1]]), radius
        k = p.a_obj or 0
        return np.array(self.pose(q, k)[:2]), self.objects[k].radius

    def gap(self, q: np.ndarray, p: _Pair, frames: tuple[np.ndarray, np.ndarray]) -> geo.Gap:
        ob = self.objects[p.b_obj]
        x, y, t = self.pose(q, p.b_obj)
        cb = np.array([x, y])
        ca, ra = self._bound(q, p, frames)
        far = geo.circles(ca, ra, cb, ob.radius)
        if far[0] > FAR_MM:  # the circles about the two are apart by more than any move: that gap will do
            return far
        if p.a_link is not None or p.a_base:
            line = self.base if p.a_base else self.outline(q, p.a_link or 0, frames)
            assert line is not None
            if isinstance(ob, Cylinder):
                return geo.polyline_circle(line, cb, ob.radius)
            return geo.polyline_polygon(line, ob.corners(x, y, t))
        oa = self.objects[p.a_obj or 0]
        xa, ya, ta = self.pose(q, p.a_obj or 0)
        ca = np.array([xa, ya])
        if isinstance(oa, Cylinder) and isinstance(ob, Cylinder):
            return geo.circles(ca, oa.radius, cb, ob.radius)
        if isinstance(oa, Box) and isinstance(ob, Box):
            return geo.polygons(oa.corners(xa, ya, ta), ob.corners(x, y, t))
        if isinstance(oa, Box):
            return geo.polygon_circle(oa.corners(xa, ya, ta), cb, ob.radius)
        g, pb, pa, nrm = geo.polygon_circle(ob.corners(x, y, t), ca, oa.radius)  # type: ignore[union-attr]
        return g, pa, pb, -nrm

    def point_jac(
        self, q: np.ndarray, p: np.ndarray, link: int | None, obj: int | None, frames: tuple[np.ndarray, np.ndarray]
    ) -> np.ndarray:
        """∂(the material point at p of a link or an object)/∂q (2, nq)."""
        J = np.zeros((2, self.nq))
        if link is not None:
            a = frames[0]
            r = p - a[: link + 1]
            J[0, : link + 1], J[1, : link + 1] = -r[:, 1], r[:, 0]
        elif obj is not None and obj in self.slot:
            s = self.slot[obj]
            x, y, _ = self.pose(q, obj)
            J[:, s : s + 2] = np.eye(2)
            J[0, s + 2], J[1, s + 2] = -(p[1] - y), p[0] - x
        return J

    def gaps(self, q: np.ndarray) -> list[tuple[_Pair, geo.Gap, np.ndarray]]:
        """Every live pair with its gap and the gap's gradient in q (n·(J_B − J_A))."""
        fr = self.frames(q)
        out = []
        for p in self.pairs:
            if p.b_obj in self.gone or p.a_obj in self.gone:
                continue
            g = self.gap(q, p, fr)
            n = g[3]
            grad = n @ (self.point_jac(q, g[2], None, p.b_obj, fr) - self.point_jac(q, g[1], p.a_link, p.a_obj, fr))
            out.append((p, g, grad))
        return out

    def potential(self, q: np.ndarray, T: float, pull: np.ndarray) -> tuple[float, np.ndarray]:
        """(E, ∂E/∂q): springs, the tendon's work at tension T (``pull`` = c_i r_i), the weights."""
        m = self.m
        th = q[: self.n]
        K, th0 = np.asarray(m.stiffness), np.asarray(m.preload)
        k3 = np.asarray(m.cubic)
        w = th + th0
        E = float(0.5 * K @ w**2 + 0.25 * k3 @ w**4 - T * pull @ th)
        grad = np.zeros(self.nq)
        grad[: self.n] = K * w + k3 * w**3 - T * pull
        if self.g.any():
            fr = self.frames(q)
            a, ang = fr
            com = np.asarray(m.link_com, dtype=float)
            for j in range(self.n):
                c, s = math.cos(ang[j]), math.sin(ang[j])
                pc = a[j] + np.array([c * com[j, 0] - s * com[j, 1], s * com[j, 0] + c * com[j, 1]])
                E -= self.weights[j] * float(self.g @ pc)
                grad -= self.weights[j] * (self.g @ self.point_jac(q, pc, j, None, fr))
            for k in self.free:
                if k in self.gone:
                    continue
                wk = self.objects[k].mass_g * G
                s_ = self.slot[k]
                E -= wk * float(self.g @ q[s_ : s_ + 2])
                grad[s_ : s_ + 2] -= wk * self.g
        return E, grad


def _bands(m: FingerModel, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each bearing's friction band at ``theta`` [N·mm]: f0 + γ⁺(θ + θ0) closing, f0 + γ⁻(θ + θ0) opening."""
    wound = theta + np.asarray(m.preload, dtype=float)
    f0 = np.asarray(m.friction, dtype=float)
    return f0 + np.asarray(m.gamma_pos) * wound, f0 + np.asarray(m.gamma_neg) * wound


def _capstan(m: FingerModel) -> np.ndarray:
    """c_i r_i: each joint's share of the tension while pulling (capstan), times its moment arm [mm]."""
    c = np.exp(-m.mu_t * np.cumsum(np.asarray(m.wrap, dtype=float)))
    out: np.ndarray = c * np.asarray(m.moment_arm, dtype=float)
    return out


class _Step:
    """One move of the minimiser from q0 at tension T: Φ over z = (q, p, n) with p − n = A(q − q0), p, n ≥ 0."""

    def __init__(
        self, scene: _Scene, q0: np.ndarray, T: float, pull: np.ndarray, normal: dict[int, float], at: np.ndarray
    ) -> None:
        """Friction's weights from the state ``at`` (the bands) and the normal forces ``normal`` (pair id → N)."""
        self.scene, self.q0, self.T, self.pull = scene, q0, T, pull
        m, n = scene.m, scene.n
        rows, w_pos, w_neg, self.friction_of = [], [], [], {}
        band, band_neg = _bands(m, at[:n])
        for i in np.flatnonzero((band > 0) | (band_neg > 0)):
            rows.append(np.eye(scene.nq)[i])
            w_pos.append(band[i])
            w_neg.append(band_neg[i])
        fr = scene.frames(q0)
        for p, g, _ in scene.gaps(q0):
            N = normal.get(id(p), 0.0)
            if p.mu > 0 and N > 0 and g[0] < TOUCH_MM:
                t = np.array([-g[3][1], g[3][0]])
                ja = scene.point_jac(q0, g[1], p.a_link, p.a_obj, fr)
                jb = scene.point_jac(q0, g[2], None, p.b_obj, fr)
                self.friction_of[id(p)] = len(rows)
                rows.append(t @ (ja - jb))
                w_pos.append(p.mu * N)
                w_neg.append(p.mu * N)
        self.A = np.asarray(rows, dtype=float).reshape(-1, scene.nq)
        self.w = np.concatenate([w_pos, w_neg]).astype(float)
        self.nd = len(rows)
        self._cache: tuple[bytes, list[Any]] | None = None

    def _gaps(self, q: np.ndarray) -> list[Any]:
        key = q.tobytes()
        if self._cache is None or self._cache[0] != key:
            self._cache = (key, self.scene.gaps(q))
        return self._cache[1]

    def objective(self, z: np.ndarray) -> tuple[float, np.ndarray]:
        nq, n = self.scene.nq, self.scene.n
        E, grad = self.scene.potential(z[:nq], self.T, self.pull)
        dx = z[n:nq] - self.q0[n:]
        grad[n:] += DRAG * dx
        return E + 0.5 * DRAG * float(dx @ dx) + float(self.w @ z[nq:]), np.concatenate([grad, self.w])

    def solve(self, bounds: list[tuple[float, float]]) -> Any:
        from scipy.optimize import minimize

        nq, nd = self.scene.nq, self.nd
        eye = np.eye(nd)
        cons = [
            {
                "type": "eq",
                "fun": lambda z: z[nq : nq + nd] - z[nq + nd :] - self.A @ (z[:nq] - self.q0),
                "jac": lambda z: np.hstack([-self.A, eye, -eye]),
            }
        ] if nd else []  # fmt: skip
        if self.scene.pairs:
            cons.append({
                "type": "ineq",
                "fun": lambda z: np.array([g[0] for _, g, _ in self._gaps(z[:nq])]),
                "jac": lambda z: np.array([np.concatenate([gr, np.zeros(2 * nd)]) for _, _, gr in self._gaps(z[:nq])]),
            })  # fmt: skip
        z0 = np.concatenate([self.q0, np.zeros(2 * nd)])
        return minimize(
            self.objective, z0, jac=True, method="SLSQP", bounds=bounds + [(0.0, None)] * (2 * nd),
            constraints=cons, options={"ftol": 1e-12, "maxiter": 300},
        )  # fmt: skip


def _bounds(scene: _Scene, q0: np.ndarray) -> tuple[list[tuple[float, float]], np.ndarray, np.ndarray]:
    """The trust box of one move (and its edges that are not the joints' own limits)."""
    thmax = np.asarray(scene.m.rotation, dtype=float)
    lo, hi = q0 - TURN_RAD, q0 + TURN_RAD
    lo[: scene.n], hi[: scene.n] = np.maximum(lo[: scene.n], 0.0), np.minimum(hi[: scene.n], thmax)
    for s in scene.slot.values():
        lo[s : s + 2], hi[s : s + 2] = q0[s : s + 2] - MOVE_MM, q0[s : s + 2] + MOVE_MM
    limit_lo = np.r_[np.zeros(scene.n), np.full(scene.nq - scene.n, -np.inf)]
    limit_hi = np.r_[thmax, np.full(scene.nq - scene.n, np.inf)]
    return list(zip(lo, hi)), np.where(lo > limit_lo + 1e-12, lo, np.nan), np.where(hi < limit_hi - 1e-12, hi, np.nan)


def _normals(scene: _Scene, q: np.ndarray, lam_in: np.ndarray) -> dict[int, float]:
    """Pair id → normal force [N] of the pairs touching at q (the gap constraints' multipliers)."""
    return {id(p): float(lam) for (p, g, _), lam in zip(scene.gaps(q), lam_in) if g[0] < TOUCH_MM and lam > 0}


def _settle(
    scene: _Scene, q: np.ndarray, T: float, pull: np.ndarray, normal: dict[int, float]
) -> tuple[np.ndarray, list[Contact], dict[int, float]]:
    """The state at tension T from q, in moves that each stay in the trust box, and its contacts. Friction's
    weights (the bearings' bands, μ·N) are taken at the move's end: each move is solved again with them until
    its end stays within SETTLED (at most FIXED_POINT times)."""
    start = q
    for _ in range(MAX_MOVES):
        bounds, lo, hi = _bounds(scene, q)
        at = q
        for _ in range(FIXED_POINT):
            step = _Step(scene, q, T, pull, normal, at)
            res = step.solve(bounds)
            new = np.clip(res.x[: scene.nq], [b[0] for b in bounds], [b[1] for b in bounds])
            normal = _normals(scene, new, np.asarray(res.multipliers, dtype=float)[step.nd :])
            settled = np.abs(new - at).max() < SETTLED
            at = new
            if settled or (step.nd == 0 and not any(p.mu for p in scene.pairs)):
                break
        at_edge = np.any(np.abs(new - lo) < 1e-9) or np.any(np.abs(new - hi) < 1e-9)
        move_start, q = q, new
        if not at_edge:
            break
    mult = np.asarray(res.multipliers, dtype=float)
    lam_eq, lam_in = mult[: step.nd], mult[step.nd :]
    live = scene.gaps(q)
    touching = [(p, g, gr, float(lam)) for (p, g, gr), lam in zip(live, lam_in) if g[0] < TOUCH_MM]
    forces = _least_friction(scene, q, start, move_start, T, pull, touching)
    contacts = []
    for k, (p, g, _, lam) in enumerate(touching):
        row = step.friction_of.get(id(p))
        N, tang = (lam, float(lam_eq[row]) if row is not None else 0.0) if forces is None else forces[k]
        if N > PRESS_N:
            point, nrm = (float(g[1][0]), float(g[1][1])), (float(g[3][0]), float(g[3][1]))
            contacts.append(Contact(p.body, p.b_obj + 1, point, nrm, float(N), float(tang)))
    if forces is not None:
        normal = {id(p): forces[k][0] for k, (p, *_) in enumerate(touching) if forces[k][0] > 0}
    return q, contacts, normal


def _least_friction(
    scene: _Scene,
    q: np.ndarray,
    start: np.ndarray,
    move_start: np.ndarray,
    T: float,
    pull: np.ndarray,
    touching: list[tuple[_Pair, geo.Gap, np.ndarray, float]],
) -> list[tuple[float, float]] | None:
    """(N, f_t) per touching contact with the least friction that holds the state (``grasp_forces``), or None
    where nothing sticks by friction (the multipliers are then the answer) or the solve fails."""
    from rjcad.physics.grasp_forces import least_friction

    m, n = scene.m, scene.n
    band_pos, band_neg = _bands(m, q[:n])
    joints = np.flatnonzero((band_pos > 0) | (band_neg > 0))
    if not joints.size and not any(p.mu > 0 for p, *_ in touching):
        return None
    _, grad = scene.potential(q, T, pull)
    grad[n:] += DRAG * (q[n:] - move_start[n:])
    fr = scene.frames(q)
    slips = []
    for p, g, _, _ in touching:
        t = np.array([-g[3][1], g[3][0]])
        slips.append(
            t @ (scene.point_jac(q, g[1], p.a_link, p.a_obj, fr) - scene.point_jac(q, g[2], None, p.b_obj, fr))
        )
    a_t = np.asarray(slips, dtype=float).reshape(len(touching), scene.nq)
    thmax = np.asarray(m.rotation, dtype=float)
    stops = [np.eye(scene.nq)[i] for i in range(n) if q[i] <= 1e-12]
    stops += [-np.eye(scene.nq)[i] for i in range(n) if q[i] >= thmax[i] - 1e-12]
    out = least_friction(
        grad,
        np.asarray([gr for _, _, gr, _ in touching], dtype=float).reshape(len(touching), scene.nq),
        a_t,
        np.asarray([p.mu for p, *_ in touching], dtype=float),
        a_t @ (q - start),
        np.column_stack([band_pos[joints], band_neg[joints], joints]).reshape(-1, 3),
        (q - start)[joints],
        np.asarray(stops, dtype=float).reshape(len(stops), scene.nq),
    )
    if out is None:
        return None
    N, f_t, _ = out
    return [(float(a), float(b)) for a, b in zip(N, f_t)]


def close_on(
    m: FingerModel,
    objects: Sequence[Object],
    *,
    max_tension_n: float = MAX_TENSION_N,
    stroke: float | None = None,
    outlines: Sequence[np.ndarray] | None = None,
    steps: int = STEPS,
    base_outline: np.ndarray | None = None,
) -> Grasp:
    """The finger ``m`` pulled by a tension ramped from 0 to ``max_tension_n`` [N] in ``steps`` readings (stopped
    when the tendon's travel Σ r_i θ_i + T/k_t reaches ``stroke`` [mm]) against ``objects``: a ``Grasp``.
    ``outlines``: the links' (default: ``template_outlines``); ``base_outline``: the base's, in the base's frame,
    which then supports free objects."""
    check_run(max_tension_n, stroke, steps)
    lines = link_outlines(m, outlines)
    scene = _Scene(m, objects, lines, base_outline)
    q = scene.start()
    for p, g, _ in scene.gaps(q):
        if g[0] < -TOUCH_MM:
            raise ParameterError(
                f"object {p.b_obj + 1}",
                objects[p.b_obj].to_dict(),
                f"overlaps {p.body.replace('link', 'link ')} of the open finger",
            )
    pull = _capstan(m)
    r = np.asarray(m.moment_arm, dtype=float)
    stretch = 0.0 if math.isinf(m.tendon_stiffness) else 1.0 / float(m.tendon_stiffness)
    out = Grasp(m.n, list(objects))
    normal: dict[int, float] = {}
    finger_reach = reach(m.link_length, lines)
    for k, T in enumerate(np.linspace(0.0, max_tension_n, int(steps))):
        q, contacts, normal = _settle(scene, q, float(T), pull, normal)
        for j in scene.free:  # out of the finger's reach, or falling free of everything: gone
            o, pose = objects[j], scene.pose(q, j)
            falling = scene.g.any() and math.hypot(pose[0] - o.x, pose[1] - o.y) > o.radius
            falling = falling and not any(c.object == j + 1 for c in contacts)
            if j not in scene.gone and (out_of_reach(o, pose, finger_reach) or falling):
                scene.gone.add(j)
                out.ejected_at = k if out.ejected_at is None else out.ejected_at
        travel = float(r @ q[: m.n]) + T * stretch
        out.record(travel, float(T), q[: m.n], contacts, [scene.pose(q, j) for j in range(len(objects))])
        if stroke is not None and travel >= stroke:
            break
    final = [scene.pose(q, j) for j in range(len(objects))]
    if out.ejected_at is None and any(
        let_go(o, j + 1, final[j], out.contacts[-1]) for j, o in enumerate(objects) if j not in scene.gone
    ):
        out.ejected_at = len(out.tension_n) - 1
    return out
