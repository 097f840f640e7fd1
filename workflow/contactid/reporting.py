"""Tables and headline numbers for people: Tables 1, 3 and 4, and summary.json's blocks.

The figures are in paper_figures and modal_figures.
"""

from __future__ import annotations

import json
import math
from typing import Mapping

import numpy as np
import pandas as pd
import xarray as xr

from .consistency import TABLE1_HZ, TABLE3, TABLE4
from .contact_laws import stiction_shear_stiffness
from .friction_parameters import fitted_intervals, fitted_parameters


def _pct(a, b):
    return 100.0 * (a / b - 1.0) if b is not None and np.isfinite(b) and b != 0 else np.nan


def table1(modal: xr.Dataset, truth: xr.Dataset | None) -> pd.DataFrame:
    """Return Table 1: natural frequencies, identified vs paper vs rig truth.

    Parameters
    ----------
    modal
        The modal fit's dataset (modal.nc): ``natural_frequency`` [Hz], ``natural_frequency_std`` [Hz] and
        ``damping_ratio`` [-] along ``mode``.
    truth
        The virtual rig's truth of the random test (data/truth/random_test.nc): ``natural_frequency`` [Hz]; None on
        measured data.

    Returns
    -------
    table : pd.DataFrame
        One row per identified mode: mode, identified_hz, std_hz, damping_ratio, paper_hz, truth_hz (Hz; NaN where
        there is none) and diff_vs_paper_pct, diff_vs_truth_pct (%).
    """
    rows = []
    for i, f in enumerate(modal["natural_frequency"].values):
        paper = TABLE1_HZ[i] if i < len(TABLE1_HZ) else np.nan
        tr = float(truth["natural_frequency"].values[i]) if truth is not None else np.nan
        rows.append(
            {
                "mode": i + 1,
                "identified_hz": f,
                "std_hz": float(modal["natural_frequency_std"].values[i]),
                "damping_ratio": float(modal["damping_ratio"].values[i]),
                "paper_hz": paper,
                "truth_hz": tr,
                "diff_vs_paper_pct": _pct(f, paper),
                "diff_vs_truth_pct": _pct(f, tr),
            }
        )
    return pd.DataFrame(rows)


def table3(stiction: xr.Dataset, truth: xr.Dataset | None) -> pd.DataFrame:
    """Return Table 3: contact stiffness at stiction, identified (or bound) vs paper vs truth.

    Parameters
    ----------
    stiction
        The stiffness fit's dataset: ``k_t``, ``k_n`` [N/m] and their ``k_t_interval``, ``k_n_interval`` (low, high)
        [N/m] (an infinite upper end: only a lower bound).
    truth
        The virtual rig's truth of the random test (data/truth/random_test.nc): ``k_t`` and ``k_n`` [N/m]; None on
        measured data.

    Returns
    -------
    table : pd.DataFrame
        Rows k_t and k_n: identified_n_per_m (NaN where only bounded), interval_low_n_per_m, interval_high_n_per_m,
        reported_as ("value" or "lower bound"), paper_n_per_m, truth_n_per_m (N/m), diff_vs_paper_pct,
        diff_vs_truth_pct (%, of the lower bound where only bounded) and truth_inside_interval.
    """
    rows = []
    for name in ("k_t", "k_n"):
        lo, hi = (float(v) for v in stiction[f"{name}_interval"].values)
        bounded = not math.isinf(hi)
        value = float(stiction[name]) if bounded else np.nan
        tr = float(truth[name]) if truth is not None else np.nan
        rows.append(
            {
                "parameter": name,
                "identified_n_per_m": value,
                "interval_low_n_per_m": lo,
                "interval_high_n_per_m": hi,
                "reported_as": "value" if bounded else "lower bound",
                "paper_n_per_m": TABLE3[name],
                "truth_n_per_m": tr,
                "diff_vs_paper_pct": _pct(value if bounded else lo, TABLE3[name]),
                "diff_vs_truth_pct": _pct(value if bounded else lo, tr),
                "truth_inside_interval": bool(lo <= tr <= hi) if np.isfinite(tr) else None,
            }
        )
    return pd.DataFrame(rows)


