"""The damping at test level (contactid/test_damping.py, gap.damping.test_level_damping, and what the gap diagnosis
does with it, gap.explain.with_damping_at_test_level): small pure parts on hand-made numbers; the profile and its test
on rig records damped otherwise in their dual-sine tests (slow); the default run's in
tests/workflow/test_workflow.py."""

import numpy as np
import pytest
from contactid.friction_fit import FitSettings
from contactid.test_damping import (
    DampingProfile,
    _threshold,
    check_reason,
    driven_mode,
    profile_dataset,
    unprofiled,
)


def test_the_driven_mode_is_the_identified_mode_nearest_the_drive():
    assert driven_mode([54.86, 166.5, 338.1], 54.0) == 0
    assert driven_mode([54.86, 166.5, 338.1], 160.0) == 1


def test_only_the_driven_modes_ratio_is_scaled():
    p = DampingProfile(
        np.array([0.9, 1.0]), np.array([0.01, 0.02]), np.zeros((2, 5)), 0.9, (0.9, 0.9), (True, True), 0.011, mode=1
    )
    np.testing.assert_allclose(p.scaled_ratios([0.003, 0.004, 0.005]), [0.003, 0.0036, 0.005])


def test_the_threshold_is_the_friction_fits_profile_rule_in_misfit_terms():
    s = FitSettings(confidence=0.95, misfit_floor=0.0)
    # chi2(0.95, 1) = 3.841; n = 50 coefficients, six parameters
    assert _threshold(0.01, 50, s) == pytest.approx(0.01 * np.sqrt(1 + 3.841459 * 50 / 44 / 50))
    # the floor on the misfit's scale takes over when the fit's own residual is below it
    assert _threshold(0.001, 50, FitSettings(confidence=0.95, misfit_floor=0.01)) == pytest.approx(
        np.sqrt(0.001**2 + 3.841459 * 1e-4 / 50)
    )


def _profile(scale, check):
    return DampingProfile(
        np.array([0.9, 1.0]),
        np.array([0.01, 0.02]),
        np.arange(10.0).reshape(2, 5),
        scale,
        (0.85, 0.95),
        (True, True),
        0.011,
        mode=0,
        check=check,
    )


def test_the_factor_is_applied_only_where_the_held_out_records_confirm_it():
    ratios = [0.004, 0.005]
    confirmed = _profile(
        0.9, {"accepted": True, "heldout_gap_chain": 0.015, "heldout_gap_updated": 0.006, "record_scatter": 0.0004}
    )
    assert confirmed.applied_scale == 0.9
    np.testing.assert_allclose(confirmed.ratios(ratios), [0.0036, 0.005])
    assert "confirmed" in check_reason(confirmed) and "1.5 %" in check_reason(confirmed)
    refused = _profile(
        0.9, {"accepted": False, "heldout_gap_chain": 0.002, "heldout_gap_updated": 0.004, "record_scatter": 0.0001}
    )
    assert refused.applied_scale == 1.0 and not refused.accepted
    np.testing.assert_allclose(refused.ratios(ratios), ratios)
    np.testing.assert_allclose(refused.scaled_ratios(ratios), [0.0036, 0.005])  # what was weighed
    assert "not confirmed" in check_reason(refused)
    untested = _profile(0.9, None)  # nothing held out
    assert untested.applied_scale == 1.0 and "no load case besides" in check_reason(untested)
    # the law at a factor is the one fitted at the nearest profiled factor
    np.testing.assert_allclose(confirmed.law_at(1.02), np.arange(5.0, 10.0))
    np.testing.assert_allclose(confirmed.law_at_scale(), np.arange(5.0))


def test_the_dataset_keeps_the_profile_the_test_and_the_factor_applied():
    p = _profile(
        0.9, {"accepted": False, "heldout_gap_chain": 0.002, "heldout_gap_updated": 0.004, "record_scatter": 0.0001}
    )
    ds = profile_dataset(p, [0.004, 0.005])
    assert float(ds["damping_scale"]) == 0.9 and float(ds["damping_scale_applied"]) == 1.0
    np.testing.assert_allclose(ds["damping_ratio_test"].values, [0.004, 0.005])
    assert ds.attrs["accepted"] == 0 and ds.attrs["heldout_gap_test_damping"] == 0.004
    assert ds.attrs["heldout_gap_random_test_damping"] == 0.002 and "not confirmed" in ds.attrs["reason"]
    # a configuration that profiles nothing: the random test's ratios
    flat = profile_dataset(unprofiled(), [0.004, 0.005])
    assert float(flat["damping_scale_applied"]) == 1.0 and flat.attrs["accepted"] == 0


