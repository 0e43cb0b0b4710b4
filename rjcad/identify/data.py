"""Campaign loading and validation: a TOML file plus CSV files (format pinned by issue #7).

Inside, angles are rad, torques N·mm, forces N, time s. Every problem with the input is one
RjcadError line naming the file and the problem.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.ndimage import median_filter

from rjcad import DEG
from rjcad.errors import ParameterError, RjcadError, quote
from rjcad.identify.signal import noise_sigma
from rjcad.io.config import check_key
from rjcad.io.untrusted import confined, read_text, read_toml
from rjcad.physics.joint import Setup
from rjcad.validate import in_range

if TYPE_CHECKING:
    from rjcad.physics.bearing_table import FrictionTable


@dataclass(frozen=True)
class Design:
    """The design the simulation assumes: joint stiffness [N·mm/rad], preload [rad], pulley radius [mm]."""

    stiffness: float
    preload: float
    pulley_radius: float
    #: the joint's manifest as the campaign names it ([design] joint), and its bearing friction per unit μ
    joint: str | None = None
    bearing: FrictionTable | None = field(default=None, compare=False, repr=False)

    def as_json(self) -> dict:
        out: dict[str, Any] = {
            "stiffness_nmm_per_rad": self.stiffness,
            "preload_deg": self.preload / DEG,
            "pulley_radius_mm": self.pulley_radius,
        }
        if self.joint is not None:
            out["joint"] = self.joint
        return out


@dataclass(frozen=True, eq=False)
class Experiment:
    """One experiment: its setup and its samples (t [s], theta [rad] from rest, y the measured quantity)."""

    file: str  # as written in the campaign TOML
    path: Path
    drive: str  # "bar" | "tendon"
    normal_load: float  # N
    routed: bool
    pulley_radius: float  # mm
    t: np.ndarray
    theta: np.ndarray
    y: np.ndarray
    rows: int  # data rows in the file
    dropped: dict = field(default_factory=dict)  # reason -> rows dropped
    bearing: FrictionTable | None = None  # the joint's bearing friction per unit μ (a tendon drive loads it)

    @property
    def quantity(self) -> str:
        return "torque_nmm" if self.drive == "bar" else "tendon_force_n"

    @property
    def setup(self) -> Setup:
        return Setup(drive=self.drive, normal_load=self.normal_load, routed=self.routed, bearing=self.bearing)

    @property
    def name(self) -> str:
        return Path(self.file).stem


@dataclass(frozen=True)
class Campaign:
    path: Path
    design: Design
    experiments: tuple[Experiment, ...]
    notes: tuple[str, ...] = ()  # e.g. "exp1.csv: dropped 3 of 3000 rows (2 non-numeric, 1 NaN)"


DESIGN_KEYS = {"stiffness_nmm_per_rad": (int, float), "preload_deg": (int, float), "pulley_radius_mm": (int, float)}
#: Optional [design] keys: the joint's manifest (rjcad joint's JSON), for the bearing friction of its geometry.
DESIGN_OPTIONAL = {"joint": str}
EXPERIMENT_KEYS = {
    "file": str,
    "drive": str,
    "normal_load_n": (int, float),
    "routed": bool,
    "pulley_radius_mm": (int, float),
}
COLUMNS = {"bar": "torque_nmm", "tendon": "tendon_force_n"}
MIN_SAMPLES = 50
MAX_BAD_FRACTION = 0.02
MIN_RANGE_DEG = 1.0
REASONS = ("non-numeric", "NaN", "infinite", "empty")  # why a row is dropped, in report order
#: Angles in radians in a theta_deg column: the campaign's |θ| stays below this "deg" (π rad: a joint's range
#: under 180°) and its load rises with the angle, within the moves (apparent_stiffness), at least
#: RADIAN_SLOPE_RATIO times faster than the design's stiffness explains: 57 times for radians (49 to 107 on
#: `rjcad bench` campaigns of every effect, 90–180°), at most 2.2 times in degrees (6.4 for a 1.5° motion
#: under 0.1° of noise).
RADIAN_MAX_DEG = 3.2
RADIAN_SLOPE_RATIO = 15.0


def load_campaign(path, allow_outside: bool = False, doc: dict | None = None) -> Campaign:
    """Read and validate a campaign TOML and its CSV files (paths relative to the TOML, inside its folder
    unless ``allow_outside``; symlinks followed). Files are read through rjcad.io.untrusted.

    Raises RjcadError (ParameterError for TOML values) with one line naming the file and the problem.
    """
    path = Path(path)
    raw = read_toml(path) if doc is None else doc
    if is_finger_campaign(raw):
        raise RjcadError(
            f"{path}: a whole-finger campaign (finger = ..., drive = 'finger'): read it with "
            "rjcad.identify.campaign.load_campaign"
        )
    doc = _read_toml(path, raw)
    where = f"{path}: "
    design = _design(doc, where)
    if design.joint is not None:
        design = replace(design, bearing=_bearing_of(path, design.joint, allow_outside))
    specs = _experiment_specs(doc, path, design, allow_outside)
    experiments, notes = [], []
    for spec in specs:
        exp, note = _load_experiment(spec)
        experiments.append(exp)
        if note:
            notes.append(note)
        table = spec.get("bearing")
        if table is not None and not math.isclose(exp.pulley_radius, table.arm, rel_tol=0.01):
            notes.append(
                f"{exp.file}: pulley radius {exp.pulley_radius:g} mm, the joint's tendon arm {table.arm:g} mm: its "
                "bearing's load is taken where the joint's own tendon leaves its band"
            )
    _check_units(design, experiments)
    return Campaign(path=path, design=design, experiments=tuple(experiments), notes=tuple(notes))


# ---- the TOML file ----


def is_finger_campaign(doc: dict) -> bool:
    """A whole-finger campaign: a top-level ``finger`` key, or an experiment with ``drive = "finger"``."""
    exps = doc.get("experiment")
    return "finger" in doc or (
        isinstance(exps, list) and any(isinstance(e, dict) and e.get("drive") == "finger" for e in exps)
    )


def _read_toml(path: Path, doc: dict | None = None) -> dict:
    """The parsed TOML document (rjcad.io.untrusted); RjcadError if it is missing, unreadable or not TOML."""
    doc = read_toml(path) if doc is None else doc
    for key in doc:
        if key not in ("design", "experiment"):
            raise RjcadError(f"{path}: unknown key or table {quote(key)}; known: [design], [[experiment]]")
    return doc


def _check(where: str, key: str, value, allowed: dict):
    """check_key, plus booleans (which check_key refuses as numbers)."""
    if allowed.get(key) is bool:
        if not isinstance(value, bool):
            raise ParameterError(f"{where}{key}", value, "must be true or false")
        return value
    return check_key(where, key, value, allowed)


def _number(where: str, key: str, value, positive: bool = False, nonnegative: bool = False) -> float:
    """A finite float from a checked TOML number; ParameterError if out of range."""
    name = f"{where}{key}"
    value = in_range(name, value, limit="must be finite")
    if positive or nonnegative:
        in_range(name, value, 0.0, lo_open=positive)
    return value


def _design(doc: dict, where: str) -> Design:
    """The [design] table: stiffness [N·mm/rad], preload [deg → rad], pulley radius [mm]."""
    known = ", ".join(DESIGN_KEYS)
    table = doc.get("design")
    if table is None:
        raise RjcadError(f"{where}missing [design] table (keys: {known})")
    if not isinstance(table, dict):
        raise RjcadError(f"{where}design must be a table: [design] with keys {known}")
    w = f"{where}[design] "
    for key, value in table.items():
        _check(w, key, value, DESIGN_KEYS | DESIGN_OPTIONAL)
    for key in DESIGN_KEYS:
        if key not in table:
            raise RjcadError(f"{where}[design]: missing key '{key}' (needed: {known})")
    joint = table.get("joint")
    if joint is not None and not joint.strip():
        raise ParameterError(f"{w}joint", joint, "must name the joint's manifest (rjcad joint's JSON)")
    return Design(
        stiffness=_number(w, "stiffness_nmm_per_rad", table["stiffness_nmm_per_rad"], positive=True),
        preload=_number(w, "preload_deg", table["preload_deg"]) * DEG,
        pulley_radius=_number(w, "pulley_radius_mm", table["pulley_radius_mm"], positive=True),
        joint=joint,
    )


def _bearing_of(toml: Path, file: str, allow_outside: bool) -> FrictionTable:
    """The bearing friction table of the joint whose manifest ``file`` the campaign names (relative to it, inside
    its folder unless ``allow_outside``): the joint rebuilt from the manifest (rjcad.design.rebuild)."""
    from rjcad.design.rebuild import joint_params
    from rjcad.io.manifest import Manifest
    from rjcad.physics.bearing_table import friction_table

    label = f"{toml}: [design] joint"
    path = _campaign_file(toml, file, label, allow_outside)
    return friction_table(joint_params(Manifest.read(path), label))


def _data_path(toml: Path, i: int, file: str, allow_outside: bool) -> Path:
    """Experiment ``i``'s CSV file (:func:`_campaign_file`)."""
    return _campaign_file(toml, file, f"{toml}: experiment {i}", allow_outside)


