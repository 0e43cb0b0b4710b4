"""Issue #37 for whole fingers: a residual the finger catalogue cannot explain is flagged, no catalogue effect is
named for it, and the missing term is proposed (per joint, or between the actuator and the tendon) with its
coefficient. The data come from tests/hidden_finger_bench.py, a finger simulator written for these tests apart
from rjcad's finger model."""

from __future__ import annotations

import hidden_finger_bench as hb
import pytest

from rjcad.identify.campaign import load_campaign
from rjcad.identify.finger.propose import FingerBasis
from rjcad.identify.finger.result import render_markdown, to_json
from rjcad.identify.propose import extend
from rjcad.identify.verdict import NOTHING_NEEDED, OUTSIDE_CATALOGUE


def _identified(folder, effect, size, **kw):
    """The JSON and report of `rjcad identify`'s finger path on the bench's campaign (1500 samples per experiment:
    the answers are those of 3000, in half the time)."""
    camp = load_campaign(hb.write(folder, effect, size, samples=1500, **kw))
    js = to_json(*extend(camp, basis=FingerBasis(camp.design.model.n)))
    return js, render_markdown(js)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("effect", "size", "joints", "term", "truth", "words"),
    [
        # every spring +5 % → −5 % over each run: the angles do not see a common scale, the tension does
        ("drift", 0.05, (1, 2, 3), "stiffness_drift", -0.10, "every spring's stiffness drifts over each run"),
        # joint 2's spring 5 % stiffer while the tendon is pulled, 5 % softer while released
        ("direction", 0.05, (2,), "direction_stiffness_j2", 0.05, "+5.0% while the tendon is pulled"),
        # a 1.5 mm play between the actuator and the tendon (c: half of it)
        ("backlash", 1.5, (1, 2, 3), "actuator_backlash_", 0.75, "a backlash of"),
    ],
)
def test_a_hidden_effect_outside_the_finger_catalogue_is_proposed(tmp_path, effect, size, joints, term, truth, words):
    js, md = _identified(tmp_path, effect, size, joints=joints)
    assert js["unexplained"] and js["unexplained_over_noise"]  # the catalogue's answer on the data as measured
    assert js["effects"] == [] and js["partial"] == []  # no catalogue effect named for it
    (p,) = js["proposed"]
    assert p["term"].startswith(term) and p["coefficient"] == pytest.approx(truth, rel=0.2)
    assert words in p["words"] and p["ci95"][0] <= p["coefficient"] <= p["ci95"][1]
    assert p["heldout_rmse_after"] < 1.1 < 1.5 < p["heldout_rmse_before"]
    assert OUTSIDE_CATALOGUE in md and p["words"] in md and any("outside it explains" in n for n in js["notes"])
    assert all(v <= 1.2 for e in js["experiments"] for v in e["final_over_noise"].values())  # beside the term


def test_the_null_finger_is_explained_and_nothing_is_proposed(tmp_path):
    js, md = _identified(tmp_path, "none", 0.0)
    assert not js["unexplained"] and js["effects"] == [] and js["proposed"] == [] and js["catalogue_only"] is None
    assert NOTHING_NEEDED in md


def test_a_direction_stiffness_common_to_every_spring_is_said_to_be_the_capstan_too(tmp_path):
    """Every spring 5 % stiffer while pulled scales the tension only, as a capstan before the actuator does: the
    catalogue's capstan_path explains it (β± = 1 ± 5 %), and the report says the data cannot tell them apart."""
    js, md = _identified(tmp_path, "direction", 0.05)
    assert js["effects"] == ["capstan_path"] and js["proposed"] == []
    assert js["params"]["beta_pos"] == pytest.approx(1.05, rel=0.01)
    assert js["params"]["beta_neg"] == pytest.approx(0.95, rel=0.01)
    assert any("cannot tell" in n and "stiffness that differs by direction" in n for n in js["notes"])
    assert "the data cannot tell them apart" in md
