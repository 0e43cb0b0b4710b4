"""docs/identify.md quotes numbers from the paper campaign's identification: they must match a fresh run."""

from __future__ import annotations

import json
import re

import pytest

from rjcad.identify.data import load_campaign
from rjcad.identify.report import fmt
from rjcad.identify.result import to_json
from rjcad.identify.select import identify


@pytest.fixture(scope="module")
def js(root):
    return to_json(identify(load_campaign(root / "examples" / "paper_campaign" / "campaign.toml")))


def _has(text: str, value, sig: int = 4):
    s = fmt(value, sig)
    alt = s.replace("-", "−")  # the doc uses a typographic minus
    assert s in text or alt in text, f"{s} not quoted in docs/identify.md"


def test_doc_quotes_the_current_numbers(js, root):
    text = (root / "docs" / "identify.md").read_text(encoding="utf-8")
    assert js["effects"] == ["coulomb_pin", "tendon_pin_friction", "capstan_path"]
    for e in js["effects"]:
        assert f"`{e}`" in text
    for name in ("mu_j_mm", "gamma_pos_nmm_per_rad", "gamma_neg_nmm_per_rad", "beta_pos", "beta_neg"):
        _has(text, js["params"][name])
    for s in js["steps"]:
        _has(text, s["delta_bic"])
        _has(text, s["heldout_rmse"], 3)
        _has(text, s["gain"], 3)
    _has(text, js["gain"], 3)
    _has(text, js["heldout_rmse_design"], 3)
    for e in js["experiments"]:
        for key in ("rmse_design", "rmse_final", "noise"):
            _has(text, e[key])
    masked = [e["samples_masked_at_reversals"] for e in js["experiments"]]
    assert f"{min(masked)}–{max(masked)} of 3000" in text
    rejected = {c["effect"]: c for c in js["candidates"] if c["step"] == len(js["steps"]) + 1}
    _has(text, rejected["spring_calibration"]["delta_bic"])
    assert re.search(r"only 0\.10 % of", text) and "0.10%" in rejected["spring_calibration"]["verdict"]


def test_committed_report_matches_a_fresh_run(js, root):
    saved = json.loads((root / "docs" / "identify" / "result.json").read_text())
    assert saved["effects"] == js["effects"]
    for k, v in js["params"].items():
        assert saved["params"][k] == pytest.approx(v, rel=1e-3), k
    assert saved["gain"] == pytest.approx(js["gain"], rel=1e-3)
    for a, b in zip(saved["experiments"], js["experiments"]):
        assert a["rmse_final"] == pytest.approx(b["rmse_final"], rel=1e-3)
