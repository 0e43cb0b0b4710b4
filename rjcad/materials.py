"""FDM printer and material profiles, read from TOML files, and the printability limits derived from them.

A profile is a TOML file (schemas: ``PRINTER_KEYS``, ``MATERIAL_KEYS``; docs/profiles.md). rjcad ships its
own in ``rjcad/data/printers`` and ``rjcad/data/materials``. A name (``--printer my-mk4``) is looked up
first in the user's folder (``user_dir()``: platformdirs' user config dir for rjcad, then ``printers/`` or
``materials/``; the user's file wins a clash), then among the built-in ones; a path (``my-mk4.toml``,
anything with a folder or a ``.toml`` ending) is read as given. Each profile keeps where it came from
(``file``, ``builtin``) and how to find it again (``ref``: its name, or the file's absolute path).

Material values are for printed parts, in MPa and g/cm³. A spiral printed flat bends along its roads, so
the in-plane datasheet values apply; where sources give a range the lower strength is taken.

Printer limits not given in the file follow one rule (``Printer.from_profile``; docs/profiles.md), so a
0.6 mm nozzle gets wider walls and gaps than a 0.4 mm one without anyone typing them:

- road width w = nozzle; thinnest wall 2·w; spring thickness in whole roads (steps of w);
- smallest gap printed side by side 5/8 of the nozzle (0.25 mm at 0.4 mm); across a Z step 2 layers;
- print-in-place clearance (desktop layout) = the material's clearance at a 0.4 mm nozzle × nozzle/0.4,
  and never below the side-by-side gap.
"""

from __future__ import annotations

import functools
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rjcad.errors import ParameterError, RjcadError
from rjcad.io.untrusted import shown_path
from rjcad.validate import in_range

DEFAULT_MATERIAL = "absplus-p430"
DEFAULT_PRINTER = "generic-0.4"

#: Built-in profiles: ``<DATA>/printers/*.toml`` and ``<DATA>/materials/*.toml``.
DATA = Path(__file__).resolve().parent / "data"
#: The nozzle the materials' clearances are stated for [mm].
REFERENCE_NOZZLE_MM = 0.4
#: Smallest side-by-side gap per mm of nozzle: 0.25 mm at 0.4 mm, rjcad's measured desktop gap.
GAP_PER_NOZZLE = 0.625


@dataclass(frozen=True)
class Material:
    """A printable polymer: modulus ``E`` and strength in MPa, density in g/cm³."""

    key: str
    name: str
    youngs_modulus_mpa: float
    yield_strength_mpa: float
    density_g_cm3: float
    source: str
    #: Print-in-place clearance at a 0.4 mm nozzle (pin to eye, cone to cone, coil to coil) [mm].
    desktop_clearance_mm: float = 0.40
    #: The TOML file it was read from; False ``builtin`` for a user's file.
    file: str = ""
    builtin: bool = True
    #: What finds it again: its name, or the absolute path it was given by.
    ref: str = ""

    @property
    def strength_to_modulus(self) -> float:
        """σ_y/E, the figure of merit for compliant parts (dimensionless)."""
        return self.yield_strength_mpa / self.youngs_modulus_mpa

    def to_profile(self) -> dict[str, Any]:
        """The profile's TOML keys and values (what a manifest embeds for a user's profile)."""
        return {
            "name": self.name,
            "youngs_modulus_mpa": self.youngs_modulus_mpa,
            "yield_mpa": self.yield_strength_mpa,
            "density_g_cm3": self.density_g_cm3,
            "clearance_mm": self.desktop_clearance_mm,
            "source": self.source,
        }

    @classmethod
    def from_profile(cls, data: dict[str, Any], key: str, file: str = "", builtin: bool = False) -> Material:
        """The material of a profile's keys (checked: ``MATERIAL_KEYS``); ParameterError naming ``file: key``."""
        v = _checked(data, MATERIAL_KEYS, shown_path(file) if file else key)
        return cls(
            key,
            v["name"],
            v["youngs_modulus_mpa"],
            v["yield_mpa"],
            v["density_g_cm3"],
            v.get("source", ""),
            desktop_clearance_mm=v.get("clearance_mm", 0.40),
            file=file,
            builtin=builtin,
            ref=key,
        )


