"""An independent brute-force spring search, used to judge the optimiser.

It shares no code with rjcad.spring: formulas are written out again, and the
geometry is scanned on grids (t, b, r_in, n) with the pitch from the
mean-radius length L = 2π·n·r_in + π·p·n² instead of the exact arc length.
"""

import math

import numpy as np

END = {"clamped": (1.0, 1.0), "pinned": (0.8, 2.0)}


def brute_force(req, margin=0.0, n_points=240, r_points=4):
    """Smallest envelope radius over a grid, or inf; constraints tightened by ``margin``."""
    mat, pr = req.material_spec, req.printer_spec
    k_end, m_end = END[req.end]
    E = mat.youngs_modulus_mpa
    K = req.joint_stiffness / 2.0
    theta = req.preload + req.rotation
    allow = mat.yield_strength_mpa / req.safety_factor
    step = pr.thickness_step_mm
    ts = [k * step for k in range(1, 200) if pr.min_wall_mm - 1e-9 <= k * step <= 3.0 + 1e-9]
    best = math.inf
    for t in ts:
        layer = pr.layer_height_mm
        b = np.arange(1, int(req.width_max / layer + 1e-9) + 1) * layer
        b = b[b >= max(req.width_min, 2.0 * t) - 1e-9]
        if b.size == 0:
            continue
        sigma = m_end * 6.0 * K * theta / (b * t * t)
        b = b[sigma <= allow * (1 - margin)]
        if b.size == 0:
            continue
        r_lo = max(req.inner_radius_min, 3.0 * t)
        if r_lo > req.inner_radius_max * (1 - margin):
            continue
        r_in = np.linspace(r_lo, req.inner_radius_max, r_points)
        L = k_end * E * b * t**3 / (12.0 * K)
        Lg, Rg = np.meshgrid(L, r_in, indexing="ij")
        # turns from min_turns up to the most that fit (p >= t)
        n_max = (-Rg + np.sqrt(Rg**2 + t * Lg / math.pi)) / t
        frac = np.linspace(0.0, 1.0, n_points)
        n = req.min_turns * (1 + margin) + (n_max[..., None] - req.min_turns * (1 + margin)) * frac
        Lg, Rg = Lg[..., None], Rg[..., None]
        with np.errstate(invalid="ignore", divide="ignore"):
            p = (Lg - 2 * math.pi * n * Rg) / (math.pi * n**2)
            gap = p * n / (n + theta / (2 * math.pi)) - t
            r_out = Rg + p * n + t / 2.0
        ok = (n >= req.min_turns * (1 + margin) - 1e-12) & (p > 0) & (gap >= pr.min_gap_mm * (1 + margin)) & (
            r_out <= req.outer_radius_max * (1 - margin))
        if ok.any():
            best = min(best, float(r_out[ok].min()))
    return best
