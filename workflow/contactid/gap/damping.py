"""The damping at test level for the identified model: a profile in each form, the one the held-out records choose.

The friction law's misfit on the calibration record is profiled over factors on the random test's damping ratios, in
each form of ``contactid.test_damping`` (``test_level_damping``); the held-out records test each form's factor as they
test an update of the structure (``confirmed_test_damping``) and choose among the forms (``chosen_test_damping``). The
rule test_damping runs it, upstream of the friction fit.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Mapping, Sequence

import numpy as np

if TYPE_CHECKING:
    from ..friction_fit import FitSettings
    from ..test_damping import DampingProfile
    from .model import IdentifiedModel
    from .records import RecordHarmonics
    from .settings import GapSettings


def test_level_damping(
    model: IdentifiedModel,
    calibration: RecordHarmonics,
    held_out: Mapping[str, RecordHarmonics],
    fit_settings: FitSettings,
    settings: GapSettings,
    seed: int,
    scales: Sequence[float],
) -> DampingProfile:
    """Return the damping at test level (``contactid.test_damping``).

    The friction law's misfit on the ``calibration`` record is profiled over ``scales`` with ``model``'s structure and
    random-test ratios, in each form of ``test_damping.FORMS`` (the driven mode's ratio alone; every mode's), each
    confirmed or not by the ``held_out`` records (``confirmed_test_damping``), one of them chosen
    (``chosen_test_damping``), and the chosen one, where confirmed, given its law's intervals.

    Parameters
    ----------
    model
        The identified model (its structure, damping ratios, frequencies and preload are used).
    calibration
        The calibration record's harmonics.
    held_out
        {case: harmonics} of the other load cases.
    fit_settings
        The friction fit's settings (``friction_fit.FitSettings``).
    settings
        The gap's settings (``settings.GapSettings``).
    seed
        The fits' random seed.
    scales
        The factors on the damping ratios to profile [-] (``nonlinear.test_damping_scales`` with 1).

    Returns
    -------
    profile : DampingProfile
        The chosen profile; ``test_damping.unprofiled`` where ``scales`` hold one factor.
    """
    from ..test_damping import FORMS, damping_profile, unprofiled, with_intervals
    from .model import NONE, fe_model

    if len(set(scales)) < 2:
        return unprofiled()
    fe = fe_model(model, NONE)
    profiles = [
        damping_profile(
            fe,
            model.damping,
            model.frequencies,
            calibration.force,
            calibration.acceleration,
            calibration.f0,
            model.preload,
            fit_settings,
            seed,
            scales,
            form,
        )
        for form in FORMS
    ]
    tested = [confirmed_test_damping(model, p, calibration, held_out, fit_settings, settings) for p in profiles]
    chosen = chosen_test_damping(tested)
    if not chosen.accepted:
        return chosen
    return with_intervals(
        chosen,
        fe,
        model.damping,
        calibration.force,
        calibration.acceleration,
        calibration.f0,
        model.preload,
        fit_settings,
        seed,
    )


def chosen_test_damping(tested: Sequence[DampingProfile]) -> DampingProfile:
    """Return the profile chosen among the forms: the confirmed one whose held-out gap is least.

    Where none is confirmed, it is the one whose misfit is least, which then is not applied. The held-out records
    choose among the forms, not the calibration record's misfit: a form can fit the calibration record better and
    widen the held-out gap where the other form narrows it (the other simulator's records, docs/measurements.md).

    Parameters
    ----------
    tested
        The profiles of each form, each with the held-out records' test (``confirmed_test_damping``).

    Returns
    -------
    profile : DampingProfile
        The chosen profile.
    """
    confirmed = [p for p in tested if p.accepted]
    if confirmed:
        return min(confirmed, key=lambda p: float(p.check["heldout_gap_updated"]))
    return min(tested, key=lambda p: float(np.min(p.misfits)))


def confirmed_test_damping(
    model: IdentifiedModel,
    profile: DampingProfile,
    calibration: RecordHarmonics,
    held_out: Mapping[str, RecordHarmonics],
    fit_settings: FitSettings,
    settings: GapSettings,
) -> DampingProfile:
    """Return ``profile`` with the held-out records' test of its factor (``profile.check``).

    The model with the random test's ratios and the model with the form's ratios times ``profile.scale``, each with
    the law fitted at its factor, are weighed on the ``held_out`` records as an update of the structure is
    (``evidence.records_test_of_update``: the gap shrinks by min_reduction of it and beyond noise_factor x the records'
    scatter), with no floor below which the gap is left alone: the floor is measured with the chain's law (rule
    gap_floor), downstream of this choice, and a factor that halves the held-out gap is confirmed at any level. No test
    where the factor is 1 or nothing is held out (the factor then is not applied).

    Parameters
    ----------
    model
        The identified model.
    profile
        The damping profile of one form.
    calibration
        The calibration record's harmonics.
    held_out
        {case: harmonics} of the other load cases.
    fit_settings
        The friction fit's settings (``friction_fit.FitSettings``).
    settings
        The gap's settings (``settings.GapSettings``).

    Returns
    -------
    profile : DampingProfile
        ``profile`` with ``check`` set where the test ran; ``profile`` itself otherwise.
    """
    import logging

    from ..test_damping import check_reason
    from .evidence import records_test_of_update

    if abs(profile.scale - 1.0) < 1e-9 or not held_out:
        logging.getLogger(__name__).info("damping at test level: %s", check_reason(profile))
        return profile
    base = dataclasses.replace(model, test_damping_ratios=()).with_friction(profile.law_at(1.0))
    scaled = dataclasses.replace(model, test_damping_ratios=tuple(profile.scaled_ratios(model.damping))).with_friction(
        profile.law_at_scale()
    )
    test = records_test_of_update(
        base, scaled, held_out, dataclasses.replace(settings, min_gap=0.0), calibration, fit_settings
    )
    out = dataclasses.replace(profile, check=test)
    logging.getLogger(__name__).info("damping at test level, x%.3g: %s", profile.scale, check_reason(out))
    return out