def stiction_summary(stiction: xr.Dataset) -> dict:
    """Return the ``stiction`` block of summary.json: k_t and k_n, or k_n_lower_bound; the structure's stiffness scale.

    Parameters
    ----------
    stiction
        The stiffness fit's dataset: ``k_t``, ``k_n``, ``k_t_interval``, ``k_n_interval`` [N/m] and, where Young's
        modulus was fitted, ``stiffness_scale`` [-] (with the attribute ``stiffness_scale_sd``).

    Returns
    -------
    block : dict
        k_t and k_t_interval (N/m); k_n and k_n_interval, or k_n_lower_bound where the interval is open above (N/m);
        stiffness_scale (Young's modulus over the config's) and stiffness_scale_sd (the sd of its prior; 0: held at 1)
        where fitted.
    """
    out = {"k_t": float(stiction["k_t"]), "k_t_interval": [float(v) for v in stiction["k_t_interval"].values]}
    if "stiffness_scale" in stiction:  # Young's modulus over the config's, and the sd of its prior (0: held at 1)
        out["stiffness_scale"] = float(stiction["stiffness_scale"])
        out["stiffness_scale_sd"] = float(stiction.attrs.get("stiffness_scale_sd", 0.0))
    lo, hi = (float(v) for v in stiction["k_n_interval"].values)
    if math.isinf(hi):
        out["k_n_lower_bound"] = lo
    else:
        out["k_n"] = float(stiction["k_n"])
        out["k_n_interval"] = [lo, hi]
    return out


def linear_summary(modal: xr.Dataset, stiction: xr.Dataset, truth: xr.Dataset | None) -> dict:
    """Return the linear part of summary.json: natural frequencies, damping ratios, the stiction block and the truth.

    Parameters
    ----------
    modal
        The modal fit's dataset (modal.nc): ``natural_frequency`` [Hz] and ``damping_ratio`` [-] along ``mode``.
    stiction
        The stiffness fit's dataset (``stiction_summary``).
    truth
        The virtual rig's truth of the random test (data/truth/random_test.nc): ``natural_frequency`` [Hz], ``k_t``
        and ``k_n`` [N/m]; None on measured data.

    Returns
    -------
    block : dict
        natural_frequencies_hz (Hz), damping_ratios, stiction and, where a truth is given, truth: its first n_modes
        natural_frequencies_hz (Hz) and stiction {k_t, k_n} (N/m).
    """
    out = {
        "natural_frequencies_hz": [float(f) for f in modal["natural_frequency"].values],
        "damping_ratios": [float(z) for z in modal["damping_ratio"].values],
        "stiction": stiction_summary(stiction),
    }
    if truth is not None:
        n = modal.sizes["mode"]
        out["truth"] = {
            "natural_frequencies_hz": [float(f) for f in truth["natural_frequency"].values[:n]],
            "stiction": {"k_t": float(truth["k_t"]), "k_n": float(truth["k_n"])},
        }
    return out


