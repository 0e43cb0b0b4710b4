"""PrusaSlicer's bundled vendor printer profiles, turned into rjcad printer profiles (TOML text).

A vendor bundle is an INI file, ``<prefix>/share/PrusaSlicer/profiles/<Vendor>.ini``, of ``[printer:NAME]``,
``[print:NAME]``, ``[filament:NAME]``, ``[printer_model:ID]`` and ``[vendor]`` sections. ``inherits = A; B``
takes A's keys, then B's over them, then the section's own over both (parents in the same bundle, resolved
the same way); a name starting with ``*`` is an abstract parent. :func:`read_printer` resolves one printer:
its nozzle, bed, and the layer heights of its default print profile (a first layer in % is of layer_height);
:func:`printer_toml` writes it with each value's source in a comment. Lengths in mm.
"""

from __future__ import annotations

import difflib
import functools
import json
import math
import shutil
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rjcad.errors import BadInput, quote

#: Where Debian's prusa-slicer package puts the bundles; looked in after the executable's own share dir.
DEFAULT_DIR = Path("/usr/share/PrusaSlicer/profiles")
#: Names of the PrusaSlicer executable on PATH.
EXECUTABLES = ("prusa-slicer", "PrusaSlicer")
INSTALL_HINT = "install prusa-slicer (Debian: apt-get install prusa-slicer)"
#: Decimals kept of a computed length (bed extent, percent first layer, midpoint): 1e-6 mm.
DECIMALS = 6

#: A resolved section: key -> (raw value, the section that set it).
Keys = dict[str, tuple[str, str]]

#: The origin of a value no section sets.
BUILTIN = "PrusaSlicer's built-in default"
#: PrusaSlicer 2.5's built-in values (its PrintConfig.cpp) of the keys read here, which a printer or print
#: profile gets when neither it nor a parent sets the key (the bundles leave bed_shape or nozzle_diameter
#: unset for a few printers).
DEFAULTS = {
    "nozzle_diameter": "0.4",
    "bed_shape": "0x0,200x0,200x200,0x200",
    "max_print_height": "200",
    "layer_height": "0.3",
    "first_layer_height": "0.35",
}


def profiles_dir(explicit: str | Path | None = None) -> Path:
    """The folder of PrusaSlicer's vendor bundles (``*.ini``): ``explicit`` if given, else
    ``<prefix>/share/PrusaSlicer/profiles`` beside the ``prusa-slicer`` executable, else :data:`DEFAULT_DIR`.
    BadInput (one line, with the install command) if none holds a bundle."""
    looked: list[Path] = []
    if explicit is not None:
        looked.append(Path(explicit))
    else:
        for exe in EXECUTABLES:
            found = shutil.which(exe)
            for path in (Path(found), Path(found).resolve()) if found else ():
                looked.append(path.parent.parent / "share" / "PrusaSlicer" / "profiles")
        looked.append(DEFAULT_DIR)
    looked = list(dict.fromkeys(looked))
    for folder in looked:
        if folder.is_dir() and any(folder.glob("*.ini")):
            return folder
    where = ", ".join(str(p) for p in looked)
    raise BadInput(f"PrusaSlicer's vendor profiles were not found (looked in {where}); {INSTALL_HINT}")


def _unquote(value: str) -> str:
    """A value as PrusaSlicer reads a string: a ``"…"`` one loses its quotes and C escapes (\\n, \\", \\\\)."""
    if len(value) < 2 or value[0] != '"' or value[-1] != '"':
        return value
    out, inner, i = [], value[1:-1], 0
    while i < len(inner):
        c = inner[i]
        if c == "\\" and i + 1 < len(inner):
            i += 1
            c = {"n": "\n", "r": "\r", "t": "\t"}.get(inner[i], inner[i])
        out.append(c)
        i += 1
    return "".join(out)


def _names(value: str) -> list[str]:
    """A ``;``-separated list of names (``inherits``, ``variants``), each trimmed and unquoted; no empty ones."""
    return [name for name in (_unquote(part.strip()) for part in value.split(";")) if name]


