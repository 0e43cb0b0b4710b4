"""Whole-finger campaigns: a TOML naming the finger and its experiments, one CSV per experiment (format pinned
by issue #18).

    finger = "finger.json"          # a finger manifest (rjcad finger) or a finger template (.toml), relative
    [[experiment]]
    file = "pull_1.csv"
    drive = "finger"
    orientation = "horizontal-palm-up"   # optional: gravity (see ORIENTATIONS), or a number [deg]

CSV columns: ``t_s``, ``tendon_mm``, optional ``tendon_force_n``, and ``theta1_deg`` … ``thetaN_deg`` (proximal
first, N the finger's joints). Inside: rad, mm, N, s. Every input problem is one line naming the file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from rjcad import DEG
from rjcad.errors import ParameterError, RjcadError, quote
from rjcad.identify.data import MIN_SAMPLES, _check_time, _data_path, _read_csv
from rjcad.io.untrusted import confined
from rjcad.physics.finger_model import FingerModel
from rjcad.physics.finger_sources import model_from_manifest, model_from_template

#: Gravity in the finger's plane, as a unit vector in the finger's frame (x along the straight finger towards
#: the tip, y towards the palm: the side the finger flexes to). A number is the angle of gravity from x
#: towards y [deg].
ORIENTATIONS = {
    "horizontal-palm-down": (0.0, 1.0),  # gravity helps flexion
    "horizontal-palm-up": (0.0, -1.0),  # gravity opposes flexion
    "vertical-tip-down": (1.0, 0.0),
    "vertical-tip-up": (-1.0, 0.0),
}
TOP_KEYS = ("finger", "experiment")
EXPERIMENT_KEYS = ("file", "drive", "orientation")
MIN_STROKE_MM = 0.5


@dataclass(frozen=True, eq=False)
class FingerExperiment:
    """One pull/release record: t [s], tendon [mm], tension [N] or None, theta (samples, N) [rad]."""

    file: str
    path: Path
    t: np.ndarray
    tendon: np.ndarray
    tension: np.ndarray | None
    theta: np.ndarray
    gravity: tuple[float, float] | None
    orientation: str | float | None
    rows: int
    dropped: dict = field(default_factory=dict)
    drive: str = "finger"

    @property
    def name(self) -> str:
        return Path(self.file).stem

    @property
    def quantities(self) -> list[str]:
        n = self.theta.shape[1]
        return [f"theta{i + 1}_deg" for i in range(n)] + (["tendon_force_n"] if self.tension is not None else [])


@dataclass(frozen=True)
class FingerDesign:
    """The design model the simulation assumes (frictionless, inextensible tendon, no gravity) and its source."""

    model: FingerModel
    source: str

    def as_json(self) -> dict:
        m = self.model
        return {
            "finger": self.source,
            "joints": m.n,
            "stiffness_nmm_per_rad": list(m.stiffness),
            "preload_deg": [p / DEG for p in m.preload],
            "rotation_deg": [r / DEG for r in m.rotation],
            "tendon_moment_arm_mm": list(m.moment_arm),
            "link_length_mm": list(m.link_length),
            "link_mass_g": list(m.link_mass),
        }


@dataclass(frozen=True)
class FingerCampaign:
    path: Path
    design: FingerDesign
    experiments: tuple[FingerExperiment, ...]
    notes: tuple[str, ...] = ()
    kind: str = "finger"

    @property
    def has_tension(self) -> bool:
        return any(e.tension is not None for e in self.experiments)


def load_finger_campaign(path: Path, doc: dict, allow_outside: bool = False) -> FingerCampaign:
    """Validate a parsed finger campaign ``doc`` (from ``path``) and read its finger and CSV files (a campaign of
    ``[[endpoint]]`` tables is read by rjcad.identify.finger.endpoint)."""
    for key in doc:
        if key not in TOP_KEYS:
            raise RjcadError(
                f'{path}: unknown key or table {quote(key)}; a finger campaign has finger = "PATH" '
                "and [[experiment]] (records) or [[endpoint]] tables"
            )
    design = finger_design(path, doc.get("finger"), allow_outside)
    tables = doc.get("experiment")
    if not isinstance(tables, list) or not tables or not all(isinstance(t, dict) for t in tables):
        raise RjcadError(f"{path}: no [[experiment]] tables; add one per CSV file")
    exps, notes, names = [], [], set()
    for i, table in enumerate(tables, start=1):
        exp, note = _experiment(path, i, table, design.model.n, allow_outside)
        if exp.name in names:
            raise RjcadError(f"{path}: experiment {i}: name {quote(exp.name)} is used twice; file names must differ")
        names.add(exp.name)
        exps.append(exp)
        if note:
            notes.append(note)
    return FingerCampaign(path, design, tuple(exps), tuple(notes))


def finger_design(path: Path, value, allow_outside: bool) -> FingerDesign:
    """The design of a campaign's ``finger`` key (relative to the campaign file ``path``)."""
    if value is None:
        raise RjcadError(
            f"{path}: missing key 'finger' (a finger manifest .json or template .toml, relative to the campaign file)"
        )
    if not isinstance(value, str) or not value.strip():
        raise ParameterError(f"{path}: finger", value, "must name a finger manifest (.json) or template (.toml)")
    where = f"{path}: finger"
    file = confined(path.parent, value, where, allow_outside)
    if not file.is_file():
        raise RjcadError(f"{where}: file {quote(value)} not found (looked for {quote(str(file), 120, repr_=False)})")
    return design_from_file(file, value, where)


