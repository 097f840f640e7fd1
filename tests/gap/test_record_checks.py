"""The records against each other and against the identified model (contactid.gap.record_checks): each decision on
synthetic harmonics, where the answer is known by construction."""

import numpy as np
import pytest
from contactid.gap.record_checks import (
    RECORDS_DISAGREE,
    Thresholds,
    accelerance_levels,
    diagnosis_outcome,
    model_evidence,
    records_check,
)
from contactid.schema import schema_defaults

SENSORS = ("a1", "a2", "a3")


def _prediction(seed=0, j=3, H=9):
    """A response the model predicts (j sensors, H harmonics; odd harmonics strongest, as a dual-sine drive's)."""
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(j, H)) + 1j * rng.normal(size=(j, H))
    P[:, 0] *= 20 * (1 + np.arange(j))
    P[:, 2] *= 10
    return P


def _noisy(P, share, seed=1):
    rng = np.random.default_rng(seed)
    n = rng.normal(size=P.shape) + 1j * rng.normal(size=P.shape)
    return P + share * np.linalg.norm(P) * n / np.linalg.norm(n)


def _check(held_out, calibration_gap=0.015, **th):
    """records_check of a calibration case leaving ``calibration_gap`` and one held-out record ``held_out(P)``."""
    P = _prediction()
    ev = {
        "lc1": model_evidence("lc1", SENSORS, _noisy(P, calibration_gap), P),
        "lc2": model_evidence("lc2", SENSORS, held_out(P), P),
    }
    return records_check({}, ev, "lc1", Thresholds(**th))


def test_thresholds_default_to_the_schema():
    assert Thresholds() == Thresholds.from_config(schema_defaults("gap", "record_checks"))


def test_a_record_of_the_same_rig_passes():
    out = _check(lambda P: _noisy(P, 0.03, seed=5))
    assert out["passed"] and out["findings"] == []


@pytest.mark.parametrize(
    "transform, check, words",
    [
        (lambda P: _noisy(P, 0.02) / 9.80665, "units_or_sign", ["0.102 times", "near 1/9.80665", "in g"]),
        (lambda P: _noisy(P, 0.02) * 1000.0, "units_or_sign", ["near 1000", "mm/s^2"]),
        (lambda P: -_noisy(P, 0.02), "units_or_sign", ["opposite sign", "flipped"]),
        (lambda P: _noisy(P, 0.02)[[1, 0, 2]], "channel_map", ["a1 holds what is predicted at a2", "swapped"]),
        (lambda P: _noisy(P, 0.02) * np.array([[1.0], [1.5], [1.0]]), "one_channel", ["channel a2 reads 1.5 times"]),
        (lambda P: _noisy(P, 0.02) * np.array([[1.0], [1.0], [-1.0]]), "one_channel", ["channel a3", "opposite sign"]),
    ],
)
def test_a_units_factor_sign_or_channel_order_is_named(transform, check, words):
    out = _check(transform)
    assert not out["passed"]
    (f,) = out["findings"]
    assert f["record"] == "lc2" and f["check"] == check and f["signature"]
    for w in words:
        assert w in f["message"], (w, f["message"])
    verdict, reason, explanation = diagnosis_outcome("normal_contact_damping", "shrinks 60 %", [{"effect": "x"}], out)
    assert verdict == RECORDS_DISAGREE and explanation == [] and "check units, signs, channel map" in reason


def test_a_gross_gap_of_no_known_form_is_a_warning_that_keeps_the_verdict():
    """A held-out record 10x the calibration case's gap and beyond gross_gap, which no factor, sign or channel order
    explains (a structure that changed, an effect outside the library): named, the verdict kept; the same
    disagreement below gross_gap is not named."""
    rng = np.random.default_rng(3)
    out = _check(lambda P: P * (1 + 0.8 * rng.normal(size=P.shape)))
    assert out["passed"]
    (f,) = out["findings"]
    assert f["check"] == "gross" and not f["signature"] and "grossly" in f["message"]
    verdict, reason, _ = diagnosis_outcome("none", "no candidate shrinks the gap", [], out)
    assert verdict == "none" and reason.startswith("lc2: the record disagrees") and "no candidate" in reason
    out = _check(lambda P: P * (1 + 0.8 * np.random.default_rng(3).normal(size=P.shape)), gross_gap=5.0)
    assert out["findings"] == []


