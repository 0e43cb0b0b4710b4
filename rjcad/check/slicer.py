"""The slicer check: PrusaSlicer slices the bodies with supports OFF; the G-code must print without them.

Each body is sliced as its own labelled object (``gcode_label_objects``), all merged on one bed with
their modelled positions kept (``--merge --dont-arrange``, the assembly centred on the bed), with a
desktop profile built from the printer (nozzle, layer, road width) and: supports off, thick bridges
off, 100 % infill (each layer's roads then cover the body's whole section, so "over the previous
layer" does not depend on an infill pattern), no skirt or brim. The G-code is read back
(``rjcad.check.gcode``) and analysed layer by layer (``rjcad.check.toolpath``): it fails when any
road rests on neither the bed nor its body's previous layer (bridges ≤ 10 mm anchored at both ends
and 45° overhangs excepted), or when two bodies' roads come closer than the printer's minimum gap.
A body that does not reach the bed fails before slicing: a slicer would drop it onto the bed.
On a printer with soluble support, roads on nothing are reported but do not fail (gaps still do).
"""

from __future__ import annotations

import hashlib
import re
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from rjcad.check.gcode import parse_gcode
from rjcad.check.overhang import BED_TOL_MM
from rjcad.check.report import BadInput, CheckResult, point
from rjcad.check.toolpath import Analysis, analyse
from rjcad.materials import Printer
from rjcad.progress import Progress, report

#: How far a body's roads may sit from its modelled outline before we say the slicer moved it [mm].
POSITION_TOL_MM = 1.0


def prusa_config(printer: Printer) -> str:
    """PrusaSlicer settings for the check: the printer's nozzle, layers and roads; supports off (see module)."""
    x, y, z = printer.build_volume_mm
    w = printer.extrusion_width_mm
    return "\n".join(
        [
            f"nozzle_diameter = {printer.nozzle_mm}",
            f"layer_height = {printer.layer_height_mm}",
            f"first_layer_height = {printer.first_layer_mm}",
            f"extrusion_width = {w}",
            f"first_layer_extrusion_width = {w}",
            f"bed_shape = 0x0,{x:g}x0,{x:g}x{y:g},0x{y:g}",
            f"max_print_height = {z:g}",
            "support_material = 0",
            "thick_bridges = 0",
            "fill_density = 100%",
            "fill_pattern = rectilinear",
            "skirts = 0",
            "brim_width = 0",
            "gcode_label_objects = 1",
            "seam_position = rear",  # the default seam placer costs seconds and changes no road's support
            "resolution = 0.01",  # contour simplification [mm]: within the meshes' own tessellation error
            "",
        ]
    )


#: G-code of this process's slicings: sha256 of what PrusaSlicer is given (its path, the settings file, each
#: body's STL bytes in order) → (G-code, seconds the slicing took). The same bodies sliced again in one run
#: (two checks, two tests) are read from here; ``GCODE_CACHE.clear()`` slices anew.
GCODE_CACHE: dict[str, tuple[str, float]] = {}


def slice_key(exe: str, config: str, stls: list[bytes]) -> str:
    """The cache key of a slicing: sha256 of the slicer's path, its settings and the bodies' STL bytes."""
    h = hashlib.sha256(f"{exe}\n{config}\n".encode())
    for s in stls:
        h.update(len(s).to_bytes(8, "little") + s)
    return h.hexdigest()


class Slicing:
    """One PrusaSlicer run on the bodies (each its own object, moved by ``offset``), started in the background so
    that the mesh checks run while it slices; or its G-code from GCODE_CACHE."""

    def __init__(self, exe: str, bodies, printer: Printer, offset: np.ndarray, timeout: float):
        self.dir = tempfile.TemporaryDirectory()
        d, config, stls, files = self.dir.name, prusa_config(printer), [], []
        for k, b in enumerate(bodies):
            m = b.copy()
            m.apply_translation(offset)
            stls.append(m.export(file_type="stl"))
            files.append(str(Path(d, f"body{k}.stl")))
            Path(files[-1]).write_bytes(stls[-1])
        self.key, self.timeout, self.gcode = slice_key(exe, config, stls), timeout, Path(d, "check.gcode")
        self.offset, self.proc, self.cached = offset, None, self.key in GCODE_CACHE
        self.t0 = time.perf_counter()
        if self.cached:
            return
        ini = Path(d, "check.ini")
        ini.write_text(config)
        self.log = open(Path(d, "log.txt"), "w+")  # noqa: SIM115  (open while the slicer runs; wait() closes it)
        self.proc = subprocess.Popen(
            [
                exe,
                "--export-gcode",
                "--merge",
                "--dont-arrange",
                "--load",
                str(ini),
                "--output",
                str(self.gcode),
                *files,
            ],
            stdout=self.log,
            stderr=subprocess.STDOUT,
            text=True,
        )

    def wait(self) -> tuple[str | None, str, float]:
        """(G-code text or None, error message, seconds the slicing took)."""
        try:
            if self.proc is None:
                return (*GCODE_CACHE[self.key][:1], "", GCODE_CACHE[self.key][1])
            try:
                code = self.proc.wait(timeout=max(self.timeout - (time.perf_counter() - self.t0), 0.0))
            except subprocess.TimeoutExpired:
                return None, f"PrusaSlicer did not finish within {self.timeout:g} s", self.timeout
            secs = time.perf_counter() - self.t0
            self.log.seek(0)
            errors = [
                ln
                for ln in self.log.read().splitlines()
                if ("error" in ln.lower() and "[trace]" not in ln) or "what():" in ln
            ]
            if code != 0 or not self.gcode.exists() or self.gcode.stat().st_size == 0 or errors:
                return None, "PrusaSlicer failed: " + (errors[-1].strip() if errors else f"exit code {code}"), secs
            GCODE_CACHE[self.key] = (self.gcode.read_text(), secs)
            return GCODE_CACHE[self.key][0], "", secs
        finally:
            self.close()

    def close(self) -> None:
        """Stop the slicer if it still runs, and remove its files."""
        if self.proc is not None:
            if self.proc.poll() is None:
                self.proc.kill()
                self.proc.wait()
            self.log.close()
            self.proc = None
        self.dir.cleanup()


