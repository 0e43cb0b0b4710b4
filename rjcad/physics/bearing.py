"""Bearing model of a joint: the contact forces that hold the moving body, and the friction they make.

The moving body (eye or hub, with its link) sits in the ground body with clearance. Its loads (the tendon,
the spring's end forces, a test load, the link's weight) push it until surfaces close; the closed surfaces
push back (normal forces only, N_i ≥ 0) so that the body is in equilibrium in every direction except the
turn about the joint axis, which the spring, the drive and friction balance. Friction torque about the axis:

    τ_f = μ · Σ N_i · ρ_i        (ρ_i the contact's distance from the axis, μ one material-pair coefficient)

Method, for a set of candidate contact points i (point p_i, unit normal n_i: the direction the ground pushes,
gap g_i at the centred pose) and the loads' resultant w = (F, M_x, M_y) about the origin:

1. where the body goes: the small displacement δ = (u_x, u_y, u_z, φ_x, φ_y) that maximises the loads'
   work w·δ with every gap open, g_i + a_i·δ ≥ 0, a_i = (n_i, (p_i × n_i)_x, (p_i × n_i)_y) (a linear
   program; among equal optima the least displaced one). The gaps under load are g_i + a_i·δ; the tilt is |φ|.
2. who pushes: among the contacts closed there, the forces with A·N = −w, N ≥ 0 and the least Σ N_i² (equal
   contact stiffness: N_i = a_i·λ). Friction is left out of this balance (first order in μ).

Frames: joint axis +Z through the origin; the moving body's frame (its link along +X) holds the contacts; a
load given in the ground frame is turned by −θ_j. Units: mm, N, N·mm, rad.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from rjcad.design.layout_desktop import CONE_ANGLE, FACET_MARGIN, ROOF_LAND
from rjcad.design.params import JointParams
from rjcad.errors import ParameterError
from rjcad.spring import rod
from rjcad.validate import in_range

#: Points per circle of a revolved contact surface.
AZIMUTHS = 36
#: A contact whose gap under load is below this is closed [mm].
CLOSED = 1e-6
#: The paper's bar test (experiment A): the bar's own weight, 0.1 N, 70 mm from the axis, along the axis
#: (the camera looked down the axis): a moment that tilts the link. The paper's F_n = 1.5 N is its estimate
#: of the pin load this makes ("due to the joint geometry"): 7 N·mm over ≈ 4.7 mm.
BAR_WEIGHT_N = 0.1
BAR_ARM_MM = 70.0


@dataclass(frozen=True)
class Contact:
    """A candidate contact point: ``surface`` name, ``point`` [mm] and unit ``normal`` (the direction the ground
    pushes the moving body) in the moving frame, ``gap`` the normal clearance at the centred pose [mm]."""

    surface: str
    point: tuple[float, float, float]
    normal: tuple[float, float, float]
    gap: float
    #: False for a pair of surfaces that must never touch (a touch there binds the joint): watched, not designed
    designed: bool = True
    #: Whose edge (rim, coil) the point is: "moving" (it slides on a ground surface) or "ground" (a moving surface
    #: slides on it: the collar along the bore's rims). The same to first order; :func:`exact_gaps` tells them apart.
    edge: str = "moving"

    def __post_init__(self) -> None:
        if self.edge not in ("moving", "ground"):
            raise ParameterError("edge", self.edge, "must be 'moving' or 'ground'")

    @property
    def radius(self) -> float:
        """Friction radius ρ: the point's distance from the axis [mm]."""
        return math.hypot(self.point[0], self.point[1])


@dataclass(frozen=True)
class Load:
    """A force [N] at a point [mm], both in the moving frame; ``name`` says what it is."""

    name: str
    force: tuple[float, float, float]
    point: tuple[float, float, float]


def ring(
    surface: str,
    radius: float,
    z: float,
    n_r: float,
    n_z: float,
    gap: float,
    count: int = AZIMUTHS,
    designed: bool = True,
    edge: str = "moving",
) -> list[Contact]:
    """``count`` contacts around a circle (radius, z); normal n_r·ê_r + n_z·ẑ (unit) at each [mm]."""
    in_range("count", count, 3, limit="must be >= 3")
    in_range("radius", radius, 0.0, unit="mm")
    in_range("gap", gap, 0.0, unit="mm")
    out = []
    for k in range(count):
        a = 2 * math.pi * k / count
        c, s = math.cos(a), math.sin(a)
        out.append(Contact(surface, (radius * c, radius * s, z), (n_r * c, n_r * s, n_z), gap, designed, edge))
    return out