@pytest.mark.slow
@pytest.mark.parametrize("factor", [0.9, 1.12])
def test_a_rig_damped_otherwise_in_its_dual_sine_tests_than_in_its_random_test_is_found_and_confirmed(
    small_config, factor
):
    """The rig's damping ``factor`` x in the dual-sine tests what it is in the random test, every mode: the law's
    misfit is least near that factor with every mode's ratio scaled, the held-out load cases confirm it, and the law
    identified with it is within 0.5 % (mu) and 8 % (kappa) of the truth; without it mu is 2-4 % off."""
    import copy

    from contactid.friction_fit import settings_from_config
    from contactid.gap.damping import test_level_damping
    from contactid.gap.pipeline import identify, rig_records
    from contactid.gap.records import record_harmonics
    from contactid.gap.settings import GapSettings
    from contactid.schema import schema_defaults

    cases = ["lc1", "lc2", "lc3"]
    cfg = copy.deepcopy(small_config)
    cfg["rig"]["true_damping"] = {"dual_sine_factor": factor}  # every mode, the dual-sine tests only
    recs, _ = rig_records(cfg, {}, 5, cases)
    K = int(cfg["nonlinear"]["n_harmonics"])
    records = {c: record_harmonics(recs[c], c, K) for c in cases}
    settings = GapSettings.from_config(cfg["gap"], 1, K)
    chain = identify(cfg, recs["random_test"], recs["lc1"])[0]
    held_out = {c: records[c] for c in cases[1:]}
    profile = test_level_damping(
        chain,
        records["lc1"],
        held_out,
        settings_from_config(cfg["friction"]),
        settings,
        1,
        schema_defaults("nonlinear")["test_damping_scales"],
    )
    assert profile.accepted and profile.form == "all"
    assert profile.applied_scale == pytest.approx(factor, rel=0.03)
    assert profile.check["heldout_gap_updated"] < 0.3 * profile.check["heldout_gap_chain"]
    truth = cfg["rig"]["truth"]["friction"]
    law = profile.law_at_scale()
    assert law[4] == pytest.approx(truth["mu"], rel=0.005)
    assert law[3] == pytest.approx(truth["kappa"], rel=0.08)
    assert abs(chain.friction[4] / truth["mu"] - 1) > 0.02  # the chain's law, with the random test's ratios


def test_summary_and_report_say_the_factor_and_whether_the_other_load_cases_confirmed_it():
    from contactid.report_text import test_damping_text
    from contactid.test_damping import damping_summary

    p = _profile(
        0.9, {"accepted": True, "heldout_gap_chain": 0.0149, "heldout_gap_updated": 0.0063, "record_scatter": 7e-5}
    )
    td = damping_summary(profile_dataset(p, [0.004, 0.005]))
    assert td["accepted"] and td["applied_scale"] == 0.9 and td["form"] == "driven" and td["driven_mode"] == 1
    assert td["heldout_gap_test_damping"] == 0.0063 and td["interval"] == [0.85, 0.95]
    assert td["law"] == {"e_f": 0.0, "k_c": 1.0, "e_t": 2.0, "kappa": 3.0, "mu": 4.0}  # fitted at 0.9
    text = test_damping_text(td)
    assert "mode 1's damping ratio $0.900$" in text and "confirm it" in text and r"$0.630\,\%$" in text
    # the law's intervals at the factor, each parameter in its own units, back in the summary
    import dataclasses

    with_law = dataclasses.replace(p, law_intervals=np.arange(10.0).reshape(5, 2), e0_interval=(1.0e7, 1.1e7))
    ds = profile_dataset(with_law, [0.004, 0.005])
    assert ds["law_interval_e_f"].attrs["units"] != ds["law_interval_kappa"].attrs["units"]
    summary = damping_summary(ds)
    assert summary["law_intervals"]["kappa"] == [6.0, 7.0] and summary["e0_interval"] == [1.0e7, 1.1e7]
    refused = damping_summary(profile_dataset(_profile(0.9, {**p.check, "accepted": False}), [0.004, 0.005]))
    assert "do not confirm it" in test_damping_text(refused) and refused["applied_scale"] == 1.0
    assert "random test's damping ratios" in test_damping_text(None)


