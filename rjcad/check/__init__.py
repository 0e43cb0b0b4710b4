"""Print-readiness checks of a mesh, the way a printer needs it.

Checks, each with a measured value, a limit and, on failure, a location in mm:
``watertight``, ``manifold``, ``bodies``, ``clearance``, ``motion`` (needs a
manifest), ``min_feature``, ``bed`` and ``slicer`` (PrusaSlicer, on request).

A body is a connected component of the mesh (STL) or a named object (3MF).
STL bodies are matched to a manifest's bodies by volume.
"""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import tempfile
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import manifold3d as m3
import numpy as np
import trimesh

from rjcad.errors import RjcadError
from rjcad.materials import Printer, get_printer

#: Tessellation allowance on measured gaps and walls [mm].
DEFAULT_ALLOWANCE = 0.02
#: Surface samples per body for the wall and gap rays.
FEATURE_SAMPLES = 20000
#: Half-angle of the ray cone used for walls and gaps [rad]; each sample takes the longest of its rays,
#: so that a convex edge or a concave corner does not pass for a thin wall or a narrow gap.
CONE_HALF_ANGLE = math.radians(25)


class BadInput(RjcadError):
    """The input is not a usable mesh (unreadable, empty, not a mesh, or not matching its manifest)."""


@dataclass
class CheckResult:
    """One check: ``passed`` is True, False, or None when skipped (``detail`` says why)."""

    name: str
    passed: bool | None
    value: Any = None
    limit: Any = None
    where: list[float] | None = None
    detail: str = ""


@dataclass
class Report:
    checks: list[CheckResult] = field(default_factory=list)
    body_names: list[str] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        """True when no check failed (skipped checks do not fail, nor pass silently: they say so)."""
        return all(c.passed is not False for c in self.checks)

    def to_dict(self) -> dict:
        return {"passed": self.passed, "bodies": self.body_names, "checks": [asdict(c) for c in self.checks]}

    def get(self, name: str) -> CheckResult:
        return next(c for c in self.checks if c.name == name)


# --------------------------------------------------------------------------
# loading
# --------------------------------------------------------------------------


def load_bodies(path: str | Path) -> tuple[list[trimesh.Trimesh], list[str] | None]:
    """Bodies of an STL (connected components) or a 3MF (named objects), and the names if any."""
    p = Path(path)
    if not p.exists():
        raise BadInput(f"{p}: file not found")
    if p.suffix.lower() not in (".stl", ".3mf"):
        raise BadInput(f"{p}: not an .stl or .3mf file")
    try:
        loaded = trimesh.load(str(p), process=True, force=None)
    except Exception as e:  # trimesh raises many kinds on garbage
        raise BadInput(f"{p}: not a readable mesh ({type(e).__name__}: {e})".splitlines()[0]) from None
    if isinstance(loaded, trimesh.Scene):
        names, bodies = [], []
        for name, geom in loaded.geometry.items():
            if isinstance(geom, trimesh.Trimesh) and len(geom.faces):
                names.append(str(name))
                bodies.append(geom)
        if not bodies:
            raise BadInput(f"{p}: the file holds no triangles")
        return bodies, names
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise BadInput(f"{p}: the file holds no triangles")
    parts = loaded.split(only_watertight=False)
    parts = sorted(parts, key=lambda b: -abs(b.volume))
    return list(parts), None


def to_manifold(mesh: trimesh.Trimesh) -> m3.Manifold:
    """manifold3d solid from a merged-vertex mesh (double precision)."""
    return m3.Manifold(m3.Mesh64(vert_properties=np.ascontiguousarray(mesh.vertices, dtype=np.float64),
                                 tri_verts=np.ascontiguousarray(mesh.faces, dtype=np.uint64)))


def _pt(x) -> list[float]:
    return [round(float(v), 3) for v in np.asarray(x).ravel()[:3]]


