"""Spring life from Table I (issue 8): data, stresses, censored fit, leave-one-out critique, hidden factors,
and the life constraint of the spring optimiser."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rjcad import life
from rjcad import spring as sp
from rjcad.errors import InfeasibleDesign
from rjcad.spring import optimise as opt


def test_packaged_table_i_with_its_conditions():
    tab = life.read_table()
    assert tab.meta["material"] == "absplus-p430" and float(tab.meta["width_mm"]) == 4.8
    assert float(tab.meta["rotation_deg"]) == 90 and float(tab.meta["preload_deg"]) == 90
    assert float(tab.meta["rate_cycles_per_min"]) == 30 and "Table I" in tab.meta["source"]
    assert tab.cycles.tolist() == [4.0e5, 4.9e5, 3.0e4, 4.0e4, 2.3e4, 1.2e5, 8.5e5]
    assert tab.censored.tolist() == [False] * 6 + [True]  # the run-out


@pytest.mark.parametrize("row", [0, 1, 2, 3, 4, 6])
def test_table_i_stresses_from_the_rod_model(row):
    # each row's spring (L, p, t from Table I; b 4.8 mm; r_in 3 mm assumed; clamped end; the designer's unwinding
    # sense) wound 0 → 180° by the rod model itself: its peak and its amplitude over the 90° → 180° cycle
    from scipy.optimize import brentq

    from rjcad.spring import rod

    tab = life.read_table()
    L, p, t = tab.length[row], tab.pitch[row], tab.thickness[row]
    n = brentq(lambda k: rod.archimedean_length(3.0, p, k) - L, 0.5, 40.0)
    res = rod.spiral_windup(3.0, p, n, 4.8, t, 2200.0, end="clamped", sense="unwind", theta_max=math.pi, steps=36)
    amp = (res.stress[-1] - np.interp(math.pi / 2, res.theta, res.stress)) / 2
    # the designer's (surrogate) stresses take the worst moment factor m over the cycle for both of its ends: the
    # amplitude within −1 % (m rises a little over the cycle, row 7) and +5 % (it falls, rows 3 and 4) of the rod's
    assert amp * 0.99 <= life.table_i().stress_amp[row] <= amp * 1.05
    assert res.stress.max() * 0.995 <= life.table_i_peaks()[row] <= res.stress.max() * 1.03
    # the old closed form with a pinned end, 0.8·E·t·θ/L, put the peak well above it
    assert 0.8 * 2200 * t * math.pi / L > 1.2 * res.stress.max()


def _negll_reference(params, X, y, cens):
    """The censored-normal negative log-likelihood written with scipy.stats (an independent check)."""
    from scipy.stats import norm

    beta, s = np.asarray(params[:-1]), math.exp(params[-1])
    mu = X @ beta
    return -(norm.logpdf(y[~cens], mu[~cens], s).sum() + norm.logsf(y[cens], mu[cens], s).sum())


@pytest.mark.parametrize("effects", [(), ("pin_backlash",), ("thin_strip",)])
def test_newton_fit_is_the_maximum_likelihood(effects):
    from scipy.optimize import minimize

    d = life.table_i()
    m = life.fit(d, effects)
    X, y = m.design(d), np.log10(d.cycles)
    ours = _negll_reference(list(m.beta()) + [math.log(m.params["s"])], X, y, d.censored)
    assert -ours == pytest.approx(m.loglik, abs=1e-9)
    bounds = [(None, None), (0, None)] + [(None, None)] * (len(effects) + 1)
    ref = min(
        (
            minimize(_negll_reference, x0, args=(X, y, d.censored), method="L-BFGS-B", bounds=bounds)
            for x0 in ([5, 1] + [0] * len(effects) + [-1], [8, 3] + [-1] * len(effects) + [-1.5])
        ),
        key=lambda r: r.fun,
    )
    assert ours <= ref.fun + 1e-6  # no optimiser finds a better point


def test_censored_row_is_a_survival_not_a_failure():
    d = life.table_i()
    i = int(np.flatnonzero(d.censored)[0])
    for effects in [(), ("pin_backlash",)]:
        base = life.fit(d, effects)
        later = life.fit(life.table_i(runout_bound=1.0e6), effects)
        # surviving longer must raise the fitted life of that design (and the law's level a)
        assert later.mean_log10(d)[i] > base.mean_log10(d)[i] + 1e-3
        assert later.params["a"] > base.params["a"]
    # a run-out is P(N > bound): read as a failure at the bound it would pull the fit down
    base = life.fit(d)
    as_failure = life.fit(life.LifeData(d.stress_amp, d.thickness, d.backlash, d.cycles, np.zeros(d.n, bool)))
    assert as_failure.params["a"] < base.params["a"] - 1e-3
    assert as_failure.loglik != pytest.approx(base.loglik)


def test_extended_model_beats_stress_only_in_leave_one_out():
    c = life.critique()
    out = c.to_dict()
    assert out["baseline"]["loo_rmse_log10"] > 0.6  # the stress-only law misses by ~5x in held-out rows
    assert out["extended"]["effects"] == ["pin_backlash"]
    assert out["extended"]["loo_rmse_log10"] < 0.5 * out["baseline"]["loo_rmse_log10"]
    assert out["gain"] == pytest.approx(out["baseline"]["loo_rmse_log10"] / out["extended"]["loo_rmse_log10"])
    assert out["gain"] > 1.8
    # the stress exponent sits on its bound: stress alone explains nothing in Table I
    assert out["baseline"]["variants"]["with_stress"]["params"]["m"] == 0.0
    # rows 5 and 6 differ only in backlash: the extended model separates them, the stress-only one cannot
    rows = out["rows"]
    assert rows[4]["baseline_cycles"] == pytest.approx(rows[5]["baseline_cycles"])
    assert rows[4]["extended_cycles"] < rows[5]["extended_cycles"] / 5
    assert abs(rows[4]["extended_residual_log10"]) < abs(rows[4]["baseline_residual_log10"])
    assert sum(out["akaike_weights"].values()) == pytest.approx(1.0)
    assert out["akaike_weights"]["pin_backlash"] > 0.5
    # the backlash coefficient's 95 % profile interval excludes 0 (a real effect) and holds the estimate
    lo, hi = out["extended"]["intervals_95"]["c_backlash"]
    assert lo < out["extended"]["params"]["c_backlash"] < hi < 0


def test_profile_interval_is_where_the_likelihood_drops_by_1_92():
    d = life.table_i()
    m = life.fit(d, ("pin_backlash",), stress=False)
    lo, hi = life.profile_interval(d, ("pin_backlash",), "c_backlash", model=m)
    for v in (lo, hi):
        prof = life.fit(d, ("pin_backlash",), fixed={"c_backlash": v}, stress=False).loglik
        assert m.loglik - prof == pytest.approx(1.9207, abs=1e-3)


def test_design_model_is_the_critiques_choice():
    c = life.critique(intervals=False)
    assert c.chosen == life.DESIGN_EFFECTS
    assert c.extended.stress == life.DESIGN_STRESS_TERM
    assert life.life_model().params == pytest.approx(c.extended.params)


def test_prediction_interval_brackets_the_median_and_widens_with_level():
    med, lo, hi = life.predict_cycles([4.0, 8.0], [1.0, 0.8], backlash=0.25)
    assert np.all(lo < med) and np.all(med < hi)
    _, lo99, hi99 = life.predict_cycles([4.0, 8.0], [1.0, 0.8], backlash=0.25, level=0.99)
    assert np.all(lo99 < lo) and np.all(hi99 > hi)
    assert life.predict_cycles(4.0, 1.0, 0.75)[0][0] < life.predict_cycles(4.0, 1.0, 0.25)[0][0] / 5


# ---------------------------------------------------------------- hidden factors (synthetic tables)


def synthetic(n, seed, backlash_per_mm=0.0, thin_per_road_ratio=0.0, m=3.0, noise=0.15, runout=2e6):
    """A fatigue table from a known law, written here and not told to the tool:
    log10 N = 6.5 − m·log10 σa + backlash_per_mm·(backlash − 0.25) + thin·(0.5 mm / t) + N(0, noise),
    with lives above ``runout`` cut to run-outs."""
    rng = np.random.default_rng(seed)
    amp = 10 ** rng.uniform(math.log10(2.0), math.log10(12.0), n)
    t = rng.choice([0.5, 0.8, 1.0, 1.2], n)
    bl = rng.choice([0.25, 0.5, 0.75], n)
    logn = (
        6.5
        - m * np.log10(amp)
        + backlash_per_mm * (bl - 0.25)
        + thin_per_road_ratio * (0.5 / t)
        + rng.normal(0.0, noise, n)
    )
    cyc = 10**logn
    return life.LifeData(amp, t, bl, np.minimum(cyc, runout), cyc >= runout)


# robust: 30 of 30 seeds pass each case at n = 30 (checked when written); three fixed seeds run here
@pytest.mark.parametrize("seed", [11, 12, 13])
@pytest.mark.parametrize(
    "effect, kw, coef",
    [("pin_backlash", {"backlash_per_mm": -1.6}, -0.8), ("thin_strip", {"thin_per_road_ratio": -1.5}, -1.5)],
)
def test_hidden_factor_is_named_with_its_sign_and_size(effect, kw, coef, seed):
    d = synthetic(30, seed, **kw)
    c = life.critique(d, intervals=False)
    assert c.chosen == (effect,)
    got = c.extended.params[life.EFFECTS[effect].param]  # c_backlash is per 0.5 mm: −1.6/mm → −0.8
    assert np.sign(got) == np.sign(coef) and abs(got - coef) < 0.35 * abs(coef)
    assert c.extended.stress and c.extended.params["m"] == pytest.approx(3.0, abs=0.6)
    assert c.to_dict()["gain"] > 1.25


@pytest.mark.parametrize("seed, m", [(21, 3.0), (22, 3.0), (23, 3.0), (24, 0.0)])
def test_no_hidden_factor_keeps_the_stress_only_law(seed, m):
    c = life.critique(synthetic(30, seed, m=m), intervals=False)
    assert c.chosen == ()
    assert c.to_dict()["gain"] == pytest.approx(1.0)
    if m > 0:
        assert c.baseline.model.stress and c.baseline.model.params["m"] == pytest.approx(3.0, abs=0.5)


def test_selection_frequencies_small_run():
    f = life.selection_frequencies(life.critique(intervals=False), n_sim=12, seed=1)
    assert set(f) == {"stress_only", "pin_backlash", "thin_strip"}
    for row in f.values():
        assert sum(row.values()) == pytest.approx(1.0)
    assert f["pin_backlash"]["pin_backlash"] > 0.5  # the fitted backlash effect is findable at Table I's points


# ---------------------------------------------------------------- life as an optimiser constraint


def test_spring_json_has_predicted_life_without_min_cycles():
    d = opt.design_spring(sp.SpringRequirement(5.2, math.pi / 2, math.pi / 2)).to_dict()
    lo, hi = d["predicted_cycles_interval"]
    assert lo < d["predicted_cycles"] < hi and d["backlash_mm"] == 0.25 and d["min_cycles"] is None
    med, lo2, _ = life.predict_cycles(d["stress_amplitude_mpa"], d["thickness_mm"], 0.25)
    assert d["predicted_cycles"] == pytest.approx(med[0]) and lo == pytest.approx(lo2[0])


def test_min_cycles_constraint_meets_or_names_life():
    req = dict(joint_stiffness=5.2, rotation=math.pi / 2, preload=math.pi / 2)
    base = opt.design_spring(sp.SpringRequirement(**req))
    ok = opt.design_spring(sp.SpringRequirement(**req, min_cycles=1e5))
    assert ok.predicted_life()[1] >= 1e5
    assert ok.to_dict()["outer_radius_mm"] == base.to_dict()["outer_radius_mm"]
    with pytest.raises(InfeasibleDesign) as e:
        opt.design_spring(sp.SpringRequirement(**req, min_cycles=1e5, backlash=0.75))
    assert e.value.constraint == "life"
    msg = str(e.value)
    assert "\n" not in msg and "--min-cycles" in msg and "backlash 0.75 mm" in msg and "--backlash" in msg


_REQ = st.tuples(
    st.floats(1.0, 20.0), st.floats(30.0, 120.0), st.floats(0.0, 120.0), st.floats(1e3, 1e6), st.floats(0.1, 1.0)
)


@settings(max_examples=60, deadline=None)
@given(_REQ)
def test_life_constraint_property(args):
    K, rot, pre, n_min, backlash = args
    kw = dict(joint_stiffness=K, rotation=math.radians(rot), preload=math.radians(pre), outer_radius_max=60.0)
    try:
        free = opt.design_spring(sp.SpringRequirement(**kw))
    except InfeasibleDesign:
        free = None
    req = sp.SpringRequirement(**kw, min_cycles=n_min, backlash=backlash)
    try:
        dsg = opt.design_spring(req)
    except InfeasibleDesign as e:
        assert e.constraint in opt.CONSTRAINTS
        if free is not None:  # only the life constraint can have made a feasible requirement infeasible
            assert e.constraint == "life"
            assert life.predict_cycles(free.stress_amplitude, free.thickness, backlash)[1][0] < n_min
        return
    assert dsg.predicted_life()[1] >= n_min * (1 - 1e-9)  # a returned design meets it
    assert free is not None
    if not life.life_model().stress:  # life independent of stress: the optimum must not move
        assert dsg.to_dict()["outer_radius_mm"] == free.to_dict()["outer_radius_mm"]


@pytest.mark.slow  # many full rod-model verifications: full suite only (fast lane < 2 min)
@settings(max_examples=40, deadline=None)
@given(st.floats(1.0, 20.0), st.floats(30.0, 150.0), st.floats(1e3, 1e7))
def test_life_constraint_with_a_stress_dependent_model(K, rot, n_min):
    # swap in a law whose life falls with stress (m ≈ 3), so --min-cycles must widen the spring
    saved = life._CACHE.get("m")
    life._CACHE["m"] = life.fit(synthetic(30, 5, backlash_per_mm=-1.6), ("pin_backlash",), stress=True)
    try:
        kw = dict(joint_stiffness=K, rotation=math.radians(rot), preload=math.pi / 2, outer_radius_max=60.0)
        try:
            free = opt.design_spring(sp.SpringRequirement(**kw))
        except InfeasibleDesign:
            return
        try:
            dsg = opt.design_spring(sp.SpringRequirement(**kw, min_cycles=n_min))
        except InfeasibleDesign as e:
            assert e.constraint in opt.CONSTRAINTS
            assert life.predict_cycles(free.stress_amplitude, free.thickness, 0.25)[1][0] < n_min
            return
        assert dsg.predicted_life()[1] >= n_min * (1 - 1e-9)
        if free.predicted_life()[1] < n_min:  # the constraint bound: a lower stress amplitude was needed
            assert dsg.stress_amplitude < free.stress_amplitude
    finally:
        if saved is None:
            life._CACHE.pop("m", None)
        else:
            life._CACHE["m"] = saved
