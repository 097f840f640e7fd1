"""The diagnosis as files: results/gap/diagnosis.json (the contract) and results/gap/gap.nc."""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING, Any

import numpy as np
import xarray as xr

from .diagnosis import Diagnosis

if TYPE_CHECKING:
    from .records import RecordHarmonics

# the force-state maps, one variable per field (name, units, what): the identified motion and what the laws leave
MAP_FIELDS = (
    ("xi", "m", "identified tangential motion xi"),
    ("xi_dot", "m/s", "identified tangential velocity"),
    ("S_residual", "N", "identified S - the friction law at the identified motion"),
    ("eta", "m", "identified normal motion eta"),
    ("eta_dot", "m/s", "identified normal velocity"),
    ("N_residual", "N", "identified N - the best elastic normal law"),
)


def json_ready(x: Any) -> Any:
    """Return ``x`` ready for json.dumps: numpy scalars as Python ones, non-finite floats as None, keys as strings.

    Dicts, lists and tuples are converted recursively (tuples become lists); non-finite floats become None (null).

    Parameters
    ----------
    x
        A value, or a nest of dicts, lists and tuples of values.

    Returns
    -------
    ready : Any
        The same value with numpy scalars as Python ones, non-finite floats as None and dict keys as strings.
    """
    if isinstance(x, dict):
        return {str(k): json_ready(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_ready(v) for v in x]
    if isinstance(x, (np.floating, float)):
        return None if not math.isfinite(float(x)) else float(x)
    if isinstance(x, (np.bool_,)):
        return bool(x)
    if isinstance(x, (np.integer,)):
        return int(x)
    return x


def diagnosis_json(diag: Diagnosis, extra: dict | None = None) -> str:
    """Return diagnosis.json's text: verdict, reason, ranking, where (the localisation summary) and the cases.

    The ranking is [{effect, heldout_gap_before, heldout_gap_after, score, ...}]; non-finite numbers are written as
    null.

    Parameters
    ----------
    diag
        The diagnosis (``Diagnosis.summary`` is written).
    extra
        Further top-level entries (None: none).

    Returns
    -------
    text : str
        The JSON text, indented by 2.
    """
    return json.dumps(json_ready({**diag.summary(), **(extra or {})}), indent=2)


def updated_model_json(updated: dict, extra: dict | None = None) -> str:
    """Return results/gap/updated_model.json's text: the model the explanation arrives at.

    Non-finite numbers (a rigid clamp's stiffness) are written as null.

    Parameters
    ----------
    updated
        The updated model's summary (``explain.updated_model_summary``).
    extra
        Further top-level entries (None: none).

    Returns
    -------
    text : str
        The JSON text, indented by 2.
    """
    return json.dumps(json_ready({**updated, **(extra or {})}), indent=2)


def localisation_variables(a: dict) -> dict:
    """Return the localisation arrays as dataset variables {name: (dims, values, attrs)}.

    The gap by sensor, harmonic and part of the cycle (relative, 1), the energy dissipated per cycle (J) and the
    force-state maps (SI: ``MAP_FIELDS``).

    Parameters
    ----------
    a
        The localisation's arrays (``localise.localise``): gap_by_sensor (n_cases, n_sensors), gap_by_harmonic
        (n_cases, n_harmonics) and gap_by_cycle_part (n_cases, 4), relative; energy_tangential and energy_normal
        (n_cases, 2: identified, simulated) in J; force_state_map (n_cases, 6, n_phase), the fields of
        ``MAP_FIELDS`` in their units.

    Returns
    -------
    variables : dict
        gap_by_sensor, gap_by_harmonic, gap_by_cycle_part, energy_tangential, energy_normal and map_<field> for each
        of ``MAP_FIELDS``, each (dims, values, attrs with units and long_name).
    """
    return {
        "gap_by_sensor": (
            ("case", "sensor"),
            a["gap_by_sensor"],
            {"units": "1", "long_name": "|A_sim - A_rec| / |A_rec| per sensor (harmonics 1..H)"},
        ),
        "gap_by_harmonic": (
            ("case", "harmonic"),
            a["gap_by_harmonic"],
            {"units": "1", "long_name": "residual per harmonic over all sensors / |A_rec|"},
        ),
        "gap_by_cycle_part": (
            ("case", "cycle_part"),
            a["gap_by_cycle_part"],
            {
                "units": "1",
                "long_name": "rms driving-point acceleration residual in each part of the cycle / rms acceleration",
            },
        ),
        "energy_tangential": (
            ("case", "source"),
            a["energy_tangential"],
            {"units": "J", "long_name": "energy dissipated per cycle by friction"},
        ),
        "energy_normal": (
            ("case", "source"),
            a["energy_normal"],
            {"units": "J", "long_name": "energy dissipated per cycle in the normal direction"},
        ),
        **{
            f"map_{name}": (
                ("case", "phase"),
                a["force_state_map"][:, k, :],
                {"units": unit, "long_name": f"force-state map over one period: {what}"},
            )
            for k, (name, unit, what) in enumerate(MAP_FIELDS)
        },
    }


def record_variables(records: dict[str, RecordHarmonics], n_harmonics: int) -> dict:
    """Return the records' acceleration harmonics 1..H, real and imaginary parts, as dataset variables.

    The harmonics are in m/s^2 with the force's phase 0; each variable is {name: (dims, values, attrs)}.

    Parameters
    ----------
    records
        The load cases' records in harmonics, by case (the order of the ``case`` dimension).
    n_harmonics
        H, the harmonics written.

    Returns
    -------
    variables : dict
        acceleration_record_real and acceleration_record_imag, dims (case, sensor, harmonic), in m/s^2.
    """
    cases, H = list(records), n_harmonics
    return {
        "acceleration_record_real": (
            ("case", "sensor", "harmonic"),
            np.array([records[c].acceleration[:, :H].real for c in cases]),
            {"units": "m/s^2", "long_name": "record harmonics (force phase 0), real part"},
        ),
        "acceleration_record_imag": (
            ("case", "sensor", "harmonic"),
            np.array([records[c].acceleration[:, :H].imag for c in cases]),
            {"units": "m/s^2", "long_name": "record harmonics, imaginary part"},
        ),
    }


def simulated_variables(diag: Diagnosis, records: dict[str, RecordHarmonics], n_harmonics: int) -> dict:
    """Return the simulated acceleration harmonics 1..H of the base model, the winner and the runner-up.

    Real and imaginary parts (m/s^2; NaN where not simulated), as dataset variables {name: (dims, values, attrs)}.

    Parameters
    ----------
    diag
        The diagnosis: its simulations (``sims``: "base" and each effect's, by case) and its ranking.
    records
        The load cases' records in harmonics, by case (the order of the ``case`` dimension).
    n_harmonics
        H, the harmonics written.

    Returns
    -------
    variables : dict
        acceleration_<label>_real and acceleration_<label>_imag for label base and the first two of the ranking,
        dims (case, sensor, harmonic), in m/s^2.
    """
    cases = list(records)
    sensors = list(records[cases[0]].sensors)
    H = n_harmonics
    models = {"base": diag.sims["base"]}
    for r in diag.ranking[:2]:
        models[r["effect"]] = diag.sims[r["effect"]]
    data = {}
    for label, sims in models.items():
        arr = np.full((len(cases), len(sensors), H), np.nan + 0j)
        for i, c in enumerate(cases):
            if sims.get(c) is not None:
                arr[i] = sims[c].acceleration[:, :H]
        data[f"acceleration_{label}_real"] = (
            ("case", "sensor", "harmonic"),
            arr.real,
            {
                "units": "m/s^2",
                "long_name": f"simulated harmonics, {label} model, real part",
                "nonfinite_meaning": "NaN: not simulated (calibration case of a candidate)",
            },
        )
        data[f"acceleration_{label}_imag"] = (
            ("case", "sensor", "harmonic"),
            arr.imag,
            {
                "units": "m/s^2",
                "long_name": f"simulated harmonics, {label} model, imaginary part",
                "nonfinite_meaning": "NaN: not simulated",
            },
        )
    return data


def ranking_variables(ranking: list[dict]) -> dict:
    """Return the candidates' held-out gap after, with its bootstrap 95 % interval, and their scores.

    Each along ``effect``, as dataset variables {name: (dims, values, attrs)}; the gaps are relative (units 1).

    Parameters
    ----------
    ranking
        The diagnosis's ranking rows: heldout_gap_after, heldout_gap_after_interval (low, high) and score are read.

    Returns
    -------
    variables : dict
        heldout_gap_after, heldout_gap_after_low, heldout_gap_after_high and score.
    """
    return {
        "heldout_gap_after": (
            "effect",
            [r["heldout_gap_after"] for r in ranking],
            {"units": "1", "long_name": "held-out gap with the candidate added"},
        ),
        "heldout_gap_after_low": (
            "effect",
            [r["heldout_gap_after_interval"][0] for r in ranking],
            {"units": "1", "long_name": "bootstrap 2.5 % quantile"},
        ),
        "heldout_gap_after_high": (
            "effect",
            [r["heldout_gap_after_interval"][1] for r in ranking],
            {"units": "1", "long_name": "bootstrap 97.5 % quantile"},
        ),
        "score": (
            "effect",
            [r["score"] for r in ranking],
            {"units": "1", "long_name": "n ln(after^2/before^2) + 2 k (lower is better)"},
        ),
    }


def gap_dataset(diag: Diagnosis, records: dict[str, RecordHarmonics], n_harmonics: int) -> xr.Dataset:
    """Return results/gap/gap.nc: the localisation arrays, the measured and simulated harmonics, the ranking.

    The simulated harmonics are the base model's, the winner's and the runner-up's.

    Parameters
    ----------
    diag
        The diagnosis: its arrays, simulations, ranking, verdict, reason, calibration case and where.
    records
        The load cases' records in harmonics, by case (the order of the ``case`` dimension).
    n_harmonics
        H, the harmonics written.

    Returns
    -------
    dataset : xr.Dataset
        The variables of ``localisation_variables``, ``record_variables``, ``simulated_variables`` and
        ``ranking_variables`` on the coordinates case, sensor, harmonic, cycle_part, source, phase and effect;
        attributes verdict, reason, calibration_case and heldout_gap_before.
    """
    cases = list(records)
    sensors = list(records[cases[0]].sensors)
    H = n_harmonics
    a = diag.arrays
    data = {
        **localisation_variables(a),
        **record_variables(records, H),
        **simulated_variables(diag, records, H),
        **ranking_variables(diag.ranking),
    }
    return xr.Dataset(
        data,
        coords={
            "case": cases,
            "sensor": sensors,
            "harmonic": np.arange(1, H + 1),
            "cycle_part": ["stick", "slip", "velocity_reversal", "peak_compression"],
            "source": ["identified", "simulated"],
            "phase": np.arange(a["force_state_map"].shape[-1]),
            "effect": [r["effect"] for r in diag.ranking],
        },
        attrs={
            "verdict": diag.verdict,
            "reason": diag.reason,
            "calibration_case": diag.calibration_case,
            "heldout_gap_before": diag.where["heldout_gap_before"],
        },
    )
