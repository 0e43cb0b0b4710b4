"""A small G-code reader: the extrusion moves of a sliced print, with their layer, object, role and width.

Understands what FDM slicers write: G0/G1 moves (G2/G3 arcs split into chords), G90/G91 and
M82/M83 (absolute or relative XYZ and E), G92, retractions and wipes (moves that do not push
filament are not extrusions), and PrusaSlicer's comments: ``;TYPE:``, ``;WIDTH:``, ``;HEIGHT:``,
``; printing object NAME id:N copy C`` / ``; stop printing object …`` (``gcode_label_objects``),
and ``M486 S<id> [A"name"]`` object labels. Units: mm.

An extrusion is a move with an XY displacement that pushes filament (ΔE > 0). Consecutive
extrusions of one object at one height, with no other move between them, form a path.
Without a ``;WIDTH:`` comment the width comes from the filament pushed:
w = A_road / h + h·(1 − π/4), A_road = ΔE·π·d²/4 / L (the rounded-rectangle road of slicers).

Read with numpy, not line by line: the plain ``G1`` lines (nine in ten of a file) are parsed as string
arrays (``numpy.strings``); the other lines (comments, modes, G92, labels, arcs) in one Python pass that
records where the state changes; the nozzle's position after each line is then a forward fill of the
last absolute value plus a running sum of the relative ones.
"""

from __future__ import annotations

import contextlib
import itertools
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

#: Largest chord of an arc (G2/G3) split into straight moves [mm].
ARC_CHORD_MM = 0.2
_OBJECT = re.compile(r";\s*printing object\s+(.*?)(?:\s+id:\S+)?(?:\s+copy\s+\d+)?\s*$")
_M486_ID = re.compile(r"\bS(-?\d+)", re.IGNORECASE)
_M486_NAME = re.compile(r'\bA"?([^"]*)"?')
_MOVES = {"G0": False, "G1": False, "G00": False, "G01": False, "G2": True, "G3": True, "G02": True, "G03": True}
_AXES = "XYZE"
#: Axis number (0…3 for X, Y, Z, E, either case) of a word's first byte; −1: a word the reader does not use.
_AXIS_OF = np.full(256, -1, dtype=np.int64)
for _k, _a in enumerate(_AXES):
    _AXIS_OF[ord(_a)] = _AXIS_OF[ord(_a.lower())] = _k
#: Powers of ten, exact in float64.
_POW10 = np.array([float(10**k) for k in range(23)])


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


def _words(code: str) -> dict[str, float]:
    """{axis letter: value} of a G-code line's words after the command."""
    out = {}
    for w in code.split()[1:]:
        try:
            out[w[0].upper()] = float(w[1:])
        except (ValueError, IndexError):
            continue
    return out


def _arc(x0: float, y0: float, rel: bool, w: dict[str, float], clockwise: bool) -> list[tuple[float, float]]:
    """The points of a G2/G3 arc from (x0, y0) in XY (I, J: centre offset from the start), chords ≤ ARC_CHORD_MM."""
    x1 = w.get("X", 0.0) + (x0 if rel else 0.0) if "X" in w else x0
    y1 = w.get("Y", 0.0) + (y0 if rel else 0.0) if "Y" in w else y0
    cx, cy = x0 + w.get("I", 0.0), y0 + w.get("J", 0.0)
    r = math.hypot(x0 - cx, y0 - cy)
    a0, a1 = math.atan2(y0 - cy, x0 - cx), math.atan2(y1 - cy, x1 - cx)
    sweep = a1 - a0
    if clockwise and sweep >= 0:
        sweep -= 2 * math.pi
    if not clockwise and sweep <= 0:
        sweep += 2 * math.pi
    n = max(1, math.ceil(abs(sweep) * r / ARC_CHORD_MM))
    pts = [(cx + r * math.cos(a0 + sweep * k / n), cy + r * math.sin(a0 + sweep * k / n)) for k in range(1, n)]
    return pts + [(x1, y1)]