def _parse(text: str, file: str) -> dict[str, dict[str, str]]:
    """Section name -> {key: raw value} of an INI text; ``#``/``;`` lines are comments. BadInput on a line
    that is neither, or on a section or key given twice (PrusaSlicer refuses those files too)."""
    sections: dict[str, dict[str, str]] = {}
    current: dict[str, str] | None = None
    name = ""
    for n, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line or line[0] in "#;":
            continue
        if line[0] == "[" and line[-1] == "]":
            name = line[1:-1].strip()
            if name in sections:
                raise BadInput(f"{file}:{n}: section [{name}] appears twice")
            current = sections[name] = {}
        elif "=" in line and current is not None:
            key, value = line.split("=", 1)
            key = key.strip()
            if key in current:
                raise BadInput(f"{file}:{n}: [{name}] sets {key} twice")
            current[key] = value.strip()
        else:
            raise BadInput(f"{file}:{n}: not a [section] nor a 'key = value' line in one: {quote(line)}")
    return sections


class _Bundle:
    """One vendor bundle: its sections, resolved through ``inherits`` on demand (and remembered)."""

    def __init__(self, path: Path, sections: dict[str, dict[str, str]]) -> None:
        self.path = path
        self.sections = sections
        self._resolved: dict[str, Keys] = {}

    @property
    def version(self) -> str:
        """The bundle's own version, ``[vendor] config_version`` (not PrusaSlicer's)."""
        return _unquote(self.sections.get("vendor", {}).get("config_version", "")) or "(no config_version)"

    def resolve(self, section: str, _stack: tuple[str, ...] = ()) -> Keys:
        """Every key of ``section`` with its parents': later parents over earlier, its own over all."""
        if section in self._resolved:
            return self._resolved[section]
        if section in _stack:
            raise BadInput(f"{self.path.name}: [{section}] inherits itself ({' -> '.join(_stack + (section,))})")
        kind = section.split(":", 1)[0]
        own = self.sections[section]
        out: Keys = {}
        for parent in _names(own.get("inherits", "")):
            if f"{kind}:{parent}" not in self.sections:
                raise BadInput(f"{self.path.name}: [{section}] inherits [{kind}:{parent}], which is not in the bundle")
            out.update(self.resolve(f"{kind}:{parent}", (*_stack, section)))
        out.update({key: (value, section) for key, value in own.items() if key != "inherits"})
        self._resolved[section] = out
        return out

    @functools.cached_property
    def printers(self) -> list[str]:
        """The concrete FFF printers, in bundle order (see :func:`printer_names` for the rule)."""
        models = {s.split(":", 1)[1]: keys for s, keys in self.sections.items() if s.startswith("printer_model:")}
        out = []
        for section in self.sections:
            kind, _, name = section.partition(":")
            if kind != "printer" or not name or name.startswith("*"):
                continue
            keys = self.resolve(section)
            model, variant = _text(keys, "printer_model"), _text(keys, "printer_variant")
            if not model or model not in models or variant not in _names(models[model].get("variants", "")):
                continue
            if _text(keys, "printer_technology", "FFF") == "FFF":
                out.append(name)
        return out

    def prints(self) -> list[str]:
        """The concrete (not ``*``) print profiles' names."""
        return [s.split(":", 1)[1] for s in self.sections if s.startswith("print:") and not s.startswith("print:*")]


@functools.lru_cache(maxsize=64)
def _parsed(path: str, mtime_ns: int, size: int) -> _Bundle:
    """The bundle at ``path``, parsed once per version of the file (its mtime and size are the cache key)."""
    from rjcad.io.untrusted import read_bytes

    file = Path(path)
    text = read_bytes(file, "text").decode("utf-8", errors="replace").removeprefix("\ufeff")
    return _Bundle(file, _parse(text, file.name))


def _bundles(folder: str | Path | None) -> list[_Bundle]:
    """Every bundle of the profiles folder (:func:`profiles_dir`), by file name."""
    out = []
    for path in sorted(profiles_dir(folder).glob("*.ini")):
        try:
            st = path.stat()
        except OSError:  # a dangling link, a loop: not a bundle
            continue
        if stat.S_ISREG(st.st_mode):  # a FIFO or a device named *.ini is no bundle (and would block a reader)
            out.append(_parsed(str(path), st.st_mtime_ns, st.st_size))
    return out


def _text(keys: Keys, key: str, default: str = "") -> str:
    """A resolved string value, unquoted; ``default`` when no section in the chain sets it."""
    return _unquote(keys[key][0]) if key in keys else default