def _matrix(contacts: Sequence[Contact]) -> np.ndarray:
    """Columns a_i = (n_i, (p_i × n_i)_x, (p_i × n_i)_y), shape (5, m)."""
    p = np.array([c.point for c in contacts], dtype=float)
    n = np.array([c.normal for c in contacts], dtype=float)
    return np.vstack([n.T, np.cross(p, n)[:, :2].T])


def resultant(loads: Iterable[Load]) -> np.ndarray:
    """(F_x, F_y, F_z, M_x, M_y, M_z) of the loads about the origin [N, N·mm]."""
    out = np.zeros(6)
    for ld in loads:
        f = np.asarray(ld.force, dtype=float)
        out[:3] += f
        out[3:] += np.cross(np.asarray(ld.point, dtype=float), f)
    return out


@dataclass(frozen=True)
class BearingState:
    """The bearing under one set of loads: ``forces`` N_i per contact [N], the displacement (u_x, u_y, u_z [mm],
    φ_x, φ_y [rad]) and the gaps under load [mm]; ``mu`` the material pair's friction coefficient."""

    contacts: tuple[Contact, ...]
    forces: np.ndarray
    displacement: np.ndarray
    gaps: np.ndarray
    mu: float
    loads: tuple[Load, ...] = field(default=())

    @property
    def friction_torque(self) -> float:
        """τ_f = μ·Σ N_i·ρ_i [N·mm]."""
        return self.mu * float(sum(f * c.radius for f, c in zip(self.forces, self.contacts)))

    @property
    def tilt(self) -> float:
        """The body's tilt off the axis, |(φ_x, φ_y)| [rad]."""
        return float(math.hypot(self.displacement[3], self.displacement[4]))

    @property
    def bearing(self) -> dict[str, float]:
        """Total normal force per bearing surface [N] (surfaces that carry > 1e-9 N)."""
        out: dict[str, float] = {}
        for f, c in zip(self.forces, self.contacts):
            if f > 1e-9:
                out[c.surface] = out.get(c.surface, 0.0) + float(f)
        return out

    @property
    def min_gap(self) -> float:
        """Smallest gap under load between surfaces not designed to bear (0 there: the joint binds) [mm]."""
        free = [g for g, c in zip(self.gaps, self.contacts) if not c.designed]
        return float(min(free)) if free else math.inf

    @property
    def binding(self) -> list[str]:
        """Surfaces that bear but are not designed to (empty when the joint runs as designed)."""
        return sorted({c.surface for f, c in zip(self.forces, self.contacts) if f > 1e-9 and not c.designed})

    def residual(self) -> np.ndarray:
        """(ΣF_x, ΣF_y, ΣF_z, ΣM_x, ΣM_y) of loads and contact forces: zero in equilibrium [N, N·mm]."""
        out: np.ndarray = resultant(self.loads)[:5] + _matrix(self.contacts) @ self.forces
        return out


def solve(contacts: Sequence[Contact], loads: Sequence[Load], mu: float) -> BearingState:
    """Where the loads put the body and which contacts push how hard (module docstring: steps 1 and 2)."""
    in_range("mu", mu, 0.0, 2.0, limit="must be in [0, 2]")
    if not contacts:
        raise ParameterError("contacts", 0, "needs at least one contact")
    A = _matrix(contacts)
    g = np.array([c.gap for c in contacts], dtype=float)
    w = resultant(loads)[:5]
    delta = _displacement(A, g, w)
    gaps = g + A.T @ delta
    forces = _forces(A, gaps, w)
    return BearingState(tuple(contacts), forces, delta, gaps, float(mu), tuple(loads))


