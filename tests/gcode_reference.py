"""The line-by-line G-code reader rjcad used before the numpy one (rjcad.check.gcode): the reference its results
are compared with (tests/test_check_gcode.py). Kept as it was; not used by rjcad.

Understands what FDM slicers write: G0/G1 moves (G2/G3 arcs split into chords), G90/G91 and
M82/M83 (absolute or relative XYZ and E), G92, retractions and wipes (moves that do not push
filament are not extrusions), and PrusaSlicer's comments: ``;TYPE:``, ``;WIDTH:``, ``;HEIGHT:``,
``; printing object NAME id:N copy C`` / ``; stop printing object …`` (``gcode_label_objects``),
and ``M486 S<id> [A"name"]`` object labels. Units: mm.

An extrusion is a move with an XY displacement that pushes filament (ΔE > 0). Consecutive
extrusions of one object at one height, with no other move between them, form a path.
Without a ``;WIDTH:`` comment the width comes from the filament pushed:
w = A_road / h + h·(1 − π/4), A_road = ΔE·π·d²/4 / L (the rounded-rectangle road of slicers).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

#: Largest chord of an arc (G2/G3) split into straight moves [mm].
ARC_CHORD_MM = 0.2
_OBJECT = re.compile(r";\s*printing object\s+(.*?)(?:\s+id:\S+)?(?:\s+copy\s+\d+)?\s*$")
_M486_ID = re.compile(r"\bS(-?\d+)", re.IGNORECASE)
_M486_NAME = re.compile(r'\bA"?([^"]*)"?')


@dataclass
class Toolpaths:
    """Extrusion moves, one row each: from (x0, y0) to (x1, y1) at height z [mm]."""

    x0: np.ndarray
    y0: np.ndarray
    x1: np.ndarray
    y1: np.ndarray
    z: np.ndarray
    width: np.ndarray
    height: np.ndarray
    obj: np.ndarray
    kind: np.ndarray
    path: np.ndarray
    objects: list[str]
    kinds: list[str]

    def __post_init__(self):
        self.length = np.hypot(self.x1 - self.x0, self.y1 - self.y0)

    def layers(self) -> np.ndarray:
        """The print heights, sorted (z rounded to 0.1 µm)."""
        return np.unique(np.round(self.z, 4))


class _State:
    """Where the nozzle is and how the next words are read."""

    def __init__(self):
        self.pos = {"X": 0.0, "Y": 0.0, "Z": 0.0, "E": 0.0}
        self.rel_xyz = False
        self.rel_e = False
        self.kind = ""
        self.width = math.nan
        self.height = math.nan
        self.obj = -1
        self.path = 0
        self.extruding = False  # the last move was an extrusion (a path continues)


def _words(code: str) -> dict[str, float]:
    """{axis letter: value} of a G-code line's words after the command."""
    out = {}
    for w in code.split()[1:]:
        try:
            out[w[0].upper()] = float(w[1:])
        except (ValueError, IndexError):
            continue
    return out


def _arc(st: _State, w: dict[str, float], clockwise: bool) -> list[tuple[float, float]]:
    """The points of a G2/G3 arc in XY (I, J: centre offset from the start), chords ≤ ARC_CHORD_MM."""
    x0, y0 = st.pos["X"], st.pos["Y"]
    x1 = w.get("X", 0.0) + (x0 if st.rel_xyz else 0.0) if "X" in w else x0
    y1 = w.get("Y", 0.0) + (y0 if st.rel_xyz else 0.0) if "Y" in w else y0
    cx, cy = x0 + w.get("I", 0.0), y0 + w.get("J", 0.0)
    r = math.hypot(x0 - cx, y0 - cy)
    a0, a1 = math.atan2(y0 - cy, x0 - cx), math.atan2(y1 - cy, x1 - cx)
    sweep = a1 - a0
    if clockwise and sweep >= 0:
        sweep -= 2 * math.pi
    if not clockwise and sweep <= 0:
        sweep += 2 * math.pi
    n = max(1, int(math.ceil(abs(sweep) * r / ARC_CHORD_MM)))
    pts = [(cx + r * math.cos(a0 + sweep * k / n), cy + r * math.sin(a0 + sweep * k / n)) for k in range(1, n)]
    return pts + [(x1, y1)]