def _setting(bundle: _Bundle, section: str, key: str) -> tuple[str, str]:
    """(value, origin) of ``key`` in ``section`` resolved: the section that sets it, else :data:`BUILTIN`
    from :data:`DEFAULTS`; BadInput if neither."""
    keys = bundle.resolve(section)
    if key in keys:
        return _unquote(keys[key][0]), keys[key][1]
    if key in DEFAULTS:
        return DEFAULTS[key], BUILTIN
    raise BadInput(f"{bundle.path.name}: [{section}] and its parents set no {key}")


def _where(origin: str, section: str) -> str:
    """Where a value of ``section`` came from, for a comment: "" (its own), ", set in [parent]", or the
    built-in default."""
    if origin == section:
        return ""
    if origin == BUILTIN:
        return f", unset in the bundle: {BUILTIN} (check it)"
    return f", set in [{origin}]"


def _numbers(bundle: _Bundle, section: str, key: str, percent: bool = False) -> tuple[list[float], str, str]:
    """A resolved number list (per extruder, or one number), finite; a trailing % dropped if ``percent``;
    with its text and :func:`_where` note. BadInput if absent or not numbers."""
    raw, origin = _setting(bundle, section, key)
    try:
        values = [float(part.strip().removesuffix("%") if percent else part) for part in raw.split(",")]
    except ValueError:
        values = []
    if not values or not all(math.isfinite(v) for v in values):
        raise BadInput(f"{bundle.path.name}: [{section}] {key} = {quote(raw)} is not a list of numbers")
    return values, raw, _where(origin, section)


def printer_names(folder: str | Path | None = None) -> list[tuple[str, str]]:
    """(printer name, bundle file stem) of every printer PrusaSlicer offers, bundle by bundle.

    The rule is PrusaSlicer's own for a vendor's printers, plus FFF only: a ``[printer:NAME]`` section whose
    name does not start with ``*``, whose resolved ``printer_model`` names a ``[printer_model:ID]`` of the
    bundle and whose ``printer_variant`` is in that model's ``variants``; ``printer_technology`` FFF (or
    unset). Templates (``printer_model`` empty) and SLA printers are left out."""
    return [(name, bundle.path.stem) for bundle in _bundles(folder) for name in bundle.printers]


def _match(wanted: str, names: list[str], where: str) -> str:
    """The printer name ``wanted`` means: exact, else case-insensitive exact, else the only name holding it
    (case-insensitive); else BadInput naming up to 5 close names."""
    if wanted in names:
        return wanted
    folded = wanted.casefold()
    same = [n for n in names if n.casefold() == folded]
    if len(same) == 1:
        return same[0]
    holding = same or [n for n in names if folded in n.casefold()]
    if len(holding) == 1:
        return holding[0]
    count = f"{len(names)} PrusaSlicer printers in {where}"
    if holding:
        close = difflib.get_close_matches(wanted, holding, n=5, cutoff=0.0)
        listed = ", ".join(repr(n) for n in close) + (", …" if len(holding) > len(close) else "")
        raise BadInput(f"{quote(wanted)} is in {len(holding)} of the {count}: {listed}; give more of the name")
    by_fold = {n.casefold(): n for n in reversed(names)}
    close = [by_fold[f] for f in difflib.get_close_matches(folded, list(by_fold), n=5, cutoff=0.5)]
    hint = f"close: {', '.join(repr(n) for n in close)}" if close else "none is close"
    raise BadInput(f"no PrusaSlicer printer is named {quote(wanted)} ({count}); {hint}")


@dataclass(frozen=True)
class _Layers:
    """Layer heights [mm], the default print profile's name ("" if none), and their comments."""

    layer: float
    first: float
    print_profile: str
    layer_note: str
    first_note: str
    source_note: str


def _print_layers(bundle: _Bundle, name: str) -> _Layers:
    """``layer_height`` and ``first_layer_height`` (mm, or % of layer_height) of ``[print:name]``, resolved."""
    section = f"print:{name}"
    layers, _, layer_where = _numbers(bundle, section, "layer_height")
    firsts, raw, first_where = _numbers(bundle, section, "first_layer_height", percent=True)
    layer, first = layers[0], firsts[0]
    if raw.endswith("%"):
        first, raw = round(layer * first / 100, DECIMALS), f"{raw} of layer_height"
    return _Layers(
        layer,
        first,
        name,
        f"[{section}] layer_height{layer_where}",
        f"[{section}] first_layer_height = {raw}{first_where}",
        f"default print profile [{section}]",
    )


