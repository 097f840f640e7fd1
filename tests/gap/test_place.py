"""Where the gap lies without the rig (gap/place.py): every threshold of the place, and where an effect acts, on
hand-made numbers (milliseconds). tests/gap/test_gap.py and tests/workflow/test_workflow.py check the same decisions on
rig data."""

import numpy as np
import pytest
from contactid.gap import place as V
from contactid.gap.place import place


def quiet_stage(**kw):
    return {"open_fraction": 0.0, "contact_force_N": 0.05, "contact_force_S": 0.012, **kw}


def drift(*z, change=0.01):
    return {f"lc{i + 1}": {"change": change, "z": v} for i, v in enumerate(z)}


ID_RES, SCATTER = [0.002, 0.002, 0.002], [0.001, 0.001, 0.001]  # misfit 2 standard errors: consistent


def test_consistent_records_put_the_gap_in_the_tangential_contact():
    name, reason = place(drift(1.0, 1.2, 0.8), quiet_stage(), ID_RES, SCATTER)
    assert name == "tangential_contact" and "the friction law leaves 1.2% of S" in reason


def test_drift_beyond_drift_factor_is_non_stationary():
    assert V.DEFAULT_PLACE.drift_z == 8.0
    name, reason = place(drift(1.0, 9.0, 12.0, change=0.05), quiet_stage(), ID_RES, SCATTER)  # median 9 > 8
    assert (
        name == "non_stationary" and reason == "the records' harmonics drift by 5 % over a record (9 standard errors)"
    )
    assert place(drift(1.0, 8.0, 12.0), quiet_stage(), ID_RES, SCATTER)[0] == "tangential_contact"  # median 8: not > 8


def test_sensor_misfit_beyond_residual_factor_is_structure_or_measurement():
    assert V.DEFAULT_PLACE.residual_factor == 20.0
    name, reason = place(drift(1, 1, 1), quiet_stage(), [0.021, 0.03, 0.001], SCATTER)  # median ratio 21
    assert name == "structure_or_measurement" and "(sensor misfit 2.1 %, 21 x the scatter)" in reason
    assert place(drift(1, 1, 1), quiet_stage(), [0.02, 0.03, 0.001], SCATTER)[0] == "tangential_contact"  # 20: not > 20


def test_an_opening_contact_is_normal_contact():
    name, reason = place(drift(1, 1, 1), quiet_stage(open_fraction=0.05), ID_RES, SCATTER)
    assert name == "normal_contact" and "falls to zero over 5% of the cycle" in reason


def test_normal_force_left_beyond_normal_limit_is_normal_contact():
    assert V.DEFAULT_PLACE.normal_limit == 0.25
    name, reason = place(drift(1, 1, 1), quiet_stage(contact_force_N=0.3), ID_RES, SCATTER)
    assert name == "normal_contact" and "no elastic normal law fits the identified N(eta): 30% of N is left" in reason
    assert place(drift(1, 1, 1), quiet_stage(contact_force_N=0.25), ID_RES, SCATTER)[0] == "tangential_contact"


def test_open_limit_is_the_share_of_the_preload_below_which_the_contact_is_open():
    assert V.DEFAULT_PLACE.open_limit == 0.02
    N0 = 70.0
    n = N0 * (1 + np.cos(np.linspace(0, 2 * np.pi, 100, endpoint=False)))  # dips to 0 at mid-cycle
    assert V.open_fraction(n, N0) == pytest.approx(np.mean(n <= 1.4))
    assert V.open_fraction(n, N0) > 0
    assert V.open_fraction(np.maximum(n, 0.021 * N0), N0) == 0.0  # 2.1 % of N0 at least: closed
    assert V.open_fraction(np.maximum(n, 0.02 * N0), N0) > 0  # at 2 % of N0: open


def test_the_checks_come_in_order_drift_structure_opening_normal():
    loud = quiet_stage(open_fraction=0.1, contact_force_N=0.5)
    bad_res = [0.1, 0.1, 0.1]
    assert place(drift(20, 20, 20), loud, bad_res, SCATTER)[0] == "non_stationary"
    assert place(drift(1, 1, 1), loud, bad_res, SCATTER)[0] == "structure_or_measurement"
    assert place(drift(1, 1, 1), loud, ID_RES, SCATTER)[1].startswith("the identified normal force falls to zero")


def test_the_place_thresholds_are_settings():
    """gap.place sets each threshold: the same records placed otherwise under other thresholds."""
    from contactid.gap.settings import GapSettings

    settings = GapSettings.from_config(
        {"place": {"drift_z": 10.0, "residual_factor": 30.0, "normal_limit": 0.4, "open_limit": 0.1}}, 1, 25
    )
    t = settings.place
    assert t == V.PlaceThresholds(10.0, 30.0, 0.4, 0.1)
    assert GapSettings.from_config({}, 1, 25).place == V.DEFAULT_PLACE
    assert place(drift(1.0, 9.0, 12.0), quiet_stage(), ID_RES, SCATTER, thresholds=t)[0] == "tangential_contact"
    assert place(drift(1, 1, 1), quiet_stage(), [0.021, 0.03, 0.001], SCATTER, thresholds=t)[0] == "tangential_contact"
    assert (
        place(drift(1, 1, 1), quiet_stage(contact_force_N=0.3), ID_RES, SCATTER, thresholds=t)[0]
        == "tangential_contact"
    )
    n = 70.0 * (1 + np.cos(np.linspace(0, 2 * np.pi, 100, endpoint=False)))
    assert V.open_fraction(n, 70.0, t.open_limit) == pytest.approx(np.mean(n <= 7.0))


def test_an_unobservable_eta_leaves_the_contact_direction_open():
    stage = {**quiet_stage(), "contact_force_N": 0.5}  # N-based: would be normal_contact
    assert place(drift(0.0, 1.0, 1.0), stage, ID_RES, SCATTER)[0] == "normal_contact"
    name, reason = place(drift(0.0, 1.0, 1.0), stage, ID_RES, SCATTER, eta_observable=False, eta_spread=0.35)
    assert name == "contact" and "35%" in reason
    # drift and the structure come first, whatever eta does; an opening contact needs N alone
    assert place(drift(1.0, 9.0, 12.0), stage, ID_RES, SCATTER, eta_observable=False)[0] == "non_stationary"
    opening = {**stage, "open_fraction": 0.1}
    assert place(drift(0.0, 1.0, 1.0), opening, ID_RES, SCATTER, eta_observable=False)[0] == "normal_contact"
    assert V.acts_where("normal_contact", "contact") and V.acts_where("tangential_contact", "contact")
    assert not V.acts_where("structure_or_measurement", "contact") and V.acts_where("any", "contact")
    assert V.acts_where("normal_contact", "normal_contact") and not V.acts_where("normal_contact", "tangential_contact")
