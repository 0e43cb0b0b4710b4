"""Unit conversions. Inside rjcad: mm, N, N·mm, rad, s; degrees only at the edges (CLI, named columns)."""

import math

#: One degree in radians: ``angle_rad = angle_deg * DEG``.
DEG = math.pi / 180.0