def _campaign_file(toml: Path, file: str, label: str, allow_outside: bool) -> Path:
    """A file the campaign names, relative to the campaign file and inside its folder (unless ``allow_outside``);
    RjcadError under ``label`` if it is outside, missing or not a file."""
    path = confined(toml.parent, file, label, allow_outside)
    try:
        if path.is_file():
            return path
        problem = "is not a file" if path.exists() else "not found"
    except (OSError, ValueError) as e:
        problem = f"cannot be opened ({getattr(e, 'strerror', None) or e})"
    raise RjcadError(f"{label}: file {quote(file)} {problem} (looked for {quote(str(path), 120, repr_=False)})")


def _experiment_specs(doc: dict, toml: Path, design: Design, allow_outside: bool = False) -> list[dict]:
    """The [[experiment]] tables, checked, with defaults filled in and the CSV path resolved (inside the
    campaign's folder unless ``allow_outside``)."""
    tables = doc.get("experiment")
    if tables is None or tables == []:
        raise RjcadError(f"{toml}: no [[experiment]] tables; add one per CSV file")
    if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
        raise RjcadError(f"{toml}: experiments must be an array of tables: one [[experiment]] per CSV file")
    specs: list[dict[str, Any]] = []
    names: dict[str, tuple[int, str]] = {}
    for i, table in enumerate(tables, start=1):
        where = f"{toml}: experiment {i}: "
        if "file" not in table:
            raise RjcadError(f"{where}missing key 'file' (the CSV file, relative to the campaign file)")
        file = _check(where, "file", table["file"], EXPERIMENT_KEYS)
        if not file.strip():
            raise ParameterError(f"{where}file", file, "must name a CSV file")
        where = f"{toml}: experiment {i} ({quote(file, repr_=False)}): "
        for key, value in table.items():
            _check(where, key, value, EXPERIMENT_KEYS)
        if "drive" not in table:
            raise RjcadError(f"{where}missing key 'drive' ('bar' or 'tendon')")
        drive = table["drive"]
        if drive not in COLUMNS:
            raise ParameterError(f"{where}drive", drive, "must be 'bar' or 'tendon'")
        routed = table.get("routed", False)
        if routed and drive == "bar":
            raise RjcadError(f"{where}routed = true is invalid with drive = 'bar': routing applies to a tendon drive")
        normal_load = _number(where, "normal_load_n", table.get("normal_load_n", 0.0), nonnegative=True)
        radius = table.get("pulley_radius_mm")
        radius = design.pulley_radius if radius is None else _number(where, "pulley_radius_mm", radius, positive=True)
        csv_path = _data_path(toml, i, file, allow_outside)
        name = Path(file).stem
        if name in names:
            j, other = names[name]
            raise RjcadError(
                f"{where}name {quote(name)} is already used by experiment {j} ({quote(other)}); "
                "experiment file names must differ"
            )
        names[name] = (i, file)
        bearing = design.bearing if drive == "tendon" else None
        specs.append(
            dict(
                file=file,
                path=csv_path,
                drive=drive,
                normal_load=normal_load,
                routed=routed,
                pulley_radius=radius,
                bearing=bearing,
            )
        )
    return specs


