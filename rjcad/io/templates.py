"""Built-in designs as plain data (no CAD imports): the default finger and the paper's finger."""

from rjcad.paper import FINGER

#: A finger template's keys and their types (the builder and the physics read the same files).
FINGER_KEYS: dict[str, type | tuple[type, ...]] = {
    "material": str,
    "printer": str,
    "clearance_mm": (int, float),
    "base_length_mm": (int, float),
    "tendon_diameter_mm": (int, float),
    "safety_factor": (int, float),
    "end": str,
    "layout": str,
    "defaults": dict,
    "joint": list,
    "object": list,
}
#: Keys of ``[defaults]`` and of each ``[[joint]]``.
FINGER_JOINT_KEYS: dict[str, type | tuple[type, ...]] = {
    "stiffness_nmm_per_rad": (int, float),
    "preload_deg": (int, float),
    "rotation_deg": (int, float),
    "link_length_mm": (int, float),
    "tendon_moment_arm_mm": (int, float),
    "arms": int,
}

#: The paper's finger (Sec. V, rjcad.paper.FINGER) as the paper printed it: 40 mm links on the Dimension
#: Elite with soluble support, so the stacked layout and its 0.25 mm clearance. The physics commands use it.
PAPER_FINGER = {
    "material": "absplus-p430",
    "printer": "dimension-elite",
    "defaults": {"preload_deg": 90, "rotation_deg": 90, "link_length_mm": FINGER.link_length},
    "joint": [{"stiffness_nmm_per_rad": k} for k in FINGER.designed_stiffness],
}

#: The default finger (templates/finger.toml says the same): the paper's three joints on a desktop printer,
#: in the support-free desktop layout. Its joints are wider than the paper's, so each link is the shortest
#: whole millimetre that holds its two joints' blocks and the tendon slot (the paper's 40 mm cannot).
DEFAULT_FINGER = {
    "material": "absplus-p430",
    "printer": "generic-0.4",
    "base_length_mm": 29,
    "defaults": {"preload_deg": 90, "rotation_deg": 90},
    "joint": [
        {"stiffness_nmm_per_rad": k, "link_length_mm": L} for k, L in zip(FINGER.designed_stiffness, (44, 48, 42))
    ],
}
