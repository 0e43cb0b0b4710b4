"""Terms outside the finger catalogue: the joint's library (rjcad.identify.propose) per joint, and a backlash
between the actuator and the tendon.

A finger's terms are built from its simulation: a term in a joint's spring shows in every channel (the joints
share the tendon), so its column is the model's sensitivity times the term's time course. With y(v) the channels
simulated at values v: s_K = ∂y/∂ln K (all springs, or joint j's), s_θ0 = ∂y/∂θ0_j [per deg of preload],
τ = t/T − ½ over each experiment, d = +1 while the tendon is pulled, −1 while it is released. A stiffness that
drifts is c·s_K·τ (c: its change over a run, a fraction), one that differs by direction c·s_K·d. A backlash of
width w between the actuator and the tendon is (y(play(path, w)) − y)/(w/2), fitted for a family of widths; its
coefficient is half the play [mm]. Each column is in the channel's units (deg, N) per unit of coefficient.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from rjcad import DEG
from rjcad.identify.finger.catalogue import actuator_tension, model_of
from rjcad.identify.finger.problem import Channel, identify_finger, tendon_path
from rjcad.identify.propose import Basis, Lag, Term, play
from rjcad.physics.finger import simulate_angles

#: Relative step of a stiffness, and step of a preload [deg], for the sensitivities (central differences).
STEP_K, STEP_PRELOAD_DEG = 1e-3, 0.05
#: Backlash widths of the family [mm] (√2 apart: a coefficient within ~20 % of the play whatever its width).
BACKLASH_MM = (0.5, 0.7, 1.0, 1.4, 2.0, 2.8, 4.0)


@dataclass(frozen=True)
class FingerColumns:
    """A channel's building blocks (full record): the prediction, its sensitivities (``k_all``: to every
    stiffness, ``k``: to each joint's, ``preload``: to each joint's preload, ``plays``: the backlash family's
    columns), τ, d, t, and whether the channel is the tension."""

    prediction: np.ndarray
    k_all: np.ndarray
    k: tuple[np.ndarray, ...]
    preload: tuple[np.ndarray, ...]
    plays: tuple[np.ndarray, ...]
    tau: np.ndarray
    direction: np.ndarray
    t: np.ndarray
    tension: bool


class _Simulated(Term):
    """A term not linear in its coefficient: fitted on its secant column at the coefficient (``run``)."""

    def run(self, sims: _Sims, c: float) -> np.ndarray:
        """The channels with the term at coefficient ``c``, simulated (not linearised)."""
        raise NotImplementedError


class _Joints(_Simulated):
    """A term of every spring (``joint`` None) or of one joint's (1…N)."""

    base = ""  # the key's stem

    def __init__(self, joint: int | None = None):
        self.joint = joint
        self.key = self.base + ("" if joint is None else f"_j{joint}")

    def who(self) -> str:
        return "every spring's" if self.joint is None else f"joint {self.joint}'s spring's"

    def sensitivity(self, c: FingerColumns) -> np.ndarray:
        return c.k_all if self.joint is None else c.k[self.joint - 1]

    def names(self, n: int) -> list[str]:
        """The parameters the term scales: every stiffness, or joint ``joint``'s."""
        return [f"stiffness_nmm_per_rad_j{j}" for j in range(1, n + 1) if self.joint in (None, j)]


class FingerDrift(_Joints):
    base, expression, unit = "stiffness_drift", "c·∂y/∂lnK·τ", "fraction of the stiffness over the run"

    def column(self, c):
        return self.sensitivity(c) * c.tau

    def run(self, sims, c):
        return sims.along_run(self.names(sims.design.n), lambda v, x: v * (1.0 + c * x))

    def words(self, coef, q, k):
        return (
            f"{self.who()} stiffness drifts over each run: {-coef / 2:+.1%} at its start, {coef / 2:+.1%} at its "
            f"end ({coef:+.1%} in all)"
        )


class FingerDirection(_Joints):
    base, expression, unit = "direction_stiffness", "c·∂y/∂lnK·d", "fraction of the stiffness, + while pulled"

    def column(self, c):
        return self.sensitivity(c) * c.direction

    def run(self, sims, c):
        up, down = (sims.changed(self.names(sims.design.n), lambda v, s=s: v * (1.0 + s * c)) for s in (1, -1))
        return np.where(sims.pulling[:, None], up, down)

    def words(self, coef, q, k):
        return (
            f"{self.who()} stiffness differs by direction of motion: {coef:+.1%} while the tendon is pulled, "
            f"{-coef:+.1%} while it is released"
        )