def load_case_summary(checks: Mapping[str, xr.Dataset], truths: Mapping[str, xr.Dataset]) -> dict:
    """Return, per load case, the driving-point harmonics read off the raw record and the validation's warnings.

    On rig cases also the truth's force amplitudes and contact extremes.

    Parameters
    ----------
    checks
        The raw checks' datasets by load case: attributes ``A1_m_per_s2``, ``A2_m_per_s2``,
        ``excitation_frequency_hz`` and ``warnings`` (a JSON list) are read.
    truths
        The virtual rig's truth datasets by load case (data/truth/<case>.nc; empty on measured data): ``N`` and ``S``
        [N] over time and the attributes ``friction_mu``, ``F1_n``, ``F3_n``, ``energy_energy_residual``,
        ``target_A1_m_per_s2`` and ``target_A2_m_per_s2``.

    Returns
    -------
    blocks : dict
        load_cases {case: {A1_m_per_s2, A2_m_per_s2 (m/s^2), excitation_frequency_hz (Hz)}}, data_warnings {case:
        [warning, ...]} and, with truths, truth_load_cases {case: {F1_n, F3_n, N_min_n, N_max_n (N), max_S_over_mu_N,
        energy_residual, target_A1_m_per_s2, target_A2_m_per_s2 (m/s^2)}}.
    """
    out = {"load_cases": {}, "data_warnings": {}}
    for case, ds in checks.items():
        out["load_cases"][case] = {
            "A1_m_per_s2": ds.attrs["A1_m_per_s2"],
            "A2_m_per_s2": ds.attrs["A2_m_per_s2"],
            "excitation_frequency_hz": ds.attrs["excitation_frequency_hz"],
        }
        out["data_warnings"][case] = json.loads(ds.attrs.get("warnings", "[]"))
    if truths:
        out["truth_load_cases"] = {}
        for case, tr in truths.items():
            mu = tr.attrs["friction_mu"]
            n = tr["N"].values
            slip = np.abs(tr["S"].values) / np.where(n > 0, mu * n, np.inf)
            out["truth_load_cases"][case] = {
                "F1_n": tr.attrs["F1_n"],
                "F3_n": tr.attrs["F3_n"],
                "N_min_n": float(n.min()),
                "N_max_n": float(n.max()),
                "max_S_over_mu_N": float(slip.max()),
                "energy_residual": tr.attrs.get("energy_energy_residual"),
                "target_A1_m_per_s2": tr.attrs["target_A1_m_per_s2"],
                "target_A2_m_per_s2": tr.attrs["target_A2_m_per_s2"],
            }
    return out


def contact_force_summary(forces: Mapping[str, xr.Dataset], nnms: Mapping[str, xr.Dataset]) -> dict:
    """Return the `contact_forces` (working method) and `contact_forces_paper` blocks of summary.json.

    Parameters
    ----------
    forces
        The identified contact forces' datasets by load case: their attributes (eta_observable,
        eta_spread_over_structures, normal_stiffness_from_n_eta_n_per_m, normal_hardening_n_per_m2, n_harmonics, the
        NRMSEs ``<q>_nrmse`` and ``paper_<q>_nrmse`` of S, N, xi, eta, and the paper decomposition's) are read.
    nnms
        The nonlinear normal modes' datasets by load case: ``phase_spread`` [deg] and the attributes
        ``complex_modes`` and ``reconstruction_nrmse``.

    Returns
    -------
    blocks : dict
        contact_forces {case: the working method's numbers} and contact_forces_paper {case: the paper chain's}.
    """
    work, paper = {}, {}
    for case, ds in forces.items():
        a = ds.attrs
        w = {
            "eta_observable": bool(a["eta_observable"]),
            "eta_spread_over_structures": a.get("eta_spread_over_structures"),
            "normal_stiffness_from_n_eta_n_per_m": a["normal_stiffness_from_n_eta_n_per_m"],
            "normal_hardening_n_per_m2": a["normal_hardening_n_per_m2"],
            "n_harmonics": a["n_harmonics"],
        }
        p = {
            "nnm_phase_spread_deg": [float(v) for v in nnms[case]["phase_spread"].values],
            "complex_modes": bool(nnms[case].attrs["complex_modes"]),
            "reconstruction_nrmse": nnms[case].attrs["reconstruction_nrmse"],
            "S_decomposition_nrmse": a["paper_S_decomposition_nrmse"],
            "N_decomposition_nrmse": a["paper_N_decomposition_nrmse"],
        }
        for q in ("S", "N", "xi", "eta"):
            if f"{q}_nrmse" in a:
                w[f"{q}_nrmse"] = a[f"{q}_nrmse"]
                p[f"{q}_nrmse"] = a[f"paper_{q}_nrmse"]
        work[case], paper[case] = w, p
    return {"contact_forces": work, "contact_forces_paper": paper}