def test_an_effect_on_the_level_is_not_taken_for_units():
    """A held-out case 20 % softer in every sensor (a nonlinearity at its level) is neither a units factor nor gross
    (below gross_gap); a gap under ten times the calibration case's is not looked at."""
    out = _check(lambda P: _noisy(P, 0.02) * 0.8)
    assert out["passed"] and out["findings"] == []
    assert _check(lambda P: _noisy(P, 0.1), calibration_gap=0.05)["trace"][0]["passed"]


def test_the_level_test_names_the_case_off_by_a_units_factor():
    rng = np.random.default_rng(0)
    F = np.array([2.0, 0.1, 1.0, 0.0])
    base = rng.normal(size=(3, 4)) + 1j * rng.normal(size=(3, 4))
    checks = {
        c: {"f0": 54.0, "acceleration": base * (1 + 0.1 * k) * F, "force": F}
        for k, c in enumerate(("lc1", "lc2", "lc3"))
    }
    assert records_check(accelerance_levels(checks), {}, "lc1", Thresholds())["passed"]
    checks["lc3"]["acceleration"] = checks["lc3"]["acceleration"] / 9.80665
    out = records_check(accelerance_levels(checks), {}, "lc1", Thresholds())
    (f,) = out["findings"]
    assert f["record"] == "lc3" and "near 1/9.80665" in f["message"] and not out["passed"]
    # two cases: which one is off is not known, both are named
    two = {c: checks[c] for c in ("lc1", "lc3")}
    assert all(
        "lc1 or lc3" in f["message"] or "lc3 or lc1" in f["message"]
        for f in records_check(accelerance_levels(two), {}, "lc1", Thresholds())["findings"]
    )


def test_the_benchmark_counts_the_checks_false_alarms():
    from contactid.gap.bench_scores import records_check_score

    rows = [
        {"records_check": {"passed": True, "findings": []}},
        {"records_check": {"passed": False, "findings": ["units_or_sign"]}},
        {"records_check": {"passed": True, "findings": ["gross"]}},
        {"failed": "the rig's records of lc2 are not finite"},
    ]
    assert records_check_score(rows) == {"items": 3, "false_alarms": 1, "gross_warnings": 1}


def test_cases_driven_at_other_frequencies_are_not_compared_by_level():
    """The accelerance of one structure changes with the drive frequency: a case at 60 Hz is not compared with cases
    at 54 Hz, and alone at its frequency it is not looked at."""
    from contactid.gap.record_checks import same_drive_groups

    F = np.array([2.0, 0.1, 1.0])
    A = np.ones((3, 3), complex)
    checks = {"lc1": {"f0": 54.0}, "lc2": {"f0": 54.1}, "lc3": {"f0": 60.0}, "lc4": {"f0": 54.05}}
    for k, c in enumerate(checks):
        checks[c].update(acceleration=A * (10.0 if c == "lc3" else 1.0 + 0.01 * k) * F, force=F)
    levels = accelerance_levels(checks)
    assert same_drive_groups(levels) == [["lc1", "lc4", "lc2"], ["lc3"]]
    assert records_check(levels, {}, "lc1", Thresholds())["findings"] == []