# ---- the CSV files ----


def _load_experiment(spec: dict) -> tuple[Experiment, str | None]:
    """One Experiment from its CSV file, and a note on dropped rows (or None)."""
    file, drive = spec["file"], spec["drive"]
    columns = ("t_s", "theta_deg", COLUMNS[drive])
    values, lines, rows, dropped, note = _read_csv(file, spec["path"], columns, drive)
    t, theta_deg, y = values
    if len(t) < MIN_SAMPLES:
        detail = " (no data rows)" if rows == 0 else ""
        raise RjcadError(f"{file}: only {len(t)} usable samples{detail}; at least {MIN_SAMPLES} are needed")
    _check_time(file, t, lines)
    _check_motion(file, theta_deg)
    exp = Experiment(
        file=file,
        path=spec["path"],
        drive=drive,
        normal_load=spec["normal_load"],
        routed=spec["routed"],
        pulley_radius=spec["pulley_radius"],
        t=t,
        theta=theta_deg * DEG,
        y=y,
        rows=rows,
        dropped=dropped,
        bearing=spec.get("bearing"),
    )
    return exp, note


def _read_csv(file: str, path: Path, columns: tuple[str, ...], drive: str):
    """The columns as float arrays with bad rows dropped.

    Returns (arrays, file line number of each kept row (1-based), data rows, {reason: count}, note or None).
    """
    lines = read_text(path, "CSV", file).split("\n")
    idx = [i for i, line in enumerate(lines) if (s := line.lstrip()) and s[0] != "#"]
    if not idx:
        raise RjcadError(f"{file}: only 0 usable samples (the file is empty); at least {MIN_SAMPLES} are needed")
    cols = _column_indices(file, lines[idx[0]], columns, drive)
    data = [lines[i] for i in idx[1:]]
    line_no = np.asarray(idx[1:], dtype=np.int64) + 1
    rows = len(data)
    if rows == 0:
        return [np.empty(0) for _ in cols], line_no, 0, {}, None
    try:  # fast path: every cell parses as a float
        table = np.loadtxt(data, delimiter=",", usecols=cols, comments=None, dtype=float, ndmin=2)
        values, codes = [table[:, k] for k in range(len(cols))], None
    except ValueError:
        values, codes = _parse_slowly(data, cols, len(lines[idx[0]].split(",")))
    bad, reason = _bad_rows(values, codes)
    n_bad = int(bad.sum())
    if n_bad == 0:
        return [np.ascontiguousarray(v) for v in values], line_no, rows, {}, None
    if n_bad > MAX_BAD_FRACTION * rows:
        first = int(np.flatnonzero(bad)[0])
        k = int(reason[first] // len(REASONS))
        why = REASONS[int(reason[first] % len(REASONS))]
        cell = _cell(data[first], cols[k])
        what = {
            "non-numeric": f"non-numeric value {_show(cell)}",
            "NaN": "NaN",
            "infinite": f"infinite value {_show(cell)}",
            "empty": "empty cell",
        }[why]
        raise RjcadError(
            f"{file}: column {columns[k]}: {what} at line {line_no[first]} "
            f"({n_bad} of {rows} rows bad; at most {MAX_BAD_FRACTION:.0%} are dropped)"
        )
    counts = np.bincount((reason[bad] % len(REASONS)).astype(int), minlength=len(REASONS))
    dropped = {r: int(c) for r, c in zip(REASONS, counts) if c}
    note = f"{file}: dropped {n_bad} of {rows} rows (" + ", ".join(f"{c} {r}" for r, c in dropped.items()) + ")"
    keep = ~bad
    return [np.ascontiguousarray(v[keep]) for v in values], line_no[keep], rows, dropped, note


def _column_indices(file: str, header: str, columns: tuple[str, ...], drive: str) -> list[int]:
    """Index of each wanted column in the header (names stripped of whitespace)."""
    names = [n.strip() for n in header.split(",")]
    for name in columns:
        if names.count(name) > 1:
            where = ", ".join(str(i + 1) for i, n in enumerate(names) if n == name)
            raise RjcadError(f"{file}: column '{name}' appears more than once (columns {where})")
    missing = [c for c in columns if c not in names]
    if missing:
        label = "column" if len(missing) == 1 else "columns"
        drive_note = f" (drive '{drive}')" if COLUMNS.get(drive) in missing else ""
        hint = ""
        if len(names) == 1 and (";" in header or "\t" in header):
            hint = " (the file must be comma-separated)"
        elif COLUMNS.get(drive) in missing:
            other = next(d for d in COLUMNS if d != drive)
            if COLUMNS[other] in names:
                hint = f" (the file has '{COLUMNS[other]}': is the drive '{other}'?)"
        raise RjcadError(
            f"{file}: missing {label} {', '.join(repr(c) for c in missing)}{drive_note}; {_found(names)}{hint}"
        )
    return [names.index(c) for c in columns]


#: What a column name in a CSV header looks like (``t_s``, ``force (N)``, ``frame``); a header otherwise is
#: not listed in an error: the file may not be a data file at all (``/etc/passwd``).
_COLUMN_NAME = re.compile(r"[A-Za-z_][\w .()\[\]%/·-]{0,39}")


def _found(names: list[str], most: int = 12) -> str:
    """'columns found: a, b, c' if the first line is a header of column names, else a sentence without its text."""
    if len(names) < 2 or not all(_COLUMN_NAME.fullmatch(n) for n in names):
        return "its first line is not a header of comma-separated column names"
    more = f", … ({len(names)} columns)" if len(names) > most else ""
    return f"columns found: {', '.join(names[:most])}{more}"


def _parse_slowly(data: list[str], cols: list[int], width: int) -> tuple[list[np.ndarray], list[np.ndarray | None]]:
    """Parse cell by cell where needed: NaN for an empty or non-numeric cell, with a code per cell
    (0 ok, 1 non-numeric, 2 empty); the code array is None for a column whose cells all parse.

    Rows are padded or cut to the header's ``width`` fields, then split in one go.
    """
    rows = [
        line if line.count(",") == width - 1 else ",".join((line.split(",") + [""] * width)[:width]) for line in data
    ]
    joined = ",".join(rows)
    flat = joined.split(",")
    underscores = "_" in joined  # float() takes '1_0'; the fast path does not
    values: list[np.ndarray] = []
    codes: list[np.ndarray | None] = []
    for j in cols:
        cells = flat[j::width]
        if not underscores:
            try:
                values.append(np.array(cells, dtype=float))
                codes.append(None)
                continue
            except ValueError:
                pass
        v, code = _parse_cells(cells)
        values.append(v)
        codes.append(code)
    return values, codes


def _parse_cells(cells: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Floats of ``cells`` (NaN where bad) and codes: 0 ok, 1 non-numeric, 2 empty."""
    out = []
    code = np.zeros(len(cells), dtype=np.int8)
    for i, c in enumerate(cells):
        try:
            if "_" in c:
                raise ValueError
            out.append(float(c))
        except ValueError:
            out.append(math.nan)
            code[i] = 1 if c.strip() else 2
    return np.array(out, dtype=float), code


def _bad_rows(values: list[np.ndarray], codes) -> tuple[np.ndarray, np.ndarray]:
    """Bad-row mask and, per row, the first bad cell as column·len(REASONS) + reason index."""
    n = len(values[0])
    bad = np.zeros(n, dtype=bool)
    reason = np.zeros(n, dtype=np.int64)
    for k in reversed(range(len(values))):  # the first bad column wins
        v = values[k]
        r = np.where(np.isnan(v), 1, np.where(np.isinf(v), 2, -1))
        c = codes[k] if codes is not None else None
        if c is not None:
            r = np.where(c == 1, 0, np.where(c == 2, 3, r))
        here = r >= 0
        reason = np.where(here, k * len(REASONS) + r, reason)
        bad |= here
    return bad, reason


def _cell(line: str, j: int) -> str:
    parts = line.split(",")
    return parts[j].strip() if j < len(parts) else ""


def _show(cell: str, limit: int = 30) -> str:
    return repr(cell if len(cell) <= limit else cell[:limit] + "...")


# ---- plausibility of the samples ----


def _check_time(file: str, t: np.ndarray, lines: np.ndarray) -> None:
    """t_s must increase strictly, row after row."""
    step = np.diff(t)
    if len(step) and not np.all(step > 0):
        i = int(np.flatnonzero(step <= 0)[0]) + 1
        raise RjcadError(f"{file}: t_s is not increasing at line {lines[i]} (t = {t[i]:.6g} s after {t[i - 1]:.6g} s)")


def _reversal_threshold(theta_deg: np.ndarray, smooth: np.ndarray) -> float:
    """Hysteresis a [deg] a reversal must exceed: max(0.5°, 10% of the smoothed range, 5·σ_noise).

    σ_noise from the raw angles' second differences (signal.noise_sigma: they cancel steady motion).
    """
    return max(0.5, 0.1 * float(np.ptp(smooth)), 5 * noise_sigma(theta_deg))


def _smooth_angle(theta_deg: np.ndarray, size: int = 7) -> np.ndarray:
    """Running median of the angle over ``size`` samples (removes camera outliers and some noise)."""
    return median_filter(np.asarray(theta_deg, dtype=float), size=size, mode="mirror")


def _has_reversal(theta: np.ndarray, a: float) -> bool:
    """True if theta rises by ≥ a and then falls by ≥ a, or falls by ≥ a and then rises by ≥ a.

    A peak at j: θ_j − min(θ_0..θ_j) ≥ a and θ_j − min(θ_j..θ_n) ≥ a (valleys likewise).
    """
    theta = np.asarray(theta, dtype=float)
    if len(theta) < 3:
        return False
    low_before = np.minimum.accumulate(theta)
    low_after = np.minimum.accumulate(theta[::-1])[::-1]
    high_before = np.maximum.accumulate(theta)
    high_after = np.maximum.accumulate(theta[::-1])[::-1]
    peak = (theta - low_before >= a) & (theta - low_after >= a)
    valley = (high_before - theta >= a) & (high_after - theta >= a)
    return bool(peak.any() or valley.any())


def _check_motion(file: str, theta_deg: np.ndarray) -> None:
    """The joint must move at least 1° and reverse at least once (on the median-filtered angle)."""
    smooth = _smooth_angle(theta_deg)
    lo, hi = float(smooth.min()), float(smooth.max())
    if hi - lo < MIN_RANGE_DEG:
        raise RjcadError(
            f"{file}: the joint angle spans only {hi - lo:.2f} deg ({lo:.1f}–{hi:.1f} deg); "
            f"it must move at least {MIN_RANGE_DEG:g} deg"
        )
    a = _reversal_threshold(theta_deg, smooth)
    if not _has_reversal(smooth, a):
        raise RjcadError(
            f"{file}: no reversal: the joint must move forward and back (range {lo:.1f}–{hi:.1f} deg, "
            f"monotonic; a reversal needs a return of at least {a:.1f} deg)"
        )


# ---- units ----


def apparent_stiffness(exp: Experiment) -> float:
    """Slope of the joint torque over the angle as read, within the moves [N·mm/rad].

    Torque τ = y (bar) or y·pulley radius (tendon). A move is a run of samples whose (median-filtered) angle
    changes by more than a quarter of its largest step, in one sense; the slope is pooled over the moves,
    each about its own means, so that friction (a constant offset along a move) drops out.
    """
    tau = exp.y if exp.drive == "bar" else exp.y * exp.pulley_radius
    theta = _smooth_angle(exp.theta)
    step = np.diff(theta, prepend=theta[0])
    sense = np.where(np.abs(step) > 0.25 * np.max(np.abs(step)), np.sign(step), 0.0)
    run = np.cumsum(np.diff(sense, prepend=0.0) != 0)  # a new id at every change of sense
    moving = sense != 0
    if not moving.any():
        return 0.0
    ids, th, ta = run[moving], theta[moving], tau[moving]
    counts = np.bincount(ids)
    mean = lambda v: (np.bincount(ids, v) / np.maximum(counts, 1))[ids]  # noqa: E731
    dth, dta = th - mean(th), ta - mean(ta)
    den = float(dth @ dth)
    return float(dth @ dta) / den if den > 0 else 0.0


def _check_units(design: Design, experiments: list[Experiment]) -> None:
    """Refuse a campaign whose theta_deg columns hold radians (RADIAN_MAX_DEG, RADIAN_SLOPE_RATIO); one line
    naming the first such file and its column."""
    top = max(float(np.max(np.abs(e.theta))) for e in experiments) / DEG
    if top > RADIAN_MAX_DEG:
        return
    for e in experiments:
        ratio = abs(apparent_stiffness(e)) / design.stiffness
        if ratio >= RADIAN_SLOPE_RATIO:
            raise RjcadError(
                f"{e.file}: column theta_deg looks like radians: every angle of the campaign is within "
                f"±{top:.2f}, and {e.quantity} rises {ratio:.0f} times faster with it than the design's "
                f"{design.stiffness:g} N·mm/rad explain: are the angles in radians? theta_deg must be in "
                "degrees"
            )
