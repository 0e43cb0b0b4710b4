"""rjcad.identify.fit on a small campaign built in memory (no files): preparation, the BIC formula, a bounded
fit that recovers a known parameter, its 95 % interval, and the identifiability test on known Jacobians."""

import math
from pathlib import Path

import numpy as np
import pytest

from rjcad.identify.bench import trajectory
from rjcad.identify.catalogue import EFFECTS, model_kwargs
from rjcad.identify.data import Campaign, Design, Experiment
from rjcad.identify.fit import Problem, base_values, confidence, param_names, predict, prepare, unidentifiable
from rjcad.physics.joint import JointModel, Setup, simulate

DESIGN = {"stiffness_nmm_per_rad": 5.2, "preload_deg": 70.0}
NOISE = {"bar": 0.1, "tendon": 0.02}  # N·mm, N
MU_J = 6.92  # mm


def campaign(mu_j=MU_J, seed=0, n=1500):
    """Experiments A (bar, 1.5 N) and D (tendon, no load) of a joint with Coulomb pin friction ``mu_j`` only."""
    rng = np.random.default_rng(seed)
    t, theta = trajectory(n, math.radians(90))
    model = JointModel(pulley_radius=6.0, **model_kwargs({**DESIGN, "mu_j_mm": mu_j}))
    exps = []
    for name, drive, fn in (("A", "bar", 1.5), ("D", "tendon", 0.0)):
        y = simulate(model, Setup(drive, fn, False), theta, t=t) + rng.normal(0, NOISE[drive], n)
        th = theta + rng.normal(0, math.radians(0.1), n)
        exps.append(
            Experiment(
                file=f"{name}.csv",
                path=Path(f"{name}.csv"),
                drive=drive,
                normal_load=fn,
                routed=False,
                pulley_radius=6.0,
                t=t,
                theta=th,
                y=y,
                rows=n,
            )
        )
    return Campaign(Path("mem.toml"), Design(5.2, math.radians(70.0), 6.0), tuple(exps))


@pytest.fixture(scope="module")
def problem():
    camp = campaign()
    return Problem(camp, prepare(camp), base_values(camp))


def test_prepare_measures_the_noise_and_folds_whole_cycles(problem):
    for p in problem.prepared:
        assert p.sigma == pytest.approx(NOISE[p.exp.drive], rel=0.15)
        assert p.valid.mean() > 0.8
        folds = p.folds[p.motion.cycle == 0]
        assert len(set(folds)) == 1  # a cycle is never split between folds
    assert problem.N == sum(int(p.valid.sum()) for p in problem.prepared)


def test_base_values_are_the_design_and_every_effect_neutral(problem):
    v = base_values(problem.campaign)
    assert v["stiffness_nmm_per_rad"] == 5.2 and v["preload_deg"] == pytest.approx(70.0)
    assert v["mu_j_mm"] == 0.0 and v["beta_pos"] == 1.0 and v["relaxation_time_s"] == 1.0
    assert set(v) == {n for e in EFFECTS.values() for n in e.param_names}


def test_bic_is_the_profiled_gaussian_formula(problem):
    values = dict(problem.fixed, mu_j_mm=5.0)
    bic, rss, ns = problem.bic(values, 1)
    by_hand_rss = [float(np.sum((p.exp.y - predict(values, p))[p.valid] ** 2)) for p in problem.prepared]
    assert rss == pytest.approx(by_hand_rss, rel=1e-9)
    assert ns == [int(p.valid.sum()) for p in problem.prepared]
    N = sum(ns)
    assert bic == pytest.approx(sum(n * math.log(r / n) for r, n in zip(rss, ns)) + 1 * math.log(N), rel=1e-12)


def test_fit_recovers_the_friction_and_lowers_the_bic(problem):
    without, _, _ = problem.bic(problem.fixed, 0)
    fr = problem.fit(["mu_j_mm"], [1.0], [0.0], [60.0])
    assert fr.names == ("mu_j_mm",) and fr.k == 1
    assert fr.values["mu_j_mm"] == pytest.approx(MU_J, rel=0.02)
    assert fr.bic < without - 100
    # at the truth the residual is the noise: RMSE per experiment close to the injected σ
    for rmse, p in zip(fr.rmse(), problem.prepared):
        assert rmse == pytest.approx(NOISE[p.exp.drive], rel=0.25)
    lo, hi = confidence(fr, problem)["mu_j_mm"]
    assert lo < MU_J < hi and hi - lo < 0.5


def test_no_free_parameter_is_the_fixed_model(problem):
    fr = problem.fit([], [], [], [])
    assert fr.names == () and fr.values == problem.fixed and fr.jac.shape == (problem.N, 0)
    assert fr.bic == pytest.approx(problem.bic(problem.fixed, 0)[0])


def test_unidentifiable_finds_dead_and_confounded_columns():
    rng = np.random.default_rng(5)
    a, b = rng.normal(size=(2, 200))
    J = np.c_[a, 2 * a, b, np.zeros(200)]
    out = unidentifiable(J, ["p", "q", "r", "s"])
    assert out["s"] == "the data do not depend on it"
    assert out["p"] == "confounded with q" and out["q"] == "confounded with p"
    assert "r" not in out
    assert unidentifiable(np.c_[a, b], ["p", "r"]) == {} and unidentifiable(np.zeros((3, 0)), []) == {}


def test_param_names_follow_the_effects_then_the_catalogue():
    assert param_names(["capstan_path", "coulomb_pin"]) == ("beta_pos", "beta_neg", "mu_j_mm")
    assert param_names([]) == ()