def design_from_file(file: Path, label: str, where: str) -> FingerDesign:
    """The design model of a finger manifest (.json) or template (.toml) ``file``."""
    if file.suffix.lower() == ".json":
        from rjcad.io.manifest import Manifest

        model = model_from_manifest(Manifest.read(file))
    elif file.suffix.lower() == ".toml":
        from rjcad.io.untrusted import read_toml
        from rjcad.physics.finger_sources import check_template_keys

        data = read_toml(file)
        check_template_keys(data, file.name)
        model = model_from_template(data)
    else:
        raise RjcadError(f"{where}: {quote(label)} must be a finger manifest (.json) or template (.toml)")
    return as_designed(model, label)


def as_designed(model: FingerModel, label: str) -> FingerDesign:
    """The design model: as designed, frictionless, no capstan, inextensible tendon, no gravity."""
    model = replace(
        model, mu_t=0.0, friction=(), gamma=(), gamma_pos=(), gamma_neg=(), gravity=None, tendon_stiffness=math.inf
    )
    return FingerDesign(model, label)


def _orientation(where: str, value) -> tuple[float, float] | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise ParameterError(f"{where}orientation", value, "must be a name or an angle [deg]")
    if isinstance(value, str):
        if value not in ORIENTATIONS:
            raise ParameterError(
                f"{where}orientation",
                value,
                f"unknown; known: {', '.join(ORIENTATIONS)}, "
                "or the angle of gravity from the finger's axis "
                "towards the palm [deg]",
            )
        return ORIENTATIONS[value]
    if not math.isfinite(value):
        raise ParameterError(f"{where}orientation", value, "must be finite")
    a = math.radians(value)
    return (math.cos(a), math.sin(a))


def _experiment(toml: Path, i: int, table: dict, n: int, allow_outside: bool):
    where = f"{toml}: experiment {i}: "
    for key in table:
        if key not in EXPERIMENT_KEYS:
            raise RjcadError(f"{where}unknown key {quote(key)}; known: {', '.join(EXPERIMENT_KEYS)}")
    file = table.get("file")
    if not isinstance(file, str) or not file.strip():
        raise RjcadError(f"{where}missing key 'file' (the CSV file, relative to the campaign file)")
    if table.get("drive") != "finger":
        raise RjcadError(
            f"{where}drive must be 'finger' in a finger campaign (got {quote(table.get('drive'))}); "
            "joint and finger experiments cannot be mixed"
        )
    gravity = _orientation(where, table.get("orientation"))
    csv = _data_path(toml, i, file, allow_outside)
    header = _header(csv, file)
    thetas = [f"theta{k + 1}_deg" for k in range(n)]
    extra = sorted(h for h in header if h.startswith("theta") and h.endswith("_deg") and h not in thetas)
    if extra:
        raise RjcadError(
            f"{file}: column {quote(extra[0])} but the finger has {n} joint{'s' * (n > 1)} (theta1_deg … theta{n}_deg)"
        )
    with_force = "tendon_force_n" in header
    columns = ("t_s", "tendon_mm", *thetas) + (("tendon_force_n",) if with_force else ())
    values, lines, rows, dropped, note = _read_csv(file, csv, columns, "finger")
    t, tendon = values[0], values[1]
    theta = np.column_stack(values[2 : 2 + n]) * DEG if len(t) else np.zeros((0, n))
    if len(t) < MIN_SAMPLES:
        raise RjcadError(f"{file}: only {len(t)} usable samples; at least {MIN_SAMPLES} are needed")
    _check_time(file, t, lines)
    if np.ptp(tendon) < MIN_STROKE_MM:
        raise RjcadError(
            f"{file}: tendon_mm moves only {np.ptp(tendon):.3g} mm; a pull needs at least {MIN_STROKE_MM:g} mm"
        )
    tension = values[-1] if with_force else None
    return FingerExperiment(
        file, csv, t, tendon, tension, theta, gravity, table.get("orientation"), rows, dropped
    ), note


def _header(path: Path, file: str) -> list[str]:
    from rjcad.io.untrusted import read_text

    for line in read_text(path, "CSV", file).split("\n"):
        s = line.strip()
        if s and not s.startswith("#"):
            return [c.strip() for c in s.split(",")]
    return []