def name_bodies(bodies: list[trimesh.Trimesh], names: list[str] | None, manifest: dict | None) -> list[str]:
    """Names for the bodies: the 3MF's, or the manifest's matched by volume (within 2 %)."""
    if manifest is None or "bodies" not in manifest:
        return names or [f"body{i + 1}" for i in range(len(bodies))]
    wanted = [(b["name"], float(b["volume_mm3"])) for b in manifest["bodies"]]
    if names is not None:
        missing = [n for n, _ in wanted if n not in names]
        if missing:
            raise BadInput(f"manifest names body '{missing[0]}' that the mesh lacks (it has: {', '.join(names)})")
        return names
    out = [f"body{i + 1}" for i in range(len(bodies))]
    free = set(range(len(bodies)))
    for name, vol in wanted:
        best = min(free, key=lambda i: abs(abs(bodies[i].volume) - vol), default=None)
        if best is None or abs(abs(bodies[best].volume) - vol) > 0.02 * vol:
            raise BadInput(f"manifest names body '{name}' ({vol:.0f} mm³) that the mesh lacks: "
                           f"no body within 2 % of that volume")
        out[best] = name
        free.discard(best)
    return out


# --------------------------------------------------------------------------
# checks
# --------------------------------------------------------------------------


def _edge_defects(mesh: trimesh.Trimesh) -> tuple[np.ndarray, bool]:
    """Undirected edges not shared by exactly two faces, and whether the winding is consistent.

    Fast path: closed and consistently wound ⟺ every directed edge a→b occurs once and b→a occurs
    too, i.e. sorted(a·N + b) == sorted(b·N + a) with no repeats.
    """
    F = np.asarray(mesh.faces, dtype=np.int64)
    n = len(mesh.vertices)
    a, b = F.ravel(), np.roll(F, -1, axis=1).ravel()
    fwd, rev = np.sort(a * n + b), np.sort(b * n + a)
    if np.array_equal(fwd, rev) and not np.any(fwd[1:] == fwd[:-1]):
        return np.empty((0, 2), dtype=np.int64), True
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    keys, counts = np.unique(lo * n + hi, return_counts=True)
    bad = keys[counts != 2]
    return np.stack([bad // n, bad % n], axis=1), bool(mesh.is_winding_consistent)


def check_watertight(bodies, names) -> CheckResult:
    """Every edge shared by exactly two faces, winding consistent."""
    bad = []
    for b, n in zip(bodies, names):
        open_edges, wound = _edge_defects(b)
        if len(open_edges) or not wound:
            where = b.vertices[open_edges[0]].mean(axis=0) if len(open_edges) else b.centroid
            bad.append((n, len(open_edges), wound, where))
    if not bad:
        return CheckResult("watertight", True, 0, 0, None, f"{len(bodies)} bodies closed and consistently wound")
    n, k, wind, where = bad[0]
    return CheckResult("watertight", False, k, 0, _pt(where),
                       f"{n}: {k} edges not shared by exactly two faces"
                       + ("" if wind else ", winding inconsistent") + (f"; {len(bad)} bodies affected" if len(bad) > 1 else ""))


def check_manifold(bodies, names) -> tuple[CheckResult, list[m3.Manifold]]:
    """manifold3d accepts every body (status NoError) with a positive volume; genus reported."""
    mans, bad, genus = [], [], []
    for b, n in zip(bodies, names):
        man = to_manifold(b)
        mans.append(man)
        st = man.status()
        if st != m3.Error.NoError or man.is_empty() or man.volume() <= 0:
            bad.append((n, st.name, b.centroid))
        else:
            genus.append(f"{n} genus {man.genus()}")
    if bad:
        n, st, where = bad[0]
        return CheckResult("manifold", False, st, "NoError", _pt(where), f"{n}: manifold3d says {st}"), mans
    return CheckResult("manifold", True, "NoError", "NoError", None, "; ".join(genus)), mans


def check_bodies(bodies, expected: int | None) -> CheckResult:
    if expected is None:
        return CheckResult("bodies", None, len(bodies), None, None, "skipped: no manifest and no --bodies")
    return CheckResult("bodies", len(bodies) == expected, len(bodies), expected, None,
                       f"{len(bodies)} separate bodies, {expected} expected")


def _closest_points(a: trimesh.Trimesh, b: trimesh.Trimesh) -> np.ndarray:
    """Midpoint of the nearest vertex pair of two meshes (a location for a gap)."""
    from scipy.spatial import cKDTree

    d, i = cKDTree(b.vertices).query(a.vertices)
    k = int(np.argmin(d))
    return (a.vertices[k] + b.vertices[i[k]]) / 2


def check_clearance(bodies, names, mans, clearance: float, allowance: float) -> CheckResult:
    """Every pair of bodies: min gap ≥ clearance − allowance and no overlap."""
    limit = clearance - allowance
    if len(bodies) < 2:
        return CheckResult("clearance", None, None, limit, None, "skipped: a single body")
    search = clearance + 1.0
    tight = (math.inf, None)
    overlap = None
    for i in range(len(mans)):
        for j in range(i + 1, len(mans)):
            lo = np.maximum(bodies[i].bounds[0], bodies[j].bounds[0])
            hi = np.minimum(bodies[i].bounds[1], bodies[j].bounds[1])
            if np.any(lo - hi > search):
                continue  # boxes farther apart than the search length
            inter = mans[i] ^ mans[j]
            vol = inter.volume()
            if vol > 1e-6 and (overlap is None or vol > overlap[0]):
                verts = np.asarray(inter.to_mesh().vert_properties)[:, :3]
                overlap = (vol, (i, j), verts.mean(axis=0))
            gap = mans[i].min_gap(mans[j], search)
            if gap < tight[0]:
                tight = (gap, (i, j))
    if overlap is not None:
        vol, (i, j), where = overlap
        return CheckResult("clearance", False, 0.0, limit, _pt(where),
                           f"{names[i]} and {names[j]} overlap by {vol:.3f} mm³")
    if tight[1] is None:
        return CheckResult("clearance", True, search, limit, None, f"no two bodies within {search:.2f} mm")
    gap, (i, j) = tight
    where = _closest_points(bodies[i], bodies[j])
    return CheckResult("clearance", bool(gap >= limit), round(float(gap), 4), round(limit, 4), _pt(where),
                       f"tightest pair {names[i]}–{names[j]}: {gap:.3f} mm (allowance {allowance} mm for tessellation)")


def manifest_joints(manifest: dict, names: list[str]) -> list[dict]:
    """Joints of a finger manifest, or the single joint of a joint manifest."""
    if "joints" in manifest:
        return list(manifest["joints"])
    if "moving_body" in manifest:
        child = manifest["moving_body"]
        parent = next(b["name"] for b in manifest["bodies"] if b["name"] != child)
        return [{"parent": parent, "child": child, "axis_point_mm": manifest["axis_point_mm"],
                 "axis_dir": manifest["axis_dir"], "rotation_deg": manifest["rotation_deg"]}]
    return []


def subtree(joints: list[dict], k: int) -> set[str]:
    """Bodies that move with joint k: its child and everything hanging from it."""
    moving = {joints[k]["child"]}
    changed = True
    while changed:
        changed = False
        for j in joints:
            if j["parent"] in moving and j["child"] not in moving:
                moving.add(j["child"])
                changed = True
    return moving


def _rot(point, direction, angle) -> np.ndarray:
    return trimesh.transformations.rotation_matrix(angle, direction, point)[:3, :4]


def check_motion(bodies, names, mans, manifest: dict | None, clearance: float, printer: Printer) -> CheckResult:
    """Each joint's subtree swept over 0..rotation about its axis never intersects the other bodies.

    Step Δθ = 0.5·min(clearance, min wall)/lever, the lever being the farthest moving vertex from the
    axis: no point moves more than half the clearance (or half the thinnest wall) between two poses,
    so a collision cannot hide between them.
    """
    if manifest is None:
        return CheckResult("motion", None, None, None, None, "skipped: no manifest")
    joints = manifest_joints(manifest, names)
    if not joints:
        return CheckResult("motion", None, None, None, None, "skipped: the manifest has no joints")
    worst = (0.0, None, None, None)  # (overlap volume, joint, angle, posed subtree)
    min_gap = (math.inf, None, None)
    first = None  # (joint, angle) of the first pose that intersects
    details = []
    for k, j in enumerate(joints):
        moving = subtree(joints, k)
        mi = [i for i, n in enumerate(names) if n in moving]
        si = [i for i, n in enumerate(names) if n not in moving]
        if not mi or not si:
            raise BadInput(f"manifest joint {k + 1} names bodies the mesh lacks: {j['parent']}, {j['child']}")
        mov = m3.Manifold.batch_boolean([mans[i] for i in mi], m3.OpType.Add)
        sta = m3.Manifold.batch_boolean([mans[i] for i in si], m3.OpType.Add)
        pt = np.asarray(j["axis_point_mm"], dtype=float)
        d = np.asarray(j["axis_dir"], dtype=float)
        d = d / np.linalg.norm(d)
        verts = np.vstack([bodies[i].vertices for i in mi])
        rel = verts - pt
        lever = float(np.max(np.linalg.norm(rel - np.outer(rel @ d, d), axis=1)))
        rot = math.radians(float(j["rotation_deg"]))
        step = 0.5 * min(clearance, printer.min_wall_mm) / lever
        n = max(1, math.ceil(rot / step))
        angles = np.linspace(0.0, rot, n + 1)
        every = max(1, len(angles) // 24)
        for a_i, a in enumerate(angles):
            posed = mov.transform(_rot(pt, d, float(a)))
            vol = (sta ^ posed).volume()
            if vol > worst[0]:
                worst = (vol, k, float(a), posed)
            if vol > 0 and first is None:
                first = (k, float(a))
            if a_i % every == 0 or a_i == len(angles) - 1:
                g = sta.min_gap(posed, clearance + 1.0)
                if g < min_gap[0]:
                    min_gap = (g, k, float(a))
        details.append(f"joint {k + 1}: {len(angles)} poses, step {math.degrees(step):.3f}° (lever {lever:.1f} mm)")
    if worst[1] is not None:
        vol, k, a, posed = worst
        inter = m3.Manifold.batch_boolean(
            [mans[i] for i, nm in enumerate(names) if nm not in subtree(joints, k)], m3.OpType.Add) ^ posed
        where = np.asarray(inter.to_mesh().vert_properties)[:, :3].mean(axis=0)
        return CheckResult("motion", False, round(math.degrees(a), 2), 0.0, _pt(where),
                           f"joint {k + 1} collides, worst at {math.degrees(a):.1f}° ({vol:.3f} mm³ overlap), "
                           f"first contact at joint {first[0] + 1}, {math.degrees(first[1]):.1f}°; "
                           + "; ".join(details))
    g, k, a = min_gap
    return CheckResult("motion", True, round(float(g), 4), 0.0, None,
                       f"free over the whole range; smallest sampled gap {g:.3f} mm at joint {k + 1}, "
                       f"{math.degrees(a):.1f}°; " + "; ".join(details))


def _cone(n: np.ndarray, half_angle: float) -> list[np.ndarray]:
    """The normals, and four directions tilted from them by ``half_angle``."""
    ref = np.where(np.abs(n[:, [0]]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
    u = np.cross(n, ref)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(n, u)
    c, s = math.cos(half_angle), math.sin(half_angle)
    return [n] + [c * n + s * w for w in (u, -u, v, -v)]


def _ray_lengths(mesh: trimesh.Trimesh, origins: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """Distance to the first hit of each ray on ``mesh`` (inf when none)."""
    out = np.full(len(origins), np.inf)
    locs, idx, _ = mesh.ray.intersects_location(origins, dirs, multiple_hits=False)
    if len(idx):
        out[idx] = np.linalg.norm(locs - origins[idx], axis=1)
    return out


def feature_sizes(mesh: trimesh.Trimesh, samples: int = FEATURE_SAMPLES, seed: int = 0):
    """Surface samples with their wall thickness (inward) and in-body gap (outward), by ray cones [mm].

    Each sample takes the longest ray of a 25° cone around its normal, projected on the normal: across
    a flat wall or gap every ray gives the true size; at an edge or a corner some ray escapes.
    """
    pts, fi = trimesh.sample.sample_surface(mesh, samples, seed=seed)
    n = mesh.face_normals[fi]
    eps = 1e-4
    wall = np.zeros(len(pts))
    gap = np.zeros(len(pts))
    for k, d in enumerate(_cone(n, CONE_HALF_ANGLE)):
        # project each ray on the normal: across a flat wall every ray of the cone then gives its thickness
        c = 1.0 if k == 0 else math.cos(CONE_HALF_ANGLE)
        wall = np.maximum(wall, c * _ray_lengths(mesh, pts - n * eps, -d))
        gap = np.maximum(gap, c * _ray_lengths(mesh, pts + n * eps, d))
    return pts, n, wall, gap


def check_min_feature(bodies, names, printer: Printer, allowance: float) -> CheckResult:
    """Thinnest wall ≥ the printer's minimum wall; gaps inside a body ≥ its minimum gap (Z gaps: vertical)."""
    worst_wall = (math.inf, None, None)
    worst_gap = (math.inf, None, None, None)  # (ratio-to-limit margin, value, where, name/limit)
    for b, name in zip(bodies, names):
        pts, n, wall, gap = feature_sizes(b)
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
    detail = (f"thinnest wall {worst_wall[0]:.3f} mm in {worst_wall[2]} (min wall {printer.min_wall_mm} mm); ")
    if worst_gap[1] is not None:
        name, lim, vert = worst_gap[3]
        detail += (f"narrowest gap inside a body {worst_gap[1]:.3f} mm in {name} "
                   f"({'vertical' if vert else 'horizontal'}, min {lim} mm); ")
    detail += f"{FEATURE_SAMPLES} ray-cone samples per body, allowance {allowance} mm"
    if not wall_ok:
        return CheckResult("min_feature", False, round(worst_wall[0], 4), printer.min_wall_mm,
                           _pt(worst_wall[1]), "wall too thin: " + detail)
    if not gap_ok:
        return CheckResult("min_feature", False, round(worst_gap[1], 4), worst_gap[3][1], _pt(worst_gap[2]),
                           "gap inside a body too narrow: " + detail)
    return CheckResult("min_feature", True, round(worst_wall[0], 4), printer.min_wall_mm, None, detail)


def check_bed(bodies, printer: Printer) -> CheckResult:
    """The mesh fits the build volume (X and Y may swap) and lies on z = 0, or can be moved there."""
    lo = np.min([b.bounds[0] for b in bodies], axis=0)
    hi = np.max([b.bounds[1] for b in bodies], axis=0)
    ext = hi - lo
    vol = np.asarray(printer.build_volume_mm)
    fits = (ext[2] <= vol[2]) and ((ext[0] <= vol[0] and ext[1] <= vol[1]) or (ext[1] <= vol[0] and ext[0] <= vol[1]))
    on_bed = abs(lo[2]) < 1e-3
    detail = (f"extent {ext[0]:.1f} × {ext[1]:.1f} × {ext[2]:.1f} mm in a {vol[0]:g} × {vol[1]:g} × {vol[2]:g} mm "
              f"volume; " + ("lies on z = 0" if on_bed else f"bottom at z = {lo[2]:.3f}: move it by {-lo[2]:.3f} mm"))
    return CheckResult("bed", bool(fits), _pt(ext), [float(v) for v in vol], None if fits else _pt(lo), detail)


def prusa_config(printer: Printer) -> str:
    """A PrusaSlicer print/printer config for the profile (nozzle, layers, bed, height)."""
    x, y, z = printer.build_volume_mm
    return "\n".join([
        f"nozzle_diameter = {printer.nozzle_mm}",
        f"layer_height = {printer.layer_height_mm}",
        f"first_layer_height = {printer.layer_height_mm}",
        f"extrusion_width = {printer.extrusion_width_mm}",
        f"bed_shape = 0x0,{x:g}x0,{x:g}x{y:g},0x{y:g}",
        f"max_print_height = {z:g}",
        "support_material = 0",
        "",
    ])


def check_slicer(bodies, printer: Printer, slicer: str | None, timeout: float = 600) -> CheckResult:
    """PrusaSlicer slices the mesh to G-code without error (skipped, with the reason, when absent)."""
    if slicer is None:
        return CheckResult("slicer", None, None, None, None, "skipped: no --slicer given")
    if slicer != "prusa":
        raise BadInput(f"--slicer {slicer!r}: the only slicer supported is 'prusa'")
    exe = shutil.which("prusa-slicer")
    if exe is None:
        return CheckResult("slicer", None, None, None, None,
                           "skipped: prusa-slicer is not installed (Debian: apt-get install prusa-slicer)")
    with tempfile.TemporaryDirectory() as d:
        stl, ini, gcode = Path(d, "mesh.stl"), Path(d, "printer.ini"), Path(d, "mesh.gcode")
        trimesh.util.concatenate(bodies).export(str(stl))
        ini.write_text(prusa_config(printer))
        try:
            r = subprocess.run([exe, "--export-gcode", "--load", str(ini), "--output", str(gcode), str(stl)],
                               capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return CheckResult("slicer", False, "timeout", f"{timeout:g} s", None, "PrusaSlicer did not finish")
        size = gcode.stat().st_size if gcode.exists() else 0
        errors = [ln for ln in (r.stderr + r.stdout).splitlines()
                  if "error" in ln.lower() and "[trace]" not in ln or "what():" in ln]
        ok = r.returncode == 0 and size > 0 and not errors
        msg = errors[-1].strip() if errors else f"exit code {r.returncode}"
        return CheckResult("slicer", ok, size, "> 0 bytes of G-code", None,
                           f"PrusaSlicer wrote {size} bytes of G-code" if ok else f"PrusaSlicer failed: {msg}")


# --------------------------------------------------------------------------
# all together
# --------------------------------------------------------------------------


def run_checks(source, manifest: dict | str | Path | None = None, clearance: float | None = None,
               printer: str | None = None, slicer: str | None = None, allowance: float = DEFAULT_ALLOWANCE,
               bodies: int | None = None) -> Report:
    """Run every check on a mesh file, or on a list of trimesh bodies; returns the report."""
    if isinstance(manifest, (str, Path)):
        try:
            manifest = json.loads(Path(manifest).read_text())
        except FileNotFoundError:
            raise BadInput(f"{manifest}: manifest not found") from None
        except json.JSONDecodeError as e:
            raise BadInput(f"{manifest}: manifest is not JSON ({e})") from None
    if isinstance(source, (str, Path)):
        meshes, names = load_bodies(source)
    else:
        meshes, names = list(source), None
        if isinstance(source, dict):
            names, meshes = list(source.keys()), list(source.values())
        if not meshes or any(len(m.faces) == 0 for m in meshes):
            raise BadInput("empty mesh")
    how = (("body names from the 3MF's objects" if isinstance(source, (str, Path)) else "body names given")
           if names is not None else
           "STL bodies matched to the manifest's bodies by volume (within 2 %)" if manifest and "bodies" in manifest
           else "bodies numbered")
    names = name_bodies(meshes, names, manifest)
    if clearance is None:
        clearance = float(manifest.get("clearance_mm", 0.25)) if manifest else 0.25
    prn = get_printer(printer or (manifest or {}).get("printer") or "generic-0.4")
    expected = bodies if bodies is not None else (len(manifest["bodies"]) if manifest and "bodies" in manifest else None)
    rep = Report(body_names=names)
    rep.checks.append(check_watertight(meshes, names))
    man_check, mans = check_manifold(meshes, names)
    rep.checks.append(man_check)
    rep.checks.append(check_bodies(meshes, expected))
    rep.checks[-1].detail += f"; {how}: " + ", ".join(
        f"{n} {abs(m.volume):.0f} mm³" for n, m in zip(names, meshes))
    solid_ok = rep.checks[0].passed and man_check.passed
    if solid_ok:
        rep.checks.append(check_clearance(meshes, names, mans, clearance, allowance))
        rep.checks.append(check_motion(meshes, names, mans, manifest, clearance, prn))
    else:
        for n in ("clearance", "motion"):
            rep.checks.append(CheckResult(n, None, None, None, None, "skipped: needs watertight, manifold bodies"))
    rep.checks.append(check_min_feature(meshes, names, prn, allowance) if rep.checks[0].passed else
                      CheckResult("min_feature", None, None, None, None, "skipped: needs watertight bodies"))
    rep.checks.append(check_bed(meshes, prn))
    rep.checks.append(check_slicer(meshes, prn, slicer))
    return rep


def format_table(rep: Report) -> str:
    """The report as a readable table."""
    rows = [("check", "result", "value", "limit", "where [mm]")]
    for c in rep.checks:
        res = "skipped" if c.passed is None else ("pass" if c.passed else "FAIL")
        rows.append((c.name, res, "" if c.value is None else str(c.value), "" if c.limit is None else str(c.limit),
                     "" if c.where is None else str(c.where)))
    w = [max(len(r[i]) for r in rows) for i in range(5)]
    lines = ["  ".join(r[i].ljust(w[i]) for i in range(5)).rstrip() for r in rows]
    lines.insert(1, "  ".join("-" * x for x in w))
    lines.append("")
    lines += [f"{c.name}: {c.detail}" for c in rep.checks if c.detail]
    lines.append("")
    lines.append("PASSED" if rep.passed else "FAILED")
    return "\n".join(lines)
