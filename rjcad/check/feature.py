"""Checks of each body's features: thinnest wall, narrowest gap inside a body, and the bed."""

from __future__ import annotations

import math

import numpy as np
import trimesh

from rjcad.check.report import CheckResult, point
from rjcad.materials import Printer

#: Surface samples per body for the wall and gap rays.
FEATURE_SAMPLES = 20000
#: Half-angle of the ray cone used for walls and gaps [rad]; each sample takes the longest of its rays,
#: so that a convex edge or a concave corner does not pass for a thin wall or a narrow gap.
CONE_HALF_ANGLE = math.radians(25)


def _frame(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit directions across each unit normal, at right angles to each other."""
    ref = np.where(np.abs(n[:, [0]]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    u = np.cross(n, ref)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return u, np.cross(n, u)


def _cone(n: np.ndarray, half_angle: float) -> list[np.ndarray]:
    """The normals, and four directions tilted from them by ``half_angle``."""
    u, v = _frame(n)
    c, s = math.cos(half_angle), math.sin(half_angle)
    return [n] + [c * n + s * w for w in (u, -u, v, -v)]


#: A gap inside a body counts only across faces within this angle of facing each other (antiparallel
#: normals): two walls across a slot (spring coils, a pin in its bore: parallel to within the tessellation's
#: few degrees). A re-entrant crease, where a 50° overhang leaves a wall or two CAD faces meet at a
#: shallow angle (a box cutting into a ring: 16°), opens as it goes out and a slicer fills its tip; no gap.
FACING_ANGLE = math.radians(10)


def _ray_lengths(
    mesh: trimesh.Trimesh, origins: np.ndarray, dirs: np.ndarray, facing: np.ndarray | None = None
) -> np.ndarray:
    """Distance to the first hit of each ray on ``mesh`` (inf when none). With ``facing`` (normals at the
    origins), a hit counts only on a face within FACING_ANGLE of antiparallel to the origin's normal."""
    out = np.full(len(origins), np.inf)
    locs, idx, tri = mesh.ray.intersects_location(origins, dirs, multiple_hits=False)
    if len(idx):
        dist = np.linalg.norm(locs - origins[idx], axis=1)
        if facing is not None:
            faces = np.einsum("ij,ij->i", mesh.face_normals[tri], facing[idx]) <= -math.cos(FACING_ANGLE)
            idx, dist = idx[faces], dist[faces]
        out[idx] = dist
    return out


def feature_sizes(mesh: trimesh.Trimesh, samples: int = FEATURE_SAMPLES, seed: int = 0):
    """Surface samples with their wall thickness (inward) and in-body gap (outward), by ray cones [mm].

    Each sample takes the longest ray of a 25° cone around its normal, projected on the normal: across
    a flat wall or gap every ray gives the true size; at an edge or a corner some ray escapes. A gap ray
    counts only where it lands on a face that faces the sample (FACING_ANGLE): creases are no gaps.
    """
    if not mesh.area > 0:  # a flat body: nothing to sample (trimesh would divide by its zero area)
        empty = np.zeros((0, 3))
        return empty, empty, np.zeros(0), np.zeros(0)
    pts, fi = trimesh.sample.sample_surface(mesh, samples, seed=seed)
    n = mesh.face_normals[fi]
    real = np.linalg.norm(n, axis=1) > 0.5  # trimesh gives degenerate faces a zero normal: no direction to cast
    pts, n = pts[real], n[real]
    eps = 1e-4
    # every ray of every cone in one call each (walls, gaps); each ray projected on the normal: across a flat
    # wall every ray of the cone then gives its thickness
    dirs = np.concatenate(_cone(n, CONE_HALF_ANGLE))
    proj = np.repeat([1.0] + [math.cos(CONE_HALF_ANGLE)] * 4, len(pts))
    normals, at = np.tile(n, (5, 1)), np.tile(pts, (5, 1))
    wall = (proj * _ray_lengths(mesh, at - normals * eps, -dirs)).reshape(5, -1).max(axis=0)
    gap = (proj * _ray_lengths(mesh, at + normals * eps, dirs, facing=normals)).reshape(5, -1).max(axis=0)
    return pts, n, wall, gap


def _wide(mesh: trimesh.Trimesh, pts: np.ndarray, n: np.ndarray, wall: np.ndarray, reach: float) -> np.ndarray:
    """Which thin samples lie on a wall that goes on ``reach`` further on every side: the points ``reach`` away
    from the wall's middle (pts − n·wall/2) along two directions across n, both ways, all lie inside the body.
    A tip or an edge that narrows to a point ends within ``reach`` on some side: the nozzle prints it as far as it
    can, and it is no thin wall."""
    mid = pts - n * (wall / 2)[:, None]
    u, v = _frame(n)
    probes = np.concatenate([mid + s * reach * w for w in (u, v) for s in (1.0, -1.0)])
    return np.asarray(mesh.contains(probes).reshape(4, len(pts)).all(axis=0))


def check_min_feature(bodies, names, printer: Printer, allowance: float) -> CheckResult:
    """Thinnest wall ≥ the printer's minimum wall; gaps inside a body ≥ its minimum gap (Z gaps: vertical).

    A sample thinner than the minimum counts only where the wall is thin over more than a nozzle's footprint: it
    goes on a nozzle's diameter on every side (``_wide``); samples at a tip that narrows to a point are excused."""
    worst_wall = (math.inf, None, None)
    worst_gap: tuple[float, float | None, np.ndarray | None, tuple[str, float, bool] | None] = (
        math.inf,
        None,
        None,
        None,
    )  # (ratio-to-limit margin, value, where, name/limit)
    tips = 0
    for b, name in zip(bodies, names):
        pts, n, wall, gap = feature_sizes(b)
        if not len(pts):
            continue
        thin = np.flatnonzero(wall < printer.min_wall_mm - allowance)
        if len(thin):
            tip = thin[~_wide(b, pts[thin], n[thin], wall[thin], printer.nozzle_mm)]
            wall[tip], tips = np.inf, tips + len(tip)
        k = int(np.argmin(wall))
        if wall[k] < worst_wall[0]:
            worst_wall = (float(wall[k]), pts[k], name)
        vertical = np.abs(n[:, 2]) > 0.7
        lim = np.where(vertical, printer.min_gap_vertical_mm, printer.min_gap_mm)
        finite = np.isfinite(gap)
        if finite.any():
            margin = np.where(finite, gap - lim, np.inf)
            k = int(np.argmin(margin))
            if margin[k] < worst_gap[0]:
                worst_gap = (float(margin[k]), float(gap[k]), pts[k], (name, float(lim[k]), bool(vertical[k])))
    wall_ok = worst_wall[0] >= printer.min_wall_mm - allowance
    gap_ok = worst_gap[0] >= -allowance
    _, gap_mm, gap_at, gap_of = worst_gap  # all None or all set: no finite gap, gap_ok
    detail = f"thinnest wall {worst_wall[0]:.3f} mm in {worst_wall[2]} (min wall {printer.min_wall_mm} mm); "
    if gap_mm is not None and gap_of is not None:
        name, gap_lim, vert = gap_of
        detail += (
            f"narrowest gap inside a body {gap_mm:.3f} mm in {name} "
            f"({'vertical' if vert else 'horizontal'}, min {gap_lim} mm); "
        )
    detail += f"{FEATURE_SAMPLES} ray-cone samples per body, allowance {allowance} mm"
    if tips:
        detail += (
            f"; {tips} samples at tips excused (thinner than the minimum wall over less than a nozzle's "
            f"footprint: {printer.nozzle_mm} mm on some side)"
        )
    if not wall_ok:
        return CheckResult(
            "min_feature",
            False,
            round(worst_wall[0], 4),
            printer.min_wall_mm,
            point(worst_wall[1]),
            "wall too thin: " + detail,
        )
    if not gap_ok:
        assert gap_mm is not None and gap_of is not None  # a gap below its limit is finite, so was recorded
        return CheckResult(
            "min_feature", False, round(gap_mm, 4), gap_of[1], point(gap_at), "gap inside a body too narrow: " + detail
        )
    return CheckResult("min_feature", True, round(worst_wall[0], 4), printer.min_wall_mm, None, detail)


def check_bed(bodies, printer: Printer) -> CheckResult:
    """The mesh fits the build volume (X and Y may swap) and lies on z = 0, or can be moved there."""
    lo = np.min([b.bounds[0] for b in bodies], axis=0)
    hi = np.max([b.bounds[1] for b in bodies], axis=0)
    ext = hi - lo
    vol = np.asarray(printer.build_volume_mm)
    fits = printer.fits(*ext)
    on_bed = abs(lo[2]) < 1e-3
    detail = (
        f"extent {ext[0]:.1f} × {ext[1]:.1f} × {ext[2]:.1f} mm in a {vol[0]:g} × {vol[1]:g} × {vol[2]:g} mm "
        f"volume; " + ("lies on z = 0" if on_bed else f"bottom at z = {lo[2]:.3f}: move it by {-lo[2]:.3f} mm")
    )
    return CheckResult("bed", bool(fits), point(ext), [float(v) for v in vol], None if fits else point(lo), detail)
