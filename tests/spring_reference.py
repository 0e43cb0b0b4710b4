"""An independent brute-force spring search, used to judge the optimiser's search (not its physics).

The physics is the rod model's, taken from the surrogate through its public API only
(``rjcad.spring.surrogate``: stiffness ratio c, torque ratio τ, stress factor m, gap ratio h); the
search shares no code with ``rjcad.spring.optimise`` or ``rjcad.spring.factors``: the geometry is
scanned on grids (t, b, r_in, p) with the turns from the mean-radius length L = 2π·n·r_in + π·p·n²
instead of the exact arc length, and L found by its own fixed point on c and τ. What the rod model
itself says about an emitted design is checked elsewhere (tests/test_spring_verified.py).
"""

import math

import numpy as np

from rjcad.spring import surrogate as sg

SENSE = "unwind"  # the joint's loading sense (issue #14)


def _margin(end):
    """The surrogate's conservative lookups where its margins exist (h7's work in progress may lack them)."""
    try:
        sg.gap_ratio_min(0.5, 4.0, 5.0, end=end, sense=SENSE)
        return True
    except KeyError:
        return False


def brute_force(req, margin=0.0, p_points=120, r_points=3):
    """Smallest envelope radius over a grid, or inf; constraints tightened by ``margin``."""
    mat, pr, end = req.material_spec, req.printer_spec, req.end
    use = _margin(end)
    E, K = mat.youngs_modulus_mpa, req.joint_stiffness / 2.0
    pre, rot = req.preload, req.rotation
    theta = pre + rot
    if theta > 2 * math.pi:
        return math.inf
    allow, g_min = mat.yield_strength_mpa / req.safety_factor, pr.min_gap_mm
    step, layer = pr.thickness_step_mm, pr.layer_height_mm
    best = math.inf
    for t in [k * step for k in range(1, 400) if pr.min_wall_mm - 1e-9 <= k * step <= 3.0 + 1e-9]:
        b = np.arange(1, int(req.width_max / layer + 1e-9) + 1) * layer
        b = b[b >= max(req.width_min, 2.0 * t) - 1e-9]
        r_lo = max(req.inner_radius_min, 3.0 * t)
        if b.size == 0 or r_lo > req.inner_radius_max * (1 - margin):
            continue
        r_in = np.linspace(r_lo, req.inner_radius_max, r_points)
        B, R, P = np.meshgrid(b, r_in, np.geomspace(t + g_min, r_lo / 0.7072, p_points), indexing="ij")
        rho = R / P
        L = E * B * t**3 / (12.0 * K)
        for _ in range(6):  # L such that the working-range slope c·K_formula·g is K
            n = (-R + np.sqrt(R**2 + P * L / math.pi)) / P
            nn = np.clip(n, 1.0, 20.0)
            tau_max = sg.torque_ratio(theta, rho, nn, end=end, sense=SENSE)
            tau_pre = sg.torque_ratio(pre, rho, nn, end=end, sense=SENSE)
            g = (theta * tau_max - pre * tau_pre) / rot
            L = sg.stiffness_ratio(rho, nn, end=end) * g * E * B * t**3 / (12.0 * K)
        n = (-R + np.sqrt(R**2 + P * L / math.pi)) / P
        T_max = sg.stiffness_ratio(rho, np.clip(n, 1.0, 20.0), end=end) * E * B * t**3 / (12.0 * L) * theta * tau_max
        m = sg.stress_factor(rho, np.clip(n, 1.0, 20.0), theta, end=end, sense=SENSE, margin=use)
        sigma = 6.0 * m * T_max / (B * t * t)
        gap = P * sg.gap_ratio_min(theta, rho, np.maximum(n, 1.0), end=end, sense=SENSE, margin=use) - t
        r_out = R + P * n + t / 2.0
        with np.errstate(invalid="ignore"):
            ok = (
                (sigma <= allow * (1 - margin))
                & (gap >= g_min * (1 + margin))
                & (n >= req.min_turns * (1 + margin))
                & (r_out <= req.outer_radius_max * (1 - margin))
                & (n <= 20.0)
            )
        if ok.any():
            best = min(best, float(r_out[ok].min()))
    return best
