"""The identification chain run in one process from raw records to the identified model.

It serves data sets that do not go through the workflow's rules one by one (the blind benchmark). It calls the same
package functions as the rules, with the same settings from the config.
"""

from __future__ import annotations

import copy
import dataclasses
from typing import TYPE_CHECKING, Any, Iterable, Mapping, Sequence

import numpy as np
import xarray as xr

from ..friction_fit import fit_friction_law, settings_from_config
from ..friction_parameters import parameter_dataset
from ..linear_chain import frf_dataset, linear_modes_dataset, modal_dataset, stiction_dataset
from ..schema import with_defaults
from .model import identified_model
from .records import record_harmonics
from .refit import identified_forces

if TYPE_CHECKING:
    import os

    from ..friction_fit import FitSettings
    from ..parameters import StructureParameters
    from ..test_damping import DampingProfile
    from ..updating_result import UpdatingResult
    from .model import IdentifiedModel
    from .record_checks import Thresholds
    from .records import RecordHarmonics
    from .settings import GapSettings


def linear_chain(cfg: Mapping, raw_random: xr.Dataset, return_frf: bool = False) -> tuple[xr.Dataset, ...]:
    """Run the linear chain: random test -> FRF -> modal -> stiction -> linear modes.

    Settings left out of ``cfg`` take the schema's defaults (``schema.with_defaults``), as in the workflow.

    Parameters
    ----------
    cfg
        The config; its ``frf``, ``modal``, ``stiction``, ``linear_modes`` and ``structure`` sections are read.
    raw_random
        The random test's raw record.
    return_frf
        Whether to return the FRF dataset too.

    Returns
    -------
    linear_modes : xr.Dataset
        The linear modes (linear_modes.nc's content).
    modal : xr.Dataset
        The modal fit (modal.nc's content).
    frf : xr.Dataset
        The FRF (frf.nc's content); only with ``return_frf``.
    """
    cfg = with_defaults(cfg)
    f, m, st, lm = (cfg[k] for k in ("frf", "modal", "stiction", "linear_modes"))
    frf = frf_dataset(
        raw_random, int(f["segment_length"]), float(f["overlap"]), f["window"], int(m["uncertainty_blocks"])
    )
    modal = modal_dataset(frf, int(m["n_modes"]), m["band_hz"], int(m["order"]))
    stiction = stiction_dataset(modal, cfg["structure"], st)
    modes = linear_modes_dataset(
        stiction, cfg["structure"], int(lm["n_modes"]), int(lm["grid_points"]), float(st["k_n_prior_n_per_m"])
    )
    return (modes, modal, frf) if return_frf else (modes, modal)


def identify(
    cfg: Mapping, raw_random: xr.Dataset, raw_calibration: xr.Dataset, n_modes: int = 8
) -> tuple[IdentifiedModel, xr.Dataset, xr.Dataset, xr.Dataset]:
    """Return the identified model from a random test and the calibration case's dual-sine record.

    The chain is the linear chain, the inverse identification and the GA fit of the friction law (no intervals).

    Parameters
    ----------
    cfg
        The config (left-out keys: the schema's defaults); ``linear_chain``'s sections, ``nonlinear.n_harmonics``,
        ``friction``, ``structure`` and ``seed`` are read.
    raw_random
        The random test's raw record.
    raw_calibration
        The calibration case's raw dual-sine record.
    n_modes
        The stuck modes the identified model keeps.

    Returns
    -------
    model : IdentifiedModel
        The identified model with its fitted friction law.
    linear_modes : xr.Dataset
        The linear modes.
    modal : xr.Dataset
        The modal fit.
    frf : xr.Dataset
        The FRF.
    """
    from .model import NONE

    cfg = with_defaults(cfg)
    modes, modal, frf = linear_chain(cfg, raw_random, return_frf=True)
    K = int(cfg["nonlinear"]["n_harmonics"])
    settings = settings_from_config(cfg["friction"])
    unfitted = parameter_dataset(np.ones(5), settings.regularization)
    model = identified_model(cfg["structure"], modes, modal, unfitted, n_modes=n_modes)
    rec = record_harmonics(raw_calibration, "calibration", K)
    forces = identified_forces(model, NONE, rec)
    fit = fit_friction_law(
        forces.xi, forces.N_dyn, forces.S, rec.f0, model.preload, settings, int(cfg["seed"]), K, intervals=False
    )
    return model.with_friction(fit.params), modes, modal, frf


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


