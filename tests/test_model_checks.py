"""Model checks (contactid.model_checks): each fit against the accuracy it assumes, and the report's paragraph."""

import numpy as np
import pytest
from contactid.beam_modes import natural_frequencies
from contactid.model_checks import friction_fit_check, model_checks, stiffness_fit_check
from contactid.report_text import model_checks_text
from contactid.stiction import frequency_sigma, stiction_stiffness
from structures import configured_structure

E = 2.164e11
TRUTH = (1.43e7, 2.37e7)


def _stiffness_fit_of_a_rig_with(youngs_modulus):
    """The stiffness fit of the nominal structure (E) to the exact frequencies of a rig whose beam has
    ``youngs_modulus`` (the same contact springs), with the workflow's 0.1 % frequency floor."""
    nominal = configured_structure(tangential_lever_arm=0.00458, youngs_modulus=E)
    rig = configured_structure(tangential_lever_arm=0.00458, youngs_modulus=youngs_modulus)
    f = natural_frequencies(rig.with_contact(*TRUTH), 3)
    return stiction_stiffness(nominal, f, frequency_sigma(f, np.zeros(3), 1e-3))


def test_a_beam_3_percent_softer_than_the_model_fails_the_stiffness_check_and_the_right_one_passes():
    right = _stiffness_fit_of_a_rig_with(E)
    check = stiffness_fit_check(right.chi2_min, 3, 0.95)
    assert check["passed"] and check["dof"] == 1 and check["limit"] == pytest.approx(3.841, abs=1e-3)
    soft = _stiffness_fit_of_a_rig_with(0.97 * E)
    # the fit trades the softer beam for a k_n 6.6 times too soft, with an interval that excludes the truth ...
    assert soft.k_n_interval[1] < TRUTH[1] / 5
    # ... and leaves a chi^2 the nominal structure cannot explain (13.0 for one degree of freedom)
    check = stiffness_fit_check(soft.chi2_min, 3, 0.95)
    assert not check["passed"] and 10 < check["value"] < 16 and check["p_value"] < 1e-3
    assert "cannot reproduce the identified frequencies" in check["message"]


def test_two_frequencies_leave_the_stiffness_fit_nothing_to_check():
    assert stiffness_fit_check(0.0, 2, 0.95) is None
    assert model_checks({"chi2_min": 0.0, "confidence": 0.95}, 2, None) == []


def test_the_friction_check_compares_the_misfit_with_the_accuracy_the_intervals_assume():
    assert friction_fit_check(0.0029, 0.01)["passed"]  # the default data's fit (0.29 %)
    assert friction_fit_check(0.01, 0.01)["passed"]  # at the floor
    failed = friction_fit_check(0.476, 0.01)  # a rig 3 % softer than the model, E (the chain's fit)
    assert not failed["passed"] and "47.6 times" in failed["message"]
    assert not friction_fit_check(float("nan"), 0.01)["passed"]
    # a fit written without its floor: the schema's (0.01)
    checks = model_checks({"chi2_min": 1.0, "confidence": 0.95}, 3, {"misfit_nrmse": 0.02})
    assert [c["check"] for c in checks] == ["stiffness_fit", "friction_fit"]
    assert checks[1]["limit"] == 0.01 and not checks[1]["passed"]


def test_the_report_says_what_a_failed_check_means_and_a_passed_one_in_a_clause():
    ok = model_checks_text(model_checks({"chi2_min": 2.5e-5, "confidence": 0.95}, 3, {"misfit_nrmse": 0.0029}))
    assert ok.startswith(r"\paragraph{Model checks.}") and r"\textbf" not in ok
    assert "reproduces the identified frequencies" in ok and r"$0.290\,\%$" in ok
    bad = model_checks_text(
        model_checks({"chi2_min": 13.1, "confidence": 0.95}, 3, {"misfit_nrmse": 0.476, "misfit_floor": 0.01})
    )
    assert bad.count(r"\textbf{") == 2 and "hold for the model's structure only" in bad
    assert bad.count("{") == bad.count("}")  # balanced for LaTeX
    assert model_checks_text([]) == ""