class PreloadDrift(_Joints):
    base, expression, unit = "preload_drift", "c·∂y/∂θ0·τ", "deg of preload over the run"

    def column(self, c):
        return c.preload[(self.joint or 1) - 1] * c.tau

    def run(self, sims, c):
        return sims.along_run([f"preload_deg_j{self.joint}"], lambda v, x: v + c * x)

    def words(self, coef, q, k):
        return f"joint {self.joint}'s preload drifts over each run by {coef:+.3g}° (a zero that wanders, or warm-up)"


class FingerLag(Lag):
    """The joint's lag (its column reads the same ``prediction`` and ``t``), in a finger's words."""

    def words(self, coef, q, k):
        return f"the measured angles and tension lagging the tendon's path by {coef * 1e3:.3g} ms"


class TensionBand(Term):
    key, expression, unit = "tension_band", "c·d (tension only)", "N, half-width"

    def column(self, c):
        return c.direction if c.tension else np.zeros_like(c.t)

    def words(self, coef, q, k):
        sense = "against" if coef < 0 else "with"
        return (
            f"a band of constant half-width {abs(coef):.3g} N {sense} the motion in the measured tension that no "
            "joint angle shows (friction between the finger and the load cell)"
        )


class ActuatorBacklash(_Simulated):
    """A play between the actuator and the tendon: the family's widths start the fit, the secant (the play of
    width 2·|c| simulated) refines it."""

    unit = "mm, half the play"

    def __init__(self, index: int):
        self.index, self.width = index, BACKLASH_MM[index]
        self.key = f"actuator_backlash_{self.width:g}mm"
        self.expression = "y(play(path, 2·|c|)) − y"

    def column(self, c):
        return c.plays[self.index]

    def run(self, sims, c):
        return sims.played(2.0 * abs(c))

    def words(self, coef, q, k):
        return (
            f"a backlash of {2 * abs(coef):.3g} mm between the actuator and the tendon (the finger stands still "
            "while the actuator takes it up after each reversal)"
        )


def library(n: int) -> tuple[Term, ...]:
    """The finger's candidate terms for ``n`` joints, in the order a tie is broken."""
    js = range(1, n + 1)
    return (
        FingerDrift(),
        FingerDirection(),
        *(FingerDrift(j) for j in js),
        *(FingerDirection(j) for j in js),
        *(PreloadDrift(j) for j in js),
        FingerLag(),
        TensionBand(),
        *(ActuatorBacklash(i) for i in range(len(BACKLASH_MM))),
    )


class FingerBasis(Basis):
    """The finger's terms, from simulations of each experiment's whole record (cached per value set)."""

    def __init__(self, n: int):
        self.library = library(n)
        self._cache: dict = {}

    def identify(self, campaign, progress):
        return identify_finger(campaign, progress)

    def measured(self, ident):
        return [_measured(ch) for ch in _channels(ident)]

    def rows(self, p):
        return p.kept[p.valid]

    def group(self, i, p):
        return p.exp_index

    def words(self, term, coef, ident):
        return term.words(coef, "", 0.0)

    def with_data(self, campaign, ident, data):
        exps = list(campaign.experiments)
        for ch, y in zip(_channels(ident), data):
            e = exps[ch.exp_index]
            if ch.quantity == "tendon_force_n":
                exps[ch.exp_index] = replace(e, tension=y)
            else:
                theta = e.theta.copy()
                theta[:, ch.index] = y * DEG
                exps[ch.exp_index] = replace(e, theta=theta)
        return replace(campaign, experiments=tuple(exps))

    secant_rounds = 3

    def matrices(self, ident, values, sizes=None):
        key = (id(ident), tuple(sorted(values.items())))
        if key not in self._cache:
            sims = {k: _Sims(ident, values, ch.exp) for k, ch in _first_channels(ident).items()}
            cols = [sims[ch.exp_index].columns(ch) for ch in _channels(ident)]
            tangent = [(c.prediction, np.column_stack([t.column(c) for t in self.library])) for c in cols]
            self._cache[key] = (ident, sims, tangent)
        _, sims, tangent = self._cache[key]
        out = []
        for ch, (pred, cols) in zip(_channels(ident), tangent):
            cols = cols.copy()
            for k, c in (sizes or {}).items():
                term = self.library[k]
                if abs(c) > 1e-9 and isinstance(term, _Simulated):
                    cols[:, k] = sims[ch.exp_index].secant(term, c)[:, ch.index]
            out.append((pred, cols))
        return out


