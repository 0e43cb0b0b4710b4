"""The spring optimiser (temporary face during the #13 split: the code still lives in rjcad/spring/__init__.py)."""

from rjcad.spring import (  # noqa: F401
    CONSTRAINTS,
    MAX_THICKNESS,
    _infeasible_message,
    design_from_dict,
    design_spring,
    optimise_arrays,
    thickness_candidates,
)
