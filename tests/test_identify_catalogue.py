"""The effect catalogue carries its own start points and `needs` text; the selector and report only ask it."""

import ast
import inspect

import pytest

from rjcad.identify import select
from rjcad.identify.catalogue import CATALOGUE, EFFECTS
from rjcad.identify.report import _not_identifiable_section
from rjcad.paper import JOINT

DESIGN = {"stiffness_nmm_per_rad": 5.2, "preload_deg": 70.0, "pulley_radius_mm": 6.0}


@pytest.mark.parametrize("eff", CATALOGUE, ids=lambda e: e.id)
def test_needs_text_goes_with_needs(eff):
    assert bool(eff.needs_text) == (eff.needs != "any")


@pytest.mark.parametrize("eff", CATALOGUE, ids=lambda e: e.id)
def test_starts_are_complete_and_inside_the_bounds(eff):
    lo, hi = eff.bounds(DESIGN)
    starts = eff.starts(DESIGN)
    assert starts
    for s in starts:
        assert list(s) == list(eff.param_names)
        for n, a, b in zip(eff.param_names, lo, hi):
            assert a <= s[n] <= b


def test_special_starts():
    assert EFFECTS["spring_calibration"].starts(DESIGN) == [EFFECTS["spring_calibration"].neutral(DESIGN)]
    relax = EFFECTS["relaxation"].starts(DESIGN)
    assert [s["relaxation_time_s"] for s in relax] == [0.6, 1.5, 6.0]
    assert EFFECTS["viscous"].starts(DESIGN) == [EFFECTS["viscous"].typical(DESIGN)]


def test_selector_names_no_effect():
    """select.py treats every effect alike: no effect id appears in it as a string."""
    strings = {
        n.value
        for n in ast.walk(ast.parse(inspect.getsource(select)))
        if isinstance(n, ast.Constant) and isinstance(n.value, str)
    }
    assert not strings & set(EFFECTS)


def test_typical_sizes_are_the_papers():
    typ = {
        **EFFECTS["coulomb_pin"].typical(DESIGN),
        **EFFECTS["tendon_pin_friction"].typical(DESIGN),
        **EFFECTS["capstan_path"].typical(DESIGN),
    }
    assert typ == {
        "mu_j_mm": JOINT.mu_j,
        "gamma_pos_nmm_per_rad": JOINT.gamma_pos,
        "gamma_neg_nmm_per_rad": JOINT.gamma_neg,
        "beta_pos": JOINT.beta_pos,
        "beta_neg": JOINT.beta_neg,
    }


def test_report_hint_reads_the_effect():
    js = {
        "not_identifiable_why": {
            "mu_j_mm": "the residuals do not depend on it",
            "cubic_nmm_per_rad3": "the residuals do not depend on it",
        }
    }
    text = "\n".join(_not_identifiable_section(js))
    assert (
        f"`mu_j_mm` (`coulomb_pin`): the residuals do not depend on it — it needs "
        f"{EFFECTS['coulomb_pin'].needs_text}." in text
    )
    assert "`cubic_nmm_per_rad3` (`stiffening`): the residuals do not depend on it." in text  # needs any: no hint
