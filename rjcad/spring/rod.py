"""Large-rotation planar rod model of the printed spiral spring (coil gap, torque, stress).

The closed-form model (rjcad.spring.coil_gap) assumes the wound spiral stays
concentric. It does not: the outer end is held at one point (a hook on a post)
and its reaction pushes the coil pack sideways, so the coils touch far earlier.

Method: corotational planar Euler–Bernoulli beam elements (u, v, θ per node; a
linear beam riding on the rigid rotation of its chord), Newton–Raphson under
displacement (or load) control with the consistent tangent, vectorised element
kernels, banded LU solve (LAPACK dgbsv, ``banded.py``). Chosen over OpenSeesPy (a new, heavy dependency for
one element) and over a shooting elastica (shooting across 5–10 turns is
ill-conditioned, the ends depend exponentially on the start values, and it
needs continuation anyway): numpy and LAPACK only, the default spring to 180° in
~0.2 s, and a Newton step that fails is simply bisected.

Conventions (mm, N, N·mm, rad, MPa):
* Centreline as the builder prints it (rjcad.cad.spiral): r = r_in + p_arm·(φ−φ0)/2π,
  counter-clockwise outwards over n turns; φ0 defaults to the joint builder's
  start angle at its default 90° preload, −π/2 − 2πn. Nodes evenly spaced in φ
  (``per_turn`` per turn) with the exact spiral tangents; gaps are measured on
  the elements' cubic (Hermite) shapes, so chords cost no sagitta error.
* Frame: the hub (pin, ground) is fixed at the origin and clamps the inner end;
  the outer end moves with the post, turned about the axis by the wind-up θ;
  ``clamped`` its angle turns by θ too, ``pinned`` it turns freely. Torque T is
  what the moving link applies about the axis, positive in the wind-up sense.
* Sense: ``"tighten"`` raises the curvature everywhere (the outer end turned the way
  the spiral winds outwards), ``"unwind"`` lowers it. The first-wave builder printed
  its spiral counter-clockwise outwards and wound it counter-clockwise: it TIGHTENED
  it (coils touch at ≈23° pinned). Since #14 the builder prints the spiral clockwise
  outwards, so the same preload and flexion UNWIND it; the designer passes
  ``sense="unwind"`` (rjcad.spring.factors.JOINT_SENSE). This module's own default
  stays ``"tighten"`` (the reference tools' sense, used by its tests).
* ``arms=2``: two interleaved arms 180° apart, each of pitch 2·p (p the coil-to-coil
  pitch) and ``turns`` turns, outer ends on posts 180° apart. Each arm is solved as
  its own rod (arm 2 printed as arm 1 turned by 180°, its end carried round by the
  same wind-up); torques add, and the net force on the hub is the vector sum of the
  two arms' inner-end reactions (``hub_force``; ``arm_force`` is one arm's). With a
  ``key`` (the outer end's clamped key, in the end's ray frame) each arm's gap to the
  OTHER arm's key is measured too (``key_gap``).
* Gap: centreline distance − t between parts more than half a turn apart along one
  arm (any parts of different arms); with ``pin_radius``, also |x| − t/2 − pin_radius
  beyond the first quarter turn (the tab). Contact is NOT modelled: the solve runs
  on past first contact (coils pass through each other); later results are those
  of a spring whose coils never touch.
* Convergence (default spring, to 180°, 80 → 240 elements per turn): gaps move
  < 0.5 µm, first contact < 0.05°, K < 0.05 %, peak stress < 0.05 %.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import SupportsInt, cast

import numpy as np

from rjcad.spring import banded
from rjcad.spring.gaps import nearest_gap

TWO_PI = 2.0 * math.pi
_BW = 5  # half-bandwidth of the global stiffness (3 dofs/node, 2 nodes/element)
_BAND_COL, _BAND_ROW = np.meshgrid(np.arange(6), np.arange(6))
_BAND_ROW = _BW + _BAND_ROW - _BAND_COL  # band row of local entry (a, b)


# --- Corotational element (Crisfield's planar beam), vectorised over elements ---


def _kinematics(X0, U):
    """Current chord (c, s, l) and rigid-rotation-free end rotations of each element."""
    d0 = X0[1:] - X0[:-1]
    L0 = np.hypot(d0[:, 0], d0[:, 1])
    c0, s0 = d0[:, 0] / L0, d0[:, 1] / L0
    d = d0 + U[1:, :2] - U[:-1, :2]
    ln = np.hypot(d[:, 0], d[:, 1])
    c, s = d[:, 0] / ln, d[:, 1] / ln
    ca, sa = c * c0 + s * s0, s * c0 - c * s0  # cos, sin of the chord's rotation α

    def local(th):  # θ_node − α, wrapped to (−π, π]
        return np.arctan2(np.sin(th) * ca - np.cos(th) * sa, np.cos(th) * ca + np.sin(th) * sa)

    return L0, ln, c, s, local(U[:-1, 2]), local(U[1:, 2])


def _element(X0, U, EA, EI):
    """Element internal forces f_e (E, 6), tangents k_e (E, 6, 6) and local (N, M1, M2)."""
    L0, ln, c, s, pa, pb = _kinematics(X0, U)
    N = EA * (ln - L0) / L0
    kb = 2.0 * EI / L0
    M1, M2 = kb * (2 * pa + pb), kb * (pa + 2 * pb)
    zero = np.zeros_like(c)
    r = np.stack([-c, -s, zero, c, s, zero], axis=1)
    z = np.stack([s, -c, zero, -s, c, zero], axis=1)
    B = np.stack([r, -z / ln[:, None], -z / ln[:, None]], axis=1)
    B[:, 1, 2] += 1.0
    B[:, 2, 5] += 1.0
    f = np.einsum("eij,ei->ej", B, np.stack([N, M1, M2], axis=1))
    D = np.zeros((len(c), 3, 3))
    D[:, 0, 0] = EA / L0
    D[:, 1, 1] = D[:, 2, 2] = 2 * kb
    D[:, 1, 2] = D[:, 2, 1] = kb
    k = B.transpose(0, 2, 1) @ (D @ B)
    k += (N / ln)[:, None, None] * z[:, :, None] * z[:, None, :]
    rz = r[:, :, None] * z[:, None, :]
    k += ((M1 + M2) / ln**2)[:, None, None] * (rz + rz.transpose(0, 2, 1))
    return f, k, N, M1, M2


def _scatter(fe, n_nodes):
    """Sum element vectors (E, 6) into the global vector (3N,)."""
    g = np.zeros(3 * n_nodes)
    g[: 3 * (n_nodes - 1)] += fe[:, :3].ravel()
    g[3:] += fe[:, 3:].ravel()
    return g


def _band(ke, n_nodes, fixed):
    """Global tangent in LAPACK band storage (rjcad.spring.banded: the matrix in rows _BW:, fill-in above);
    rows/columns of ``fixed`` dofs → identity."""
    n = 3 * n_nodes
    T = np.zeros((2 * _BW + 1, 6, len(ke)))
    T[_BAND_ROW, _BAND_COL] = ke.transpose(1, 2, 0)  # T[BW + a − b, b, e] = k_e[a, b]
    storage = banded.band_storage(n, _BW, _BW)
    ab = storage[_BW:]
    ab[:, : n - 3] += T[:, :3].transpose(0, 2, 1).reshape(2 * _BW + 1, -1)
    ab[:, 3:] += T[:, 3:].transpose(0, 2, 1).reshape(2 * _BW + 1, -1)
    ab[:, fixed] = 0.0
    for k in range(-_BW, _BW + 1):
        j = fixed + k
        ok = (j >= 0) & (j < n)
        ab[_BW - k, j[ok]] = 0.0
    ab[_BW, fixed] = 1.0
    return storage


# --- General rod solver ---


@dataclass(frozen=True)
class RodSolution:
    """Converged states of :func:`solve_rod`, one row per load factor λ.

    ``U`` (S, N, 3): displacements and rotations; ``reaction`` (S, N, 3): force and
    moment each support applies to the rod (zero at free dofs); ``moment`` (S, N):
    bending moment at the nodes, EI·Δκ (positive = more counter-clockwise curvature);
    ``axial`` (S, N−1) element axial forces; ``iterations`` Newton iterations per step.
    """

    lam: np.ndarray
    X0: np.ndarray
    tangent0: np.ndarray
    U: np.ndarray
    reaction: np.ndarray
    moment: np.ndarray
    axial: np.ndarray
    iterations: np.ndarray

    def positions(self, k: int = -1) -> np.ndarray:
        """Current node positions (N, 2) at step k."""
        return self.X0 + self.U[k, :, :2]

    def tangents(self, k: int = -1) -> np.ndarray:
        """Current tangent angles (N,) at step k [rad]."""
        return self.tangent0 + self.U[k, :, 2]


def polyline_tangents(X):
    """Tangent angles of a smooth curve through the nodes: chord bisectors, ends extrapolated."""
    d = np.diff(X, axis=0)
    beta = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    if len(beta) == 1:
        return np.repeat(beta, 2)
    mid = 0.5 * (beta[:-1] + beta[1:])
    return np.concatenate([[2 * beta[0] - mid[0]], mid, [2 * beta[-1] - mid[-1]]])


def _bc_setup(bc: dict, n_nodes):
    """Prescribed dof indices and a function λ → their values."""
    items = [(int(n) % n_nodes, v) for n, v in bc.items()]
    dofs, getters = [], []
    for node, v in items:
        pattern = v(0.0) if callable(v) else v
        for i, val in enumerate(pattern):
            if val is None:
                continue
            dofs.append(3 * node + i)
            getters.append((v, i))

    def values(lam):
        return np.array([f(lam)[i] if callable(f) else f[i] * lam for f, i in getters], dtype=float)

    return np.array(dofs, dtype=int), values


def _newton(X0, U, lam, f_ext, fixed, target, EA, EI, tol, max_iter):
    """Equilibrium at λ from U (copied); returns (U, iterations) or None if it diverged."""
    U = U.copy()
    n = len(X0)
    du_p = np.zeros(3 * n)
    du_p[fixed] = target - U.ravel()[fixed]
    scale = tol * max(1.0, float(np.ptp(X0, axis=0).max()))
    for it in range(1, max_iter + 1):
        fe, ke, *_ = _element(X0, U, EA, EI)
        r = lam * f_ext - _scatter(fe, n)
        if it == 1:  # predictor: carry the prescribed increment through the tangent
            dp = du_p.reshape(n, 3)
            r -= _scatter(np.einsum("eij,ej->ei", ke, np.concatenate([dp[:-1], dp[1:]], axis=1)), n)
        r[fixed] = du_p[fixed] if it == 1 else 0.0
        try:
            du = banded.solve(_band(ke, n, fixed), r, _BW, _BW)
        except (np.linalg.LinAlgError, ValueError):
            return None
        if not np.all(np.isfinite(du)) or np.abs(du[2::3]).max(initial=0) > 1.0:
            return None  # non-finite or a rotation jump > 1 rad: cut the step
        U += du.reshape(n, 3)
        free = np.ones(3 * n, bool)
        free[fixed] = False
        if it > 1 and np.abs(du[free]).max(initial=0.0) < scale:
            return U, it
    return None


class RodSolveError(RuntimeError):
    """Newton found no equilibrium at load fraction ``fraction`` (0..1), even in bisected steps."""

    def __init__(self, fraction: float):
        super().__init__(f"rod solve did not converge at λ = {fraction:.6g}")
        self.fraction = float(fraction)


def solve_rod(
    nodes, bc, load=None, *, EI, EA, steps=20, tangents=None, tol: float = 1e-6, max_iter: int = 30, max_cuts: int = 12
) -> RodSolution:
    """Quasi-static large-rotation solve of a planar rod through its nodes (a chain of elements).

    ``nodes`` (N, 2) stress-free centreline [mm]; ``bc`` {node: (ux, uy, rot)} with
    floats (final values, applied ∝ λ) or None (free), or {node: λ ↦ (ux, uy, rot)}
    for non-proportional paths; ``load`` {node: (Fx, Fy, M)} dead loads ∝ λ [N, N·mm];
    EI [N·mm²], EA [N] scalars or per element; ``steps`` an int (λ = k/steps) or the
    λ values; ``tangents`` the stress-free tangent angles at the nodes (for the
    geometry only; default: chord bisectors). Newton stops when the largest free-dof
    correction < tol × the rod's extent; steps that fail to converge are bisected.
    """
    X0 = np.asarray(nodes, dtype=float)
    n = len(X0)
    lams = np.linspace(0, 1, int(cast(SupportsInt, steps)) + 1)[1:] if np.isscalar(steps) else np.asarray(steps, float)
    fixed, values = _bc_setup(bc, n)
    f_ext = np.zeros(3 * n)
    for node, F in (load or {}).items():
        f_ext[3 * (int(node) % n) : 3 * (int(node) % n) + 3] += F
    EA = np.broadcast_to(np.asarray(EA, float), (n - 1,))
    EI = np.broadcast_to(np.asarray(EI, float), (n - 1,))
    U = np.zeros((n, 3))
    U.ravel()[fixed] = values(0.0)
    states, its = [U.copy()], [0]
    prev = None  # last converged (λ, U) before the current one: secant predictor
    lam = 0.0
    for lam1 in lams:
        step, total, cuts = lam1 - lam, 0, 0
        while lam < lam1 - 1e-14:
            nxt = min(lam + step, lam1)
            guess = U if prev is None else U + (U - prev[1]) * ((nxt - lam) / (lam - prev[0]))
            out = _newton(X0, guess, nxt, f_ext, fixed, values(nxt), EA, EI, tol, max_iter)
            if out is None:
                cuts += 1
                if cuts > max_cuts:
                    raise RodSolveError(nxt)
                step /= 2
                continue
            prev = (lam, U)
            U, it = out
            lam, total = nxt, total + it
        states.append(U.copy())
        its.append(total)
    return _collect(X0, tangents, np.concatenate([[0.0], lams]), np.array(states), its, f_ext, fixed, EA, EI)


def _collect(X0, tangents, lams, Us, its, f_ext, fixed, EA, EI):
    n = len(X0)
    reac, mom, ax = [], [], []
    for lam, U in zip(lams, Us):
        fe, _, N, M1, M2 = _element(X0, U, EA, EI)
        r = np.zeros(3 * n)
        r[fixed] = (_scatter(fe, n) - lam * f_ext)[fixed]
        reac.append(r.reshape(n, 3))
        mom.append(np.concatenate([[-M1[0]], M2]))
        ax.append(N)
    t0 = polyline_tangents(X0) if tangents is None else np.asarray(tangents, float)
    return RodSolution(lams, X0, t0, Us, np.array(reac), np.array(mom), np.array(ax), np.array(its))


# --- Spiral geometry and coil gap ---


def archimedean_length(r_in, pitch, turns):
    """Exact length of r(φ) = r_in + p·φ/2π over n turns [mm] (asinh closed form)."""
    k = pitch / TWO_PI
    u = np.array([r_in / k, r_in / k + TWO_PI * turns])
    prim = u * np.sqrt(u * u + 1.0) + np.arcsinh(u)
    return float(0.5 * k * (prim[1] - prim[0]))


def spiral_nodes(
    r_in: float, pitch: float, turns: float, phi0: float, per_turn: float = 80
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nodes (N, 2), exact tangent angles (N,) and spiral angle φ − φ0 (N,) of one arm."""
    m = max(8, math.ceil(turns * per_turn))
    a = np.linspace(0.0, TWO_PI * turns, m + 1)
    k = pitch / TWO_PI
    r = r_in + k * a
    phi = phi0 + a
    X = np.stack([r * np.cos(phi), r * np.sin(phi)], axis=1)
    tangent = phi + np.arctan2(r, k)  # direction of dX/dφ
    return X, tangent, a