def test_records_whose_force_sign_is_flipped_everywhere_are_named_through_the_calibration_case():
    """Every record's force flipped (one acquisition's sign error): the model fitted to the calibration record cannot
    reproduce it either, so the held-out records are no worse than it; a calibration gap beyond gross_gap is looked
    at too, and a sign that explains it is named."""
    P = _prediction()
    ev = {c: model_evidence(c, SENSORS, -0.8 * _noisy(P, 0.3, seed=k), P) for k, c in enumerate(("lc1", "lc2"))}
    out = records_check({}, ev, "lc1", Thresholds())
    assert not out["passed"]
    assert {f["record"] for f in out["findings"]} == {"lc1", "lc2"}
    (cal,) = [f for f in out["findings"] if f["record"] == "lc1"]
    assert "does not reproduce even its calibration record" in cal["message"] and "opposite sign" in cal["message"]


def test_a_response_the_model_overpredicts_at_one_level_is_no_units_error():
    """A contact that opens at the highest level (the blind benchmark's contact-separation items): the record's
    response is a fifth of the model's prediction, a common factor explains most of the gap, but the record's
    accelerance among its peers is as theirs: the model, not the record, is off (a gross warning, the verdict kept).
    The same factor near 1/9.81 that the peers show too is the record's units."""
    P = _prediction()
    levels = {c: (54.0, np.ones((3, 2), complex) * (1.0 + 0.05 * k)) for k, c in enumerate(("lc1", "lc2", "lc3"))}
    ev = {
        "lc1": model_evidence("lc1", SENSORS, _noisy(P, 0.01), P),
        "lc3": model_evidence("lc3", SENSORS, 0.2 * _noisy(P, 0.1), P),
    }
    out = records_check(levels, ev, "lc1", Thresholds())
    assert out["passed"] and [f["check"] for f in out["findings"]] == ["gross"]
    ev["lc3"] = model_evidence("lc3", SENSORS, _noisy(P, 0.02) / 9.80665, P)
    assert records_check(levels, ev, "lc1", Thresholds())["passed"]  # the peers do not show it: not the record's
    levels["lc3"] = (54.0, levels["lc3"][1] / 9.80665)
    out = records_check(levels, ev, "lc1", Thresholds())
    assert not out["passed"] and {f["check"] for f in out["findings"]} == {"accelerance_level", "units_or_sign"}


def test_a_factor_the_peers_see_only_partly_is_no_units_error():
    """Contact separation at one level: the model overpredicts the record 9 times and its peers see it 1.8 times
    lower than theirs: not the record's units. Without peers a factor counts within a third of the tolerance of a
    units factor: 9.0 does not (8 % off 9.81), 9.75 does."""
    P = _prediction()
    one = np.ones((3, 2), complex)
    levels = {"lc1": (54.0, one), "lc2": (54.0, one), "lc3": (54.0, one / 1.8)}
    ev = {
        "lc1": model_evidence("lc1", SENSORS, _noisy(P, 0.01), P),
        "lc3": model_evidence("lc3", SENSORS, _noisy(P, 0.05) / 9.0, P),
    }
    assert records_check(levels, ev, "lc1", Thresholds())["passed"]
    alone = {"lc1": levels["lc1"], "lc3": (60.0, one)}  # lc3 alone at its drive: no peer
    assert records_check(alone, ev, "lc1", Thresholds())["passed"]
    ev["lc3"] = model_evidence("lc3", SENSORS, _noisy(P, 0.05) / 9.75, P)
    assert not records_check(alone, ev, "lc1", Thresholds())["passed"]


def test_a_units_factor_names_its_direction():
    """One table for every check (contactid.units_factors): a record 1/9.81 times off is in g labelled m/s^2, 1000
    times off in mm/s^2 (or its force in kN), 1/1000 its force in mN; 4.5 (lbf's 4.448) is no units factor here."""
    from contactid.units_factors import units_error

    assert "g labelled m/s^2" in units_error(0.102, 0.15)[1]
    assert "mm/s^2" in units_error(980.0, 0.15)[1] and units_error(980.0, 0.15)[0] == 1000.0
    assert "mN" in units_error(1.1e-3, 0.15)[1]
    assert units_error(4.5, 0.15) is None and units_error(0.102, 0.15)[0] == pytest.approx(1 / 9.80665)
    assert units_error(0.125, 0.15) is None and units_error(0.125, 0.3) is not None
