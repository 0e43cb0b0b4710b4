"""Noisy bench signals → smoothed angle, velocity, motion direction, holds, reversals and cycles.

Angles rad, time s. The camera angle is smoothed with a quadratic Savitzky–Golay filter; the
direction comes from a displacement Schmitt trigger (the joint must move ``h`` away from its
last extremum to count as reversed), so noise during holds never flips it. Samples whose
direction is ambiguous (around each reversal) are masked, as the paper dropped ~10 samples
around each reversal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import median_filter
from scipy.signal import savgol_coeffs, savgol_filter

from rjcad import DEG

MAD = 1.4826  # σ = MAD·median|x − median| for Gaussian noise


def noise_sigma(y) -> float:
    """White-noise σ from second differences: σ = 1.4826·median|Δ²y − med|/√6 (robust to steps)."""
    d2 = np.diff(np.asarray(y, dtype=float), 2)
    if len(d2) < 3:
        return 0.0
    return float(MAD * np.median(np.abs(d2 - np.median(d2))) / math.sqrt(6.0))


@dataclass(frozen=True, eq=False)
class Motion:
    """What the angle signal says about the motion, one entry per sample."""

    theta: np.ndarray  # smoothed angle [rad]
    velocity: np.ndarray  # [rad/s]
    direction: np.ndarray  # ±1, held through holds
    valid: np.ndarray  # bool: direction unambiguous (False around reversals)
    hold: np.ndarray  # bool: the joint stands still (part of a hold ≥ min_hold s)
    cycle: np.ndarray  # int: index of the forward–back cycle (a new one starts at each minimum)
    reversals: np.ndarray  # sample indices where the direction changes
    sigma_theta: float  # raw angle noise [rad]
    step: float  # hysteresis h [rad]
    window: int  # smoothing window [samples]
    glitches: np.ndarray | None = None  # bool: camera outliers, replaced by the running median
    at_reversal: np.ndarray | None = None  # bool: masked because the direction is ambiguous there
    velocity_sigma: float = 0.0  # σ of the velocity estimate from the angle noise alone [rad/s]

    @property
    def n_cycles(self) -> int:
        return int(self.cycle.max()) + 1 if len(self.cycle) else 0


def _window(t: np.ndarray, span_s: float) -> int:
    dt = float(np.median(np.diff(t)))
    w = round(span_s / dt) if dt > 0 else 5
    w = max(5, min(w, max(5, len(t) // 20)))
    return w | 1  # odd


def analyse_motion(t, theta, *, span_s: float = 0.05, span_v_s: float = 0.15, min_hold_s: float = 0.5) -> Motion:
    """Smooth θ, estimate θ̇, the held motion direction, holds, reversals, ambiguity mask and cycles.

    Savitzky–Golay on the sample index: θ order 2 over ``span_s``; θ̇ = dθ/di / dt_i, order 2 over ``span_v_s``.
    Direction: Schmitt trigger with h = max((2√(2 ln n) + 2)·σ_smooth, 0.01°) on the smoothed angle.
    """
    t = np.asarray(t, dtype=float)
    raw = np.asarray(theta, dtype=float)
    n = len(raw)
    w = _window(t, span_s)
    sig = noise_sigma(raw)
    glitch = spikes(raw, sig)
    if glitch.any():  # a camera glitch: replace by the running median before smoothing
        raw = np.where(glitch, median_filter(raw, size=5, mode="nearest"), raw)
    th = savgol_filter(raw, w, 2, mode="interp") if n >= w else raw.copy()
    wv = _window(t, span_v_s)  # velocity: a wider window, local slope (noise ∝ w^−3/2, bias ∝ θ‴·w²)
    vel = (savgol_filter(raw, wv, 2, deriv=1, mode="interp") if n >= wv else np.gradient(raw)) / np.gradient(t)
    # σ of the velocity: white angle noise through the derivative kernel, σ_v = σ_θ·√Σh²/Δt
    sig_v = (
        (sig * math.sqrt(float(np.sum(savgol_coeffs(wv, 2, deriv=1) ** 2))) if n >= wv else sig / math.sqrt(2))
        / max(float(np.median(np.diff(t))), 1e-12)
        if n > 1
        else 0.0
    )
    # σ of the smoothed angle: white noise through the SG kernel (Σh² of its central row)
    sig_s = sig * math.sqrt(float(np.sum(savgol_coeffs(w, 2) ** 2))) if n >= w else sig
    # the range of n Gaussian samples stays below 2·√(2 ln n)·σ: a hold never trips the trigger
    h = max((2.0 * math.sqrt(2.0 * math.log(max(n, 2))) + 2.0) * sig_s, 0.01 * DEG)

    start_dir, exts = _schmitt(th, h)
    direction, reversals, valid = _direction_and_mask(th, start_dir, exts, h, w)
    hold = _holds(vel, t, sig, wv, min_hold_s)
    cycle = _cycles(n, reversals, direction)
    at_reversal = ~valid
    valid = valid & ~_widen(glitch, w)
    return Motion(
        theta=th,
        velocity=vel,
        direction=direction,
        valid=valid,
        hold=hold,
        cycle=cycle,
        reversals=reversals,
        sigma_theta=sig,
        step=h,
        window=w,
        glitches=glitch,
        at_reversal=at_reversal,
        velocity_sigma=sig_v,
    )


def spikes(x, sigma: float, k: float = 8.0) -> np.ndarray:
    """Isolated outliers: |x − running median of 5| > k·σ (a median keeps steps, so friction jumps stay)."""
    x = np.asarray(x, dtype=float)
    if len(x) < 5 or sigma <= 0:
        return np.zeros(len(x), dtype=bool)
    return np.abs(x - median_filter(x, size=5, mode="nearest")) > k * sigma


def _widen(mask: np.ndarray, w: int) -> np.ndarray:
    """``mask`` grown by half a smoothing window on each side."""
    if not mask.any():
        return mask
    return np.convolve(mask.astype(float), np.ones(w), mode="same") > 0


def _schmitt(th: np.ndarray, h: float):
    """Displacement hysteresis: a reversal when θ leaves its running extremum by more than h.

    Returns (initial direction ±1, index of the extremum before each reversal).
    """
    n = len(th)
    up = np.flatnonzero(th - th[0] > h)
    dn = np.flatnonzero(th[0] - th > h)
    s = 1.0 if (up[0] if len(up) else n) <= (dn[0] if len(dn) else n) else -1.0
    s0, exts, i = s, [], 0
    while i < n:
        seg = th[i:] * s
        leave = np.flatnonzero(np.maximum.accumulate(seg) - seg > h)
        if not len(leave):
            break
        c = int(leave[0])
        e = i + int(np.argmax(seg[: c + 1]))
        exts.append(e)
        s, i = -s, e + 1
    return s0, np.array(exts, dtype=int)


def _direction_and_mask(th, s0, exts, h, w):
    """Direction per sample, reversal indices, and a mask that is False where the direction is ambiguous.

    Around each extremum, the samples within h of it form a block. A short block is a turn: the
    direction switches after the extremum and the whole block is masked. A long block is a hold:
    the old direction is kept through it and only its end is masked, back to the earliest start
    consistent with the departure's pace (from 2h to 4h away from the hold level, for any start
    growing like t¹…t³), plus half a window.
    """
    n = len(th)
    valid = np.ones(n, dtype=bool)
    direction = np.empty(n)
    half = w // 2 + 1
    s, prev, revs = s0, 0, []
    for e in exts:
        near = np.abs(th - th[e]) <= h
        a = e
        while a > 0 and near[a - 1]:
            a -= 1
        b = e
        while b < n - 1 and near[b + 1]:
            b += 1
        c = min(b + 1, n - 1)
        # departure pace from displacement (not the noisy velocity), measured from the hold level:
        # d ∝ (t − t₀)^k with 1 ≤ k ≤ 3 gives t₀ ≥ i₂ − (i₄ − i₂)/(2^{1/3} − 1) for d(i₂) = 2h, d(i₄) = 4h
        level = float(np.median(th[a : b + 1]))
        dep = np.abs(th[c:] - level)
        i2 = np.flatnonzero(dep > 2 * h)
        i4 = np.flatnonzero(dep > 4 * h)
        back = int(i2[0]) + math.ceil((int(i4[0]) - int(i2[0])) / (2 ** (1 / 3) - 1)) if len(i2) and len(i4) else n - c
        n_amb = back + half
        if b - a + 1 <= 3 * n_amb:  # a turn
            switch, lo = e + 1, max(a - half, 0)
        else:  # a hold, then a departure
            lo = max(a, c - n_amb)
            switch = lo
        switch = max(switch, prev)
        direction[prev:switch] = s
        valid[lo : min(b + half + 1, n)] = False
        revs.append(switch)
        s, prev = -s, switch
    direction[prev:] = s
    return direction, np.array(revs, dtype=int), valid


def _holds(vel, t, sig, w, min_hold_s) -> np.ndarray:
    """True where |θ̇| stays below a noise-scaled threshold for at least ``min_hold_s``."""
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    # σ of the SG derivative for white noise ≈ σ·√(12/(w(w²−1)))/dt
    sig_v = sig * math.sqrt(12.0 / (w * (w * w - 1))) / dt
    moving_speed = np.percentile(np.abs(vel), 90) if len(vel) else 0.0
    thr = max(5.0 * sig_v, 0.02 * moving_speed, 1e-6)
    out = np.zeros(len(vel), dtype=bool)
    for a, b in runs(np.abs(vel) < thr):
        if t[b - 1] - t[a] >= min_hold_s:
            out[a:b] = True
    return out


def runs(mask) -> list[tuple[int, int]]:
    """(start, end) of each run of True in ``mask``, end exclusive."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], np.asarray(mask, dtype=np.int8), [0]])))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))


def _cycles(n: int, reversals: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Cycle index per sample: a new cycle starts at each reversal from backward to forward (a minimum)."""
    starts = np.zeros(n, dtype=int)
    mins = [r for r in reversals if r < n and direction[r] > 0]
    starts[np.array(mins, dtype=int)] = 1
    return np.cumsum(starts)
