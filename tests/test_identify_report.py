"""The identification report: files and PNGs, the text against the JSON, not-identifiable and null cases."""

import copy

import matplotlib.image as mpimg
import numpy as np
import pytest

from rjcad.errors import RjcadError
from rjcad.identify.bench import write_campaign
from rjcad.identify.catalogue import EFFECTS
from rjcad.identify.data import load_campaign
from rjcad.identify.report import fmt, render_markdown, unit_of, write_report
from rjcad.identify.result import to_json
from rjcad.identify.select import identify

FILES = ["fit.png", "residuals.png", "steps.png", "diagnostics.png", "report.md"]
ROUTED_ONLY = [{"name": "C", "drive": "tendon", "normal_load": 0.0, "routed": True}]


def _run(tmp_path_factory, name, effects, **kw):
    """Synthetic campaign → identification → report; (ident, js, paths, report.md text)."""
    base = tmp_path_factory.mktemp(name)
    write_campaign(base / "campaign", effects, seed=1, **kw)
    ident = identify(load_campaign(base / "campaign" / "campaign.toml"))
    js = to_json(ident)
    paths = write_report(ident, js, base / "out" / "report")
    return ident, js, paths, (base / "out" / "report" / "report.md").read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def paper(tmp_path_factory):
    return _run(tmp_path_factory, "paper", ["coulomb_pin", "tendon_pin_friction", "capstan_path"])


@pytest.fixture(scope="module")
def routed_only(tmp_path_factory):
    return _run(tmp_path_factory, "routed", ["tendon_pin_friction", "capstan_path"], experiments=ROUTED_ONLY)


@pytest.fixture(scope="module")
def null(tmp_path_factory):
    return _run(tmp_path_factory, "null", [])


def test_all_files_written_and_pngs_are_images(paper):
    _, _, paths, _ = paper
    out = paths[0].parent
    assert [p.name for p in paths] == FILES
    assert sorted(p.name for p in out.iterdir()) == sorted(FILES)  # no temporary files left behind
    for p in paths[:3]:
        raw = p.read_bytes()
        assert raw.startswith(b"\x89PNG\r\n\x1a\n") and len(raw) > 20_000, p.name
        img = mpimg.imread(p)
        assert img.ndim == 3 and img.shape[0] > 300 and img.shape[1] > 500
        assert float(np.std(img[..., :3])) > 0.05, f"{p.name} is blank"


def test_effects_causes_and_step_table(paper):
    _, js, _, md = paper
    assert js["effects"] == ["coulomb_pin", "tendon_pin_friction", "capstan_path"]
    for i, eid in enumerate(js["effects"], 1):
        assert f"{i}. `{eid}` — {EFFECTS[eid].cause}." in md
    assert f"| 0 | design simulation | — | — | {fmt(js['heldout_rmse_design'], 3)} | 1 |" in md
    for i, s in enumerate(js["steps"], 1):
        assert s["action"] == "added"
        short = EFFECTS[s["effect"]].name
        row = (
            f"| {i} | `{s['effect']}` | {short} | {fmt(s['delta_bic'])} | {fmt(s['heldout_rmse'], 3)} | "
            f"{fmt(s['gain'], 3)} |"
        )
        assert row in md
    for png in ("fit.png", "residuals.png", "steps.png", "diagnostics.png"):
        assert f"]({png})" in md


def test_experiment_table_params_and_noise_floor(paper):
    _, js, _, md = paper
    for e in js["experiments"]:
        unit = "N·mm" if e["quantity"] == "torque_nmm" else "N"
        label = "torque" if unit == "N·mm" else "tendon force"
        row = (
            f"| {e['file']} | {label} [{unit}] | {fmt(e['rmse_design'])} | {fmt(e['rmse_final'])} | "
            f"{fmt(e['noise'])} | {fmt(e['final_over_noise'], 3)} | "
            f"{e['samples_masked_at_reversals']} of {e['samples']} | 0 |"
        )
        assert row in md
        assert e["samples_masked_at_reversals"] > 0
    for name, (lo, hi) in js["param_ci95"].items():
        assert f"| `{name}` | " in md and f"[{fmt(lo)}, {fmt(hi)}] | {unit_of(name)} |" in md
    assert "mu_j_mm = " + fmt(js["params"]["mu_j_mm"]) + " mm" in md
    # the spring was not fitted here: its parameters show as design values
    assert "| `stiffness_nmm_per_rad` | `spring_calibration` | 5.2 | not fitted (design value) |" in md
    assert "at the noise floor in all 5 experiments" in md
    assert "## Not identifiable" not in md
    assert "## Rejected candidates" in md and "## Diagnostics" in md
    # the design residual's evidence, as diagnose worded it
    ev = js["experiments"][0]["diagnostics_design"]["hints"][0]["evidence"]
    assert ev in md