def table4(fit: xr.Dataset, truth_friction: Mapping | None) -> pd.DataFrame:
    """Return Table 4: fitted value and interval, the paper's chain's fit, the paper's value and the rig truth.

    The working method's fitted value and interval of each friction parameter, the paper's chain's fit beside it,
    the paper's value and the rig truth, plus e_0 at the preload.

    Parameters
    ----------
    fit
        The friction fit's dataset: the parameters along ``parameter`` (``friction_parameters.fitted_parameters`` and
        ``fitted_intervals``; e_f, e_t [N/m], k_c [1/m], kappa, mu [-]), ``bounded_below``, ``bounded_above``, the
        paper chain's ``paper_*`` where fitted, and the attributes ``e0_at_preload_n_per_m``, ``e0_interval_low``,
        ``e0_interval_high``, ``paper_e0_at_preload_n_per_m`` and ``preload_n``.
    truth_friction
        The rig's true friction law (config ``rig.truth.friction``: e_f_n_per_m, k_c_per_m, e_t_n_per_m, kappa, mu);
        None (or empty) on measured data.

    Returns
    -------
    table : pd.DataFrame
        One row per parameter and e0_at_preload: identified, interval_low, interval_high, reported_as ("value",
        "upper bound", "lower bound" or "not determined"), paper_chain_fit, paper_value, truth (in the parameter's
        unit), diff_vs_truth_pct (%; NaN for e_t) and truth_inside_interval.
    """
    rows = []
    keys = {"e_f": "e_f_n_per_m", "k_c": "k_c_per_m", "e_t": "e_t_n_per_m", "kappa": "kappa", "mu": "mu"}
    values, intervals = fitted_parameters(fit), fitted_intervals(fit)
    paper = fitted_parameters(fit, "paper_") if "paper_e_f" in fit else np.full(len(values), np.nan)
    for i, name in enumerate(fit["parameter"].values):
        tr = float(truth_friction[keys[name]]) if truth_friction else np.nan
        v = float(values[i])
        lo, hi = float(intervals[i, 0]), float(intervals[i, 1])
        kind = (
            "value"
            if fit["bounded_below"].values[i] and fit["bounded_above"].values[i]
            else "upper bound"
            if fit["bounded_above"].values[i]
            else "lower bound"
            if fit["bounded_below"].values[i]
            else "not determined"
        )
        rows.append(
            {
                "parameter": name,
                "identified": v,
                "interval_low": lo,
                "interval_high": hi,
                "reported_as": kind,
                "paper_chain_fit": float(paper[i]),
                "paper_value": TABLE4[name],
                "truth": tr,
                "diff_vs_truth_pct": _pct(v, tr) if name != "e_t" else np.nan,
                "truth_inside_interval": bool(lo <= tr <= hi) if np.isfinite(tr) else None,
            }
        )
    e0 = fit.attrs["e0_at_preload_n_per_m"]
    e0_paper = float(stiction_shear_stiffness_paper(fit.attrs["preload_n"]))
    e0_truth = (
        float(
            stiction_shear_stiffness(
                fit.attrs["preload_n"], float(truth_friction["e_f_n_per_m"]), float(truth_friction["k_c_per_m"])
            )
        )
        if truth_friction
        else np.nan
    )
    rows.append(
        {
            "parameter": "e0_at_preload",
            "identified": e0,
            "interval_low": fit.attrs["e0_interval_low"],
            "interval_high": fit.attrs["e0_interval_high"],
            "reported_as": "value",
            "paper_chain_fit": fit.attrs.get("paper_e0_at_preload_n_per_m", np.nan),
            "paper_value": e0_paper,
            "truth": e0_truth,
            "diff_vs_truth_pct": _pct(e0, e0_truth),
            "truth_inside_interval": bool(fit.attrs["e0_interval_low"] <= e0_truth <= fit.attrs["e0_interval_high"])
            if np.isfinite(e0_truth)
            else None,
        }
    )
    return pd.DataFrame(rows)


def stiction_shear_stiffness_paper(preload: float) -> float:
    """Return e_0 of the paper's Table 4 law at the preload (Eq. 22).

    Parameters
    ----------
    preload
        The static normal preload N0 [N].

    Returns
    -------
    e0 : float
        The stiction shear stiffness e_0 = e_f (1 - exp(-k_c N0 / e_f)) [N/m].
    """
    return float(stiction_shear_stiffness(preload, TABLE4["e_f"], TABLE4["k_c"]))