def rig_records(
    cfg: Mapping, effects: Mapping, seed: int, cases: Iterable[str], random_test: bool = True
) -> tuple[dict, dict]:
    """Return raw records of the virtual rig with ``effects`` on, and whether each case's response control converged.

    The convergence is truth, never in a raw record: it is returned apart from them.

    Parameters
    ----------
    cfg
        The config (left-out keys: the schema's defaults); ``rig``, ``structure``, ``random_test`` and
        ``load_cases`` are read.
    effects
        {effect: magnitude in its rig unit} (``rig.effects``), replacing the config's.
    seed
        The rig's random seed.
    cases
        The load cases to simulate.
    random_test
        Whether to simulate the random test too.

    Returns
    -------
    records : dict
        {'random_test': raw dataset, case: raw dataset, ...}.
    converged : dict
        {case: 1 where the response control converged, else 0}.
    """
    from ..rig.dual_sine import dual_sine_test
    from ..rig.random_test import random_test_datasets
    from ..rig.structure import random_test_rig_config

    cfg = with_defaults(cfg)
    rig = copy.deepcopy(dict(cfg["rig"]))
    rig["effects"] = dict(effects)
    out, converged = {}, {}
    if random_test:
        out["random_test"] = random_test_datasets(
            cfg["structure"], random_test_rig_config(rig), cfg["random_test"], seed
        )[0]
    fs = float(cfg["random_test"]["sampling_rate_hz"])
    for case in cases:
        raw, truth = dual_sine_test(
            cfg["structure"],
            rig,
            cfg["load_cases"][case],
            fs,
            float(rig["noise_fraction"]),
            seed,
            case,
            cfg["structure"]["sensors"]["names"],
        )
        converged[case] = int(truth.attrs["control_converged"])
        out[case] = raw
    return out, converged


def structure_update(structure: StructureParameters, modal: xr.Dataset, settings: GapSettings) -> UpdatingResult | None:
    """Return the base structure updated from the random test's modal fit (``contactid.updating``).

    Parameters
    ----------
    structure
        The base structure, with the chain's k_t and k_n.
    modal
        The modal fit (modal.nc's content: natural frequencies, their sd and the residues).
    settings
        The gap's settings (``settings.GapSettings``): model_updating and the updating's parameters.

    Returns
    -------
    update : UpdatingResult | None
        The update; None when gap.model_updating is off.
    """
    from ..stiction import frequency_sigma
    from ..updating import update_structure

    if not settings.model_updating:
        return None
    f = modal["natural_frequency"].values
    sigma = frequency_sigma(f, modal["natural_frequency_std"].values, settings.frequency_floor)
    return update_structure(
        structure,
        f,
        sigma,
        modal["residue_abs"].values,
        settings.residue_accuracy,
        settings.updating_parameters,
        confidence=settings.updating_confidence,
        prior_sd=dict(settings.updating_prior_sd),
        gain_sd=float(getattr(settings, "updating_gain_sd", 0.0)),
    )