@dataclass
class _Events:
    """What the lines other than plain G1 moves change, by line number (each list in line order)."""

    words: dict[int, dict[str, float]] = field(default_factory=dict)  # moves' words (G0…G3 with a comment, …)
    arcs: dict[int, bool] = field(default_factory=dict)  # line → clockwise
    g92: dict[int, dict[str, float]] = field(default_factory=dict)
    modes: list[tuple[int, int, int]] = field(default_factory=list)  # (line, rel_xyz or −1, rel_e or −1)
    kind: list[tuple[int, str]] = field(default_factory=list)
    width: list[tuple[int, float]] = field(default_factory=list)
    height: list[tuple[int, float]] = field(default_factory=list)
    obj: list[tuple[int, int]] = field(default_factory=list)  # (line, object index) where the object changes
    objects: list[str] = field(default_factory=list)
    filament: float = 1.75
    current: int = -1
    obj_ids: dict[str, int] = field(default_factory=dict)
    label_names: dict[int, str] = field(default_factory=dict)
    label_index: dict[int, int] = field(default_factory=dict)
    label: int = -1

    def set_object(self, i: int, idx: int) -> None:
        if idx != self.current:
            self.current = idx
            self.obj.append((i, idx))

    def comment(self, i: int, text: str) -> None:
        if text.startswith(";TYPE:"):
            self.kind.append((i, text[6:].strip()))
        elif text.startswith((";WIDTH:", ";HEIGHT:")):
            key, _, value = text[1:].partition(":")
            try:
                v = float(value)
            except ValueError:  # a malformed tag: the width then comes from the filament pushed
                v = math.nan
            (self.width if key == "WIDTH" else self.height).append((i, v))
        elif "stop printing object" in text:
            self.set_object(i, -1)
        elif "printing object" in text:
            m = _OBJECT.match(text)
            if m:
                name = m.group(1).strip()
                if name not in self.obj_ids:
                    self.obj_ids[name] = len(self.objects)
                    self.objects.append(name)
                self.set_object(i, self.obj_ids[name])
        elif text.startswith("; filament_diameter ="):
            with contextlib.suppress(ValueError):
                self.filament = float(text.split("=", 1)[1].split(",")[0])

    def m486(self, i: int, code: str) -> None:
        """M486 labels: ``S<id>`` starts object id (−1: none); ``A"name"`` names the object of ``S`` or the current
        one."""
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
                self.set_object(i, -1)
                return
            if self.label not in self.label_index:
                self.label_index[self.label] = len(self.objects)
                self.objects.append(self.label_names.get(self.label, f"object {self.label}"))
            self.set_object(i, self.label_index[self.label])

    def line(self, i: int, raw: str) -> None:
        code, _, comment = raw.partition(";")
        if comment:
            self.comment(i, ";" + comment)
        code = code.strip()
        if not code:
            return
        head = code.split(maxsplit=1)[0].upper()
        if head in _MOVES:
            self.words[i] = _words(code)
            if _MOVES[head]:
                self.arcs[i] = head in ("G2", "G02")
        elif head in ("G90", "G91"):
            self.modes.append((i, int(head == "G91"), int(head == "G91")))
        elif head in ("M82", "M83"):
            self.modes.append((i, -1, int(head == "M83")))
        elif head == "G92":
            self.g92[i] = _words(code)
        elif head == "M486":
            self.m486(i, code)


