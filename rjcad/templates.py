"""Built-in designs as plain data (no CAD imports): the paper's finger."""

#: The paper's finger (Sec. V); templates/finger.toml says the same.
PAPER_FINGER = {
    "material": "absplus-p430",
    "printer": "generic-0.4",
    "clearance_mm": 0.25,
    "defaults": {"preload_deg": 90, "rotation_deg": 90, "link_length_mm": 40},
    "joint": [{"stiffness_nmm_per_rad": 5.2}, {"stiffness_nmm_per_rad": 7.8}, {"stiffness_nmm_per_rad": 10.4}],
}