def workflow_models(
    structure_cfg: Mapping,
    inputs: Any,
    cases: Sequence[str],
    calibration_case: str,
    n_harmonics: int,
    friction_cfg: Mapping,
    settings: GapSettings,
    seed: int,
) -> tuple[dict, FitSettings, xr.Dataset, IdentifiedModel, IdentifiedModel, UpdatingResult | None]:
    """Return what the gap's rules (gap_diagnosis, friction_intervals) read from the workflow's files.

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` section.
    inputs
        The rule's inputs (Snakemake's ``input``), naming by attribute ``modes``, ``modal``, ``fit``, ``updating``
        (model_updating.json) and ``raw`` (the load cases' records, in the order of ``cases``).
    cases
        The load cases.
    calibration_case
        The calibration case's name.
    n_harmonics
        The harmonics of each record compared.
    friction_cfg
        The config's ``friction`` section.
    settings
        The gap's settings (``settings.GapSettings``).
    seed
        The random seed.

    Returns
    -------
    records : dict
        {case: RecordHarmonics} of the load cases.
    fit_settings : FitSettings
        The friction fit's settings.
    modal : xr.Dataset
        modal.nc's content.
    chain : IdentifiedModel
        The chain's own model.
    model : IdentifiedModel
        The model to diagnose (``diagnosed_model``).
    updating : UpdatingResult | None
        The model update; None when updating is off.
    """
    import json

    from ..io import load_dataset

    modal = load_dataset(inputs.modal)
    records = workflow_records(inputs.raw, cases, n_harmonics)
    fit_settings = settings_from_config(friction_cfg)
    with open(inputs.updating) as fh:
        upd_summary = json.load(fh)
    chain, model, upd = diagnosed_model(
        structure_cfg,
        load_dataset(inputs.modes),
        modal,
        load_dataset(inputs.fit),
        records[calibration_case],
        upd_summary,
        fit_settings,
        settings,
        seed,
        {c: r for c, r in records.items() if c != calibration_case},
    )
    return records, fit_settings, modal, chain, model, upd


def diagnosed_model(
    structure_cfg: Mapping,
    modes: xr.Dataset,
    modal: xr.Dataset,
    fit: xr.Dataset,
    calibration: RecordHarmonics,
    updating_summary: Mapping,
    fit_settings: FitSettings,
    settings: GapSettings,
    seed: int,
    held_out: Mapping[str, RecordHarmonics] | None = None,
) -> tuple[IdentifiedModel, IdentifiedModel, UpdatingResult | None]:
    """Return the models a diagnosis of the workflow's datasets works with.

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` section.
    modes
        linear_modes.nc's content.
    modal
        modal.nc's content.
    fit
        friction_fit.nc's content.
    calibration
        The calibration record's harmonics.
    updating_summary
        model_updating.json's summary (``UpdatingResult.summary``; ``enabled`` says whether updating is on).
    fit_settings
        The friction fit's settings (``friction_fit.FitSettings``).
    settings
        The gap's settings (``settings.GapSettings``).
    seed
        The random seed.
    held_out
        {case: harmonics} of the other load cases, which may also accept an update (None: none).

    Returns
    -------
    chain : IdentifiedModel
        The chain's own model from linear_modes.nc, modal.nc and friction_fit.nc.
    model : IdentifiedModel
        The model to diagnose: the chain's updated by the summary (``updated_model``), or the chain's own when
        updating is off.
    updating : UpdatingResult | None
        The update; None when updating is off.
    """
    from ..updating_result import UpdatingResult

    chain = identified_model(structure_cfg, modes, modal, fit)
    if not updating_summary["enabled"]:
        return chain, chain, None
    upd = UpdatingResult.from_summary(updating_summary, chain.structure)
    model, upd = updated_model(chain, modal, calibration, fit_settings, settings, seed, upd, held_out)
    return chain, model, upd


