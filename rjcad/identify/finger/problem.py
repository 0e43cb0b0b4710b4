"""Fitting a finger campaign: every measured channel (each joint's angle, the tension) of every experiment is
one residual series with its own noise σ, so the joint pipeline's BIC, held-out cycles, relevance and
identifiability apply unchanged (rjcad.identify.select.Selector, subclassed here).

The model input is the tendon path: ``tendon_mm`` smoothed and made monotone within each pull and release
(its noise would otherwise make the model reverse, and stick, at every jitter). Channels are in degrees
(angles) and N (tension).
"""

from __future__ import annotations

import os
import threading
from dataclasses import dataclass, field, replace

import numpy as np

from rjcad import DEG
from rjcad.identify.finger.catalogue import AFTER_SIMULATION, acting_gravity, actuator_tension, catalogue, model_of
from rjcad.identify.finger.data import FingerCampaign, FingerExperiment
from rjcad.identify.fit import Problem
from rjcad.identify.select import Selector
from rjcad.identify.signal import Motion, analyse_motion, noise_sigma, spikes
from rjcad.physics.finger import simulate_angles


@dataclass(frozen=True, eq=False)
class Channel:
    """One measured series of one experiment: ``index`` 0…N−1 a joint angle [deg], N the tension [N]."""

    exp: FingerExperiment
    exp_index: int
    index: int
    quantity: str
    y: np.ndarray
    path: np.ndarray  # the tendon path the model is driven with [mm]
    pulling: np.ndarray  # bool per sample
    motion: Motion  # of the tendon (cycles, reversals, holds)
    sigma: float
    span: float
    folds: np.ndarray
    outliers: np.ndarray
    full_path: np.ndarray | None = None  # the whole record's path; with gravity the model runs on it (lag per step)
    kept: np.ndarray | None = None  # indices of the fitted samples in the whole record

    @property
    def valid(self) -> np.ndarray:
        return self.motion.valid & ~self.outliers


def tendon_path(t, tendon) -> tuple[np.ndarray, np.ndarray, Motion]:
    """The smoothed tendon displacement, monotone within each pull and release run; pulling flags; its motion."""
    m = analyse_motion(t, tendon)
    path = m.theta.copy()
    d = m.direction
    starts = np.flatnonzero(np.r_[True, d[1:] != d[:-1]])
    ends = np.r_[starts[1:], len(d)]
    for a, b in zip(starts, ends):
        seg = path[a:b]
        path[a:b] = np.maximum.accumulate(seg) if d[a] > 0 else np.minimum.accumulate(seg)
    return path, d > 0, m


#: Samples per experiment the fit works on: without damping, relaxation and gravity the model is
#: rate-independent, so simulating it on every q-th sample, every turn of the tendon kept, is exact at those
#: samples; q = ⌈n / FIT_SAMPLES⌉. With gravity (iterated to an equilibrium within each step), damping or
#: relaxation (integrated over each step) the model runs on every sample and is compared on those: integrated
#: over the kept samples' longer steps instead, a damped model differs from the record by enough that switching
#: gravity on (which runs on every sample) "improved" the fit by ΔBIC −33 on a bench record without gravity.
FIT_SAMPLES = 1000


