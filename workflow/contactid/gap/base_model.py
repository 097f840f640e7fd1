"""The base model: the structure updated from the random test before the candidates, the friction law refitted.

The random test's update of the structure (``structure_update``, ``contactid.updating``; the rule model_updating) is
accepted by its chi^2 test or, where that does not accept it, by the held-out dual-sine records; where the random test
cannot tell the channels' gains from the structure's factors, the records choose between the two updates
(``updated_model``). The accepted update has the contact forces identified again and the friction law refitted on the
calibration record (``settled_update``); the model a diagnosis starts from is the result (``pipeline.diagnosed_model``,
the blind benchmark).
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING, Mapping

import xarray as xr

from ..friction_fit import fit_friction_law
from .refit import identified_forces

if TYPE_CHECKING:
    from ..friction_fit import FitSettings
    from ..parameters import StructureParameters
    from ..updating_result import UpdatingResult
    from .model import IdentifiedModel
    from .records import RecordHarmonics
    from .settings import GapSettings


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