def _refined_min(g, floor=-np.inf):
    """Minimum of a sampled profile: parabola through the three samples around it, ≥ floor."""
    i = int(np.argmin(g))
    if 0 < i < len(g) - 1 and np.all(np.isfinite(g[i - 1 : i + 2])):
        a, b, c = g[i - 1], g[i], g[i + 1]
        den = a - 2 * b + c
        if den > 0:
            return max(b - (c - a) ** 2 / (8 * den), floor), i
    return float(g[i]), i


# --- The spiral spring under wind-up ---

SENSES = {"tighten": 1.0, "unwind": -1.0}
ENDS = ("clamped", "pinned")


@dataclass(frozen=True)
class RodResult:
    """One spring wound from 0 to θ_max; arrays over the wind-up angles ``theta`` [rad].

    torque: one spring, all arms [N·mm]; stress: max|M|·6/(b t²) [MPa] at arc length
    ``stress_s`` from the inner end, point ``stress_xy``; gap: min(coil_gap, hub_gap) [mm]
    at ``gap_s``/``gap_xy`` (on arm 1); first_contact: θ where gap crosses 0 (linear
    interpolation) or None; pin_force: per post [N]; hub_force: net on the hub [N];
    centreline (arms, N, 2) at θ_max. Points in the hub (ground) frame. ``arm_force``: the largest
    inner-end reaction of one arm [N]; ``key_gap``: each arm's strip to the other arm's key [mm] (None
    without a key or with one arm).
    """

    theta: np.ndarray
    torque: np.ndarray
    stress: np.ndarray
    stress_s: np.ndarray
    stress_xy: np.ndarray
    gap: np.ndarray
    gap_s: np.ndarray
    gap_xy: np.ndarray
    coil_gap: np.ndarray
    hub_gap: np.ndarray | None
    first_contact: float | None
    pin_force: np.ndarray
    hub_force: np.ndarray
    max_moment: np.ndarray
    centreline: np.ndarray
    length: float
    k_formula: float
    iterations: np.ndarray
    arm_force: np.ndarray | None = None
    key_gap: np.ndarray | None = None

    @property
    def stiffness_ratio(self) -> np.ndarray:
        """Secant stiffness T/θ over the closed form arms·E·b·t³/(12·L_arm) (NaN at θ = 0)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.torque / (self.theta * self.k_formula)


def _rotation_path(X_end, angle, clamped):
    """λ ↦ prescribed (ux, uy, rot) of the outer end carried round the axis by λ·angle."""

    def path(lam):
        c, s = math.cos(lam * angle), math.sin(lam * angle)
        x, y = X_end
        return (c * x - s * y - x, s * x + c * y - y, lam * angle if clamped else None)

    return path


def node_gaps(X, tangents, a, t, arms: int = 1, pin_radius=None, other=None):
    """Gaps at the nodes of arm 1 [mm]: to the nearest other coil (either arm), and to the pin.

    X (N, 2), tangents (N,) current; a (N,) printed spiral angle φ − φ0 of each node.
    Coil gap: distance to the nearest part of the strip(s) more than half a turn away
    along the same arm (arm 2 = ``other`` (X2, tangents2), default −X), minus t. Hub gap
    (None without pin_radius): |X| − t/2 − pin_radius, beyond the first quarter turn (inf there).
    """
    g = nearest_gap(X, X, tangents, a, a)
    if arms == 2:
        X2, tang2 = (-X, tangents + math.pi) if other is None else other
        g = np.minimum(g, nearest_gap(X, X2, tang2))
    hub = None
    if pin_radius is not None:
        hub = np.where(a >= math.pi / 2 - 1e-9, np.hypot(X[:, 0], X[:, 1]) - t / 2 - pin_radius, np.inf)
    return g - t, hub


def key_box(X_end, u: tuple[float, float], w: float, angle: float) -> np.ndarray:
    """Corners (4, 2) of a clamped end's key [mm]: radially u[0]..u[1] from the printed end point ``X_end``
    along its ray, 0..w across it on the side the spiral winds on (counter-clockwise), turned about the axis
    by ``angle`` [rad] (the end's rotation: a clamped end turns rigidly with its post)."""
    r = math.hypot(*X_end)
    e1 = np.asarray(X_end, float) / r
    e2 = np.array([-e1[1], e1[0]])
    pts = np.array([(r + du) * e1 + dv * e2 for du in u for dv in (0.0, w)])[[0, 1, 3, 2]]
    return _rotate(pts, angle)


def _rotate(pts, angle):
    """Points (M, 2) turned about the origin by ``angle`` [rad]."""
    c, s = math.cos(angle), math.sin(angle)
    return pts @ np.array([[c, s], [-s, c]])


def box_gap(X, tangents, box, t) -> float:
    """Smallest gap between a strip of thickness t through X (N, 2) and a convex quadrilateral ``box`` (4, 2)
    [mm]: the strip's nodes against the box (signed: negative inside) and the box's corners against the strip's
    cubic shape, minus t/2."""
    inside = np.full(len(X), np.inf)
    outside = np.zeros(len(X))
    for i in range(4):
        A, B = box[i], box[(i + 1) % 4]
        d = B - A
        ln = math.hypot(*d)
        n = np.array([d[1], -d[0]]) / ln  # outward normal of a counter-clockwise box
        x = np.clip(((X - A) @ d) / ln**2, 0.0, 1.0)
        dist = np.hypot(*(X - A - x[:, None] * d).T)
        side = (X - A) @ n
        inside = np.minimum(inside, np.where(side < 0, dist, np.inf))
        outside = np.maximum(outside, side)
    sdf = np.where(outside <= 0, -inside, np.inf)
    for i in range(4):  # outside: distance to the nearest edge
        A, B = box[i], box[(i + 1) % 4]
        d = B - A
        x = np.clip(((X - A) @ d) / (d @ d), 0.0, 1.0)
        sdf = np.where(outside > 0, np.minimum(sdf, np.hypot(*(X - A - x[:, None] * d).T)), sdf)
    corners = nearest_gap(box, X, tangents)
    return float(min(sdf.min(), corners.min())) - t / 2


def _measure(sol, k, a, s, t, arms, pin_radius, sgn, sol2=None, keys=None, turn=0.0):
    """One wind-up state: torque, peak |M| and where, gaps and where, end forces.

    ``sol2``: arm 2's own solution (two arms); ``keys``: each arm's key corners (2, 4, 2) as printed, turned by
    λ·``turn`` [rad] at this state."""
    if sol2 is not None:
        return _measure_pair(sol, sol2, k, a, s, t, pin_radius, sgn, keys, turn)
    X, R, m = sol.positions(k), sol.reaction[k], np.abs(sol.moment[k])
    i_m = int(np.argmax(m))
    coil, hub = node_gaps(X, sol.tangents(k), a, t, arms, pin_radius)
    gap, i_g = _refined_min(coil if hub is None else np.minimum(coil, hub), -t)
    return dict(
        torque=arms * sgn * (R[-1, 2] + X[-1, 0] * R[-1, 1] - X[-1, 1] * R[-1, 0]),
        max_moment=m[i_m],
        stress_s=s[i_m],
        stress_xy=X[i_m],
        gap=gap,
        gap_s=s[i_g],
        gap_xy=X[i_g],
        coil_gap=_refined_min(coil, -t)[0],
        hub_gap=np.nan if hub is None else _refined_min(hub)[0],
        pin_force=np.hypot(*R[-1, :2]),
        hub_force=np.hypot(*R[0, :2]) if arms == 1 else 0.0,
    )


def _measure_pair(sol, sol2, k, a, s, t, pin_radius, sgn, keys, turn):
    """:func:`_measure` of two arms, each its own solution: torques and hub reactions summed, gaps on both arms."""
    sols = (sol, sol2)
    X = [q.positions(k) for q in sols]
    tang = [q.tangents(k) for q in sols]
    R = [q.reaction[k] for q in sols]
    m = [np.abs(q.moment[k]) for q in sols]
    i_arm = int(m[1].max() > m[0].max())
    i_m = int(np.argmax(m[i_arm]))
    coil, hub = node_gaps(X[0], tang[0], a, t, 2, pin_radius, other=(X[1], tang[1]))
    coil2, hub2 = node_gaps(X[1], tang[1], a, t, 2, pin_radius, other=(X[0], tang[0]))
    if hub is not None:
        hub = np.minimum(hub, hub2)
    coil = np.minimum(coil, coil2)
    gap, i_g = _refined_min(coil if hub is None else np.minimum(coil, hub), -t)
    hub_r = [Ri[0, :2] for Ri in R]
    row = dict(
        torque=sgn * sum(Ri[-1, 2] + Xi[-1, 0] * Ri[-1, 1] - Xi[-1, 1] * Ri[-1, 0] for Xi, Ri in zip(X, R)),
        max_moment=m[i_arm][i_m],
        stress_s=s[i_m],
        stress_xy=X[i_arm][i_m],
        gap=gap,
        gap_s=s[i_g],
        gap_xy=X[0][i_g],
        coil_gap=_refined_min(coil, -t)[0],
        hub_gap=np.nan if hub is None else _refined_min(hub)[0],
        pin_force=max(np.hypot(*Ri[-1, :2]) for Ri in R),
        hub_force=float(np.hypot(*(hub_r[0] + hub_r[1]))),
        arm_force=max(float(np.hypot(*f)) for f in hub_r),
    )
    if keys is not None:
        angle = float(sol.lam[k]) * turn
        row["key_gap"] = min(box_gap(X[i], tang[i], _rotate(keys[1 - i], angle), t) for i in (0, 1))
    return row


def spiral_windup(
    r_in,
    pitch,
    turns,
    b,
    t,
    E,
    end: str = "clamped",
    arms: int = 1,
    phi0=None,
    sense: str = "tighten",
    theta_max: float = math.pi,
    steps: int = 36,
    per_turn: int = 80,
    pin_radius=None,
    key: tuple[float, float, float] | None = None,
) -> RodResult:
    """Wind one printed spiral spring from 0 to ``theta_max`` [rad] in ``steps`` equal steps.

    r_in, pitch (coil-to-coil; each arm has arms·pitch), turns (per arm), b, t [mm], E [MPa];
    end ``clamped``/``pinned`` (outer end); sense ``tighten`` (the joint's) or ``unwind``;
    phi0: start angle (default the builder's at 90° preload, −π/2 − 2π·turns);
    pin_radius: also measure the gap to the hub/pin of that radius; key (u0, u1, w) [mm], two arms only: each
    outer end's key, radially u0..u1 from the end's centreline point, w wide beyond the end (:func:`key_box`).
    """
    if end not in ENDS or sense not in SENSES or arms not in (1, 2):
        raise ValueError(f"end in {ENDS}, sense in {tuple(SENSES)}, arms 1 or 2; got {end!r}, {sense!r}, {arms!r}")
    phi0 = -math.pi / 2 - TWO_PI * turns if phi0 is None else phi0
    X, tang, a = spiral_nodes(r_in, arms * pitch, turns, phi0, per_turn)
    sgn = SENSES[sense]
    EI, EA = E * b * t**3 / 12.0, E * b * t

    def wind(Xa, tang_a):
        path = _rotation_path(Xa[-1], sgn * theta_max, end == "clamped")
        return solve_rod(Xa, {0: (0.0, 0.0, 0.0), -1: path}, EI=EI, EA=EA, steps=steps, tangents=tang_a)

    sol = wind(X, tang)
    sol2 = wind(-X, tang + math.pi) if arms == 2 else None  # arm 2: printed as arm 1 turned by 180°
    keys = None
    if key is not None and arms == 2:
        keys = np.stack([key_box(Xa[-1], key[:2], key[2], 0.0) for Xa in (X, -X)])
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(X, axis=0).T))])
    extra = dict(sol2=sol2, keys=keys, turn=sgn * theta_max) if arms == 2 else {}
    rows = [_measure(sol, k, a, s, t, arms, pin_radius, sgn, **extra) for k in range(len(sol.lam))]
    col = {k: np.array([r[k] for r in rows]) for k in rows[0]}
    theta = theta_max * sol.lam
    L = archimedean_length(r_in, arms * pitch, turns)
    Xend = sol.positions(-1)
    return RodResult(
        theta=theta,
        stress=col["max_moment"] * 6 / (b * t * t),
        hub_gap=None if pin_radius is None else col.pop("hub_gap"),
        first_contact=first_crossing(theta, col["gap"]),
        centreline=np.stack([Xend, -Xend])[:arms] if sol2 is None else np.stack([Xend, sol2.positions(-1)]),
        length=L,
        k_formula=arms * E * b * t**3 / (12.0 * L),
        iterations=sol.iterations,
        **{k: v for k, v in col.items() if k != "hub_gap"},
    )


