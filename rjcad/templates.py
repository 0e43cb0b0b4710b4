"""Built-in designs as plain data (no CAD imports): the paper's finger."""

from rjcad.paper import FINGER

#: The paper's finger (Sec. V, rjcad.paper.FINGER); templates/finger.toml says the same.
PAPER_FINGER = {
    "material": "absplus-p430",
    "printer": "generic-0.4",
    "clearance_mm": 0.25,
    "defaults": {"preload_deg": 90, "rotation_deg": 90, "link_length_mm": FINGER.link_length},
    "joint": [{"stiffness_nmm_per_rad": k} for k in FINGER.designed_stiffness],
}
