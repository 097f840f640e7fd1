"""The numbers' formatting the gap section's modules share.

Those modules: ``report``, ``report_diagnosis``, ``report_base_model``, ``report_benchmark``.
"""

from __future__ import annotations

from ..latex import latex_number


def num(x: float | None) -> float:
    """Return a diagnosis.json number as a float, NaN where it is null.

    diagnosis.json writes null where a number was not finite.

    Parameters
    ----------
    x
        The number as read from the JSON, or None [-]: the callers pass dimensionless gaps, shares, scores and
        chi^2 values (the value keeps whatever unit it has).

    Returns
    -------
    value : float
        ``x`` as a float, NaN where it is None [unit of x].
    """
    return float("nan") if x is None else float(x)


def pct(x: float | None) -> str:
    """Return a diagnosis.json fraction as a LaTeX percentage.

    Three significant digits; "--" where the fraction is null.

    Parameters
    ----------
    x
        The fraction as read from the JSON (0.05 for 5 %), or None [-].

    Returns
    -------
    text : str
        The percentage as LaTeX text, or "--".
    """
    return "--" if x is None else f"${latex_number(100 * float(x), 3)}$\\,\\%"
