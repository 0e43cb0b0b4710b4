"""The wound strip for the CAD tests: an independent rod-model run (rjcad.spring.rod's solver only) of the
spring as the joint prints it, and a check that it clears the built bodies over the joint's range."""

import math

import manifold3d as m3
import numpy as np
from mesh_tools import manifold

from rjcad.spring import rod


def printed_centreline(p, per_turn=80):
    """Nodes and tangent angles of the printed strip: clockwise outwards, outer end at −preload."""
    d = p.spring
    a = np.linspace(0.0, 2 * math.pi * d.turns, math.ceil(d.turns * per_turn) + 1)
    k = d.pitch / (2 * math.pi)
    r = d.inner_radius + k * a
    phi = -p.preload + 2 * math.pi * d.turns - a
    X = np.stack([r * np.cos(phi), r * np.sin(phi)], axis=1)
    dx = k * np.cos(phi) + r * np.sin(phi)  # dX/da
    dy = k * np.sin(phi) - r * np.cos(phi)
    return X, np.arctan2(dy, dx)


def wind(p, theta_max, steps):
    """The rod model's solution with the outer end turned counter-clockwise by λ·θ_max (unwinding)."""
    X, tang = printed_centreline(p)
    x, y = X[-1]
    clamped = p.end_condition == "clamped"

    def path(lam):
        c, s = math.cos(lam * theta_max), math.sin(lam * theta_max)
        return (c * x - s * y - x, s * x + c * y - y, lam * theta_max if clamped else None)

    d = p.spring
    EI = d.youngs_modulus * d.width * d.thickness**3 / 12
    return rod.solve_rod(
        X, {0: (0.0, 0.0, 0.0), -1: path}, EI=EI, EA=EI * 12 / d.thickness**2, steps=steps, tangents=tang
    )


def strip_manifold(P, t, z0, z1):
    """The strip of centreline P (N, 2), width t, extruded over z0..z1."""
    d = np.gradient(P, axis=0)
    n = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.linalg.norm(d, axis=1)[:, None]
    poly = np.vstack([P + n * t / 2, (P - n * t / 2)[::-1]])
    cs = m3.CrossSection([poly.tolist()], m3.FillRule.NonZero)
    return m3.Manifold.extrude(cs, z1 - z0).translate((0.0, 0.0, z0))


def wound_strip_clearance(p, meshes, step_deg: float = 10.0) -> float:
    """The layout's wound-strip clearance (stacked: :func:`stacked_wound_clearance`, desktop:
    :func:`desktop_wound_clearance`) [mm]."""
    if p.layout == "desktop":
        return desktop_wound_clearance(p, meshes, step_deg)
    return stacked_wound_clearance(p, meshes, step_deg)


def desktop_wound_clearance(p, meshes, step_deg: float = 10.0) -> float:
    """Smallest gap between the wound strip on the bed and the ground body (cup, socket, lugs, web), and
    between the strip beyond its inner tab and the hub, over all wind-ups (θ_j = wind-up − preload once
    seated); asserts there is no overlap [mm].

    The rod model winds the stacked layout's spring (clockwise outwards, inner end fixed, outer end turned
    counter-clockwise); the desktop spring is that one mirrored across XZ and turned to the socket's ray, in
    the hub's (moving) frame, which turns by θ_j in the world."""
    from rjcad.design.layout_desktop import SOCKET_RAY

    ground = manifold(meshes["ground"])
    d, L = p.spring, p.desktop
    steps = math.ceil(math.degrees(p.preload + p.rotation) / step_deg)
    sol = wind(p, p.preload + p.rotation, steps)
    wind_up = (p.preload + p.rotation) * sol.lam
    tightest = math.inf
    for k in range(len(wind_up)):
        P = sol.positions(k)[:-2].copy()  # the last node is held by the key
        P[:, 1] *= -1.0  # mirror across XZ
        a = SOCKET_RAY + max(0.0, wind_up[k] - p.preload)  # to the socket's ray, then the joint's turn
        c, s = math.cos(a), math.sin(a)
        P = P @ np.array([[c, s], [-s, c]])
        strip = strip_manifold(P, d.thickness, 0.0, L.b)
        assert strip.volume() > 0.5 * d.width * d.thickness * d.length
        assert (strip ^ ground).volume() < 1e-9, math.degrees(wind_up[k])
        tightest = min(tightest, strip.min_gap(ground, 2.0))
        # beyond the first half turn (the tab), the strip's inner face stays off the hub
        r = np.hypot(P[:, 0], P[:, 1])
        half = int(len(P) / (2 * d.turns))
        tightest = min(tightest, float(r[half:].min()) - d.thickness / 2 - L.r_h)
    return tightest


def stacked_wound_clearance(p, meshes, step_deg: float = 10.0) -> float:
    """Smallest gap between the wound strip and the ground block (all wind-ups) or the moving body (turned with
    the joint, wind-ups from the preload on), both spring layers; asserts there is no overlap [mm]."""
    ground, moving = manifold(meshes["ground"]), manifold(meshes["moving"])
    block = ground ^ m3.Manifold.cube((50.0, 200.0, 200.0)).translate((-50.0 - p.ground_block_start + 0.01, -100, -100))
    assert block.volume() > 0
    d = p.spring
    steps = math.ceil(math.degrees(p.preload + p.rotation) / step_deg)
    sol = wind(p, p.preload + p.rotation, steps)
    theta = (p.preload + p.rotation) * sol.lam
    tightest = math.inf
    for k in range(len(theta)):
        P = sol.positions(k)[:-2]  # the last node is held by the fitting
        R = np.eye(4)
        c, s = math.cos(theta[k] - p.preload), math.sin(theta[k] - p.preload)
        R[:2, :2] = [[c, -s], [s, c]]
        mv = moving.transform(R[:3, :4])
        for z0, z1 in (p.z_spring1, p.z_spring2):
            strip = strip_manifold(P, d.thickness, z0, z1)
            # not vacuous (coils that pass through each other, as the rod model lets them, count once)
            assert strip.volume() > 0.5 * d.width * d.thickness * d.length
            assert (strip ^ block).volume() < 1e-9, math.degrees(theta[k])
            tightest = min(tightest, strip.min_gap(block, 2.0))
            if theta[k] >= p.preload - 1e-9:  # seated: the moving body turns with the end
                assert (strip ^ mv).volume() < 1e-9, math.degrees(theta[k])
                tightest = min(tightest, strip.min_gap(mv, 2.0))
    return tightest
