"""rjcad: design, build and check 3D-printable elastic rotational joints.

Units inside the package: mm, N, N·mm, rad. Degrees appear only at the CLI
and in files whose keys or columns say so (``*_deg``).
"""

import math

from rjcad.errors import InfeasibleDesign, ParameterError, RjcadError

#: One degree in radians: ``angle_rad = angle_deg * DEG``.
DEG = math.pi / 180.0

__version__ = "0.1.0"

__all__ = ["DEG", "InfeasibleDesign", "ParameterError", "RjcadError", "__version__"]
