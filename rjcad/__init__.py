"""rjcad: design, build and check 3D-printable elastic rotational joints.

Units inside the package: mm, N, N·mm, rad. Degrees appear only at the CLI, in the Python API's keywords that
end ``_deg``, and in files whose keys or columns say so (``*_deg``).

The Python API (``rjcad.api``; docs/api.md) is reachable from here: ``rjcad.build_joint`` and the other names
of ``API`` import it on first use (PEP 562), so that ``import rjcad`` stays light (no OpenCASCADE, trimesh,
SciPy or numba).
"""

import math

from rjcad.errors import InfeasibleDesign, MissingExtra, ParameterError, RjcadError

#: One degree in radians: ``angle_rad = angle_deg * DEG``.
DEG = math.pi / 180.0

__version__ = "0.1.0"

#: The API's names here → the module that defines them (imported on first use) and their name there.
API = {
    "Box": ("rjcad.api", "Box"),
    "Closure": ("rjcad.api", "Closure"),
    "Cylinder": ("rjcad.api", "Cylinder"),
    "Grasp": ("rjcad.api", "Grasp"),
    "grasp": ("rjcad.api", "grasp"),
    "Finger": ("rjcad.api", "Finger"),
    "Joint": ("rjcad.api", "Joint"),
    "Spring": ("rjcad.api", "Spring"),
    "build_finger": ("rjcad.api", "build_finger"),
    "build_joint": ("rjcad.api", "build_joint"),
    "design_spring": ("rjcad.api", "design_spring"),
    "finger_params": ("rjcad.api", "finger_params"),
    "joint_params": ("rjcad.api", "joint_params"),
    "CheckReport": ("rjcad.check.report", "Report"),
    "CheckResult": ("rjcad.check.report", "CheckResult"),
}

__all__ = ["DEG", "InfeasibleDesign", "MissingExtra", "ParameterError", "RjcadError", "__version__", *API]


def __getattr__(name: str):
    """An API name, imported from its module on first use (then kept here)."""
    if name not in API:
        raise AttributeError(f"module 'rjcad' has no attribute {name!r}")
    import importlib

    module, attr = API[name]
    value = getattr(importlib.import_module(module), attr)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(API))