@dataclass(frozen=True)
class Printer:
    """What a printer can make, in mm.

    ``thickness_step_mm``: spring thickness t is a whole multiple of this. For
    road-based slicers it is the extrusion width (t = k roads); for printers
    that vary the road width it is a fine step.
    ``min_gap_mm`` is the smallest gap printed side by side in XY;
    ``min_gap_vertical_mm`` the smallest gap across a Z step (a surface
    printed over another part's top face).
    """

    key: str
    name: str
    nozzle_mm: float
    extrusion_width_mm: float
    layer_height_mm: float
    min_wall_mm: float
    min_gap_mm: float
    min_gap_vertical_mm: float
    thickness_step_mm: float
    soluble_support: bool
    build_volume_mm: tuple[float, float, float]
    source: str
    first_layer_mm: float = 0.0
    file: str = ""
    builtin: bool = True
    ref: str = ""
    #: The derived limits the file set itself (``DERIVED``'s keys).
    overrides: tuple[str, ...] = ()

    @classmethod
    def from_profile(cls, data: dict[str, Any], key: str, file: str = "", builtin: bool = False) -> Printer:
        """The printer of a profile's keys (checked: ``PRINTER_KEYS``), each limit not given derived by the
        rule (module docstring); ParameterError naming ``file: key``."""
        where = shown_path(file) if file else key
        v = _checked(data, PRINTER_KEYS, where)
        nozzle, layer = v["nozzle_mm"], v["layer_mm"]
        label = f"{where}: layer_mm"
        in_range(label, layer, 0.02, nozzle, unit="mm", limit=f"must be in [0.02, {nozzle:g}] mm (the nozzle)")
        width = v.get("extrusion_width_mm", nozzle)
        derived = {
            "extrusion_width_mm": width,
            "min_wall_mm": 2.0 * width,
            "min_gap_mm": GAP_PER_NOZZLE * nozzle,
            "min_gap_vertical_mm": 2.0 * layer,
            "thickness_step_mm": width,
        }
        lim = {k: v.get(k, d) for k, d in derived.items()}
        return cls(
            key,
            v["name"],
            nozzle_mm=nozzle,
            extrusion_width_mm=lim["extrusion_width_mm"],
            layer_height_mm=layer,
            min_wall_mm=lim["min_wall_mm"],
            min_gap_mm=lim["min_gap_mm"],
            min_gap_vertical_mm=lim["min_gap_vertical_mm"],
            thickness_step_mm=lim["thickness_step_mm"],
            soluble_support=v["soluble_support"],
            build_volume_mm=(float(v["bed_mm"][0]), float(v["bed_mm"][1]), float(v["bed_mm"][2])),
            source=v.get("source", ""),
            first_layer_mm=v.get("first_layer_mm", layer),
            file=file,
            builtin=builtin,
            ref=key,
            overrides=tuple(k for k in derived if k in v),
        )

    def to_profile(self) -> dict[str, Any]:
        """The profile's TOML keys and values, the derived limits included (what a manifest embeds)."""
        return {
            "name": self.name,
            "nozzle_mm": self.nozzle_mm,
            "layer_mm": self.layer_height_mm,
            "first_layer_mm": self.first_layer_mm,
            "bed_mm": list(self.build_volume_mm),
            "soluble_support": self.soluble_support,
            "extrusion_width_mm": self.extrusion_width_mm,
            "min_wall_mm": self.min_wall_mm,
            "min_gap_mm": self.min_gap_mm,
            "min_gap_vertical_mm": self.min_gap_vertical_mm,
            "thickness_step_mm": self.thickness_step_mm,
            "source": self.source,
        }

    def desktop_clearance(self, material: Material) -> float:
        """Print-in-place clearance on this printer: the material's (at a 0.4 mm nozzle) × nozzle/0.4, at least
        ``min_gap_mm`` [mm]."""
        return max(material.desktop_clearance_mm * (self.nozzle_mm / REFERENCE_NOZZLE_MM), self.min_gap_mm)

    def check_gap(self, name: str, gap: object) -> float:
        """``gap`` [mm] if this printer prints it between bodies side by side (>= ``min_gap_mm``), else
        ParameterError naming ``name``."""
        return in_range(
            name,
            gap,
            self.min_gap_mm,
            unit="mm",
            tol=1e-12,
            not_a_number="must be a number",
            limit=f"must be >= {self.min_gap_mm:g} mm on {self.key}: the smallest gap it prints "
            "side by side (its min_gap_mm)",
        )

    @property
    def bed_length(self) -> float:
        """The bed's longest side, along which a joint or a straight finger lies [mm]."""
        return max(self.build_volume_mm[:2])

    def fits(self, dx: float, dy: float, dz: float) -> bool:
        """An object of extent dx × dy × dz [mm] fits the build volume (X and Y may swap)."""
        vx, vy, vz = self.build_volume_mm
        return dz <= vz and ((dx <= vx and dy <= vy) or (dy <= vx and dx <= vy))

    @property
    def thickness_is_road_multiple(self) -> bool:
        """True when t must be a whole number of extrusion roads."""
        return abs(self.thickness_step_mm - self.extrusion_width_mm) < 1e-12