def _channels(ident) -> list[Channel]:
    return ident.prepared


def _first_channels(ident) -> dict[int, Channel]:
    out: dict[int, Channel] = {}
    for ch in _channels(ident):
        out.setdefault(ch.exp_index, ch)
    return out


def _measured(ch: Channel) -> np.ndarray:
    e = ch.exp
    if ch.quantity == "tendon_force_n":
        assert e.tension is not None
        return e.tension
    return e.theta[:, ch.index] / DEG


class _Sims:
    """One experiment's simulations for the columns: at ``values``, with stiffnesses and preloads stepped, and on
    the backlash family's paths."""

    def __init__(self, ident, values: dict[str, float], exp):
        self.design = ident.campaign.design.model
        self.exp, self.values = exp, values
        self._secants: dict = {}
        self.tau = (exp.t - exp.t[0]) / (float(exp.t[-1] - exp.t[0]) or 1.0) - 0.5
        path, pulling, _ = tendon_path(exp.t, exp.tendon)
        self.path, self.pulling = path, pulling
        n = self.design.n
        kn = [f"stiffness_nmm_per_rad_j{j}" for j in range(1, n + 1)]
        self.base = self._run(values)
        self.k_all = self._diff(
            values, {k: values[k] * (1 + STEP_K) for k in kn}, {k: values[k] * (1 - STEP_K) for k in kn}, 2 * STEP_K
        )
        self.k = tuple(
            self._diff(values, {k: values[k] * (1 + STEP_K)}, {k: values[k] * (1 - STEP_K)}, 2 * STEP_K) for k in kn
        )
        pn = [f"preload_deg_j{j}" for j in range(1, n + 1)]
        s = STEP_PRELOAD_DEG
        self.preload = tuple(self._diff(values, {k: values[k] + s}, {k: values[k] - s}, 2 * s) for k in pn)
        self.plays = tuple((self.played(w) - self.base) / (w / 2) for w in BACKLASH_MM)

    def changed(self, names: list[str], change) -> np.ndarray:
        """The channels with each of ``names`` set to ``change(its value)``."""
        return self._run({**self.values, **{k: change(self.values[k]) for k in names}})

    def along_run(self, names: list[str], change, points: int = 5) -> np.ndarray:
        """The channels with ``names`` changing along each run as ``change(value, τ)``: simulated at ``points``
        values of τ and interpolated per sample (exact for a model without memory, as the design model is)."""
        grid = np.linspace(-0.5, 0.5, points)
        runs = np.stack([self.changed(names, lambda v, x=x: change(v, x)) for x in grid])
        u = (self.tau + 0.5) * (points - 1)
        i = np.clip(np.floor(u).astype(int), 0, points - 2)
        f = (u - i)[:, None]
        rows = np.arange(len(u))
        return runs[i, rows] * (1 - f) + runs[i + 1, rows] * f

    def played(self, width: float) -> np.ndarray:
        """The channels with the tendon's path seen through a play of ``width`` [mm]."""
        return self._run(self.values, play(self.path, width, 1.0))

    def secant(self, term: _Simulated, c: float) -> np.ndarray:
        """The term's column at coefficient ``c``: (y(c) − y(0))/c (cached)."""
        key = (term.key, c)
        if key not in self._secants:
            self._secants[key] = (term.run(self, c) - self.base) / c
        return self._secants[key]

    def _run(self, values, path=None) -> np.ndarray:
        """Channels (samples, N + 1): the angles [deg] and the actuator's tension [N]."""
        m = model_of(values, self.design, self.exp.gravity)
        theta, T = simulate_angles(m, self.path if path is None else path, self.exp.t if m.rate_dependent else None)
        return np.column_stack([theta / DEG, actuator_tension(values, T, self.pulling)])

    def _diff(self, values, up, down, step) -> np.ndarray:
        return (self._run({**values, **up}) - self._run({**values, **down})) / step

    def columns(self, ch: Channel) -> FingerColumns:
        t = self.exp.t
        i = ch.index
        return FingerColumns(
            prediction=self.base[:, i],
            k_all=self.k_all[:, i],
            k=tuple(a[:, i] for a in self.k),
            preload=tuple(a[:, i] for a in self.preload),
            plays=tuple(a[:, i] for a in self.plays),
            tau=self.tau,
            direction=np.where(self.pulling, 1.0, -1.0),
            t=t,
            tension=ch.quantity == "tendon_force_n",
        )
