"""rjcad: design, build and check 3D-printable elastic rotational joints.

Units inside the package: mm, N, N·mm, rad. Degrees appear only at the CLI
and in files whose keys or columns say so (``*_deg``).
"""

from rjcad.errors import InfeasibleDesign, ParameterError, RjcadError

__version__ = "0.1.0"

__all__ = ["InfeasibleDesign", "ParameterError", "RjcadError", "__version__"]
