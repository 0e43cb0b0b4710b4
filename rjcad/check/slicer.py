"""The slicer check: PrusaSlicer turns the mesh into G-code without an error (when installed)."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

import trimesh

from rjcad.check.report import BadInput, CheckResult
from rjcad.materials import Printer


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