class _Reader:
    """Accumulates extrusion rows while reading lines."""

    def __init__(self):
        self.st = _State()
        self.rows: list[tuple] = []
        self.objects: list[str] = []
        self.obj_ids: dict[str, int] = {}
        self.kinds: list[str] = []
        self.kind_ids: dict[str, int] = {}
        self.filament = 1.75
        self.label_names: dict[int, str] = {}
        self.label_index: dict[int, int] = {}
        self.label = -1

    def object_index(self, name: str) -> int:
        if name not in self.obj_ids:
            self.obj_ids[name] = len(self.objects)
            self.objects.append(name)
        return self.obj_ids[name]

    def set_object(self, idx: int) -> None:
        if idx != self.st.obj:
            self.st.obj = idx
            self.st.extruding = False

    def comment(self, text: str) -> None:
        st = self.st
        if text.startswith(";TYPE:"):
            st.kind = text[6:].strip()
        elif text.startswith((";WIDTH:", ";HEIGHT:")):
            key, _, value = text[1:].partition(":")
            try:
                setattr(st, key.lower(), float(value))
            except ValueError:  # a malformed tag: the width then comes from the filament pushed
                setattr(st, key.lower(), math.nan)
        elif "stop printing object" in text:
            self.set_object(-1)
        elif "printing object" in text:
            m = _OBJECT.match(text)
            if m:
                self.set_object(self.object_index(m.group(1).strip()))
        elif text.startswith("; filament_diameter ="):
            try:
                self.filament = float(text.split("=", 1)[1].split(",")[0])
            except ValueError:
                pass

    def m486(self, code: str) -> None:
        """M486 labels: ``S<id>`` starts object id (−1: none), ``A"name"`` names the object of ``S`` or the current one."""
        sid = _M486_ID.search(code)
        name = _M486_NAME.search(code)
        if name:
            key = int(sid.group(1)) if sid else self.label
            self.label_names[key] = name.group(1).strip()
            if key in self.label_index:
                self.objects[self.label_index[key]] = self.label_names[key]
            return
        if sid:
            self.label = int(sid.group(1))
            if self.label < 0:
                self.set_object(-1)
                return
            if self.label not in self.label_index:
                self.label_index[self.label] = len(self.objects)
                self.objects.append(self.label_names.get(self.label, f"object {self.label}"))
            self.set_object(self.label_index[self.label])

    def move(self, w: dict[str, float], points: list[tuple[float, float]] | None) -> None:
        st, pos = self.st, self.st.pos
        x0, y0, z0 = pos["X"], pos["Y"], pos["Z"]
        rel = st.rel_xyz
        x = (x0 + w["X"] if rel else w["X"]) if "X" in w else x0
        y = (y0 + w["Y"] if rel else w["Y"]) if "Y" in w else y0
        if "Z" in w:
            pos["Z"] = z0 + w["Z"] if rel else w["Z"]
            if pos["Z"] != z0:
                st.extruding = False
        pos["X"], pos["Y"] = x, y
        de = 0.0
        if "E" in w:
            de = w["E"] if st.rel_e else w["E"] - pos["E"]
            pos["E"] = pos["E"] + w["E"] if st.rel_e else w["E"]
        if x == x0 and y == y0:
            return
        if de <= 0:
            st.extruding = False
            return
        if not st.extruding:
            st.path += 1
            st.extruding = True
        kind = self.kind_ids.get(st.kind)
        if kind is None:
            kind = self.kind_ids[st.kind] = len(self.kinds)
            self.kinds.append(st.kind)
        if points is None:
            self.rows.append((x0, y0, x, y, pos["Z"], st.width, st.height, de, st.obj, kind, st.path))
            return
        pts = [(x0, y0)] + points
        total = sum(math.dist(a, b) for a, b in zip(pts[:-1], pts[1:]))
        for a, b in zip(pts[:-1], pts[1:]):
            self.rows.append(
                (
                    a[0],
                    a[1],
                    b[0],
                    b[1],
                    pos["Z"],
                    st.width,
                    st.height,
                    de * math.dist(a, b) / total,
                    st.obj,
                    kind,
                    st.path,
                )
            )

    def line(self, raw: str) -> None:
        if raw.startswith("G1 "):  # the bulk of a file: a plain move without a comment
            try:
                self.move({w[0].upper(): float(w[1:]) for w in raw.split()[1:]}, None)
                return
            except (ValueError, IndexError):
                pass
        code, _, comment = raw.partition(";")
        if comment:
            self.comment(";" + comment)
        code = code.strip()
        if not code:
            return
        head = code.split(maxsplit=1)[0].upper()
        st = self.st
        if head in ("G0", "G1", "G00", "G01"):
            self.move(_words(code), None)
        elif head in ("G2", "G3", "G02", "G03"):
            w = _words(code)
            self.move(w, _arc(st, w, head in ("G2", "G02")))
        elif head == "G90":
            st.rel_xyz = st.rel_e = False
        elif head == "G91":
            st.rel_xyz = st.rel_e = True
        elif head == "M82":
            st.rel_e = False
        elif head == "M83":
            st.rel_e = True
        elif head == "G92":
            for axis, v in _words(code).items():
                if axis in st.pos:
                    st.pos[axis] = v
        elif head == "M486":
            self.m486(code)


def parse_gcode(text: str) -> Toolpaths:
    """The extrusion moves of a G-code text (see the module's docstring for what is understood)."""
    rd = _Reader()
    for raw in text.splitlines():
        if raw:
            rd.line(raw)
    cols = np.array(rd.rows, dtype=float).reshape(-1, 11)
    x0, y0, x1, y1, z, width, height, de = (cols[:, i] for i in range(8))
    length = np.hypot(x1 - x0, y1 - y0)
    layers = np.unique(np.round(z, 4))
    below = np.searchsorted(layers, np.round(z, 4)) - 1
    h_guess = np.where(below >= 0, np.round(z, 4) - layers[np.maximum(below, 0)], np.round(z, 4))
    height = np.where(np.isnan(height), h_guess, height)
    area = de * math.pi * rd.filament**2 / 4 / np.maximum(length, 1e-9)
    from_e = area / np.maximum(height, 1e-9) + height * (1 - math.pi / 4)
    width = np.where(np.isnan(width), from_e, width)
    return Toolpaths(
        x0,
        y0,
        x1,
        y1,
        z,
        width,
        height,
        cols[:, 8].astype(int),
        cols[:, 9].astype(int),
        cols[:, 10].astype(int),
        rd.objects,
        rd.kinds,
    )


def assert_same(a: Toolpaths, b: Toolpaths) -> None:
    """Two readers' Toolpaths are equal, row for row and bit for bit (NaN equal to NaN)."""
    for f in ("x0", "y0", "x1", "y1", "z", "width", "height", "obj", "kind", "path", "length"):
        u, v = getattr(a, f), getattr(b, f)
        assert u.dtype.kind == v.dtype.kind and np.array_equal(u, v, equal_nan=True), f
    assert a.objects == b.objects and a.kinds == b.kinds
