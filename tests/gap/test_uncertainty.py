"""Friction intervals with a model-form term (issue 15, item 6): the spreads, the widening, and the physics
behind the structural term (the data bind mu a, not mu)."""

import dataclasses

import numpy as np
import pytest
from contactid.friction_fit import FitSettings
from contactid.gap.uncertainty import (
    NAMES,
    FrictionUncertainty,
    bound_products,
    spread_sd,
    widened_interval,
    with_e0,
)


def params(mu=0.4, kappa=0.28, e0_scale=1.0):
    return with_e0([3.8e7 * e0_scale, 2.55e5, 0.0, kappa, mu], 70.0)


def test_spread_of_load_cases_is_the_rms_change_on_each_parameters_scale():
    best = params()
    alt = [params(mu=0.44, kappa=0.30), params(mu=0.36, kappa=0.24)]
    sd = spread_sd(best, alt)
    i_mu, i_kappa = NAMES.index("mu"), NAMES.index("kappa")
    assert sd[i_mu] == pytest.approx(np.sqrt((np.log(1.1) ** 2 + np.log(0.9) ** 2) / 2), rel=1e-12)  # mu: on ln
    assert sd[i_kappa] == pytest.approx(np.sqrt((0.02**2 + 0.04**2) / 2), rel=1e-12)  # kappa: linear
    assert np.all(spread_sd(best, []) == 0)


def test_spread_of_structure_pairs_adds_the_half_differences_of_each_axis_in_quadrature():
    best = params()
    # two axes: mu moves +-5 % along the first, +-2 % along the second
    alt = [params(mu=0.4 / 1.05), params(mu=0.4 * 1.05), params(mu=0.4 / 1.02), params(mu=0.4 * 1.02)]
    sd = spread_sd(best, alt, pairs=True)
    assert sd[NAMES.index("mu")] == pytest.approx(np.hypot(np.log(1.05), np.log(1.02)), rel=1e-12)


def test_interval_is_widened_by_z_sd_on_each_side_and_clipped_to_the_bounds():
    bounds = FitSettings().bounds
    value = params()
    profile = np.column_stack([value * 0.99, value * 1.01])
    profile[NAMES.index("kappa")] = [0.27, 0.29]
    sd = np.zeros(6)
    sd[NAMES.index("mu")] = 0.1
    sd[NAMES.index("kappa")] = 0.5  # far beyond kappa's bounds [0, 0.95]
    out = widened_interval(profile, sd, 0.95, bounds)
    i = NAMES.index("mu")
    assert out[i, 0] == pytest.approx(0.99 * 0.4 * np.exp(-1.959964 * 0.1), rel=1e-6)
    assert out[i, 1] == pytest.approx(1.01 * 0.4 * np.exp(1.959964 * 0.1), rel=1e-6)
    assert list(out[NAMES.index("kappa")]) == [0.0, 0.95]
    j = NAMES.index("e_f")  # no spread: the profile interval as it was
    assert list(out[j]) == pytest.approx(list(profile[j]))


def test_coverage_and_relative_halfwidth():
    value = params()
    interval = np.column_stack([value * 0.9, value * 1.1])
    u = FrictionUncertainty(value, interval, np.zeros(6), np.zeros(6), interval, 0.95, {}, [])
    assert u.covers({"mu": 0.43, "kappa": 0.2, "e0": None}) == {"mu": True, "kappa": False}
    assert u.relative_halfwidth(("mu",))["mu"] == pytest.approx(0.1)
    assert u.summary()["mu"]["scale"] == "log" and u.summary()["kappa"]["scale"] == "linear"