def friction_summary(fit: xr.Dataset, validations: Mapping[str, xr.Dataset]) -> dict:
    """Return the `friction` and `validation_nrmse` blocks of summary.json.

    Parameters
    ----------
    fit
        The friction fit's dataset: the parameters and intervals (``friction_parameters``), ``bounded_below``,
        ``bounded_above``, ``correlation`` and the attributes ``e0_at_preload_n_per_m``, ``e0_interval_low``,
        ``e0_interval_high``, ``misfit_nrmse`` and ``regularization``.
    validations
        The validation datasets by load case: attributes ``nrmse_vs_identified``, ``nrmse_other_regularization`` and
        (rig cases) ``nrmse_vs_truth``.

    Returns
    -------
    blocks : dict
        friction (each parameter, e0_at_preload, intervals, only_bounded, misfit_nrmse, correlation_e_f_k_c,
        regularization, S_change_other_regularization), validation_nrmse and, on rig cases,
        validation_nrmse_vs_truth.
    """
    p = dict(zip(fit["parameter"].values, (float(v) for v in fitted_parameters(fit))))
    intervals = {n: [float(lo), float(hi)] for n, (lo, hi) in zip(fit["parameter"].values, fitted_intervals(fit))}
    bounded_only = [
        n
        for n, b, a in zip(fit["parameter"].values, fit["bounded_below"].values, fit["bounded_above"].values)
        if not (b and a)
    ]
    out = {
        "friction": {
            **p,
            "e0_at_preload": fit.attrs["e0_at_preload_n_per_m"],
            "intervals": {**intervals, "e0_at_preload": [fit.attrs["e0_interval_low"], fit.attrs["e0_interval_high"]]},
            "only_bounded": bounded_only,
            "misfit_nrmse": fit.attrs["misfit_nrmse"],
            "correlation_e_f_k_c": float(fit["correlation"].values[0, 1]),
            "regularization": fit.attrs["regularization"],
            # S of the fitted parameters read the other way (slip_limit vs as printed), NRMSE per case
            "S_change_other_regularization": {c: v.attrs["nrmse_other_regularization"] for c, v in validations.items()},
        },
        "validation_nrmse": {c: v.attrs["nrmse_vs_identified"] for c, v in validations.items()},
    }
    if any("nrmse_vs_truth" in v.attrs for v in validations.values()):
        out["validation_nrmse_vs_truth"] = {
            c: v.attrs["nrmse_vs_truth"] for c, v in validations.items() if "nrmse_vs_truth" in v.attrs
        }
    return out


def model_form_summary(intervals: Mapping) -> dict:
    """Return `friction.model_form_intervals` of summary.json from friction_intervals.json.

    Parameters
    ----------
    intervals
        friction_intervals.json's content: ``model`` and ``parameters`` (``confidence`` and, per parameter, its
        ``value`` and ``interval``) are read.

    Returns
    -------
    block : dict
        The model the intervals are for (``chain`` or ``updated``), the confidence and per parameter its value and
        interval with the model-form term (``e0`` is e_0 at the preload).
    """
    par = intervals["parameters"]
    return {
        "model": intervals["model"],
        "confidence": par["confidence"],
        **{n: {"value": v["value"], "interval": v["interval"]} for n, v in par.items() if n != "confidence"},
    }


def records_check_summary(check: Mapping, data_warnings: dict[str, list[str]]) -> dict:
    """Return `records_check` of summary.json from record_checks.json (``gap.record_checks.records_check``).

    Each finding's message is added to ``data_warnings`` under its record (in place), so that every warning about a
    record is in one list.

    Parameters
    ----------
    check
        record_checks.json's content: ``passed``, ``findings`` (each with record, check and message), ``gaps`` and
        ``calibration_case`` are read.
    data_warnings
        summary.json's warnings by record, added to in place.

    Returns
    -------
    block : dict
        passed, the findings, heldout_gap_to_model (each case's gap to the identified model) and calibration_case.
    """
    for f in check.get("findings", []):
        data_warnings.setdefault(f["record"], []).append(f"records check ({f['check']}): {f['message']}")
    return {
        "passed": bool(check.get("passed", True)),
        "findings": list(check.get("findings", [])),
        "heldout_gap_to_model": dict(check.get("gaps", {})),
        "calibration_case": check.get("calibration_case"),
    }