# ------------------------------------------------------------------ schemas

#: A profile key: (type, lowest, highest, unit); a number's range is checked, ``None`` bounds are open.
_Spec = tuple[type | tuple[type, ...], float | None, float | None, str]

#: A printer profile's keys; ``name``, ``nozzle_mm``, ``layer_mm``, ``bed_mm`` and ``soluble_support``
#: are required, the rest optional (the derived limits: their rule when absent).
PRINTER_KEYS: dict[str, _Spec] = {
    "name": (str, None, None, ""),
    "nozzle_mm": ((int, float), 0.1, 2.0, "mm"),
    "layer_mm": ((int, float), 0.02, 2.0, "mm"),
    "first_layer_mm": ((int, float), 0.02, 2.0, "mm"),
    "bed_mm": (list, 20.0, 2000.0, "mm"),
    "soluble_support": (bool, None, None, ""),
    "extrusion_width_mm": ((int, float), 0.1, 3.0, "mm"),
    "min_wall_mm": ((int, float), 0.1, 10.0, "mm"),
    "min_gap_mm": ((int, float), 0.05, 5.0, "mm"),
    "min_gap_vertical_mm": ((int, float), 0.02, 5.0, "mm"),
    "thickness_step_mm": ((int, float), 0.01, 3.0, "mm"),
    "source": (str, None, None, ""),
}
PRINTER_REQUIRED = ("name", "nozzle_mm", "layer_mm", "bed_mm", "soluble_support")

#: A material profile's keys; ``clearance_mm`` (at a 0.4 mm nozzle; default 0.40) and ``source`` optional.
MATERIAL_KEYS: dict[str, _Spec] = {
    "name": (str, None, None, ""),
    "youngs_modulus_mpa": ((int, float), 10.0, 50000.0, "MPa"),
    "yield_mpa": ((int, float), 1.0, 2000.0, "MPa"),
    "density_g_cm3": ((int, float), 0.3, 5.0, "g/cm³"),
    "clearance_mm": ((int, float), 0.05, 3.0, "mm"),
    "source": (str, None, None, ""),
}
MATERIAL_REQUIRED = ("name", "youngs_modulus_mpa", "yield_mpa", "density_g_cm3")


