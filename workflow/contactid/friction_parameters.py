"""The modified Valanis law's parameters (Eqs. 21-22) in the friction fit's datasets.

One variable per parameter, each in its own units, with its profile-likelihood interval
(results/friction/friction_fit.nc); light enough for the report's and the diagnosis' modules to read them without the
fit's numerics.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import xarray as xr

PARAMETER_NAMES = ("e_f", "k_c", "e_t", "kappa", "mu")
PARAMETER_UNITS = ("N/m", "1/m", "N/m", "1", "1")  # of e_f, k_c, e_t, kappa, mu (Eqs. 21-22)
ESTIMATES = ("value", "interval_low", "interval_high")
GRID_FIELDS = (("grid_points", "1"), *zip(PARAMETER_NAMES, PARAMETER_UNITS), ("misfit", "1"))


def parameter_variables(
    params: np.ndarray, intervals: np.ndarray | None = None, prefix: str = "", what: str = "fitted"
) -> dict:
    """Return one dataset variable per parameter of the law (Eqs. 21-22).

    Each is named ``prefix`` + the parameter's name, in the parameter's own units, over the dimension ``estimate``:
    the value and, given ``intervals``, the profile-likelihood interval's ends (``ESTIMATES``).

    Parameters
    ----------
    params
        The law's parameters in the order of ``PARAMETER_NAMES``: e_f [N/m], k_c [1/m], e_t [N/m], kappa [-],
        mu [-]; shape (5,).
    intervals
        Their profile-likelihood intervals, in each parameter's units (as ``params``: [N/m], [1/m], [N/m], [-],
        [-]), shape (5, 2): lower and upper end (NaN where not profiled); None for the values alone.
    prefix
        Prefix of the variables' names (``"paper_"`` for the fit to the paper's chain's forces).
    what
        What the values are, the start of each variable's ``long_name``.

    Returns
    -------
    variables : dict
        {prefix + name: ("estimate", values, attributes)} per parameter: its value, and with ``intervals`` the
        interval's ends (values of shape (1,) or (3,), in the units of ``PARAMETER_UNITS``), with the attributes
        ``units`` and ``long_name``; the data variables of an ``xr.Dataset``.
    """
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


def fitted_parameters(fit: xr.Dataset, prefix: str = "") -> np.ndarray:
    """Return the law's fitted parameters from a dataset with the variables of ``parameter_variables``.

    Parameters
    ----------
    fit
        A friction-fit dataset (results/friction/friction_fit.nc, or ``parameter_dataset``'s) with one variable per
        parameter over the dimension ``estimate``.
    prefix
        Prefix of the variables' names (``"paper_"`` for the fit to the paper's chain's forces).

    Returns
    -------
    params : np.ndarray
        e_f [N/m], k_c [1/m], e_t [N/m], kappa [-], mu [-] (the order of ``PARAMETER_NAMES``), shape (5,).
    """
    return np.array([float(fit[prefix + name].sel(estimate="value")) for name in PARAMETER_NAMES])


def fitted_intervals(fit: xr.Dataset, prefix: str = "") -> np.ndarray:
    """Return the parameters' profile-likelihood intervals from a dataset with the variables of ``parameter_variables``.

    Parameters
    ----------
    fit
        A friction-fit dataset (results/friction/friction_fit.nc) whose parameter variables hold the estimates
        ``interval_low`` and ``interval_high``.
    prefix
        Prefix of the variables' names (``"paper_"`` for the fit to the paper's chain's forces).

    Returns
    -------
    intervals : np.ndarray
        Lower and upper end of each parameter's interval, in the parameters' units (e_f [N/m], k_c [1/m],
        e_t [N/m], kappa [-], mu [-]), shape (5, 2).
    """
    return np.array(
        [[float(fit[prefix + n].sel(estimate=e)) for e in ("interval_low", "interval_high")] for n in PARAMETER_NAMES]
    )


def parameter_dataset(params: np.ndarray | Sequence[float], regularization: str) -> xr.Dataset:
    """Return a friction-fit dataset of the law's parameters alone (what ``gap.model.identified_model`` reads).

    Parameters
    ----------
    params
        The law's parameters in the order of ``PARAMETER_NAMES``: e_f [N/m], k_c [1/m], e_t [N/m], kappa [-],
        mu [-]; shape (5,).
    regularization
        How the law reads Eq. 21 (friction_fit.regularization: ``"none"`` or ``"slip_limit"``), kept as the
        dataset's attribute ``regularization``.

    Returns
    -------
    fit : xr.Dataset
        One variable per parameter (``parameter_variables``) over ``estimate`` = ["value"].
    """
    import xarray as xr

    return xr.Dataset(
        parameter_variables(np.asarray(params, dtype=float)),
        coords={"estimate": ["value"]},
        attrs={"regularization": regularization},
    )