def _look_alikes(bundle: _Bundle, name: str) -> list[str]:
    """Print profiles named like ``name``: the same words (an ``@`` prefix dropped), else all its words."""

    def words(text: str) -> list[str]:
        return sorted(w.lstrip("@").casefold() for w in text.split())

    want = words(name)
    same = [p for p in bundle.prints() if words(p) == want]
    return same or [p for p in bundle.prints() if set(want) <= set(words(p))]


def _layers(bundle: _Bundle, section: str) -> _Layers:
    """The printer's layer heights: from its default print profile; if the bundle lacks that profile (a stale
    name), from the profiles named like it when they all agree; else the midpoint of min/max_layer_height."""
    wanted = _text(bundle.resolve(section), "default_print_profile")
    if not wanted:
        why = "it names no default print profile"
    elif f"print:{wanted}" in bundle.sections:
        return _print_layers(bundle, wanted)
    else:
        alikes = _look_alikes(bundle, wanted)
        found = [_print_layers(bundle, p) for p in alikes]
        if found and len({(f.layer, f.first) for f in found}) == 1:
            more = f" and {len(found) - 1} more named like it" if len(found) > 1 else ""
            stale = f" (its default [print:{wanted}] is not in the bundle: taken from [print:{alikes[0]}]{more})"
            source = f"default print profile [print:{wanted}], not in the bundle: [print:{alikes[0]}]{more}"
            first = found[0]
            return _Layers(first.layer, first.first, wanted, first.layer_note + stale, first.first_note, source)
        why = f"its default print profile [print:{wanted}] is not in the bundle" + (
            f" and the {len(alikes)} named like it differ" if alikes else ""
        )
    low = _numbers(bundle, section, "min_layer_height")[0][0]
    high = _numbers(bundle, section, "max_layer_height")[0][0]
    layer = round((low + high) / 2, DECIMALS)
    return _Layers(
        layer,
        layer,
        wanted,
        f"midpoint of [{section}] min_layer_height {low:g} and max_layer_height {high:g}: {why}",
        f"as layer_mm: {why}",
        f"no default print profile to read ({why}): layer heights from min/max_layer_height",
    )


def _bed(bundle: _Bundle, section: str) -> tuple[list[float], str]:
    """[x, y, z] [mm]: ``bed_shape``'s bounding box and ``max_print_height``; and its comment."""
    shape_text, origin = _setting(bundle, section, "bed_shape")
    try:
        points = [tuple(float(c) for c in p.strip().split("x")) for p in shape_text.split(",")]
    except ValueError:
        points = []
    if len(points) < 3 or any(len(p) != 2 or not all(map(math.isfinite, p)) for p in points):
        raise BadInput(f"{bundle.path.name}: [{section}] bed_shape is not a polygon 'XxY,XxY,…' of 3 or more points")
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    x, y = round(max(xs) - min(xs), DECIMALS), round(max(ys) - min(ys), DECIMALS)
    zs, _, z_where = _numbers(bundle, section, "max_print_height")
    corners = {(a, b) for a in (min(xs), max(xs)) for b in (min(ys), max(ys))}
    shape = (
        "" if len(points) == 4 and set(points) == corners else f" of a {len(points)}-point (round?) bed: not all usable"
    )
    note = f"bed_shape bounding box (x, y){shape}{_where(origin, section)}; max_print_height (z){z_where}"
    return [x, y, zs[0]], note


def _soluble_note(extruders: int, single_nozzle: bool) -> str:
    """The comment of ``soluble_support`` (always false on import)."""
    if extruders < 2:
        return "a single-extruder printer: no soluble support"
    what = f"{extruders} filaments through one nozzle (MMU)" if single_nozzle else f"{extruders} extruders"
    return f"{what}: soluble support needs a soluble filament loaded; rjcad assumes none, set true if you load one"


