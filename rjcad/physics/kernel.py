"""How the finger solver's kernels are compiled (numba): the options they share, and why.

``cache=True``: compiled once, then loaded from ``__pycache__``. ``error_model="numpy"``: a float division by zero
gives ±inf or nan instead of raising ZeroDivisionError. On a valid model no divisor in the solver is zero (moment
arms, stiffnesses, time steps and T_r are > 0, γ stays below K, a linear system's pivot is checked first), so no
answer changes. What goes is a zero test and an exception path after each division: numba cannot prune the
reference counting of a kernel's arrays across such paths (an atomic increment and decrement per array per call,
unlike the arithmetic, not free), and with them a step without weight counted references about 100 times and
spent more time on that than on solving.
"""

from __future__ import annotations

from numba import njit

#: A compiled kernel.
kernel = njit(cache=True, error_model="numpy")
#: A small kernel numba writes into each caller (per joint or per tension, called many times a step).
inline_kernel = njit(cache=True, error_model="numpy", inline="always")
#: A whole path's loop: it releases the GIL, so that fits of several candidates run side by side.
path_kernel = njit(cache=True, error_model="numpy", nogil=True)
