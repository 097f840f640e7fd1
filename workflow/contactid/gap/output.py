"""The diagnosis as files: results/gap/diagnosis.json (the contract) and results/gap/gap.nc."""

from __future__ import annotations

import json
import math

import numpy as np
import xarray as xr

from .diagnosis import Diagnosis

# the force-state maps, one variable per field (name, units, what): the identified motion and what the laws leave
MAP_FIELDS = (
    ("xi", "m", "identified tangential motion xi"),
    ("xi_dot", "m/s", "identified tangential velocity"),
    ("S_residual", "N", "identified S - the friction law at the identified motion"),
    ("eta", "m", "identified normal motion eta"),
    ("eta_dot", "m/s", "identified normal velocity"),
    ("N_residual", "N", "identified N - the best elastic normal law"),
)


def json_ready(x):
    """``x`` ready for json.dumps: numpy scalars as Python ones, non-finite floats as None (null), keys as
    strings."""
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
    """diagnosis.json: verdict, reason, ranking [{effect, heldout_gap_before, heldout_gap_after, score, ...}],
    where (localisation summary), cases (non-finite numbers as null)."""
    return json.dumps(json_ready({**diag.summary(), **(extra or {})}), indent=2)


def updated_model_json(updated: dict, extra: dict | None = None) -> str:
    """results/gap/updated_model.json: the model the explanation arrives at (``explain.updated_model_summary``),
    non-finite numbers (a rigid clamp's stiffness) as null."""
    return json.dumps(json_ready({**updated, **(extra or {})}), indent=2)


def localisation_variables(a: dict) -> dict:
    """The localisation arrays as dataset variables {name: (dims, values, attrs)}: the gap by sensor, harmonic and
    part of the cycle (relative, 1), the energy dissipated per cycle (J) and the force-state maps (SI)."""
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


def record_variables(records: dict, n_harmonics: int) -> dict:
    """The records' acceleration harmonics 1..H (m/s^2, force phase 0), real and imaginary parts, as dataset
    variables {name: (dims, values, attrs)}."""
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


def simulated_variables(diag: Diagnosis, records: dict, n_harmonics: int) -> dict:
    """The simulated acceleration harmonics 1..H (m/s^2) of the base model, the winner and the runner-up, real and
    imaginary parts (NaN where not simulated), as dataset variables {name: (dims, values, attrs)}."""
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


def ranking_variables(ranking: list) -> dict:
    """The candidates' held-out gap after (relative, 1) with its bootstrap 95 % interval and their scores, along
    ``effect``, as dataset variables {name: (dims, values, attrs)}."""
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


def gap_dataset(diag: Diagnosis, records: dict, n_harmonics: int) -> xr.Dataset:
    """The localisation arrays and the measured and simulated harmonics (base model, winner, runner-up)."""
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
