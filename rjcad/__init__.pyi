# Types of rjcad/__init__.py for type checkers: with the API's names that it imports on first use (PEP 562).
from rjcad.api import (
    Box,
    Closure,
    Cylinder,
    Finger,
    Grasp,
    Joint,
    Spring,
    build_finger,
    build_joint,
    design_spring,
    finger_params,
    grasp,
    joint_params,
)
from rjcad.check.report import CheckResult
from rjcad.check.report import Report as CheckReport
from rjcad.errors import InfeasibleDesign, MissingExtra, ParameterError, RjcadError

DEG: float
__version__: str
API: dict[str, tuple[str, str]]

__all__ = [
    "DEG",
    "Box",
    "CheckReport",
    "CheckResult",
    "Closure",
    "Cylinder",
    "Finger",
    "Grasp",
    "InfeasibleDesign",
    "Joint",
    "MissingExtra",
    "ParameterError",
    "RjcadError",
    "Spring",
    "__version__",
    "build_finger",
    "build_joint",
    "design_spring",
    "finger_params",
    "grasp",
    "joint_params",
]
