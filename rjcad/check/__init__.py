"""Print-readiness checks of a mesh, the way a printer needs it.

Checks, each with a measured value, a limit and, on failure, a location in mm:
``watertight``, ``manifold``, ``bodies``, ``clearance``, ``motion`` (needs a
manifest), ``min_feature``, ``bed``, ``overhang`` (prints without support?) and ``slicer``
(PrusaSlicer with supports off, on request).

A body is a connected component of the mesh (STL) or a named part (3MF; else a named object).
STL bodies are matched to a manifest's bodies by volume.

Modules: ``load`` (mesh file, manifest, body names), ``mesh_checks`` (the bodies at rest),
``motion`` (the joints' sweep), ``copies`` (the simplified copies gaps and sweeps are measured on, so that
their cost follows the shape, not the triangle count), ``feature`` (walls, gaps, bed), ``overhang`` (downward surfaces),
``slicer`` (PrusaSlicer, supports off: started in the background before the mesh checks, so that they run while
it slices; its G-code kept per process in ``GCODE_CACHE``) with ``gcode`` (G-code reader) and ``toolpath`` (its
analysis), ``report``.
"""

from __future__ import annotations

from pathlib import Path

from rjcad.check.copies import simplified
from rjcad.check.feature import CONE_HALF_ANGLE, FEATURE_SAMPLES, check_bed, check_min_feature, feature_sizes
from rjcad.check.load import body_volume, load_bodies, load_manifest, name_bodies
from rjcad.check.mesh_checks import check_bodies, check_clearance, check_manifold, check_watertight
from rjcad.check.motion import check_motion, motion_joints, subtree
from rjcad.check.overhang import check_overhang
from rjcad.check.report import BadInput, CheckResult, Report, format_table, skipped
from rjcad.check.slicer import GCODE_CACHE, Slicing, check_slicer, finish_slicer, prusa_config, start_slicer
from rjcad.io.manifest import Manifest
from rjcad.materials import Printer, printer_of
from rjcad.progress import Progress, report

__all__ = [
    "CONE_HALF_ANGLE",
    "DEFAULT_ALLOWANCE",
    "FEATURE_SAMPLES",
    "GCODE_CACHE",
    "BadInput",
    "CheckResult",
    "Report",
    "check_bed",
    "check_bodies",
    "check_clearance",
    "check_manifold",
    "check_min_feature",
    "check_motion",
    "check_overhang",
    "check_slicer",
    "check_watertight",
    "feature_sizes",
    "finish_slicer",
    "format_table",
    "load_bodies",
    "load_manifest",
    "motion_joints",
    "name_bodies",
    "prusa_config",
    "required_clearance",
    "run_checks",
    "start_slicer",
    "subtree",
]

#: Tessellation allowance on measured gaps and walls [mm].
DEFAULT_ALLOWANCE = 0.02


def _bodies_of(source) -> tuple[list, list[str] | None, str | None]:
    """Meshes and names (if known) of a mesh file, a list or a {name: mesh} dict; and how they are named."""
    if isinstance(source, (str, Path)):
        meshes, names = load_bodies(source)
        return meshes, names, "body names from the 3MF's parts (else its objects)"
    meshes, names = list(source), None
    if isinstance(source, dict):
        names, meshes = list(source.keys()), list(source.values())
    if not meshes or any(len(m.faces) == 0 for m in meshes):
        raise BadInput("empty mesh")
    return meshes, names, "body names given"


def required_clearance(man: Manifest, prn: Printer) -> float | None:
    """The gap ``rjcad check`` requires of a manifest's bodies when none is given: the manifest's clearance,
    raised to the printer's minimum gap (a gap the printer cannot print fails the check) [mm]; None without one."""
    return max(float(man.clearance_mm), prn.min_gap_mm) if man.clearance_mm is not None else None


def run_checks(
    source,
    manifest: Manifest | dict | str | Path | None = None,
    clearance: float | None = None,
    printer: str | None = None,
    slicer: str | None = None,
    allowance: float = DEFAULT_ALLOWANCE,
    bodies: int | None = None,
    progress: Progress | None = None,
) -> Report:
    """Run every check on a mesh file, or on a list of trimesh bodies; returns the report. ``progress`` (a
    ``rjcad.progress.Progress``) is told each check by name and the slicer's phases."""
    man = load_manifest(manifest)
    report(progress, "reading the mesh")
    meshes, names, how = _bodies_of(source)
    listed = man is not None and man.bodies is not None
    if names is None:
        how = "STL bodies matched to the manifest's bodies by volume (within 2 %)" if listed else "bodies numbered"
    names = name_bodies(meshes, names, man)
    if clearance is None:
        clearance = float(man.clearance_mm) if man is not None and man.clearance_mm is not None else 0.25
    prn = printer_of(printer, man)
    expected = (
        bodies if bodies is not None else (len(man.bodies) if man is not None and man.bodies is not None else None)
    )
    started = start_slicer(meshes, names, prn, slicer)  # PrusaSlicer slices in the background meanwhile
    try:
        rep = _mesh_checks(meshes, names, man, how, expected, clearance, prn, allowance, progress)
        rep.checks.append(finish_slicer(started, meshes, names, prn, allowance, progress))
    finally:
        if isinstance(started, Slicing):
            started.close()
    return rep


#: The checks in the report's order (the progress line counts them).
CHECKS = ("watertight", "manifold", "bodies", "clearance", "motion", "min_feature", "bed", "overhang", "slicer")


def _mesh_checks(meshes, names, man, how, expected, clearance, prn, allowance, progress=None) -> Report:
    """Every check but the slicer's, in the report's order."""

    def step(name: str) -> None:
        report(progress, name, CHECKS.index(name), len(CHECKS))

    rep = Report(body_names=names)
    step("watertight")
    rep.checks.append(check_watertight(meshes, names))
    step("manifold")
    man_check, mans = check_manifold(meshes, names)
    rep.checks.append(man_check)
    step("bodies")
    rep.checks.append(check_bodies(meshes, expected))
    rep.checks[-1].detail += f"; {how}: " + ", ".join(
        f"{n} {abs(body_volume(m)):.0f} mm³" for n, m in zip(names, meshes)
    )
    if rep.checks[0].passed and man_check.passed:
        step("clearance")
        copies = simplified(mans)  # shared by clearance and motion
        rep.checks.append(check_clearance(meshes, names, mans, clearance, allowance, copies))
        step("motion")
        rep.checks.append(check_motion(meshes, names, mans, man, clearance, prn, copies))
    else:
        rep.checks += [skipped(n, "skipped: needs watertight, manifold bodies") for n in ("clearance", "motion")]
    step("min_feature")
    rep.checks.append(
        check_min_feature(meshes, names, prn, allowance)
        if rep.checks[0].passed
        else skipped("min_feature", "skipped: needs watertight bodies")
    )
    step("bed")
    rep.checks.append(check_bed(meshes, prn))
    step("overhang")
    rep.checks.append(check_overhang(meshes, names, prn))
    return rep