def _checked(data: dict[str, Any], keys: dict[str, _Spec], label: str) -> dict[str, Any]:
    """``data`` with every key known, of its type and in range, and the required ones present; numbers as
    floats. ParameterError naming ``label: key``."""
    for k, value in data.items():
        if k not in keys:
            raise ParameterError(f"{label}: {k}", value, f"unknown key; known keys: {', '.join(keys)}")
    for k in PRINTER_REQUIRED if keys is PRINTER_KEYS else MATERIAL_REQUIRED:
        if k not in data:
            raise RjcadError(
                f"{label}: {k} is required (a {'printer' if keys is PRINTER_KEYS else 'material'} "
                f"profile gives {', '.join(PRINTER_REQUIRED if keys is PRINTER_KEYS else MATERIAL_REQUIRED)})"
            )
    out: dict[str, Any] = {}
    for k, value in data.items():
        want, lo, hi, unit = keys[k]
        name = f"{label}: {k}"
        if want is list:
            if not isinstance(value, list) or len(value) != 3:
                raise ParameterError(name, value, "must be [x, y, z], three numbers [mm]")
            out[k] = [_number(f"{name}[{i + 1}]", x, lo, hi, unit) for i, x in enumerate(value)]
        elif want is bool or want is str:
            if not isinstance(value, want):
                raise ParameterError(name, value, f"must be {'true or false' if want is bool else 'a string'}")
            out[k] = value
        else:
            out[k] = _number(name, value, lo, hi, unit)
    return out