def exact_gaps(contacts: Sequence[Contact], delta: Sequence[float] | np.ndarray) -> np.ndarray:
    """Each contact's gap with the body moved by δ = (u_x, u_y, u_z, φ_x, φ_y) exactly: turned by the rotation
    vector (φ_x, φ_y, 0) about the origin, then shifted by u [mm]. Each surface is its tangent plane there.

    A moving edge at p on a ground plane (normal n, fixed):   g + n·(R·p + u − p).
    A ground edge at p under a moving plane (normal R·n):     g + (R·n)·(R·p + u − p).

    Both are :func:`solve`'s linearised gaps g + n·(u + φ × p) to first order; their second-order terms,
    ≈ ρ·φ²/2, reach tenths of a mm at a tilt of several degrees (docs/bearing.md)."""
    from scipy.spatial.transform import Rotation  # only the exact gaps need it (0.8 s of import)

    d = np.asarray(delta, dtype=float)
    R = Rotation.from_rotvec([d[3], d[4], 0.0]).as_matrix()
    p = np.array([c.point for c in contacts], dtype=float)
    n = np.array([c.normal for c in contacts], dtype=float)
    g = np.array([c.gap for c in contacts], dtype=float)
    turned = np.array([c.edge == "ground" for c in contacts])[:, None]
    normals = np.where(turned, n @ R.T, n)
    out: np.ndarray = g + np.sum(normals * (p @ R.T + d[:3] - p), axis=1)
    return out


@dataclass(frozen=True)
class FirstTouch:
    """Where the exact gaps first close along a solved displacement scaled from rest (s·δ, 0 < s ≤ 1): the
    fraction ``s``, the tilt there [rad] and the contact that closes."""

    s: float
    tilt: float
    contact: Contact


def first_touch(state: BearingState, closed: float = 1e-3, steps: int = 64) -> FirstTouch | None:
    """The first contact whose exact gap (:func:`exact_gaps`) falls below ``closed`` [mm] as the body moves along
    ``state``'s own displacement from rest; None when none does before the whole displacement. A scan of
    ``steps``, then bisection in the first step that closes."""
    contacts, d = state.contacts, np.asarray(state.displacement, dtype=float)

    def least(s: float) -> float:
        return float(exact_gaps(contacts, s * d).min())

    if least(0.0) <= closed:
        return None  # touching at rest: nothing to follow
    lo = 0.0
    for s in np.linspace(0.0, 1.0, steps + 1)[1:]:
        if least(float(s)) <= closed:
            hi = float(s)
            break
        lo = float(s)
    else:
        return None
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if least(mid) > closed else (lo, mid)
    i = int(np.argmin(exact_gaps(contacts, hi * d)))
    return FirstTouch(hi, hi * float(math.hypot(d[3], d[4])), contacts[i])


def _displacement(A: np.ndarray, g: np.ndarray, w: np.ndarray) -> np.ndarray:
    """max w·δ subject to g + Aᵀδ ≥ 0, the least displaced of equal optima (δ = δ⁺ − δ⁻, a tiny cost on |δ|)."""
    from scipy.optimize import linprog  # 0.3 s of import that only a bearing solve needs

    scale = float(np.abs(w).max())
    if scale == 0.0:
        return np.zeros(5)
    eps = 1e-7 * scale
    cost = np.concatenate([-w + eps, w + eps])
    res = linprog(cost, A_ub=np.hstack([-A.T, A.T]), b_ub=g, bounds=(0, None), method="highs")
    if res.status == 3:
        raise ParameterError("contacts", len(g), "cannot hold the load: the body moves off without closing a gap")
    if res.status != 0:
        raise RuntimeError(f"bearing displacement: {res.message}")
    x = np.asarray(res.x, dtype=float)
    delta: np.ndarray = x[:5] - x[5:]
    return delta


