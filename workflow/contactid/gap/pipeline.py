"""The identified model and the records a diagnosis starts from: the chain run in one process, or the workflow's files.

In one process from raw records (``linear_chain``, ``identify``, ``rig_records``), it serves data sets that do not go
through the workflow's rules one by one (the blind benchmark): it calls the same package functions as the rules, with
the same settings from the config. From the workflow's files (``workflow_models``, ``workflow_records``,
``workflow_record_checks``), it gives the gap's rules the records' harmonics, the chain's model and the model to
diagnose (the base model, ``base_model.updated_model``); ``records_check_of`` checks records against a model.
"""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING, Any, Iterable, Mapping, Sequence

import numpy as np
import xarray as xr

from ..friction_fit import fit_friction_law, settings_from_config
from ..friction_parameters import parameter_dataset
from ..linear_chain import frf_dataset, linear_modes_dataset, modal_dataset, stiction_dataset
from ..schema import with_defaults
from .base_model import updated_model
from .model import identified_model
from .records import record_harmonics
from .refit import identified_forces

if TYPE_CHECKING:
    import os

    from ..friction_fit import FitSettings
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