def _number(name: str, value: Any, lo: float | None, hi: float | None, unit: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(name, value, f"must be a number [{unit}]" if unit else "must be a number")
    return float(
        in_range(
            name, value, lo, hi, unit=unit, not_a_number="must be a number", limit=f"must be in [{lo:g}, {hi:g}] {unit}"
        )
    )


# ------------------------------------------------------------------ lookup


def user_dir() -> Path:
    """The user's profile folder: platformdirs' user config dir for rjcad (Linux: ``$XDG_CONFIG_HOME/rjcad``,
    by default ``~/.config/rjcad``); printers in ``printers/``, materials in ``materials/``."""
    import platformdirs

    return Path(platformdirs.user_config_dir("rjcad", appauthor=False))


def normalise(name: str) -> str:
    """A profile's key: lower case, ``-`` for ``_`` and spaces."""
    return str(name).strip().lower().replace("_", "-").replace(" ", "-")


def _is_path(name: str) -> bool:
    return name.lower().endswith(".toml") or "/" in name or os.sep in name


def shown_file(kind: str, path: str, builtin: bool) -> str:
    """Where a ``kind`` ("printers" or "materials") profile comes from, as messages print it: ``rjcad/data/KIND/
    NAME.toml`` for a built-in one, else its file below the working or home folder (``shown_path``)."""
    return f"rjcad/data/{kind}/{Path(path).name}" if builtin else shown_path(path)


@functools.lru_cache(maxsize=256)
def _read(kind: str, path: str, mtime_ns: int, size: int, key: str, builtin: bool, ref: str) -> Printer | Material:
    from dataclasses import replace

    from rjcad.io.untrusted import read_toml

    data = read_toml(path, name=shown_file(kind, path, builtin))
    cls = Printer if kind == "printers" else Material
    return replace(cls.from_profile(data, key, file=path, builtin=builtin), ref=ref)


def _load(kind: str, path: Path, key: str, builtin: bool, ref: str) -> Printer | Material:
    try:
        st = path.stat()
    except OSError:
        st = None
    return _read(kind, str(path), st.st_mtime_ns if st else 0, st.st_size if st else 0, key, builtin, ref)


def _files(folder: Path) -> dict[str, Path]:
    """Normalised file stem → path of every ``*.toml`` in ``folder`` (none if it does not exist)."""
    try:
        return {normalise(p.stem): p for p in sorted(folder.glob("*.toml")) if p.is_file()}
    except OSError:
        return {}


@functools.lru_cache(maxsize=2)
def _builtin(kind: str) -> dict[str, Printer | Material]:
    return {key: _load(kind, p, key, True, key) for key, p in _files(DATA / kind).items()}


def find(kind: str, name: str) -> Printer | Material:
    """The printer (``kind`` "printers") or material ("materials") called or stored at ``name``."""
    text = str(name)
    singular = kind[:-1]
    if _is_path(text):
        path = Path(text).expanduser()
        if not path.exists():
            raise ParameterError(singular, text, f"no such {singular} profile file")
        if not path.is_file():  # a FIFO, a device or a folder: the reader refuses it, naming what it is
            from rjcad.io.untrusted import read_toml

            read_toml(path, name=text)
        path = path.resolve()
        return _load(kind, path, normalise(path.stem), False, str(path))
    key = normalise(text)
    user = _files(user_dir() / kind)
    builtin = _builtin(kind)
    if key in user:
        return _load(kind, user[key], key, False, key)
    if key in builtin:
        return builtin[key]
    for found in [_load(kind, p, k, False, k) for k, p in user.items()] + list(builtin.values()):
        if key == normalise(found.name):
            return found
    known = ", ".join(sorted(set(builtin) | set(user)))
    raise ParameterError(singular, name, f"known {kind}: {known}; or the path of a {singular} profile (.toml)")


def get_material(name: str | Material) -> Material:
    """The material called ``name`` (case and ``_``/``-``/space insensitive), or read from the file ``name``."""
    found = name if isinstance(name, Material) else find("materials", name)
    assert isinstance(found, Material)
    return found


def get_printer(name: str | Printer) -> Printer:
    """The printer profile called ``name``, or read from the file ``name``."""
    found = name if isinstance(name, Printer) else find("printers", name)
    assert isinstance(found, Printer)
    return found


def everything(kind: str) -> list[Printer | Material]:
    """Every profile of ``kind`` rjcad can see by name: the user's, then the built-in ones they do not shadow."""
    user = {k: _load(kind, p, k, False, k) for k, p in _files(user_dir() / kind).items()}
    return list(user.values()) + [v for k, v in _builtin(kind).items() if k not in user]


def __getattr__(name: str) -> Any:
    """``MATERIALS`` and ``PRINTERS``: the built-in profiles by key (read on first use)."""
    if name == "MATERIALS":
        return _builtin("materials")
    if name == "PRINTERS":
        return _builtin("printers")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# ------------------------------------------------------------------ manifests


def profile_entries(printer: Printer, material: Material) -> dict[str, Any]:
    """Manifest keys for a user's profiles (``printer_profile``, ``material_profile``: the file and every value,
    so that the manifest is read the same elsewhere); none for the built-in ones."""
    out: dict[str, Any] = {}
    for name, prof in (("printer_profile", printer), ("material_profile", material)):
        if not prof.builtin:
            out[name] = {"file": prof.file, **prof.to_profile()}
    return out


def from_manifest(
    kind: str, name: str | None, extra: dict[str, Any], label: str = "manifest"
) -> Printer | Material | None:
    """The profile a manifest names (``kind`` "printers" or "materials"): the one it embeds
    (``profile_entries``) if any, else ``name`` looked up, else None."""
    embedded = extra.get(f"{kind[:-1]}_profile")
    if isinstance(embedded, dict):
        values = {k: v for k, v in embedded.items() if k != "file"}
        cls = Printer if kind == "printers" else Material
        file = embedded.get("file")
        return cls.from_profile(values, normalise(name or kind[:-1]), file=str(file) if file else "", builtin=False)
    return find(kind, name) if name else None


def printer_of(printer: str | None, manifest: Any = None) -> Printer:
    """The printer a check uses: ``printer`` if given, else the manifest's (its embedded profile first), else
    the default."""
    if printer:
        return get_printer(printer)
    if manifest is not None:
        found = from_manifest("printers", manifest.printer, manifest.extra)
        if isinstance(found, Printer):
            return found
    return get_printer(DEFAULT_PRINTER)


def beside(value: Any, folder: str | os.PathLike[str]) -> Any:
    """A profile named in a file: a relative path (``my.toml``) is taken from that file's ``folder``; a name,
    an absolute path or a non-string unchanged."""
    if isinstance(value, str) and _is_path(value) and not Path(value).expanduser().is_absolute():
        return str(Path(folder) / value)
    return value


def profiles_beside(data: dict[str, Any], folder: str | os.PathLike[str]) -> dict[str, Any]:
    """``data`` (a design file's table) with its ``printer`` and ``material`` taken from ``folder`` (``beside``)."""
    return {k: beside(v, folder) if k in ("printer", "material") else v for k, v in data.items()}
