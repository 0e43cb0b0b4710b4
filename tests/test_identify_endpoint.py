"""Finger endpoints as data (issue #18, part 2: the paper's finger endpoint as a campaign): every set of effects
that explains a few end angles is found, the simplest is the answer, and the others are reported as what the
endpoints cannot decide."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rjcad.errors import RjcadError
from rjcad.identify.campaign import load_campaign
from rjcad.identify.finger.bench import _template_text
from rjcad.identify.finger.catalogue import catalogue, model_of
from rjcad.identify.finger.data import design_from_file
from rjcad.identify.finger.endpoint import identify_endpoints, render_markdown
from rjcad.io.templates import PAPER_FINGER
from rjcad.physics.finger import simulate_path


def _campaign(d, finger, endpoints):
    (d / "f.toml").write_text(_template_text(finger))
    text = 'finger = "f.toml"\n'
    for td, th, sig in endpoints:
        text += f"\n[[endpoint]]\ntendon_mm = {td}\ntheta_deg = {json.dumps(list(th))}\nsigma_deg = {sig}\n"
    (d / "campaign.toml").write_text(text)
    return d / "campaign.toml"


@pytest.mark.slow
def test_paper_endpoint_names_the_families_it_cannot_tell_apart(tmp_path, cli):
    """The paper's 65/50/50° at 25 mm with the paper's design: per-joint moment arms explain it with the fewest
    parameters, and the same arms as the endpoint fit of rjcad.physics.paper_finger (reference solver, its own
    parametrisation); the softer distal springs with a common arm (paper-finger.md's family) explain it as well and
    are reported, with the same values; so are families with more parameters than angles."""
    from rjcad.physics import paper_finger as pf

    path = _campaign(tmp_path, PAPER_FINGER, [(25.0, [65, 50, 50], 2.0)])
    js = identify_endpoints(load_campaign(path))
    fams = {e.name: e for e in pf.explanations()}
    arms = fams["moment arms per joint"].params
    assert js["effects"] == ["moment_arm"] and js["explained"]
    for j in (1, 2, 3):
        assert js["params"][f"tendon_moment_arm_mm_j{j}"] == pytest.approx(arms[f"r{j}_mm"], rel=0.01)
    soft = next(a for a in js["ambiguous"] if "stiffness_nmm_per_rad_j2" in a["params"])
    fam = fams["moment arm + distal springs softer"].params
    assert soft["params"]["moment_arm_scale"] * 6.0 == pytest.approx(fam["r_mm"], rel=0.01)
    assert soft["params"]["stiffness_nmm_per_rad_j2"] == pytest.approx(7.8 * fam["k2_scale"], rel=0.01)
    assert soft["free_parameters"] == 3 and abs(soft["delta_bic"]) < 1e-3
    kinds = {tuple(a["effects"]) for a in js["ambiguous"]}
    assert ("coulomb_pin", "moment_arm") in kinds  # paper-finger.md's pin-friction family
    assert all("record" in a["separate_by"] for a in js["ambiguous"])
    assert js["gain"] > 10 and js["experiments"][0]["rmse_design"]["theta2_deg"] == pytest.approx(40.0, abs=0.5)
    md = render_markdown(js)
    assert "## What the endpoints cannot decide" in md and "| endpoint 1 | 25 | 65.0, 50.0, 50.0 |" in md
    r = cli("identify", str(path), "--json", str(tmp_path / "r.json"))
    assert r.code == 0, r.err
    assert "explains it as well: spring_calibration, moment_arm" in r.out
    assert json.loads((tmp_path / "r.json").read_text())["kind"] == "finger-endpoint"


@pytest.mark.slow
def test_hidden_capstan_found_from_one_endpoint(tmp_path):
    """An endpoint simulated with tendon friction along the finger (μα = 0.3) at 14 mm, where no joint is at a
    stop (distal springs a little softer: the joints close together): the one-parameter answer is the capstan, within 5 %;
    the design model does not explain it."""
    finger = {**PAPER_FINGER, "joint": [{"stiffness_nmm_per_rad": k} for k in (6.0, 5.6, 5.2)]}
    (tmp_path / "f.toml").write_text(_template_text(finger))
    design = design_from_file(tmp_path / "f.toml", "f.toml", "test").model
    vals = {}
    for e in catalogue(design):
        vals.update(e.neutral(None))
    vals["mu_alpha"] = 0.3
    end = np.degrees(simulate_path(model_of(vals, design, None), np.linspace(0, 14.0, 600)).theta[-1])
    assert 1 < end.min() and end.max() < 89
    js = identify_endpoints(load_campaign(_campaign(tmp_path, finger, [(14.0, end.round(3).tolist(), 0.5)])))
    assert js["effects"] == ["capstan_along_finger"]
    assert js["params"]["mu_alpha"] == pytest.approx(0.3, rel=0.05)
    design_fit = js["candidates"][0]
    assert design_fit["effects"] == [] and not design_fit["explains"]
    assert all(a["free_parameters"] >= 1 for a in js["ambiguous"])


def test_bad_endpoint_campaigns(tmp_path):
    cases = {
        "count": ([(25.0, [65, 50], 2.0)], "3 angles"),
        "stroke": ([(-1.0, [65, 50, 50], 2.0)], "tendon_mm"),
        "sigma": ([(25.0, [65, 50, 50], 0.0)], "sigma_deg"),
    }
    for name, (eps, words) in cases.items():
        d = tmp_path / name
        d.mkdir()
        with pytest.raises(RjcadError, match=words):
            load_campaign(_campaign(d, PAPER_FINGER, eps))
    d = tmp_path / "mixed"
    d.mkdir()
    path = _campaign(d, PAPER_FINGER, [(25.0, [65, 50, 50], 2.0)])
    path.write_text(path.read_text() + '\n[[experiment]]\nfile = "a.csv"\ndrive = "finger"\n')
    with pytest.raises(RjcadError, match="cannot be mixed"):
        load_campaign(path)
    path.write_text('finger = "f.toml"\n[[endpoint]]\ntendon_mm = 25\ntheta_deg = [65, 50, 50]\nangle = 3\n')
    with pytest.raises(RjcadError, match="unknown key 'angle'"):
        load_campaign(path)