def _moved(tp, bodies, names, offset) -> str | None:
    """A body with no roads, or whose roads' XY extent is more than POSITION_TOL_MM off its modelled one."""
    for k, (b, name) in enumerate(zip(bodies, names)):
        label = f"body{k}.stl"
        sel = tp.obj == tp.objects.index(label) if label in tp.objects else np.zeros(len(tp.obj), dtype=bool)
        if not sel.any():
            return f"PrusaSlicer printed nothing of {name}"
        xs, ys = np.r_[tp.x0[sel], tp.x1[sel]] - offset[0], np.r_[tp.y0[sel], tp.y1[sel]] - offset[1]
        off = np.abs(np.array([xs.min(), ys.min(), xs.max(), ys.max()]) - np.r_[b.bounds[0][:2], b.bounds[1][:2]])
        if off.max() > POSITION_TOL_MM:
            return (
                f"PrusaSlicer moved {name}: its roads' extent is {off.max():.2f} mm off its modelled one "
                "(the check needs the bodies where they were modelled)"
            )
    return None


def _describe(a: Analysis, offset: np.ndarray) -> tuple[str, list[float] | None]:
    """The failures in words, and the worst place in model coordinates."""

    def back(p):
        return point(np.asarray(p) - offset)

    parts, where = [], None
    if a.failures:
        first = min(a.failures, key=lambda r: (r.layer, -r.length))
        worst = max(a.failures, key=lambda r: r.length)
        where = back(worst.where)
        n_layers = len({r.layer for r in a.failures})
        parts.append(
            f"{len(a.failures)} stretches of filament on nothing in {n_layers} layers; first failing layer "
            f"{first.layer} (z = {first.z:.2f}): {first.body}, {first.length:.1f} mm anchored at "
            f"{first.anchors} end(s), at {back(first.where)}, under it {first.under}; worst (where): "
            f"{worst.body} in layer {worst.layer}, {worst.length:.1f} mm anchored at {worst.anchors} end(s), "
            f"under it {worst.under}"
        )
    return "; ".join(parts), where


def check_slicer(
    bodies, names, printer: Printer, slicer: str | None, allowance: float = 0.02, timeout: float = 600
) -> CheckResult:
    """Slice with supports off and read the G-code back (skipped, with the reason, without PrusaSlicer)."""
    return finish_slicer(start_slicer(bodies, names, printer, slicer, timeout), bodies, names, printer, allowance)


