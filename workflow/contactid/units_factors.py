"""The factors by which a vibration record written in other units than its labels is off, and what each means.

One table for every check that names a units error (the raw checks' level against the FRF, the stiffness step's FRF
amplitudes, the records' check).
"""

from __future__ import annotations

import numpy as np

# (factor, what a record whose accelerance is that many times the expected one has, what one 1/factor times has);
# the metric ones only: a factor of 4.448 (lbf) or 3.28 (ft) is as near what an effect a model lacks does to a
# prediction (4-5 times at a level where a contact opens: the blind benchmark's contact-separation items)
UNIT_FACTORS = (
    (
        9.80665,
        "the force in kgf labelled N",
        "accelerations in g labelled m/s^2 (multiply them by 9.80665, or give the unit g in an imported file's "
        "channel map)",
    ),
    (1000.0, "accelerations in mm/s^2 labelled m/s^2, or the force in kN labelled N", "the force in mN labelled N"),
    (100.0, "accelerations in cm/s^2 labelled m/s^2", "accelerations in m/s^2 read from a file in cm/s^2 twice"),
)


def units_error(ratio: float, tolerance: float) -> tuple[float, str] | None:
    """Return the units factor an accelerance ratio is near, and what it means.

    The ratio is matched against every factor of ``UNIT_FACTORS`` and its inverse, in the table's order; the first
    within ``tolerance`` is named.

    Parameters
    ----------
    ratio
        An accelerance of the record over the expected one [-].
    tolerance
        Relative distance from a units factor (on a log scale: within a factor 1 + tolerance) that still counts as
        that factor [-].

    Returns
    -------
    factor : float
        The units factor or its inverse that ``ratio`` is near [-]; the whole result is None where none is.
    meaning : str
        What a record off by that factor has (for example "the force in kgf labelled N").
    """
    for factor, larger, smaller in UNIT_FACTORS:
        for value, meaning in ((factor, larger), (1.0 / factor, smaller)):
            if ratio > 0 and abs(np.log(ratio / value)) <= np.log1p(tolerance):
                return value, meaning
    return None


def near_units(ratio: float, tolerance: float) -> bool:
    """Return whether a ratio is within a tolerance of a units factor or its inverse (``units_error``).

    Parameters
    ----------
    ratio
        An accelerance of the record over the expected one [-].
    tolerance
        Relative distance from a units factor (on a log scale: within a factor 1 + tolerance) that still counts as
        that factor [-].

    Returns
    -------
    near : bool
        True where ``units_error`` names a factor.
    """
    return units_error(ratio, tolerance) is not None