def read_printer(name: str, folder: str | Path | None = None) -> dict[str, Any]:
    """The PrusaSlicer printer ``name`` (exact, else case-insensitive, else the only name holding it), resolved:
    ``name``, ``vendor`` (bundle file stem), ``nozzle_mm`` (first extruder's), ``layer_mm``, ``first_layer_mm``,
    ``bed_mm`` [x, y, z], ``print_profile`` (its default print profile's name, "" if none), ``source`` (one
    line), ``extruders``, ``comments`` (the TOML line comments, by key). Lengths in mm."""
    where = profiles_dir(folder)
    catalogue = {p: b for b in _bundles(where) for p in b.printers}
    printer = _match(name, list(catalogue), str(where))
    bundle = catalogue[printer]
    section = f"printer:{printer}"
    keys = bundle.resolve(section)
    nozzles, nozzle_text, nozzle_where = _numbers(bundle, section, "nozzle_diameter")
    layers = _layers(bundle, section)
    bed, bed_note = _bed(bundle, section)
    for what, value in (("nozzle_diameter", nozzles[0]), ("layer height", layers.layer), ("bed", min(bed))):
        if not value > 0:
            raise BadInput(f"{bundle.path.name}: [{section}] {what} = {value:g} mm is not positive")
    several = f" (first of {len(nozzles)}: {nozzle_text})" if len(nozzles) > 1 else ""
    single_nozzle = _text(keys, "single_extruder_multi_material", "0") == "1"
    return {
        "name": printer,
        "vendor": bundle.path.stem,
        "nozzle_mm": nozzles[0],
        "layer_mm": layers.layer,
        "first_layer_mm": layers.first,
        "bed_mm": bed,
        "print_profile": layers.print_profile,
        "source": f"PrusaSlicer vendor bundle {bundle.path.name} {bundle.version}: [{section}], {layers.source_note}",
        "extruders": len(nozzles),
        "comments": {
            "name": "PrusaSlicer printer preset name",
            "nozzle_mm": f"[{section}] nozzle_diameter{several}{nozzle_where}",
            "layer_mm": layers.layer_note,
            "first_layer_mm": layers.first_note,
            "bed_mm": bed_note,
            "soluble_support": _soluble_note(len(nozzles), single_nozzle),
            "source": "the sections read",
        },
    }


def _toml_str(text: str) -> str:
    """A TOML basic string (JSON's escapes are TOML's)."""
    return json.dumps(text, ensure_ascii=False)


def _num(value: Any) -> str:
    """A length for TOML: the shortest repr of the float, e.g. 0.2, 250.0."""
    x = float(value)
    if not math.isfinite(x):
        raise BadInput(f"printer profile value {value!r} is not a finite number")
    return repr(x)


def printer_toml(printer: dict[str, Any], key: str) -> str:
    """The rjcad printer profile ``key`` for a :func:`read_printer` result, as TOML text: one value a line,
    each with its source as a comment."""
    comments = {
        "name": "PrusaSlicer printer preset name",
        "nozzle_mm": "nozzle_diameter",
        "layer_mm": "layer_height of the default print profile",
        "first_layer_mm": "first_layer_height of the default print profile",
        "bed_mm": "bed_shape bounding box (x, y) and max_print_height (z)",
        "soluble_support": _soluble_note(int(printer.get("extruders", 1)), False),
        "source": "the sections read",
    }
    comments.update(printer.get("comments", {}))
    bed = ", ".join(_num(v) for v in printer["bed_mm"])
    rows = [
        ("name", _toml_str(str(printer["name"]))),
        ("nozzle_mm", _num(printer["nozzle_mm"])),
        ("layer_mm", _num(printer["layer_mm"])),
        ("first_layer_mm", _num(printer["first_layer_mm"])),
        ("bed_mm", f"[{bed}]"),
        ("soluble_support", "false"),
        ("source", _toml_str(str(printer["source"]))),
    ]
    texts = [f"{k} = {v}" for k, v in rows]
    width = max((len(t) for t in texts if len(t) <= 48), default=0)
    header = " ".join(f"# rjcad printer profile {_toml_str(key)}, imported from PrusaSlicer's bundled profiles".split())
    lines = [header + " (rjcad profiles import-prusaslicer)"]
    lines += [f"{t.ljust(width)}  # {' '.join(comments[k].split())}" for t, (k, _) in zip(texts, rows)]
    return "\n".join(lines) + "\n"
