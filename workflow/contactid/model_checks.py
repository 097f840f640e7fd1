"""Model checks: each identification step's fit against the accuracy it assumes.

The raw checks (``contactid.raw_checks``) say whether the records are fit for identification; these say
whether the identified model is fit for the records. Two fits state their own accuracy:

- the stiffness fit (Table 3) weighs the identified natural frequencies by their uncertainty
  (``stiction.frequency_uncertainty_floor`` and the modal fit's scatter): with more frequencies than its
  two stiffnesses, its minimum chi^2 follows a chi^2 law with n - 2 degrees of freedom when the nominal
  structure is right. A minimum beyond that law's ``confidence`` quantile means the structure with contact
  springs cannot reproduce the frequencies: k_t and k_n then absorb a structural error (Young's modulus,
  masses, lever arm, clamp), and their intervals hold for the model's structure only. On a rig 3 % softer
  than the model (E), the fit put k_n at 3.6e6 N/m (truth 2.37e7) with an interval that excluded the truth,
  at chi^2 = 13.1 for one degree of freedom (docs/measurements.md, "A rig whose beam is softer than the model, the
  benchmark's time by stage, and the test suite");
- the friction fit (Table 4) profiles its intervals with the identified S assumed accurate to
  ``friction.misfit_floor`` (relative): a misfit beyond it means the law, or the S it is fitted to, does not
  describe the record to that accuracy, and its intervals are narrower than the error of its parameters.

Each check is a dict {check, value, limit, passed, message} (the stiffness fit's also ``dof`` and ``p_value``);
``message`` is plain text for people.
"""

from __future__ import annotations

import math
from typing import Mapping

# What a failed check means, said once for the rule logs (plain text) and the report (LaTeX, ``contactid.report_text``):
# the finding, then its consequence; {k_t}, {k_n} and {S} are the symbols as each medium writes them
STIFFNESS_FINDING = (
    "the structure with contact springs cannot reproduce the identified frequencies within their uncertainty"
)
STIFFNESS_CONSEQUENCE = (
    "{k_t} and {k_n} absorb a structural error (masses, lever arm, clamp, or a Young's modulus beyond its prior) and "
    "their intervals hold for the model's structure only. Model updating (the gap diagnosis) says which structural "
    "change the data support"
)
FRICTION_FINDING = "the law, or the {S} it is fitted to, does not describe the record to that accuracy"
FRICTION_CONSEQUENCE = (
    "its parameters carry a model-form error their profile-likelihood intervals do not hold (the gap diagnosis says "
    "where it lies)"
)
PLAIN = {"k_t": "k_t", "k_n": "k_n", "S": "S"}


def stiffness_fit_check(chi2_min: float, n_frequencies: int, confidence: float) -> dict | None:
    """Check the stiffness fit's consistency: its minimum chi^2 against the quantile of the chi^2 law it follows.

    ``chi2_min`` (the weighted misfit's minimum over k_t, k_n) is compared with the ``confidence`` quantile of chi^2
    with ``n_frequencies`` - 2 degrees of freedom.

    Parameters
    ----------
    chi2_min
        The weighted misfit's minimum over k_t and k_n (residuals in units of the frequencies' uncertainty) [-].
    n_frequencies
        How many identified natural frequencies the fit weighs.
    confidence
        The quantile the limit is taken at (e.g. 0.95) [-].

    Returns
    -------
    check : dict | None
        {check: "stiffness_fit", value, limit, dof, passed, p_value, message}; None where the fit has no degree of
        freedom left (two frequencies or fewer: k_t and k_n fit any two).
    """
    dof = int(n_frequencies) - 2
    if dof < 1:
        return None
    from scipy.stats import chi2

    limit = float(chi2.ppf(confidence, dof))
    value = float(chi2_min)
    passed = bool(value <= limit)
    p = float(chi2.sf(value, dof))
    head = f"stiffness fit: chi^2 = {value:.3g} for {dof} degree{'s' if dof > 1 else ''} of freedom"
    if passed:
        message = (
            f"{head} (limit {limit:.3g} at {100 * confidence:g} %): the structure with contact springs reproduces the "
            "frequencies"
        )
    else:
        message = (
            f"{head}, beyond the limit {limit:.3g} at {100 * confidence:g} % (p = {p:.2g}): {STIFFNESS_FINDING}; "
            + STIFFNESS_CONSEQUENCE.format(**PLAIN)
        )
    return {
        "check": "stiffness_fit",
        "value": value,
        "limit": limit,
        "dof": dof,
        "passed": passed,
        "p_value": p,
        "message": message,
    }


def friction_fit_check(misfit_nrmse: float, misfit_floor: float) -> dict:
    """Check the friction fit's consistency: its misfit against the accuracy its intervals assume.

    The misfit (NRMSE of the law against the identified S) is compared with the relative accuracy the fit's
    profile-likelihood intervals assume for that S (``friction.misfit_floor``).

    Parameters
    ----------
    misfit_nrmse
        The fit's NRMSE of S, relative to the rms of the identified S [-] (a ratio, not %; NaN fails).
    misfit_floor
        The relative accuracy the intervals assume for S (config ``friction.misfit_floor``) [-].

    Returns
    -------
    check : dict
        {check: "friction_fit", value, limit, passed, message}.
    """
    value, limit = float(misfit_nrmse), float(misfit_floor)
    passed = bool(math.isfinite(value) and value <= limit)
    head = f"friction fit: the law fits the identified S to {100 * value:.3g} % (NRMSE)"
    if passed:
        message = f"{head}, within the accuracy its intervals assume ({100 * limit:.3g} %)"
    else:
        ratio = value / limit if limit > 0 else math.inf
        message = (
            f"{head}, {ratio:.3g} times the accuracy its intervals assume ({100 * limit:.3g} %, "
            f"friction.misfit_floor): {FRICTION_FINDING.format(**PLAIN)}; {FRICTION_CONSEQUENCE}"
        )
    return {"check": "friction_fit", "value": value, "limit": limit, "passed": passed, "message": message}


def model_checks(stiction_attrs: Mapping, n_frequencies: int, fit_attrs: Mapping | None = None) -> list[dict]:
    """Return every model check the results allow: the stiffness fit's and, for a fitted law, the friction fit's.

    Parameters
    ----------
    stiction_attrs
        The stiction dataset's attributes: ``chi2_min`` and ``confidence`` (default 0.95) are read.
    n_frequencies
        How many identified natural frequencies the stiffness fit weighs.
    fit_attrs
        The friction fit dataset's attributes: ``misfit_nrmse`` and ``misfit_floor`` (a fit written before it kept
        one: the schema's default) are read; None where the friction law was not fitted.

    Returns
    -------
    checks : list[dict]
        The stiffness fit's check (``stiffness_fit_check``; left out where it has no degree of freedom) and the
        friction fit's (``friction_fit_check``).
    """
    out = []
    stiff = stiffness_fit_check(
        float(stiction_attrs["chi2_min"]), n_frequencies, float(stiction_attrs.get("confidence", 0.95))
    )
    if stiff is not None:
        out.append(stiff)
    if fit_attrs is not None:
        floor = fit_attrs.get("misfit_floor")
        if floor is None:
            from .schema import schema_defaults

            floor = schema_defaults("friction")["misfit_floor"]
        out.append(friction_fit_check(float(fit_attrs["misfit_nrmse"]), float(floor)))
    return out
