"""Issue #37, honest acceptance: an identification says when its residual is not explained, in the same words
and JSON keys for a joint and a finger, and never "nothing was needed" while a residual is left."""

from __future__ import annotations

import copy
import csv
import math

import pytest

from rjcad.identify.verdict import FLOOR_RATIO, NOTHING_NEEDED, OUTSIDE_CATALOGUE, verdict_json, verdict_sentences


def test_the_verdict_keys_and_words():
    explained = verdict_json({"A.csv": 1.02, "B.csv": FLOOR_RATIO}, [])
    assert explained == {"unexplained": False, "unexplained_over_noise": {}, "partial": []}
    assert verdict_sentences({**explained, "effects": []}) == [NOTHING_NEEDED]
    assert verdict_sentences({**verdict_json({"A.csv": 1.0}, ["viscous"]), "effects": ["viscous"]}) == []
    left = verdict_json({"A.csv": 1.0, "B.csv": 2.95, "C.csv": None}, [])
    assert left == {"unexplained": True, "unexplained_over_noise": {"B.csv": 2.95}, "partial": []}
    words = verdict_sentences({**left, "effects": []})
    assert words[-1] == OUTSIDE_CATALOGUE and "B.csv (2.95× noise)" in words[0]
    partial = verdict_json({"B.csv": 2.95}, ["viscous"])
    assert partial["partial"] == ["viscous"]
    (line,) = verdict_sentences({**partial, "effects": ["viscous"]})
    assert "not explained" in line and "`viscous`" in line and "partial" in line and NOTHING_NEEDED not in line


def _drift(path, k, preload_deg, arm, quantity, size=0.05):
    """The spring's stiffness drifting linearly from +size to −size over the run (not a catalogue effect),
    added to a campaign file's measured quantity: δ = size·K·(θ + θ₀)·(1 − 2t/T), as a force over the arm for
    a tendon."""
    with path.open(encoding="utf-8") as f:
        rows = list(csv.reader(f))
    head, data = rows[0], rows[1:]
    t_end = float(data[-1][0])
    col = head.index(quantity)
    for r in data:
        t, theta = float(r[0]), math.radians(float(r[1]))
        d = size * k * (theta + math.radians(preload_deg)) * (1.0 - 2.0 * float(t) / t_end)
        r[col] = f"{float(r[col]) + (d if quantity == 'torque_nmm' else d / arm):.6f}"
    with path.open("w", encoding="utf-8", newline="") as f:
        csv.writer(f).writerows([head, *data])


@pytest.fixture(scope="module")
def drifting(tmp_path_factory):
    from rjcad.identify.bench import write_campaign
    from rjcad.identify.data import load_campaign
    from rjcad.identify.propose import extend
    from rjcad.identify.report import render_markdown
    from rjcad.identify.result import to_json

    base = tmp_path_factory.mktemp("drift") / "c"
    write_campaign(base, [], seed=1)
    camp = load_campaign(base / "campaign.toml")
    for e in camp.experiments:
        _drift(base / e.file, 5.2, 70.0, 6.0, e.quantity)
    js = to_json(*extend(load_campaign(base / "campaign.toml")))
    return js, render_markdown(js)


def test_a_drifting_stiffness_is_flagged_unexplained(drifting):
    js, md = drifting
    assert js["unexplained"] and js["unexplained_over_noise"]
    assert all(v > FLOOR_RATIO for v in js["unexplained_over_noise"].values())
    assert js["partial"] == js["effects"]
    assert NOTHING_NEEDED not in md and "The residual is not explained" in md
    assert [p["term"] for p in js["proposed"]] == ["stiffness_drift"]  # +5 % → −5 %: c = −0.10
    assert js["proposed"][0]["coefficient"] == pytest.approx(-0.10, rel=0.2)
    if not js["effects"]:
        assert OUTSIDE_CATALOGUE in md
    else:
        assert "explain only part of the data: partial" in md


def test_the_finger_report_never_says_nothing_was_needed_over_a_residual():
    """The finger report's words come from the same verdict: with nothing accepted and a quantity 5× its noise,
    it says the design model misses something the catalogue does not hold."""
    from rjcad.identify.finger.result import render_markdown

    js = {
        "design": {"finger": "paper", "joints": 1},
        "effects": [],
        "gain": 1.0,
        "joints": [],
        "ambiguous": [],
        "params": {},
        "param_ci95": {},
        "not_identifiable": [],
        "not_identifiable_why": {},
        "experiments": [
            {
                "file": "A.csv",
                "quantities": ["theta1_deg"],
                "rmse_design": {"theta1_deg": 0.5},
                "rmse_final": {"theta1_deg": 0.5},
                "noise": {"theta1_deg": 0.1},
                "final_over_noise": {"theta1_deg": 5.0},
            }
        ],
        "candidates": [],
        "notes": [],
    }
    left = {**js, **verdict_json({"A.csv: theta1_deg": 5.0}, [])}
    md = render_markdown(left)
    assert OUTSIDE_CATALOGUE in md and "A.csv: theta1_deg (5× noise)" in md and NOTHING_NEEDED not in md
    fine = copy.deepcopy(js)
    fine["experiments"][0]["final_over_noise"]["theta1_deg"] = 1.0
    md = render_markdown({**fine, **verdict_json({"A.csv: theta1_deg": 1.0}, [])})
    assert NOTHING_NEEDED in md and "not explained" not in md