def updated_model(
    model: IdentifiedModel,
    modal: xr.Dataset,
    calibration: RecordHarmonics | None,
    fit_settings: FitSettings,
    settings: GapSettings,
    seed: int,
    upd: UpdatingResult | None = None,
    held_out: Mapping[str, RecordHarmonics] | None = None,
) -> tuple[IdentifiedModel, UpdatingResult | None]:
    """Return the base model updated from the random test before the candidates, settled by ``settled_update``.

    Where the accelerometer channels' gains took part in the update but the random test cannot tell them from the
    structure's factors (``UpdatingResult.structure_alone``'s ``gains_needed`` false), both updates are settled and
    the ``held_out`` records choose (``evidence.records_test_of_gains``): the one without the gains unless the records
    call for them; the test is kept in ``gains_versus_structure``.

    Parameters
    ----------
    model
        The base model (the chain's).
    modal
        The random test's modal fit (modal.nc's content).
    calibration
        The calibration record's harmonics (None: the gains are not weighed by the records).
    fit_settings
        The friction fit's settings (``friction_fit.FitSettings``).
    settings
        The gap's settings (``settings.GapSettings``).
    seed
        The random seed.
    upd
        The update when already computed (None: ``structure_update`` computes it).
    held_out
        {case: harmonics} of the other load cases (None: none).

    Returns
    -------
    model : IdentifiedModel
        The model to diagnose.
    updating : UpdatingResult | None
        The update; None when updating is off.
    """
    import logging

    if upd is None:
        upd = structure_update(model.structure, modal, settings)
    if upd is None:
        return model, None
    alone = upd.structure_alone
    if not alone or alone.get("gains_needed") or not held_out or calibration is None:
        return settled_update(model, calibration, fit_settings, settings, seed, upd, held_out)
    from .evidence import records_test_of_gains

    m_gains, u_gains = settled_update(model, calibration, fit_settings, settings, seed, upd, held_out)
    m_alone, u_alone = settled_update(model, calibration, fit_settings, settings, seed, upd.without_gains(), held_out)
    test = records_test_of_gains(
        m_gains, u_gains.channel_gains, m_alone, held_out, calibration, fit_settings, settings, chain=model
    )
    test.update(gains_drop=alone["gains_drop"], gains_threshold=alone["gains_threshold"])
    logging.getLogger(__name__).info(
        "model updating: the random test cannot tell the channels' gains from the structure's factors (chi^2 %.3g "
        "lower with them, %.3g needed); held-out gap %.4g with the gains, %.4g without them, %.4g not updated "
        "(records' scatter %.2g): the update %s them",
        test["gains_drop"],
        test["gains_threshold"],
        test["heldout_gap_gains"],
        test["heldout_gap_structure"],
        test["heldout_gap_chain"],
        test["record_scatter"],
        "with" if test["gains_preferred"] else "without",
    )
    if test["gains_preferred"]:
        return m_gains, dataclasses.replace(u_gains, gains_versus_structure=test)
    return m_alone, dataclasses.replace(u_alone, gains_versus_structure=test)