def start_slicer(bodies, names, printer: Printer, slicer: str | None, timeout: float = 600):
    """The slicer check's verdict if it needs no slicing (skipped, mid-air, too big), else the Slicing started."""
    if slicer is None:
        return CheckResult("slicer", None, None, None, None, "skipped: no --slicer given")
    if slicer != "prusa":
        raise BadInput(f"--slicer {slicer!r}: the only slicer supported is 'prusa'")
    exe = shutil.which("prusa-slicer")
    if exe is None:
        return CheckResult(
            "slicer",
            None,
            None,
            None,
            None,
            "skipped: prusa-slicer is not installed (Debian: apt-get install prusa-slicer)",
        )
    lo = np.min([b.bounds[0] for b in bodies], axis=0)
    hi = np.max([b.bounds[1] for b in bodies], axis=0)
    for b, name in zip(bodies, names):
        if b.bounds[0][2] - lo[2] > BED_TOL_MM:
            return CheckResult(
                "slicer",
                False,
                "mid-air",
                "on the bed",
                point(b.vertices[np.argmin(b.vertices[:, 2])]),
                f"{name} starts at z = {b.bounds[0][2] - lo[2]:.2f} mm above the bed: it would start "
                "in mid-air (a slicer drops each object onto the bed, so no slice can show it)",
            )
    bed = np.asarray(printer.build_volume_mm[:2])
    ext = hi - lo
    if np.any(ext > np.asarray(printer.build_volume_mm)):
        turn = (
            " (turned 90° it would: turn it)"
            if ext[1] <= bed[0] and ext[0] <= bed[1] and ext[2] <= printer.build_volume_mm[2]
            else ""
        )
        return CheckResult(
            "slicer",
            False,
            "does not fit",
            [float(v) for v in printer.build_volume_mm],
            None,
            f"the bodies ({ext[0]:.1f} × {ext[1]:.1f} × {ext[2]:.1f} mm) do not fit the "
            f"{printer.key} build volume as placed{turn}; not sliced",
        )
    offset = np.r_[bed / 2 - (lo[:2] + hi[:2]) / 2, -lo[2]]
    return Slicing(exe, bodies, printer, offset, timeout)


def finish_slicer(
    started, bodies, names, printer: Printer, allowance: float = 0.02, progress: Progress | None = None
) -> CheckResult:
    """The slicer check: wait for the Slicing (``start_slicer``), read its G-code back and judge it. ``progress``
    (a ``rjcad.progress.Progress``) is told each phase: slicing, reading the G-code, analysing the layers."""
    if isinstance(started, CheckResult):
        return started
    offset = started.offset
    report(progress, "slicer: PrusaSlicer slicing", 8, 9)
    gcode, error, t_slice = started.wait()
    if gcode is None:
        return CheckResult("slicer", False, "no G-code", "G-code", None, error)
    t0 = time.perf_counter()
    report(progress, "slicer: reading the G-code", 8, 9)
    tp = parse_gcode(gcode)
    version = re.search(r"generated by (PrusaSlicer \S+)", gcode[:2000])
    moved = _moved(tp, bodies, names, offset)
    if moved:
        return CheckResult("slicer", False, "moved", "modelled positions", None, moved)
    by_obj = [names[int(o[4:-4])] for o in tp.objects]
    report(progress, "slicer: analysing the layers", 8, 9)
    a = analyse(tp, by_obj, printer.min_gap_mm)
    t_read = time.perf_counter() - t0
    text, where = _describe(a, offset)
    gap_ok = a.min_gap >= printer.min_gap_mm - allowance
    pair = sorted(a.gap_pair or (), key=names.index)
    gap = (
        f"closest bodies {'–'.join(pair)}: {a.min_gap:.3f} mm in layer {a.gap_layer} at "
        f"{point(np.asarray(a.gap_where) - offset)} (minimum {printer.min_gap_mm} mm, allowance {allowance} mm)"
        if a.gap_pair
        else "no two bodies' roads within reach of each other"
    )
    if not gap_ok and where is None:
        where = point(np.asarray(a.gap_where) - offset)
    how = (
        f"{version.group(1) if version else 'PrusaSlicer'}, supports off, {printer.nozzle_mm} mm nozzle, "
        f"{printer.layer_height_mm} mm layers, thick bridges off, 100 % infill; {a.layers} layers; "
        f"sliced in {t_slice:.1f} s{' (G-code from this run’s cache)' if started.cached else ''}, "
        f"G-code read in {t_read:.1f} s"
    )
    bridges = f"{a.bridges} bridges excused (longest {a.longest_bridge:.1f} mm)"
    if a.failures and printer.soluble_support:
        text = f"not failing: {printer.key} prints soluble support under these; " + text
    passed = (not a.failures or printer.soluble_support) and gap_ok
    fail_layers = len({r.layer for r in a.failures})
    return CheckResult(
        "slicer",
        passed,
        fail_layers,
        0,
        where,
        "; ".join(x for x in (text, gap, bridges, print_estimate(gcode), how) if x),
    )


def print_estimate(gcode: str) -> str:
    """PrusaSlicer's own estimates from the G-code's closing comments: print time and filament, at the check's
    settings (100 % infill) (empty if absent)."""
    tail = gcode[-20000:]
    t = re.search(r"estimated printing time \(normal mode\) = ([^\n]+)", tail)
    mm = re.search(r"filament used \[mm\] = ([\d.]+)", tail)
    cm3 = re.search(r"filament used \[cm3\] = ([\d.]+)", tail)
    parts = []
    if t:
        parts.append(f"estimated print time {t.group(1).strip()}")
    if mm:
        parts.append(
            f"filament {float(mm.group(1)) / 1000:.2f} m" + (f" ({float(cm3.group(1)):.1f} cm³)" if cm3 else "")
        )
    return ", ".join(parts) + (" at 100 % infill" if parts else "")