def _forces(A: np.ndarray, gaps: np.ndarray, w: np.ndarray) -> np.ndarray:
    """N ≥ 0 on the closed contacts with A·N = −w and the least Σ N² [N].

    Its dual: N = max(0, Aᵀλ), λ maximising −wᵀλ − ½·|max(0, Aᵀλ)|² (Newton with backtracking, 5 unknowns);
    if the closed contacts cannot balance w, the non-negative least-squares balance instead.
    """
    from scipy.optimize import nnls

    forces = np.zeros(A.shape[1])
    closed = np.flatnonzero(gaps < CLOSED)
    scale = float(np.abs(w).max())
    if scale == 0.0 or closed.size == 0:
        return forces
    B, b = A[:, closed], -w

    def dual(lam: np.ndarray) -> float:
        return float(b @ lam - 0.5 * np.sum(np.maximum(0.0, B.T @ lam) ** 2))

    lam = np.linalg.lstsq(B @ B.T, b, rcond=None)[0]
    for _ in range(100):
        n = np.maximum(0.0, B.T @ lam)
        grad = b - B @ n
        if np.abs(grad).max() <= 1e-13 * max(1.0, scale):
            forces[closed] = n
            return forces
        S = B[:, n > 0]
        step = np.linalg.lstsq(S @ S.T + 1e-12 * np.eye(5), grad, rcond=None)[0]
        t, f0 = 1.0, dual(lam)
        while dual(lam + t * step) < f0 + 1e-4 * t * float(grad @ step) and t > 1e-12:
            t /= 2
        lam = lam + t * step
    forces[closed] = nnls(B, b)[0]
    return forces


# --- the layouts' contacts ----------------------------------------------------------------------------


def stacked_contacts(p: JointParams, count: int = AZIMUTHS) -> list[Contact]:
    """The paper's knuckle: the eye's bore on the pin (rims at the eye's faces, at the pin's radius) and the
    eye's faces on the cheeks (bottom pushed up, top pushed down), each face out to the moving body's reach
    over the cheek along each ray: the flange (R_e + 0.6) or, inside the band's beam (|y| ≤ R_e, +X), the cheek's rim."""
    _need(p, "stacked")
    c, (z0, z1) = p.clearance_mm, p.z_eye
    R_e, R_c = p.eye_radius, p.cheek_radius
    out = ring("pin", p.pin_radius, z0, 1.0, 0.0, c, count) + ring("pin", p.pin_radius, z1, 1.0, 0.0, c, count)
    gaps = {"cheek below": (z0, 1.0, z0 - p.z_cheek1[1]), "cheek above": (z1, -1.0, p.z_cheek2[0] - z1)}
    for name, (z, nz, gap) in gaps.items():
        out += ring(name, p.pin_radius + c, z, 0.0, nz, gap, count)
        for k in range(count):
            a = 2 * math.pi * k / count
            reach = min(R_c, R_e + 0.6)
            if math.cos(a) > 0:  # the beam: the ray leaves it at y = ±R_e
                reach = min(R_c, max(reach, R_e / max(abs(math.sin(a)), 1e-12)))
            out.append(Contact(name, (reach * math.cos(a), reach * math.sin(a), z), (0.0, 0.0, nz), gap))
    x_post, gap_post = p.post_ring_radius - p.post_radius, p.post_ring_radius - p.post_radius - R_c
    for zc in (p.z_cheek1, p.z_cheek2):  # watched: the post passes the cheek's rim
        for z in zc:
            out.append(Contact("post on cheek rim", (x_post, 0.0, z), (1.0, 0.0, 0.0), gap_post, designed=False))
    return out


def desktop_contacts(p: JointParams, count: int = AZIMUTHS) -> list[Contact]:
    """The desktop hub in its cup: the flare under the roof (a cone, pushed down and in), the collar in the roof's
    bore (rims at the bore's ends), the arm's underside on the roof's top (a line along the arm, +X: pushed up and
    out). Cone normals are (±sin α, ±cos α) in (r, z), α the cone angle from horizontal."""
    _need(p, "desktop")
    L = p.desktop
    sa, ca = math.sin(CONE_ANGLE), math.cos(CONE_ANGLE)
    g_cone = L.c + FACET_MARGIN
    out: list[Contact] = []
    # the roof's inner rim on the flare's cone (a ground edge), the flare's rim on the roof's cone (a moving edge)
    out += ring("flare", L.R_bore, L.roof_under(L.R_bore), -sa, -ca, g_cone, count, edge="ground")
    out += ring("flare", L.R_flare, L.roof_under(L.R_flare), -sa, -ca, g_cone, count)
    r_land = L.R_bore + ROOF_LAND
    for z in (L.roof_under(L.R_bore), L.roof_top(r_land)):  # the bore's rims: the collar slides along them
        out += ring("collar", L.R_bore, z, -1.0, 0.0, L.R_bore - L.R_band, count, edge="ground")
    out += _arm_on_roof(p, count)
    # watched: the flare's rim inside the cup's wall, the wound spring's outer coils inside the wall
    out += ring("flare rim on cup wall", L.R_flare, L.flare_top(L.R_flare), -1.0, 0.0, L.R_ci - L.R_flare, count, False)
    for z in (0.0, L.b):
        out += ring("spring on cup wall", p.wound_radius, z, -1.0, 0.0, L.R_ci - p.wound_radius, count, False)
    return out