def settled_update(
    model: IdentifiedModel,
    calibration: RecordHarmonics,
    fit_settings: FitSettings,
    settings: GapSettings,
    seed: int,
    upd: UpdatingResult,
    held_out: Mapping[str, RecordHarmonics] | None = None,
) -> tuple[IdentifiedModel, UpdatingResult]:
    """Return the base model updated by ``upd``, with the inverse identification and the friction fit redone.

    They are redone on the calibration record. The model is the chain's own when the update is not accepted. An
    update the random test's chi^2 test did not accept (its ``proposal``) is accepted when the ``held_out`` records
    show a held-out gap above the floor that the update explains materially (``settings.updating_records_test``;
    ``evidence.records_test_of_update``); the result then says ``accepted_by`` "records" and keeps the test in
    ``records_test``.

    Parameters
    ----------
    model
        The base model (the chain's).
    calibration
        The calibration record's harmonics.
    fit_settings
        The friction fit's settings (``friction_fit.FitSettings``).
    settings
        The gap's settings (``settings.GapSettings``).
    seed
        The random seed.
    upd
        The random test's update.
    held_out
        {case: RecordHarmonics} of the load cases other than the calibration case (None: none).

    Returns
    -------
    model : IdentifiedModel
        The model to diagnose.
    updating : UpdatingResult
        The update, accepted by the records where they did (with ``records_test``).
    """
    import logging

    log = logging.getLogger(__name__)
    if not upd.accepted:
        if upd.proposal is None or not held_out or not getattr(settings, "updating_records_test", False):
            log.info(
                "model updating: not accepted (chi2 %.3g -> %.3g, a drop below %.3g for the %.2g factors the data "
                "bind); the chain's structure is kept",
                upd.chi2_nominal,
                upd.chi2_updated,
                upd.chi2_threshold,
                upd.effective_factors,
            )
            return model, upd
        from .evidence import records_attribution, records_test_of_update

        p = upd.proposal
        m2 = _refitted(model, upd.proposed_structure(), calibration, fit_settings, seed)
        test = records_test_of_update(model, m2, held_out, settings, calibration, fit_settings)
        factors = ", ".join(f"{k} {v:.4g}" for k, v in p["factors"].items())
        if not test["accepted"]:
            log.info(
                "model updating: not accepted (chi2 %.3g -> %.3g, a drop below %.3g for the %.2g factors the data "
                "bind; held-out gap %.4g -> %.4g with it, records' scatter %.2g); the chain's structure is kept",
                upd.chi2_nominal,
                upd.chi2_updated,
                upd.chi2_threshold,
                upd.effective_factors,
                test["heldout_gap_chain"],
                test["heldout_gap_updated"],
                test["record_scatter"],
            )
            return model, dataclasses.replace(upd, records_test=test)
        test["attribution"] = records_attribution(
            model,
            p["factors"],
            lambda f: _without_factor(model, upd, f),
            calibration,
            held_out,
            fit_settings.bounds,
            test["record_scatter"],
            test.get("heldout_gap_chain_alone", test["heldout_gap_chain"]),  # the attribution's gaps hold no drift
            settings,
        )
        log.info(
            "model updating: accepted by the records (chi2 %.3g -> %.3g, not significant alone; held-out gap "
            "%.4g -> %.4g, records' scatter %.2g): %s, k_t %.4g, k_n %.4g N/m; friction law refitted",
            upd.chi2_nominal,
            upd.chi2_updated,
            test["heldout_gap_chain"],
            test["heldout_gap_updated"],
            test["record_scatter"],
            factors,
            float(p["k_t"]),
            float(p["k_n"]),
        )
        return m2, upd.accept_proposal(test)
    log.info(
        "model updating: accepted (chi2 %.3g -> %.3g, a drop above %.3g for the %.2g factors the data bind): %s, "
        "k_t %.4g, k_n %.4g N/m; friction law refitted",
        upd.chi2_nominal,
        upd.chi2_updated,
        upd.chi2_threshold,
        upd.effective_factors,
        ", ".join(f"{k} {v:.4g}" for k, v in upd.factors.items()),
        upd.k_t,
        upd.k_n,
    )
    return _refitted(model, upd.structure, calibration, fit_settings, seed), upd


def _without_factor(model, upd, factor: str):
    """Return the structure of ``upd``'s proposal with ``factor`` at 1 (the others as proposed).

    Its stiffness fit is redone as a mass candidate's is (``IdentifiedModel.refit_stiffness``: k_t and k_n refitted
    to the chain's frequencies, k_n kept where the chain's modes use the prior k_n), E as the factors set it.
    """
    from ..updating_model import apply_factors

    p = upd.proposal
    factors = {k: (1.0 if k == factor else float(v)) for k, v in p["factors"].items()}
    s = apply_factors(upd.nominal.with_contact(float(p["k_t"]), float(p["k_n"])), factors)
    return model.refit_stiffness(s, free_modulus=False)