def _decimals(buf: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The numbers written in ``buf[lo:hi]`` (bytes), each as Python's ``float`` reads it (NaN: not a number).

    A plain decimal ([sign] digits [. digits], ≤ 15 digits) is its integer mantissa m over 10^k (k digits after
    the point): both exact in float64, so their quotient is the correctly rounded value, as ``float`` gives.
    Anything else (an exponent, a stray letter) is read by ``float`` itself.
    """
    n = hi - lo
    out = np.full(len(lo), np.nan)
    if not len(lo):
        return out
    mantissa, digits, frac = np.zeros(len(lo), np.int64), np.zeros(len(lo), np.int64), np.zeros(len(lo), np.int64)
    dots, plain = np.zeros(len(lo), bool), (n >= 1) & (n <= 17)
    neg = buf[np.minimum(lo, len(buf) - 1)] == 45
    for j in range(min(int(n.max()), 17)):  # Horner's rule, one column of characters at a time
        c = buf[np.minimum(lo + j, len(buf) - 1)]
        on = j < n
        digit = on & (c >= 48) & (c <= 57)
        dot = on & (c == 46)
        plain &= ~on | digit | dot | (j == 0) & ((c == 45) | (c == 43))
        plain &= ~(dot & dots)
        mantissa = np.where(digit, mantissa * 10 + (c.astype(np.int64) - 48), mantissa)
        digits += digit
        frac += digit & dots
        dots |= dot
    plain &= (digits >= 1) & (digits <= 15)
    value = mantissa / _POW10[np.minimum(frac, 22)]
    out[plain] = np.where(neg, -value, value)[plain]
    for k in np.flatnonzero(~plain).tolist():
        out[k] = _float(buf[lo[k] : hi[k]].tobytes().decode(errors="replace"))
    return out


def _plain_moves(buf: np.ndarray, starts: np.ndarray, ends: np.ndarray, plain: np.ndarray) -> dict[str, np.ndarray]:
    """X, Y, Z, E of the plain ``G1`` lines (NaN: absent), by line: each word after the first, its letter and the
    number after it; the last readable word of an axis counts, as when the words are read into a dict."""
    space = (buf == 32) | (buf == 9)
    word = np.flatnonzero(space[:-1] & ~space[1:] & (buf[1:] != 10)) + 1
    line = np.searchsorted(starts, word, side="right") - 1
    word, line = word[plain[line]], line[plain[line]]
    axis = _AXIS_OF[buf[word]]
    word, line, axis = word[axis >= 0], line[axis >= 0], axis[axis >= 0]
    delim = np.r_[np.flatnonzero(space | (buf == 10)), len(buf)]
    stop = np.minimum(delim[np.searchsorted(delim, word)], ends[line])
    value = _decimals(buf, word + 1, stop)
    out = {}
    for k, a in enumerate(_AXES):
        sel = (axis == k) & ~np.isnan(value)
        col = np.full(len(starts), np.nan)
        ln, v = line[sel], value[sel]
        last = np.r_[ln[1:] != ln[:-1], True] if len(ln) else np.zeros(0, dtype=bool)
        col[ln[last]] = v[last]
        out[a] = col
    return out


def _float(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan


def _fill(events: Sequence[tuple[int, float]], n: int, initial: float) -> np.ndarray:
    """Per line, the value of the last event at or before it (``initial`` before the first)."""
    if not events:
        return np.full(n, initial, dtype=float)
    at, val = np.array([e[0] for e in events]), np.array([e[1] for e in events], dtype=float)
    k = np.searchsorted(at, np.arange(n), side="right") - 1
    return np.where(k >= 0, val[np.maximum(k, 0)], initial)


def _position(word: np.ndarray, move: np.ndarray, rel: np.ndarray, g92: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One axis's position after each line, and its move's relative word (0 elsewhere): a move's absolute
    word or a G92 sets it, a relative word adds to it (the running sum since the last set)."""
    given = move & ~np.isnan(word)
    is_set = (given & ~rel) | ~np.isnan(g92)
    set_val = np.where(~np.isnan(g92), g92, word)
    add = np.where(given & rel, word, 0.0)
    total = np.cumsum(add)
    idx = np.arange(len(word))
    last = np.maximum.accumulate(np.where(is_set, idx, -1))
    base = np.where(last >= 0, set_val[np.maximum(last, 0)], 0.0)
    since = total - np.where(last >= 0, total[np.maximum(last, 0)], 0.0)
    return base + since, add


def parse_gcode(text: str) -> Toolpaths:
    """The extrusion moves of a G-code text (see the module's docstring for what is understood)."""
    raw = text.replace("\r\n", "\n").replace("\r", "\n").encode()
    buf = np.frombuffer(raw, dtype=np.uint8)
    ends = np.flatnonzero(buf == 10)
    if len(buf) and buf[-1] != 10:
        ends = np.r_[ends, len(buf)]
    starts = np.r_[0, ends[:-1] + 1].astype(np.int64)
    n = len(starts)
    head = np.minimum(starts[:, None] + np.arange(3), max(len(buf) - 1, 0))
    plain = (
        (ends - starts >= 3) & np.all(buf[head] == np.frombuffer(b"G1 ", dtype=np.uint8), axis=1)
        if len(buf)
        else np.zeros(0, bool)
    )
    plain[np.searchsorted(starts, np.flatnonzero(buf == 59), side="right") - 1] = False  # a comment: read in Python
    ev = _Events()
    for i in np.flatnonzero(~plain & (ends > starts)).tolist():
        ev.line(i, raw[starts[i] : ends[i]].decode(errors="replace"))
    words = _plain_moves(buf, starts, ends, plain)
    g92 = {a: np.full(n, np.nan) for a in _AXES}
    for i, w in ev.words.items():
        for a in _AXES:
            words[a][i] = w.get(a, math.nan)
    for i, w in ev.g92.items():
        for a in _AXES:
            g92[a][i] = w.get(a, math.nan)
    move = plain.copy()
    move[list(ev.words)] = True
    rel_xyz = _fill([(i, r) for i, r, _ in ev.modes if r >= 0], n, 0) > 0
    rel_e = _fill([(i, e) for i, _, e in ev.modes], n, 0) > 0
    pos = {a: _position(words[a], move, rel_e if a == "E" else rel_xyz, g92[a]) for a in _AXES}
    before = {a: np.r_[0.0, p[:-1]] for a, (p, _) in pos.items()}
    x, y, z = pos["X"][0], pos["Y"][0], pos["Z"][0]
    has_e = move & ~np.isnan(words["E"])
    de = np.where(has_e, np.where(rel_e, words["E"], words["E"] - before["E"]), 0.0)
    xy = move & ((x != before["X"]) | (y != before["Y"]))
    extrude = xy & (de > 0)
    obj = _fill(ev.obj, n, -1).astype(int)
    breaks = (xy & ~extrude) | (move & ~np.isnan(words["Z"]) & (z != before["Z"])) | (obj != np.r_[-1, obj[:-1]])
    rows = np.flatnonzero(extrude)
    count = np.cumsum(breaks)
    new_path = count[rows] - np.r_[0, count[rows[:-1]]] > 0
    if len(rows):
        new_path[0] = True
    names: dict[str, int] = {"": 0}  # each ;TYPE: text once, "" before the first
    kind_id = np.array([0] + [names.setdefault(k, len(names)) for _, k in ev.kind])
    kind_line = kind_id[_fill([(i, k + 1) for k, (i, _) in enumerate(ev.kind)], n, 0).astype(int)[rows]]
    used, first, kind = np.unique(kind_line, return_index=True, return_inverse=True)
    rank = np.argsort(np.argsort(first))  # kinds numbered in the order of their first extrusion
    text_of = {v: k for k, v in names.items()}
    cols = dict(
        x0=before["X"][rows],
        y0=before["Y"][rows],
        x1=x[rows],
        y1=y[rows],
        z=z[rows],
        width=_fill(ev.width, n, math.nan)[rows],
        height=_fill(ev.height, n, math.nan)[rows],
        de=de[rows],
        obj=obj[rows],
        kind=rank[kind].reshape(-1),
        path=np.cumsum(new_path),
    )
    kinds = [text_of[int(k)] for _, k in sorted(zip(rank, used))]
    if ev.arcs:
        cols = _split_arcs(cols, rows, ev, rel_xyz)
    return _toolpaths(cols, ev.objects, kinds, ev.filament)


def _split_arcs(cols: dict, rows: np.ndarray, ev: _Events, rel_xyz: np.ndarray) -> dict:
    """Each arc's row replaced by its chords (ARC_CHORD_MM), the filament shared by their lengths."""
    pieces: list[list[tuple[float, float]] | None] = []
    for k, line in enumerate(rows.tolist()):
        if line not in ev.arcs:
            pieces.append(None)
            continue
        start = (float(cols["x0"][k]), float(cols["y0"][k]))
        pieces.append([start] + _arc(*start, bool(rel_xyz[line]), ev.words[line], ev.arcs[line]))
    count = np.array([1 if p is None else len(p) - 1 for p in pieces])
    out = {key: np.repeat(v, count) for key, v in cols.items()}
    at = np.cumsum(count) - count
    for k, pts in enumerate(pieces):
        if pts is None:
            continue
        total = sum(math.dist(a, b) for a, b in itertools.pairwise(pts))
        for m, (a, b) in enumerate(itertools.pairwise(pts)):
            j = at[k] + m
            out["x0"][j], out["y0"][j], out["x1"][j], out["y1"][j] = a[0], a[1], b[0], b[1]
            out["de"][j] = cols["de"][k] * math.dist(a, b) / total
    return out


def _toolpaths(cols: dict, objects: list[str], kinds: list[str], filament: float) -> Toolpaths:
    """The rows as Toolpaths; a missing height is the step from the layer below, a missing width comes from the
    filament pushed (see the module's docstring)."""
    x0, y0, x1, y1, z, de = (np.asarray(cols[k], dtype=float) for k in ("x0", "y0", "x1", "y1", "z", "de"))
    length = np.hypot(x1 - x0, y1 - y0)
    layers = np.unique(np.round(z, 4))
    below = np.searchsorted(layers, np.round(z, 4)) - 1
    h_guess = np.where(below >= 0, np.round(z, 4) - layers[np.maximum(below, 0)], np.round(z, 4))
    height = np.where(np.isnan(cols["height"]), h_guess, cols["height"])
    area = de * math.pi * filament**2 / 4 / np.maximum(length, 1e-9)
    from_e = area / np.maximum(height, 1e-9) + height * (1 - math.pi / 4)
    width = np.where(np.isnan(cols["width"]), from_e, cols["width"])
    return Toolpaths(
        x0,
        y0,
        x1,
        y1,
        z,
        width,
        height,
        np.asarray(cols["obj"], dtype=int),
        np.asarray(cols["kind"], dtype=int),
        np.asarray(cols["path"], dtype=int),
        objects,
        kinds,
    )
