"""The modified Valanis law's parameters (Eqs. 21-22) in the friction fit's datasets: one variable per parameter,
each in its own units, with its profile-likelihood interval (results/friction/friction_fit.nc); light enough for the
report's and the diagnosis' modules to read them without the fit's numerics."""

from __future__ import annotations

import numpy as np

PARAMETER_NAMES = ("e_f", "k_c", "e_t", "kappa", "mu")
PARAMETER_UNITS = ("N/m", "1/m", "N/m", "1", "1")  # of e_f, k_c, e_t, kappa, mu (Eqs. 21-22)
ESTIMATES = ("value", "interval_low", "interval_high")
GRID_FIELDS = (("grid_points", "1"), *zip(PARAMETER_NAMES, PARAMETER_UNITS), ("misfit", "1"))


def parameter_variables(params, intervals=None, prefix: str = "", what: str = "fitted") -> dict:
    """One dataset variable per parameter of the law (Eqs. 21-22), named ``prefix`` + its name, in its own units,
    over the dimension ``estimate``: the value and, given ``intervals`` ((5, 2): lower, upper end), the
    profile-likelihood interval's ends (``ESTIMATES``)."""
    n = 1 if intervals is None else 3
    out = {}
    for i, (name, unit) in enumerate(zip(PARAMETER_NAMES, PARAMETER_UNITS)):
        values = [params[i]] if intervals is None else [params[i], intervals[i][0], intervals[i][1]]
        ends = "" if intervals is None else " and its profile-likelihood interval"
        out[prefix + name] = (
            "estimate",
            np.asarray(values[:n], dtype=float),
            {"units": unit, "long_name": f"{what} {name}{ends}"},
        )
    return out


def fitted_parameters(fit, prefix: str = "") -> np.ndarray:
    """The law's parameters (e_f, k_c, e_t, kappa, mu; N/m, 1/m, N/m, 1, 1) from a dataset with the variables of
    ``parameter_variables``."""
    return np.array([float(fit[prefix + name].sel(estimate="value")) for name in PARAMETER_NAMES])


def fitted_intervals(fit, prefix: str = "") -> np.ndarray:
    """The parameters' profile-likelihood intervals (5, 2): lower and upper end, in the parameters' units."""
    return np.array(
        [[float(fit[prefix + n].sel(estimate=e)) for e in ("interval_low", "interval_high")] for n in PARAMETER_NAMES]
    )


def parameter_dataset(params, regularization: str):
    """A friction-fit dataset of the law's parameters alone (what ``gap.model.identified_model`` reads)."""
    import xarray as xr

    return xr.Dataset(
        parameter_variables(np.asarray(params, dtype=float)),
        coords={"estimate": ["value"]},
        attrs={"regularization": regularization},
    )