def _kept(m: Motion, n: int) -> np.ndarray:
    """Indices of the samples the fit uses: every q-th, plus the samples on both sides of each turn."""
    q = max(1, -(-n // FIT_SAMPLES))
    keep = np.zeros(n, dtype=bool)
    keep[::q] = True
    keep[-1] = True
    turns = np.flatnonzero(m.direction[1:] != m.direction[:-1])
    keep[turns] = keep[np.minimum(turns + 1, n - 1)] = True
    return np.flatnonzero(keep)


def _subset(m: Motion, idx: np.ndarray) -> Motion:
    arrays = {f: getattr(m, f)[idx] for f in ("theta", "velocity", "direction", "valid", "hold", "cycle")}
    extra = {f: getattr(m, f)[idx] for f in ("glitches", "at_reversal") if getattr(m, f) is not None}
    return replace(m, **arrays, **extra, reversals=np.searchsorted(idx, m.reversals))


def prepare_finger(campaign: FingerCampaign, n_folds: int = 2) -> list[Channel]:
    out = []
    for k, e in enumerate(campaign.experiments):
        path, pulling, m = tendon_path(e.t, e.tendon)
        idx = _kept(m, len(e.t))
        near_zero_full = path - path.min() < 4.0 * max(noise_sigma(e.tendon), 1e-6)
        series = [(f"theta{i + 1}_deg", e.theta[:, i] / DEG) for i in range(e.theta.shape[1])]
        if e.tension is not None:
            series.append(("tendon_force_n", e.tension))
        # at zero stroke the tension of a preloaded finger steps from 0 (slack) to the preload's (taut): within
        # the tendon reading's noise of its lowest value the model cannot tell which, so those tension samples
        # are left out
        near_zero = near_zero_full[idx]
        full_path = path
        path, pulling, m = path[idx], pulling[idx], _subset(m, idx)
        for i, (q, y_full) in enumerate(series):
            sig = noise_sigma(y_full)  # from the full record (consecutive samples)
            y = y_full[idx]
            lo, hi = np.percentile(y[m.valid] if m.valid.any() else y, [0.5, 99.5])
            span = float(hi - lo)
            sig = max(sig, 1e-6 * max(span, 1e-12), 1e-9)
            folds = m.cycle % n_folds if m.n_cycles >= n_folds else np.full(len(y), -1)
            bad = spikes(y, sig) | (near_zero if q == "tendon_force_n" else False)
            out.append(Channel(e, k, i, q, y, path, pulling, m, sig, span, folds, bad, full_path, idx))
    return out


#: Value sets whose simulations each thread remembers: a Jacobian's β columns (``AFTER_SIMULATION``) reuse the
#: simulation of the point itself, a few evaluations back.
RECENT = 4


@dataclass
class _Runs:
    """The simulations of one value set: the models (by gravity direction) and each experiment's θ and T."""

    models: dict = field(default_factory=dict)
    out: dict[int, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)


class Simulator:
    """The finger model's channels for a set of parameter values, one simulation per experiment (cached)."""

    def __init__(self, campaign: FingerCampaign):
        self.design = campaign.design.model
        self._local = threading.local()  # one cache per thread: candidate fits run side by side

    def _runs(self, values: dict[str, float]) -> _Runs:
        """This thread's simulations with ``values`` (the parameters the simulation reads), the RECENT last kept."""
        key = tuple(sorted(kv for kv in values.items() if kv[0] not in AFTER_SIMULATION))
        recent = self._local.__dict__.setdefault("recent", {})
        runs = recent.pop(key, None) or _Runs()
        recent[key] = runs  # the most recent last
        if len(recent) > RECENT:
            del recent[next(iter(recent))]
        return runs

    def channel(self, values: dict[str, float], ch: Channel) -> np.ndarray:
        runs = self._runs(values)
        if ch.exp_index not in runs.out:
            g = acting_gravity(values, ch.exp.gravity)
            if g not in runs.models:  # the experiments without weight share one model
                runs.models[g] = model_of(values, self.design, g)
            m = runs.models[g]
            if m.gravity is not None or m.rate_dependent:  # on every sample (see FIT_SAMPLES)
                assert ch.full_path is not None and ch.kept is not None  # prepare_finger sets both
                theta, T = simulate_angles(m, ch.full_path, ch.exp.t if m.rate_dependent else None)
                runs.out[ch.exp_index] = theta[ch.kept], T[ch.kept]
            else:
                runs.out[ch.exp_index] = simulate_angles(m, ch.path)
        theta, T = runs.out[ch.exp_index]
        if ch.index < theta.shape[1]:
            return theta[:, ch.index] / DEG
        return actuator_tension(values, T, ch.pulling)


class FingerProblem(Problem):
    """The least-squares problem over every channel (residuals whitened by each channel's σ)."""

    def __init__(self, campaign, prepared, fixed, sim: Simulator):
        super().__init__(campaign, prepared, fixed)
        self.sim = sim
        self.channels: list[Channel] = prepared  # ``prepared``, typed: Problem names the joint's Prepared

    def residuals(self, values: dict[str, float], masks=None) -> list[np.ndarray]:
        out = []
        for i, p in enumerate(self.channels):
            mask = p.valid if masks is None else masks[i]
            out.append((p.y[mask] - self.sim.channel(values, p)[mask]) / p.sigma)
        return out


class FingerSelector(Selector):
    """The joint pipeline's selection, on a finger's channels with the finger catalogue."""

    post_check_nfev = 20  # a finger's refit from the fitted point converges in a few steps; each costs ~15 ms
    workers = min(2, os.cpu_count() or 1)  # the compiled solver releases the GIL: candidates fit side by side
    # Selector's annotations name the joint pipeline's Campaign; a finger selector's campaign is a finger's
    campaign: FingerCampaign  # type: ignore[assignment]

    def __init__(self, campaign: FingerCampaign):
        self.catalogue = catalogue(campaign.design.model)
        self.sim = Simulator(campaign)
        #: parameters held at their design value whatever the selection does (the scale angles cannot see)
        self.reference: dict[str, str] = {}
        if not campaign.has_tension:
            self.reference["stiffness_nmm_per_rad_j1"] = (
                "joint angles alone fix the springs' stiffness ratios, not their scale (a stiffer finger pulled "
                "harder closes the same): joint 1's stiffness is the reference; a tension record would fix it"
            )
        super().__init__(campaign)  # type: ignore[arg-type]  # (see ``campaign`` above)

    def free_names(self, effects, frozen=None) -> tuple[str, ...]:
        return tuple(n for n in super().free_names(effects, frozen) if n not in self.reference)

    def _prepare(self, campaign):
        return prepare_finger(campaign)

    def run(self):
        ident = super().run()
        for name, why in self.reference.items():
            if name in self.param_names(ident.effects):
                ident.not_identifiable[name] = why
        if "capstan_path" in ident.effects:
            ident.notes.append(
                "capstan_path scales the tension by β⁺ while pulling and β⁻ while releasing and leaves the angles "
                "alone; so does a stiffness that differs by direction by the same fraction in every spring: the "
                "data cannot tell them apart (a load cell at the finger's base, past the tendon's path, would)"
            )
        if not self.campaign.has_tension and "spring_calibration" in ident.effects:
            ident.notes.append(
                "without a tension record joint 1's stiffness is held at its design value (joint "
                "angles cannot fix the springs' common scale: a stiffer finger pulled harder closes "
                "the same); the other joints' springs are fitted with it held there"
            )
        return ident

    def _base(self, campaign) -> dict[str, float]:
        vals = {}
        for e in self.catalogue:
            vals.update(e.neutral(None))
        return vals

    def _design_json(self, campaign) -> dict:
        return campaign.design.as_json()

    def problem(self, fixed):
        return FingerProblem(self.campaign, self.prepared, fixed, self.sim)

    def predict(self, values, p) -> np.ndarray:
        return self.sim.channel(values, p)


def identify_finger(campaign: FingerCampaign, progress=None):
    """Find what the finger's design model gets wrong, which effects explain it, and the gain; ``progress`` (a
    ``rjcad.progress.Progress``) is told each step."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        selector = FingerSelector(campaign)
        selector.progress = progress
        return selector.run()