def first_crossing(theta, gap):
    """First θ where ``gap`` falls below 0, linearly interpolated; None if it never does."""
    below = np.nonzero(np.asarray(gap) < 0)[0]
    if below.size == 0:
        return None
    k = int(below[0])
    if k == 0:
        return float(theta[0])
    g0, g1 = gap[k - 1], gap[k]
    return float(theta[k - 1] + (theta[k] - theta[k - 1]) * g0 / (g0 - g1))


def _small(r_in, pitch, turns, t, end, arms, sense, per_turn, theta):
    return spiral_windup(
        r_in, pitch, turns, 1.0, t, 1.0, end, arms, sense=sense, theta_max=theta, steps=1, per_turn=per_turn
    )


def stiffness_ratio(
    r_in,
    pitch,
    turns,
    t,
    end: str = "clamped",
    arms: int = 1,
    sense: str = "tighten",
    per_turn: int = 80,
    theta: float = 1e-3,
) -> float:
    """Small-wind-up K_rod / (arms·E·b·t³/12L_arm) (independent of E and b)."""
    return float(_small(r_in, pitch, turns, t, end, arms, sense, per_turn, theta).stiffness_ratio[-1])


def stress_factor(
    r_in,
    pitch,
    turns,
    t,
    end: str = "clamped",
    arms: int = 1,
    sense: str = "tighten",
    per_turn: int = 80,
    theta: float = 1e-3,
) -> float:
    """Small-wind-up max|M| / T of one arm (the closed form's m: 1 clamped, 2 pinned)."""
    res = _small(r_in, pitch, turns, t, end, arms, sense, per_turn, theta)
    return float(res.max_moment[-1] * arms / res.torque[-1])


def windup_design(design, E, theta_max: float, **kw) -> RodResult:
    """:func:`spiral_windup` for an object with width, thickness, inner_radius, pitch, turns."""
    return spiral_windup(
        design.inner_radius, design.pitch, design.turns, design.width, design.thickness, E, theta_max=theta_max, **kw
    )
