"""The numbers' formatting the gap section's modules share (``report``, ``report_diagnosis``, ``report_base_model``,
``report_benchmark``)."""

from __future__ import annotations

from ..latex import latex_number


def num(x) -> float:
    """A diagnosis.json number (null where it was not finite) as a float."""
    return float("nan") if x is None else float(x)


def pct(x) -> str:
    """A diagnosis.json fraction as a LaTeX percentage (three significant digits), "--" where it is null."""
    return "--" if x is None else f"${latex_number(100 * float(x), 3)}$\\,\\%"