def _refitted(model, structure, calibration, fit_settings, seed: int):
    """Return the model with ``structure``, its contact forces identified again and its friction law fitted to them.

    The forces are identified from the calibration record.
    """
    from .model import NONE

    m2 = dataclasses.replace(model, structure=structure)
    forces = identified_forces(m2, NONE, calibration)
    fit = fit_friction_law(
        forces.xi,
        forces.N_dyn,
        forces.S,
        calibration.f0,
        m2.preload,
        fit_settings,
        int(seed),
        calibration.acceleration.shape[1],
        intervals=False,
        label="friction fit after updating",
    )
    return m2.with_friction(fit.params)


def workflow_record_checks(
    structure_cfg: Mapping,
    inputs: Any,
    cases: Sequence[str],
    calibration_case: str,
    n_harmonics: int,
    thresholds: Thresholds,
) -> dict:
    """Return the records' check (``records_check_of``) from the workflow's files.

    The prediction is the chain's identified model (not updated).

    Parameters
    ----------
    structure_cfg
        The config's ``structure`` section.
    inputs
        The rule's inputs (Snakemake's ``input``), naming by attribute ``modes``, ``modal``, ``fit`` and ``raw``
        (the load cases' records, in the order of ``cases``).
    cases
        The load cases.
    calibration_case
        The calibration case's name.
    n_harmonics
        The harmonics of each record compared.
    thresholds
        The check's thresholds (gap.record_checks).

    Returns
    -------
    check : dict
        ``record_checks.records_check``'s result: passed, findings, trace, gaps, calibration_case.
    """
    from ..io import load_dataset
    from .model import identified_model

    model = identified_model(
        structure_cfg, load_dataset(inputs.modes), load_dataset(inputs.modal), load_dataset(inputs.fit)
    )
    records = workflow_records(inputs.raw, cases, n_harmonics)
    return records_check_of(model, records, calibration_case, n_harmonics, thresholds)


def workflow_records(paths: Iterable[str | os.PathLike], cases: Iterable[str], n_harmonics: int) -> dict:
    """Return the load cases' dual-sine records in harmonics: what the gap's rules compare the model with.

    Parameters
    ----------
    paths
        The records' files, in the order of ``cases``.
    cases
        The load cases.
    n_harmonics
        The harmonics 1..n_harmonics kept.

    Returns
    -------
    records : dict
        {case: RecordHarmonics}.
    """
    from ..io import read_raw

    return {c: record_harmonics(read_raw(path, dual_sine=True), c, int(n_harmonics)) for c, path in zip(cases, paths)}


def records_check_of(
    model: IdentifiedModel,
    records: Mapping[str, RecordHarmonics],
    calibration_case: str,
    n_harmonics: int,
    thresholds: Thresholds,
) -> dict:
    """Return ``record_checks.records_check`` of the records' harmonics.

    It checks their accelerances at the drive, and each against ``model``'s prediction at its measured force
    (harmonics 1..``n_harmonics``).

    Parameters
    ----------
    model
        The model whose prediction the records are checked against.
    records
        {case: RecordHarmonics}.
    calibration_case
        The calibration case's name.
    n_harmonics
        The harmonics compared.
    thresholds
        The check's thresholds (gap.record_checks).

    Returns
    -------
    check : dict
        ``record_checks.records_check``'s result: passed, findings, trace, gaps, calibration_case.
    """
    from .model import NONE
    from .record_checks import accelerance_levels, model_evidence, records_check
    from .simulation import simulate

    H = int(n_harmonics)
    evidence = {}
    for case, rec in records.items():
        sim = simulate(model, NONE, rec)
        evidence[case] = model_evidence(case, rec.sensors, rec.acceleration[:, :H], sim.acceleration[:, :H])
    levels = accelerance_levels(
        {c: {"f0": r.f0, "acceleration": r.acceleration, "force": r.force} for c, r in records.items()}
    )
    return records_check(levels, evidence, calibration_case, thresholds)