def test_not_identifiable_section(routed_only):
    ident, js, _paths, md = routed_only
    assert ident.not_identifiable, "identify did not flag β/γ as confounded on a single routed tendon experiment"
    assert "## Not identifiable from this campaign" in md
    assert "were **not fitted**" in md
    for name, why in js["not_identifiable_why"].items():
        assert f"- `{name}` (" in md and why in md
    assert "confounded with" in md
    accepted = js["effects"][0]
    other = "capstan_path" if accepted == "tendon_pin_friction" else "tendon_pin_friction"
    assert f"The parameters of `{accepted}` are confounded with" in md and f"(`{other}`)" in md
    # a frozen parameter is never shown with an interval
    for name in js["not_identifiable"]:
        assert name not in js["param_ci95"]
    assert "at the noise floor in all" not in md and "The final residual is at the noise floor." in md


def test_null_case(null):
    _, js, paths, md = null
    assert js["effects"] == [] and js["steps"] == []
    assert "Nothing beyond the design model was needed" in md
    assert "Found:" not in md and "## Not identifiable" not in md
    table = [line for line in md.splitlines() if line.startswith("| ") and "design simulation" in line]
    assert table == [f"| 0 | design simulation | — | — | {fmt(js['heldout_rmse_design'], 3)} | 1 |"]
    assert all(p.exists() and p.stat().st_size > 10_000 for p in paths[:3])
    # every candidate of the only step appears as rejected
    for c in js["candidates"]:
        assert f"| `{c['effect']}` | 1 | {fmt(c['delta_bic'])} |" in md


def test_dropped_step_and_notes_render(paper):
    _, js, _, _ = paper
    js = copy.deepcopy(js)
    s = dict(js["steps"][-1], action="dropped", delta_bic=-3.2, heldout_rmse=1.01, gain=80.0)
    js["steps"].append(s)
    js["notes"].append("A_bar_Fn1.5.csv: dropped 3 of 3000 rows (2 non-numeric, 1 NaN)")
    md = render_markdown(js)
    assert f"| B1 | `{s['effect']}` (dropped) | {EFFECTS[s['effect']].name} | -3.2 | 1.01 | 80 |" in md
    assert "backward pass" in md
    assert "## Notes" in md and "- A_bar_Fn1.5.csv: dropped 3 of 3000 rows" in md
    assert "](fit.png)" not in md  # no plots given: none linked


def test_rerun_is_byte_identical_and_bad_out_dir(routed_only, tmp_path):
    ident, js, paths, _ = routed_only
    again = write_report(ident, js, tmp_path / "again")
    for a, b in zip(paths, again):
        assert a.read_bytes() == b.read_bytes(), a.name
    (tmp_path / "file").write_text("x")
    with pytest.raises(RjcadError, match="not a directory"):
        write_report(ident, js, tmp_path / "file")


def test_number_and_unit_formatting():
    assert fmt(-24880.4) == "-24880"
    assert fmt(0.0197953) == "0.0198"
    assert fmt(3.12607) == "3.126"
    assert fmt(0.949429, 3) == "0.949"
    assert fmt(5.04e-5) == "5.040e-05"
    assert fmt(None) == "—" and fmt(float("nan")) == "—" and fmt(0.0) == "0"
    assert unit_of("mu_j_mm") == "mm" and unit_of("preload_deg") == "deg"
    assert unit_of("gamma_pos_nmm_per_rad") == "N·mm/rad" and unit_of("cubic_nmm_per_rad3") == "N·mm/rad³"
    assert unit_of("viscous_nmm_s_per_rad") == "N·mm·s/rad" and unit_of("relaxation_time_s") == "s"
    assert unit_of("beta_pos") == "–"
