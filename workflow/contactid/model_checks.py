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

# What a failed check means, said once for the rule logs (plain text) and the report (LaTeX, ``contactid.latex``):
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
    """The stiffness fit's consistency: ``chi2_min`` (the weighted misfit's minimum over k_t, k_n) against the
    ``confidence`` quantile of chi^2 with ``n_frequencies`` - 2 degrees of freedom. None where the fit has no
    degree of freedom left (two frequencies or fewer: k_t and k_n fit any two)."""
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
    """The friction fit's consistency: its misfit (NRMSE of the law against the identified S) against the relative
    accuracy its profile-likelihood intervals assume for that S (``friction.misfit_floor``)."""
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


def model_checks(stiction_attrs, n_frequencies: int, fit_attrs=None) -> list[dict]:
    """Every model check the results allow: the stiffness fit's (from the stiction dataset's attributes
    ``chi2_min`` and ``confidence``, ``n_frequencies`` identified frequencies) and, where the friction law was
    fitted (``fit_attrs``, the fit dataset's attributes), the friction fit's: ``misfit_nrmse`` against the fit's
    ``misfit_floor`` (a fit written before it kept one: the schema's default)."""
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