@pytest.mark.slow  # rig records, the chain and three friction refits (about 15 s)
def test_what_the_data_bind_keeps_its_interval_when_the_lever_arm_opens_mus():
    # structures along two axes: the lever arm +-10 % (mu and e_0 refit as 1/a and 1/a^2: mu a, e_0 a^2 stay),
    # then E +-1 % with mu +-2 % at the same arm; a = 7.5 mm
    a = 7.5e-3
    value = params()
    i_e0 = NAMES.index("e0")
    fits = [params(mu=0.4 / s) for s in (0.9, 1.1)] + [params(mu=0.4 * s) for s in (0.98, 1.02)]
    for f, s in zip(fits, (0.9, 1.1)):
        f[i_e0] = value[i_e0] / s**2
    arms = [0.9 * a, 1.1 * a, a, a]
    profile = np.column_stack([value * 0.99, value * 1.01])
    sd_cases = np.zeros(6)
    sd_cases[NAMES.index("mu")] = 0.01
    out = bound_products(value, profile, sd_cases, a, fits, arms, 0.95)
    mu_a, e0_a2 = out["mu_a"], out["e0_a2"]
    assert mu_a["value"] == pytest.approx(0.4 * a) and mu_a["unit"] == "m"
    half = (np.log(1.02) - np.log(0.98)) / 2
    assert mu_a["sd_structure"] == pytest.approx(half, rel=1e-9)  # the lever arm's axis adds nothing
    assert e0_a2["sd_structure"] == pytest.approx(0.0, abs=1e-12)
    z = 1.959964
    assert mu_a["interval"][1] == pytest.approx(1.01 * 0.4 * a * np.exp(z * np.hypot(0.01, half)), rel=1e-6)
    # while mu's own structure spread carries the lever arm's 10 %
    assert spread_sd(value, fits, pairs=True)[NAMES.index("mu")] > 0.09
    u = FrictionUncertainty(value, profile, sd_cases, np.zeros(6), profile, 0.95, {}, fits, out)
    assert u.covers({"mu_a": 0.4 * a * 1.02, "e0_a2": value[NAMES.index("e0")] * a**2 * 1.05}) == {
        "mu_a": True,
        "e0_a2": False,
    }
    assert u.summary()["e0_a2"]["unit"] == "N m" and u.relative_halfwidth(("mu_a",))["mu_a"] < 0.1


@pytest.mark.slow
def test_the_data_bind_mu_times_the_lever_arm_not_mu(default_config):
    """Scaling the tangential lever arm a by lambda (with k_t / lambda^2, so that the linear data stay the same)
    scales the identified S by 1 / lambda and xi by lambda: the refitted mu moves by 1 / lambda while mu a and
    e_0 a^2 stay. That is why the structural term of mu's interval follows the lever arm's prior."""
    from contactid.friction_fit import settings_from_config
    from contactid.gap.pipeline import identify, rig_records
    from contactid.gap.records import record_harmonics
    from contactid.gap.uncertainty import _refit

    cfg = default_config
    recs, _ = rig_records(cfg, {}, 1, ["lc1"])
    model, _, _, _ = identify(cfg, recs["random_test"], recs["lc1"])
    rec = record_harmonics(recs["lc1"], "lc1", 25)
    fit_settings = settings_from_config(cfg["friction"])
    out = {}
    for lam in (1.0, 1.05, 0.95):
        p = model.structure
        p2 = p.replace(tangential_lever_arm=lam * p.tangential_lever_arm).with_contact(p.k_t / lam**2, p.k_n)
        out[lam] = with_e0(
            _refit(dataclasses.replace(model, structure=p2), rec, fit_settings, 1, "lever").params, model.preload
        )
    mu, e0 = NAMES.index("mu"), NAMES.index("e0")
    for lam in (1.05, 0.95):
        assert abs(out[lam][mu] / out[1.0][mu] - 1) > 0.04  # mu itself moves with the lever arm ...
        assert out[lam][mu] * lam == pytest.approx(out[1.0][mu], rel=3e-3)  # ... mu a does not
        assert out[lam][e0] * lam**2 == pytest.approx(out[1.0][e0], rel=0.03)  # e_0 a^2 nearly (k_b is finite)
