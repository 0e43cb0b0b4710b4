"""Spring lifetime from the paper's Table I: a stress-only Basquin law, its critique, and extensions.

- :mod:`~rjcad.life.table`: Table I as shipped and as model input (stresses from ``rjcad.spring.formulas``).
- :mod:`~rjcad.life.effects`: the candidate causes (terms added to the mean log life).
- :mod:`~rjcad.life.likelihood`: censored-normal maximum likelihood, profile intervals, leave-one-out.
- :mod:`~rjcad.life.critique`: the stress-only law against each cause (AICc, leave-one-out, bootstrap).
- :mod:`~rjcad.life.constraint`: the design model, as the spring optimiser's life constraint.
- :mod:`~rjcad.life.doc`: docs/life.md and life.png.

From the spring package this imports only ``rjcad.spring.formulas`` (which imports nothing from rjcad),
so ``rjcad.spring.optimise`` can import ``rjcad.life`` without a cycle.
"""

from rjcad.life.constraint import _CACHE as _CACHE  # re-exported: the tests swap the cached design model
from rjcad.life.constraint import (
    DESIGN_EFFECTS,
    DESIGN_STRESS_TERM,
    amplitude_limit,
    life_model,
    predict_cycles,
    remedy,
)
from rjcad.life.critique import LOO_CUT, Candidate, Critique, critique, selection_frequencies, simulate
from rjcad.life.doc import write_doc, write_plot
from rjcad.life.effects import EFFECTS, ROAD_WIDTH, Effect
from rjcad.life.likelihood import LEVEL, LifeModel, fit, loo, loo_rmse, profile_interval
from rjcad.life.table import LifeData, Table, read_table, row_stresses, table_i, table_i_peaks

__all__ = [
    "DESIGN_EFFECTS",
    "DESIGN_STRESS_TERM",
    "EFFECTS",
    "LEVEL",
    "LOO_CUT",
    "ROAD_WIDTH",
    "Candidate",
    "Critique",
    "Effect",
    "LifeData",
    "LifeModel",
    "Table",
    "amplitude_limit",
    "critique",
    "fit",
    "life_model",
    "loo",
    "loo_rmse",
    "predict_cycles",
    "profile_interval",
    "read_table",
    "remedy",
    "row_stresses",
    "selection_frequencies",
    "simulate",
    "table_i",
    "table_i_peaks",
    "write_doc",
    "write_plot",
]