def test_the_held_out_records_choose_among_the_forms():
    import dataclasses

    from contactid.gap.damping import chosen_test_damping

    def tested(form, misfit, accepted, after):
        p = _profile(0.9, {"accepted": accepted, "heldout_gap_chain": 0.015, "heldout_gap_updated": after})
        return dataclasses.replace(p, form=form, misfits=np.array([misfit, 0.02]))

    # the better fit of the calibration record is refused by the held-out records: the confirmed form is applied
    every, driven = tested("all", 0.0077, False, 0.030), tested("driven", 0.0084, True, 0.0063)
    assert chosen_test_damping([driven, every]).form == "driven"
    # both confirmed: the lower held-out gap
    assert chosen_test_damping([driven, tested("all", 0.0077, True, 0.005)]).form == "all"
    # none confirmed: the least misfit is reported, and not applied
    none = chosen_test_damping([tested("driven", 0.0084, False, 0.02), every])
    assert none.form == "all" and none.applied_scale == 1.0


def test_the_diagnosed_model_carries_the_damping_only_where_no_effect_explains_the_gap():
    from contactid.gap.explain import with_damping_at_test_level

    law = {"e_f": 3.8e7, "k_c": 2.5e5, "e_t": 1e3, "kappa": 0.3, "mu": 0.395}
    td = {
        "accepted": True,
        "form": "driven",
        "driven_mode": 1,
        "scale": 0.91,
        "law": law,
        "heldout_gap_random_test_damping": 0.0149,
        "heldout_gap_test_damping": 0.0063,
        "reason": "confirmed",
    }
    chain = {
        "what": "the identified model (no effect explained)",
        "effects": {},
        "model_updating": None,
        "friction": {"mu": 0.386},
        "heldout_gap": 0.0149,
    }
    out = with_damping_at_test_level(chain, td, [], 68.67)
    assert out["damping_at_test_level"]["applied"] and out["friction"]["mu"] == 0.395
    assert out["heldout_gap"] == 0.0063 and "damping at test level" in out["what"]
    assert out["friction"]["e0_at_preload"] > 0
    # an effect explained: its refit is the model, the damping not applied
    step = [{"effect": "viscous_friction", "kind": "effect"}]
    kept = with_damping_at_test_level({**chain, "effects": {"viscous_friction": {}}}, td, step, 68.67)
    assert not kept["damping_at_test_level"]["applied"] and kept["friction"]["mu"] == 0.386
    assert "effect" in kept["damping_at_test_level"]["why"]
    # a model-form step names no effect: applied
    form = [{"effect": "structural_damping", "kind": "model_form"}]
    assert with_damping_at_test_level(chain, td, form, 68.67)["damping_at_test_level"]["applied"]
    # not confirmed by the held-out records, or the structure updated: not applied
    refused = with_damping_at_test_level(chain, {**td, "accepted": False, "reason": "not confirmed"}, [], 68.67)
    assert not refused["damping_at_test_level"]["applied"] and refused["heldout_gap"] == 0.0149
    updated = with_damping_at_test_level({**chain, "model_updating": {"k_t": 1.0}}, td, [], 68.67)
    assert not updated["damping_at_test_level"]["applied"]
    assert with_damping_at_test_level(chain, None, [], 68.67) == chain


def test_the_reports_paragraph_says_what_became_of_the_factor():
    from contactid.gap.report_diagnosis import damping_at_test_level_text

    td = {
        "form": "driven",
        "driven_mode": 1,
        "scale": 0.91,
        "heldout_gap_random_test_damping": 0.0149,
        "heldout_gap_test_damping": 0.0063,
        "applied": True,
    }
    text = damping_at_test_level_text({"damping_at_test_level": td})
    assert r"\paragraph{Damping at test level.}" in text and "mode 1's damping ratio $0.910$" in text
    assert r"$1.49$\,\%" in text and "carries it" in text and r"updated\_model.json" in text
    refused = damping_at_test_level_text({"damping_at_test_level": {**td, "applied": False, "why": "not confirmed"}})
    assert "Not applied: not confirmed." in refused
    assert damping_at_test_level_text({"damping_at_test_level": {**td, "scale": 1.0}}) == ""
    assert damping_at_test_level_text({}) == ""
