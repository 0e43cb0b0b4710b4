"""FDM materials and printer profiles.

Values are for printed parts, in MPa and g/cm³. A spiral printed flat (joint
axis vertical, spring width ``b`` along Z) bends along its roads, the strong
in-plane direction, so the in-plane (XY/XZ-on-edge) datasheet values apply.
Where sources give a range, the lower strength is taken: the optimiser
divides it by a safety factor, and an optimistic yield is the failure that
hurts.
"""

from __future__ import annotations

from dataclasses import dataclass

from rjcad.errors import ParameterError
from rjcad.validate import in_range

DEFAULT_MATERIAL = "absplus-p430"
DEFAULT_PRINTER = "generic-0.4"


@dataclass(frozen=True)
class Material:
    """A printable polymer: modulus ``E`` and strength in MPa, density in g/cm³."""

    key: str
    name: str
    youngs_modulus_mpa: float
    yield_strength_mpa: float
    density_g_cm3: float
    source: str
    #: Print-in-place clearance on a desktop 0.4 mm printer (pin to eye, cone to cone, coil to coil) [mm].
    desktop_clearance_mm: float = 0.40

    @property
    def strength_to_modulus(self) -> float:
        """σ_y/E, the figure of merit for compliant parts (dimensionless)."""
        return self.yield_strength_mpa / self.youngs_modulus_mpa


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


#: Where the desktop clearances come from.
DESKTOP_CLEARANCE_SOURCE = (
    "desktop print-in-place practice for a 0.4 mm nozzle and 0.2 mm layers (issue #15): "
    "PLA 0.35 mm, ABS 0.40 mm, PETG 0.45 mm (it strings and sticks to itself); PA12 and "
    "Ultem taken as PETG"
)

MATERIALS: dict[str, Material] = {
    m.key: m
    for m in (
        Material(
            "absplus-p430",
            "ABSplus-P430",
            2200.0,
            31.0,
            1.04,
            "Stratasys ABSplus-P430 datasheet: tensile modulus 2,200 MPa, "
            "tensile yield 31 MPa, ultimate 33 MPa (XZ); the paper's material",
        ),
        Material(
            "abs-m30",
            "ABS-M30",
            2413.0,
            33.0,
            1.04,
            "Stratasys ABS-M30 datasheet (2,413 MPa = 350 ksi, 36 MPa ultimate) and "
            "Loughborough University tensile tests (33-36 MPa); lower strength taken",
        ),
        Material(
            "pla",
            "PLA",
            3000.0,
            35.0,
            1.24,
            "Stratasys PLA datasheet and typical filament datasheets: E 2,500-3,500 MPa, "
            "XY strength 26-45 MPa; mid modulus, lower-middle strength taken",
            desktop_clearance_mm=0.35,
        ),
        Material(
            "petg",
            "PETG",
            2100.0,
            44.0,
            1.27,
            "typical PETG filament datasheets: E 2,000-3,000 MPa, XY yield 44-56 MPa; lower values taken",
            desktop_clearance_mm=0.45,
        ),
        Material(
            "pa12",
            "PA12",
            1400.0,
            43.0,
            1.01,
            "3D Systems PA12 datasheet: E about 1,400 MPa, tensile strength about 43 MPa",
            desktop_clearance_mm=0.45,
        ),
        Material(
            "ultem-9085",
            "Ultem 9085",
            2400.0,
            69.0,
            1.34,
            "Stratasys ULTEM 9085 resin datasheet: E about 2,200-2,400 MPa, tensile strength 69-72 MPa",
            desktop_clearance_mm=0.45,
        ),
    )
}

PRINTERS: dict[str, Printer] = {
    p.key: p
    for p in (
        Printer(
            "generic-0.4",
            "Generic FDM, 0.4 mm nozzle, no soluble support",
            nozzle_mm=0.4,
            extrusion_width_mm=0.4,
            layer_height_mm=0.2,
            min_wall_mm=0.8,
            min_gap_mm=0.25,
            min_gap_vertical_mm=0.4,
            thickness_step_mm=0.4,
            soluble_support=False,
            build_volume_mm=(220.0, 220.0, 250.0),
            source="rjcad default for desktop FDM: walls of 2 roads, vertical gaps of 2 layers",
        ),
        Printer(
            "dimension-elite",
            "Stratasys Dimension Elite (the paper's printer), soluble support",
            nozzle_mm=0.3,
            extrusion_width_mm=0.5,
            layer_height_mm=0.178,
            min_wall_mm=0.5,
            min_gap_mm=0.25,
            min_gap_vertical_mm=0.25,
            thickness_step_mm=0.05,
            soluble_support=True,
            build_volume_mm=(203.0, 203.0, 305.0),
            source="Stratasys Dimension Elite spec sheet (203x203x305 mm, 0.178 mm layers); "
            "the paper printed 0.5 mm strips and 0.25 mm backlash with soluble support",
        ),
    )
}


def _normalise(name: str) -> str:
    return str(name).strip().lower().replace("_", "-").replace(" ", "-")


def get_material(name: str) -> Material:
    """The material called ``name`` (case and ``_``/``-``/space insensitive)."""
    key = _normalise(name)
    for m in MATERIALS.values():
        if key in (m.key, _normalise(m.name)):
            return m
    raise ParameterError("material", name, f"known materials: {', '.join(MATERIALS)}")


def get_printer(name: str) -> Printer:
    """The printer profile called ``name``."""
    key = _normalise(name)
    if key in PRINTERS:
        return PRINTERS[key]
    raise ParameterError("printer", name, f"known printers: {', '.join(PRINTERS)}")
