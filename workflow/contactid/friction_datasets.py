"""The friction fit's datasets: the fitted law (rule friction_fit) and the S it predicts (rule validate).

The law is fitted (``contactid.friction_fit``) to the calibration case's identified forces, with the paper's
chain's forces fitted beside it; a load case's S is predicted by the fitted law from its own identified xi and N.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .friction import PARAMETER_NAMES, REGULARIZATIONS, valanis_friction_force

# log: contactid.friction_fit's logger, the name every line of the friction fit carries
from .friction_fit import FitResult, FitSettings, fit_friction_law, log
from .friction_parameters import ESTIMATES, GRID_FIELDS, fitted_parameters, parameter_variables
from .friction_problem import N_OPEN
from .harmonics import periodic_grid

if TYPE_CHECKING:
    import xarray as xr


def _fit_on_forces(
    S, xi, N, fs: float, f0: float, preload: float, settings: FitSettings, seed: int, n_harmonics: int, label: str
) -> FitResult:
    """Return the law fitted (``fit_friction_law``) to one method's S, xi and N_dyn records.

    S (N), xi (m) and N_dyn (N) records sampled at ``fs`` (Hz), fitted through their first ``n_harmonics`` harmonics of
    ``f0`` (Hz).
    """
    from .harmonics import fourier_series

    c = [fourier_series(x, fs, f0, n_harmonics)[0] for x in (xi, N, S)]
    return fit_friction_law(*c, f0, preload, settings, seed, n_harmonics, label=label)


def _fit_variables(res: FitResult) -> dict:
    """Return the dataset's variables of the working method's fit.

    One variable per parameter (e_f, k_c, e_t in N/m, 1/m, N/m; kappa, mu dimensionless) with its interval, the bounds,
    correlation, the GA's misfits per generation and the grid refinements.
    """
    return {
        **parameter_variables(res.params, res.intervals),
        "bounded_below": (
            "parameter",
            res.bounded[:, 0].astype(int),
            {"units": "1", "long_name": "1 if the data bound it from below inside the search range"},
        ),
        "bounded_above": (
            "parameter",
            res.bounded[:, 1].astype(int),
            {"units": "1", "long_name": "1 if the data bound it from above inside the search range"},
        ),
        "correlation": (
            ("parameter", "parameter_"),
            res.correlation,
            {
                "units": "1",
                "long_name": "correlation at the optimum",
                "nonfinite_meaning": "NaN: the parameter is insensitive at the optimum",
            },
        ),
        "ga_best": (
            "generation",
            [b for _, b, _ in res.logbook],
            {"units": "1", "long_name": "best misfit (NRMSE of S) per generation"},
        ),
        "ga_mean": (
            "generation",
            [m for _, _, m in res.logbook],
            {"units": "1", "long_name": "mean misfit per generation"},
        ),
        **{
            f"refinement_{name}": (
                "refinement",
                np.array(res.grid_history)[:, k],
                {"units": unit, "long_name": f"{name} per grid refinement"},
            )
            for k, (name, unit) in enumerate(GRID_FIELDS)
        },
    }


def _fit_attrs(
    res: FitResult, forces, preload: float, f0: float, settings: FitSettings, seed: int, n_harmonics: int
) -> dict:
    """Return the dataset's attributes of the working method's fit.

    e_0 at the preload and its interval (N/m), misfit, settings, and the share of the record with the contact open
    (identified N total <= ``N_OPEN``).
    """
    attrs = {
        "e0_at_preload_n_per_m": res.e0_at_preload,
        "e0_interval_low": res.e0_interval[0],
        "e0_interval_high": res.e0_interval[1],
        "misfit_nrmse": res.misfit,
        "grid_points": res.grid_points,
        "preload_n": preload,
        "excitation_frequency_hz": f0,
        "n_harmonics": n_harmonics,
        "seed": seed,
        "population": settings.population,
        "generations": settings.generations,
        "regularization": settings.regularization,
        "confidence": settings.confidence,
        "misfit_floor": settings.misfit_floor,  # the accuracy the intervals assume for S (contactid.model_checks)
        "warnings": "; ".join(res.warnings) or "none",
    }
    n_total = preload + forces["N_dyn"].values
    attrs["open_fraction"] = float(np.mean(n_total <= N_OPEN))  # share of the record with the contact open
    return attrs


def _paper_fit_outputs(paper_forces, preload: float, fit) -> tuple[dict, dict]:
    """Return (variables, attributes) of the law fitted to the paper's chain's forces by ``fit``.

    ``fit`` is ``_fit_on_forces`` with the record's settings bound; when the forces cannot be fitted (their total N
    reaches 0 N, or the fit fails), no variable and the reason as ``paper_fit_error``.
    """
    try:
        n_paper = preload + paper_forces["N_dyn_paper"].values
        if np.min(n_paper) <= 0:  # not a separation the working method sees: the paper's N is wrong
            raise ValueError(
                f"the normal force reaches {np.min(n_paper):.3g} N <= 0 N, where the working "
                "method's contact stays closed: the paper's N is not a physical normal force"
            )
        rp = fit(
            paper_forces["S_paper"].values,
            paper_forces["xi_paper"].values,
            paper_forces["N_dyn_paper"].values,
            "friction fit (paper's chain)",
        )
    except ValueError as exc:  # e.g. the paper's N reaches zero: the law is not defined there
        log.warning("the paper's chain's forces cannot be fitted: %s", exc)
        return {}, {"paper_fit_error": str(exc)}
    data = parameter_variables(rp.params, rp.intervals, prefix="paper_", what="fitted to the paper's chain's forces:")
    return data, {"paper_e0_at_preload_n_per_m": rp.e0_at_preload, "paper_misfit_nrmse": rp.misfit}


def friction_fit_dataset(
    forces: xr.Dataset,
    preload: float,
    settings: FitSettings,
    seed: int,
    n_harmonics: int,
    paper_forces: xr.Dataset | None = None,
) -> xr.Dataset:
    """Fit the friction law to the calibration case's identified forces and return the fit's dataset.

    The working method's forces are fitted; the paper's chain's forces are fitted beside them when given
    (reproduction).

    Parameters
    ----------
    forces
        The calibration case's identified contact forces (rule contact_forces): ``S`` [N], ``xi`` [m] and ``N_dyn``
        (the dynamic part of the normal force) [N] over a uniformly sampled ``time`` [s], with the attribute
        ``excitation_frequency_hz``.
    preload
        Static normal preload N0 [N].
    settings
        The fit's settings (bounds, GA, grid, confidence, regularization).
    seed
        Seed of the genetic algorithm.
    n_harmonics
        Harmonics of the excitation frequency the records are fitted through.
    paper_forces
        The paper's chain's forces (variables ``S_paper``, ``xi_paper``, ``N_dyn_paper`` in N, m, N, on the same
        ``time``), or None for no reproduction fit.

    Returns
    -------
    fit : xr.Dataset
        One variable per law parameter (e_f, k_c, e_t, kappa, mu, over ``estimate``: value and profile-likelihood
        interval), ``bounded_below``, ``bounded_above``, ``correlation`` (``parameter`` x ``parameter_``), the GA's
        ``ga_best`` and ``ga_mean`` per ``generation``, the grid refinements; the attributes of the fit (e_0 at the
        preload and its interval in N/m, misfit, settings, open fraction); with ``paper_forces``, the paper's
        chain's fit under the prefix ``paper_`` or its ``paper_fit_error``.
    """
    import xarray as xr

    fs = 1.0 / float(forces["time"].values[1] - forces["time"].values[0])
    f0 = float(forces.attrs["excitation_frequency_hz"])

    def run(S, xi, N, label):
        return _fit_on_forces(S, xi, N, fs, f0, preload, settings, seed, n_harmonics, label)

    res = run(forces["S"].values, forces["xi"].values, forces["N_dyn"].values, "friction fit")
    data = _fit_variables(res)
    attrs = _fit_attrs(res, forces, preload, f0, settings, seed, n_harmonics)
    if paper_forces is not None:
        paper_data, paper_attrs = _paper_fit_outputs(paper_forces, preload, run)
        data.update(paper_data)
        attrs.update(paper_attrs)
    return xr.Dataset(
        data,
        coords={
            "parameter": list(PARAMETER_NAMES),
            "parameter_": list(PARAMETER_NAMES),
            "generation": np.arange(len(res.logbook)),
            "estimate": list(ESTIMATES),
        },
        attrs=attrs,
    )


def validation_dataset(
    forces: xr.Dataset, fit: xr.Dataset, preload: float, n_harmonics: int, truth: xr.Dataset | None = None
) -> xr.Dataset:
    """Predict S(t) of a load case from its own identified xi(t), N(t) with the fitted law.

    On a fine periodic grid (the fit's ``grid_points`` per period), with the NRMSE against the identified S and,
    given the truth, against the true S; the law is also evaluated under the other reading of Eq. 21
    (``regularization``) to show how much that choice matters.

    Parameters
    ----------
    forces
        The load case's identified contact forces (rule contact_forces): ``xi`` [m], ``xi_dot`` [m/s], ``N_dyn`` [N]
        and ``S`` [N] over a uniformly sampled ``time`` [s], with the attribute ``excitation_frequency_hz``.
    fit
        The friction fit's dataset (``friction_fit_dataset``): the law's parameters and the attributes
        ``grid_points`` and ``regularization``.
    preload
        Static normal preload N0 [N].
    n_harmonics
        Harmonics of the excitation frequency the records are synthesised from.
    truth
        The rig's truth for the load case (variable ``S`` [N] on the same ``time``), or None (measured records).

    Returns
    -------
    validation : xr.Dataset
        ``xi``, ``xi_dot``, ``N`` (total), ``S_identified``, ``S_predicted`` (and ``S_truth``) over one period
        (``phase``, fraction of the period), the S means removed; attributes ``nrmse_vs_identified`` (and
        ``nrmse_vs_truth``) and ``nrmse_other_regularization`` (the other reading's prediction against this one's), as
        fractions, with ``excitation_frequency_hz``, ``regularization`` and ``other_regularization``.
    """
    import xarray as xr

    from .harmonics import fourier_series
    from .identification import nrmse

    fs = 1.0 / float(forces["time"].values[1] - forces["time"].values[0])
    f0 = float(forces.attrs["excitation_frequency_hz"])
    m = int(fit.attrs["grid_points"])
    c = {v: fourier_series(forces[v].values, fs, f0, n_harmonics)[0] for v in ("xi", "N_dyn", "S", "xi_dot")}
    xi = periodic_grid(c["xi"], f0, m)[0]
    N = preload + periodic_grid(c["N_dyn"], f0, m)[0]
    S_id = periodic_grid(c["S"], f0, m)[0]
    xi_dot = periodic_grid(c["xi_dot"], f0, m)[0]
    reading = fit.attrs["regularization"]
    S_pred = valanis_friction_force(xi, N, fitted_parameters(fit)[None, :], regularization=reading)[0]
    other = next(r for r in REGULARIZATIONS if r != reading)
    S_other = valanis_friction_force(xi, N, fitted_parameters(fit)[None, :], regularization=other)[0]
    S_pred, S_other = S_pred - S_pred.mean(), S_other - S_other.mean()
    attrs = {
        "nrmse_vs_identified": nrmse(S_pred, S_id),
        "excitation_frequency_hz": f0,
        "regularization": reading,
        "other_regularization": other,
        "nrmse_other_regularization": nrmse(S_other, S_pred),
    }
    data = {
        "xi": ("phase", xi, {"units": "m", "long_name": "identified xi over one period"}),
        "xi_dot": ("phase", xi_dot, {"units": "m/s", "long_name": "identified d xi/dt over one period"}),
        "N": ("phase", N, {"units": "N", "long_name": "total normal force (preload + identified dynamic part)"}),
        "S_identified": ("phase", S_id - S_id.mean(), {"units": "N", "long_name": "identified S, mean removed"}),
        "S_predicted": ("phase", S_pred, {"units": "N", "long_name": "S predicted by the fitted law, mean removed"}),
    }
    if truth is not None:
        ts = periodic_grid(fourier_series(truth["S"].values, fs, f0, max(n_harmonics, 60))[0], f0, m)[0]
        attrs["nrmse_vs_truth"] = nrmse(S_pred, ts)
        data["S_truth"] = ("phase", ts - ts.mean(), {"units": "N", "long_name": "true S, mean removed"})
    return xr.Dataset(
        data,
        coords={"phase": ("phase", np.arange(m) / m, {"units": "1", "long_name": "fraction of the period"})},
        attrs=attrs,
    )