def _arm_on_roof(p: JointParams, count: int) -> list[Contact]:
    """The arm's underside (a plane along +X falling at the cone angle, |y| ≤ w_a) over the roof's top cone:
    along its middle line (the roof's top + the clearance there) and its two edges, where the cone has fallen
    away by (ρ − x)·tan α; normal and gap are the cone's at the point (ρ = √(x² + y²))."""
    L = p.desktop
    sa, ca, tan_a = math.sin(CONE_ANGLE), math.cos(CONE_ANGLE), math.tan(CONE_ANGLE)
    r0, r1 = L.R_bore + ROOF_LAND, L.R_co
    out = []
    for y in (-L.w_arm, 0.0, L.w_arm):
        x0, x1 = math.sqrt(max(r0 * r0 - y * y, 0.0)), math.sqrt(r1 * r1 - y * y)
        for x in np.linspace(x0, x1, max(3, count // 6)):
            rho = math.hypot(float(x), y)
            gap = (L.cz + (rho - x) * tan_a) * ca
            normal = (sa * x / rho, sa * y / rho, ca)
            out.append(Contact("arm on roof", (float(x), y, L.roof_top(rho)), normal, gap))
    return out


def contacts_of(p: JointParams, count: int = AZIMUTHS) -> list[Contact]:
    """The contacts of ``p``'s layout."""
    return desktop_contacts(p, count) if p.layout == "desktop" else stacked_contacts(p, count)


def _need(p: JointParams, layout: str) -> None:
    if p.layout != layout:
        raise ParameterError("layout", p.layout, f"this bearing is the {layout} layout's")


# --- the loads -----------------------------------------------------------------------------------------


def _turn(v: Sequence[float], angle: float) -> tuple[float, float]:
    c, s = math.cos(angle), math.sin(angle)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def tendon_load(p: JointParams, tension: float, theta_j: float) -> Load:
    """The tendon on the moving body, when it ends in the moving link: the tension T [N] along the ground's
    channel (−X of the ground frame), where the tendon leaves the band (ground (0, r, z_t)); the wrap on the band
    and the pull at the anchor are internal. In the moving frame (turned by −θ_j)."""
    in_range("tension", tension, 0.0, unit="N")
    fx, fy = _turn((-tension, 0.0), -theta_j)
    x, y = _turn((0.0, p.moment_arm), -theta_j)
    return Load("tendon", (fx, fy, 0.0), (x, y, p.z_mid))


@dataclass(frozen=True)
class SpringForces:
    """The springs' end forces on the moving body over the range: ``theta_j`` (K,) [rad], ``force`` (K, 2) [N]
    and ``point`` (K, 2) [mm] in the moving frame, per spring; ``heights`` the springs' mid-planes [mm]."""

    theta_j: np.ndarray
    force: np.ndarray
    point: np.ndarray
    heights: tuple[float, ...]

    def loads(self, theta_j: float) -> list[Load]:
        """The springs' loads at θ_j (linear between the samples)."""
        f = [float(np.interp(theta_j, self.theta_j, self.force[:, i])) for i in (0, 1)]
        q = [float(np.interp(theta_j, self.theta_j, self.point[:, i])) for i in (0, 1)]
        return [Load("spring", (f[0], f[1], 0.0), (q[0], q[1], z)) for z in self.heights]

    def magnitude(self) -> np.ndarray:
        """|F| of one spring over the range [N]."""
        return np.asarray(np.hypot(self.force[:, 0], self.force[:, 1]))


def spring_forces(p: JointParams, samples: int = 10) -> SpringForces:
    """The rod model's end forces (rjcad.spring.rod, the wind-up of rjcad.design.envelope.wound_states) on the
    moving body, θ_j = 0..rotation; see :func:`_spring_frames` for the frames."""
    d = p.spring
    heights = (d.width / 2,) if p.layout == "desktop" else (sum(p.z_spring1) / 2, sum(p.z_spring2) / 2)
    th, f, inner, outer = _rod_end_forces(
        d.inner_radius, d.pitch, d.turns, d.thickness, d.width * d.youngs_modulus, p.preload, p.rotation, samples
    )
    desktop = p.layout == "desktop"
    f, q = _spring_frames(desktop, th, f, inner if desktop else outer)
    return SpringForces(th, f, q, heights)


def _spring_frames(desktop: bool, th: np.ndarray, f: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """From the rod's frame (hub fixed; R0 the force its clamp puts on the strip) to the moving body's.

    Desktop: the hub moves; its frame is the rod's turned by π, and the strip pushes the hub with −R0, i.e. R0
    there, at the inner end −X_0. Stacked: the strip pushes the post with −R_end = R0 at the outer end; the ground
    frame is the rod's mirrored (y → −y), the moving frame the ground's turned by −θ_j.
    """
    if desktop:
        return f, -q
    mirror = np.array([1.0, -1.0])
    fm, qm = f * mirror, q * mirror
    c, s = np.cos(-th), np.sin(-th)
    turn = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)  # (K, 2, 2)
    return np.einsum("kij,kj->ki", turn, fm), np.einsum("kij,kj->ki", turn, qm)


@lru_cache(maxsize=64)
def _rod_end_forces(
    r_in: float, pitch: float, turns: float, t: float, eb: float, preload: float, rotation: float, samples: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """θ_j (K,), the hub clamp's force on the strip R0 (K, 2) [N], the inner and the outer end (K, 2) [mm], in the
    rod's frame: the counter-clockwise spiral ending at +preload, its outer end turned clockwise by preload + θ_j
    (inner end clamped at the origin, outer end's angle carried: clamped); ``eb`` = E·b [N/mm]."""
    windup = preload + rotation
    X, tangents, _ = rod.spiral_nodes(r_in, pitch, turns, preload - 2 * math.pi * turns, per_turn=40)
    x, y = X[-1]

    def path(lam: float) -> tuple[float, float, float]:
        c, s = math.cos(lam * windup), math.sin(lam * windup)
        return (c * x + s * y - x, -s * x + c * y - y, -lam * windup)

    start = preload / windup
    lams = np.concatenate([np.linspace(0.0, start, 7)[1:], start + np.linspace(0.0, 1.0, samples)[1:] * (1 - start)])
    sol = rod.solve_rod(
        X, {0: (0.0, 0.0, 0.0), -1: path}, EI=eb * t**3 / 12.0, EA=eb * t, steps=lams, tangents=tangents
    )
    keep = np.flatnonzero(sol.lam >= start - 1e-12)
    th = windup * sol.lam[keep] - preload
    ends = np.array([sol.positions(int(k))[-1] for k in keep])
    return th, sol.reaction[keep, 0, :2], np.repeat(X[:1], len(keep), axis=0), ends


def bar_loads(p: JointParams, drive_torque: float, push_at: float | None = BAR_ARM_MM) -> list[Load]:
    """The paper's bar (experiment A) on the moving link: its weight, BAR_WEIGHT_N along −Z at BAR_ARM_MM on +X,
    and the drive: drive_torque / push_at along +Y at push_at on +X (a push on the bar, by default at its middle),
    or a couple about the axis (``push_at`` None: no force on the link) [N, mm]. The paper does not say which."""
    weight = Load("bar weight", (0.0, 0.0, -BAR_WEIGHT_N), (BAR_ARM_MM, 0.0, p.z_mid))
    if push_at is None:
        return [weight]
    return [weight, Load("bar drive", (0.0, drive_torque / push_at, 0.0), (push_at, 0.0, p.z_mid))]


def spring_torque(p: JointParams, theta_j: float) -> float:
    """The joint's springs' torque at θ_j, rod model (all springs) [N·mm]."""
    return p.springs * p.spring.rod.torque_at(p.preload + theta_j)


def locking_mu(p: JointParams, poses: int = 13) -> float:
    """The μ above which the tendon cannot turn the joint at some pose, whatever its tension: r / max S₁(θ_j), S₁
    the bearing's Σ N·ρ under the tendon alone per newton [mm/N·N] (the contact solve is homogeneous in the load:
    S grows as S₁·T, and r·T = τ_s + μ·S has no root once μ·S₁ ≥ r); inf if the tendon loads no surface."""
    contacts = contacts_of(p)
    s1 = max(
        solve(contacts, [tendon_load(p, 1.0, float(t))], 1.0).friction_torque
        for t in np.linspace(0.0, p.rotation, poses)
    )
    return p.moment_arm / s1 if s1 > 0 else math.inf


class BearingLocked(RuntimeError):
    """The friction a drive's own load makes grows faster than the drive: the joint locks (self-locking)."""


@dataclass(frozen=True)
class Drive:
    """One quasi-static pose of a driven joint: θ_j [rad], direction s (+1 flexing, −1 releasing), the drive
    (torque [N·mm] for the bar, tendon tension [N]) and the bearing there; τ = τ_spring + s·τ_friction."""

    theta_j: float
    direction: int
    drive: float
    state: BearingState


def driven(
    p: JointParams,
    mu: float,
    theta_j: float,
    direction: int,
    drive: str = "tendon",
    extra: Sequence[Load] = (),
    springs: SpringForces | None = None,
    push_at: float | None = BAR_ARM_MM,
) -> Drive:
    """The pose θ_j moving in ``direction`` with friction from the bearing: the drive that balances the spring and
    the friction its own load makes (fixed point of r·T = τ_s + s·τ_f(T), or τ = τ_s + s·τ_f(τ) for the bar)."""
    if direction not in (1, -1) or drive not in ("tendon", "bar"):
        raise ParameterError("direction/drive", (direction, drive), "direction ±1, drive 'tendon' or 'bar'")
    springs = spring_forces(p) if springs is None else springs
    contacts = contacts_of(p)
    tau_s = spring_torque(p, theta_j)
    tol, too_much = 1e-9 * max(1.0, tau_s), 50.0 * (abs(tau_s) + 1.0)

    def at(tau_f: float) -> tuple[float, BearingState]:
        """The drive τ that a friction τ_f asks for, and the bearing under it (a tendon only pulls: τ ≥ 0; the
        hand on the bar also holds it back: τ < 0 where the spring alone cannot return the joint)."""
        tau = tau_s + direction * tau_f
        tau = max(tau, 0.0) if drive == "tendon" else tau
        own = [tendon_load(p, tau / p.moment_arm, theta_j)] if drive == "tendon" else bar_loads(p, tau, push_at)
        return tau, solve(contacts, [*own, *springs.loads(theta_j), *extra], mu)

    # the fixed point τ_f = friction(τ(τ_f)) by secant steps (the friction is piecewise linear in the drive, so
    # a few steps land on it); a plain step where the secant would leave τ_f ≥ 0
    x0, x1, h0, plain = 0.0, 0.0, math.nan, 0.0
    for _ in range(200):
        tau, state = at(x1)
        if abs(tau) > too_much:
            if x1 == plain:  # a plain step went this far: the friction outgrows the drive
                break
            x1, h0 = plain, math.nan  # the secant went too far: the plain step instead
            continue
        h1 = state.friction_torque - x1
        if abs(h1) <= tol:
            return Drive(theta_j, direction, tau / p.moment_arm if drive == "tendon" else tau, state)
        plain = state.friction_torque
        x_next = x1 - h1 * (x1 - x0) / (h1 - h0) if math.isfinite(h0) and h1 != h0 else plain
        if not (math.isfinite(x_next) and x_next >= 0.0):
            x_next = plain
        x0, h0, x1 = x1, h1, x_next
    raise BearingLocked(f"μ = {mu:g} at θ_j = {math.degrees(theta_j):.1f}°: the drive's own friction outgrows it")
