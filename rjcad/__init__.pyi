# Types of rjcad/__init__.py for type checkers: with the API's names that it imports on first use (PEP 562).
from rjcad.api import (
    Closure,
    Finger,
    Joint,
    Spring,
    build_finger,
    build_joint,
    design_spring,
    finger_params,
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
    "CheckReport",
    "CheckResult",
    "Closure",
    "Finger",
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
    "joint_params",
]
