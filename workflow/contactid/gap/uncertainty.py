"""Friction-law intervals with a model-form term (issue 15, item 6).

The profile-likelihood intervals of the friction fit (``contactid.friction_fit``) state what the calibration
record's scatter allows *if the model is right*. Off the model (a structure a few per cent off, another damping
form, another normal law) they are overconfident: the fitted parameters move more than they say. Two spreads
measure how far they move with what the data cannot tell apart:

- **load cases**: the law refitted (polished from the calibration optimum) on the contact forces of each
  other load case. A right model gives the same parameters at every amplitude; a wrong one drifts with it.
  sd_cases = rms over the other cases of the change from the calibration fit.
- **structure**: the law refitted on the calibration forces identified with each structure the random test
  allows (``UpdatingResult.posterior_structures``: +-1 posterior sd along each principal axis). The
  tangential lever arm a is the main term: the linear data bind a^2 k_t, not a; the contact forces scale
  as S ~ 1/a and xi ~ a, so the data bind mu a and e_0 a^2, and mu is known no better than a is.
  sd_structure = sqrt(sum over axes of ((p_plus - p_minus) / 2)^2).

The interval with model form widens the profile interval by z sd on each side, sd = sqrt(sd_cases^2 +
sd_structure^2), z the normal quantile of the confidence; on a log scale for the positive parameters
(e_f, k_c, mu, e_0), linear for e_t and kappa, and clipped to the search bounds.

What the data bind (``PRODUCTS``): mu a (m) and e_0 a^2 (N m) with the lever arm a of the structure each value was
fitted with, the same spreads over load cases (a is one structure's) and over the structures (each refit times
its own a): an interval that does not widen with the lever arm the random test leaves open.
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ..contact_laws import stiction_shear_stiffness
from ..friction import PARAMETER_NAMES
from ..friction_fit import FitSettings, fit_friction_law
from .model import NONE, IdentifiedModel
from .records import RecordHarmonics
from .refit import identified_forces

log = logging.getLogger(__name__)

NAMES = (*PARAMETER_NAMES, "e0")  # the five law parameters and e_0 at the preload (Eq. 22)
LOG_SCALE = np.array([True, True, False, False, True, True])  # e_f, k_c, mu, e_0 spread on a log scale
# what the data bind when the lever arm is open: (name, parameter, power of a, unit); spread on a log scale
PRODUCTS = (("mu_a", "mu", 1, "m"), ("e0_a2", "e0", 2, "N m"))


@dataclass
class FrictionUncertainty:
    """Per parameter (``NAMES``): the value, the profile-likelihood interval (6, 2), the model-form standard
    deviations from the load cases and from the structure (on the parameter's scale: ln for LOG_SCALE, else
    linear), the interval with model form (6, 2), and the refits behind them ({case: (6,)}, [(6,), ...])."""

    value: np.ndarray
    profile: np.ndarray
    sd_cases: np.ndarray
    sd_structure: np.ndarray
    interval: np.ndarray
    confidence: float
    case_fits: dict
    structure_fits: list
    products: dict = dataclasses.field(default_factory=dict)  # {PRODUCTS name: {value, profile, sd_*, interval}}

    def interval_of(self, n: str) -> tuple:
        """(interval with model form (2,), value) of a name of NAMES or PRODUCTS."""
        if n in self.products:
            return self.products[n]["interval"], self.products[n]["value"]
        i = NAMES.index(n)
        return self.interval[i], self.value[i]

    def covers(self, truth: Mapping) -> dict:
        """{name: whether the interval with model form holds the true value} for the names in ``truth`` (NAMES
        and PRODUCTS)."""
        out = {}
        for n in (*NAMES, *self.products):
            if n in truth and truth[n] is not None:
                (lo, hi), _ = self.interval_of(n)
                out[n] = bool(lo <= float(truth[n]) <= hi)
        return out

    def relative_halfwidth(self, names=NAMES) -> dict:
        """{name: half the interval with model form over the value} (a relative +- of the interval)."""
        out = {}
        for n in names:
            (lo, hi), v = self.interval_of(n)
            out[n] = float((hi - lo) / 2.0 / max(abs(v), 1e-300))
        return out

    def summary(self) -> dict:
        """JSON-ready {name: {value, profile_interval, sd_cases, sd_structure, interval, scale}}."""
        return (
            {
                n: {
                    "value": float(self.value[i]),
                    "profile_interval": [float(v) for v in self.profile[i]],
                    "sd_cases": float(self.sd_cases[i]),
                    "sd_structure": float(self.sd_structure[i]),
                    "interval": [float(v) for v in self.interval[i]],
                    "scale": "log" if LOG_SCALE[i] else "linear",
                }
                for i, n in enumerate(NAMES)
            }
            | {
                n: {
                    "value": float(v["value"]),
                    "profile_interval": [float(x) for x in v["profile"]],
                    "sd_cases": float(v["sd_cases"]),
                    "sd_structure": float(v["sd_structure"]),
                    "interval": [float(x) for x in v["interval"]],
                    "scale": "log",
                    "unit": v["unit"],
                }
                for n, v in self.products.items()
            }
            | {"confidence": self.confidence}
        )


def with_e0(params, preload: float) -> np.ndarray:
    """The five law parameters followed by e_0 at the preload (N/m, Eq. 22)."""
    p = np.asarray(params, float)
    return np.append(p, float(stiction_shear_stiffness(preload, p[0], p[1])))


def _scaled(p: np.ndarray) -> np.ndarray:
    p = np.asarray(p, float)
    return np.where(LOG_SCALE, np.log(np.maximum(np.abs(p), 1e-300)), p)


def spread_sd(best: np.ndarray, alternatives, pairs: bool = False) -> np.ndarray:
    """Model-form sd of each parameter on its scale: the rms change of ``alternatives`` (rows (6,)) from
    ``best``, or with ``pairs`` (rows in +-pairs along axes) sqrt(sum ((plus - minus) / 2)^2). Zeros without
    alternatives."""
    alt = [np.asarray(a, float) for a in alternatives]
    if not alt:
        return np.zeros(len(NAMES))
    z = np.array([_scaled(a) for a in alt])
    if pairs:
        half = (z[1::2] - z[0::2]) / 2.0
        return np.sqrt(np.sum(half**2, axis=0))
    return np.sqrt(np.mean((z - _scaled(best)) ** 2, axis=0))


def widened_interval(profile: np.ndarray, sd: np.ndarray, confidence: float, bounds) -> np.ndarray:
    """The profile interval (6, 2) widened by z sd on each side (z the normal quantile of ``confidence``) on
    each parameter's scale, clipped to the search ``bounds`` ((5, 2) of the law; e_0 unclipped)."""
    from scipy.stats import norm  # here: scipy.stats takes 0.3 s to import

    z = float(norm.ppf(0.5 + confidence / 2.0))
    lo, hi = _scaled(profile[:, 0]) - z * sd, _scaled(profile[:, 1]) + z * sd
    lo = np.where(LOG_SCALE, np.exp(np.minimum(lo, 700.0)), lo)
    hi = np.where(LOG_SCALE, np.exp(np.minimum(hi, 700.0)), hi)
    b = np.array(list(bounds) + [(0.0, np.inf)], float)
    return np.column_stack([np.clip(lo, b[:, 0], b[:, 1]), np.clip(hi, b[:, 0], b[:, 1])])


def bound_products(
    value: np.ndarray,
    profile: np.ndarray,
    sd_cases: np.ndarray,
    lever_arm: float,
    structure_fits,
    structure_arms,
    confidence: float,
) -> dict:
    """{name: {value, profile, sd_cases, sd_structure, interval, unit}} of PRODUCTS (mu a in m, e_0 a^2 in N m):
    ``value``/``profile``/``sd_cases`` of NAMES times ``lever_arm`` (m) to the product's power (the load cases share
    one structure), the structure spread (``spread_sd``) over ``structure_fits`` (rows (6,) in +-pairs) each times
    its own arm (``structure_arms``, m), the interval widened by ``widened_interval`` (log scale, unbounded)."""

    def times_arm(rows, arm):  # NAMES rows with mu times a and e_0 times a^2
        w = np.ones(len(NAMES))
        for _, par, power, _ in PRODUCTS:
            w[NAMES.index(par)] = float(arm) ** power
        return np.asarray(rows, float) * (w[:, None] if np.ndim(rows) == 2 else w)

    own = times_arm(value, lever_arm)
    sd_s = spread_sd(own, [times_arm(f, a) for f, a in zip(structure_fits, structure_arms)], pairs=True)
    prof = times_arm(profile, lever_arm)
    interval = widened_interval(prof, np.hypot(sd_cases, sd_s), confidence, [(0.0, np.inf)] * (len(NAMES) - 1))
    out = {}
    for name, par, _, unit in PRODUCTS:
        i = NAMES.index(par)
        out[name] = {
            "value": float(own[i]),
            "profile": prof[i],
            "sd_cases": float(sd_cases[i]),
            "sd_structure": float(sd_s[i]),
            "interval": interval[i],
            "unit": unit,
        }
    return out


def _refit(
    model: IdentifiedModel, rec: RecordHarmonics, settings: FitSettings, seed: int, label: str, intervals: bool = False
):
    forces = identified_forces(model, NONE, rec)
    return fit_friction_law(
        forces.xi,
        forces.N_dyn,
        forces.S,
        rec.f0,
        model.preload,
        settings,
        int(seed),
        rec.acceleration.shape[1],
        intervals=intervals,
        label=label,
        start=model.friction,
    )


def friction_uncertainty(
    model: IdentifiedModel, records: Mapping, calibration: str, settings: FitSettings, seed: int, structures=()
) -> FrictionUncertainty:
    """The friction law of ``model`` (fitted on ``records[calibration]``) with its profile intervals and the
    model-form spreads over the other load cases in ``records`` and over ``structures`` (see the module)."""
    structures = list(structures)
    quiet = logging.getLogger("contactid.friction_fit")
    level = quiet.level
    cal = records[calibration]
    fit = _refit(model, cal, settings, seed, "friction intervals", intervals=True)
    value = with_e0(fit.params, model.preload)
    profile = np.vstack([fit.intervals, np.array(fit.e0_interval)[None, :]])
    quiet.setLevel(
        logging.ERROR
    )  # the refits' progress lines (and bound warnings the fit itself gave) would bury the log
    try:
        cases = {
            c: with_e0(_refit(model, r, settings, seed, f"refit on {c}").params, model.preload)
            for c, r in records.items()
            if c != calibration
        }
        structs = [
            with_e0(
                _refit(
                    dataclasses.replace(model, structure=p), cal, settings, seed, "refit on a posterior structure"
                ).params,
                model.preload,
            )
            for p in structures
        ]
    finally:
        quiet.setLevel(level)
    sd_c = spread_sd(value, list(cases.values()))
    sd_s = spread_sd(value, structs, pairs=True)
    interval = widened_interval(profile, np.hypot(sd_c, sd_s), settings.confidence, settings.bounds)
    products = bound_products(
        value,
        profile,
        sd_c,
        model.structure.tangential_lever_arm,
        structs,
        [p.tangential_lever_arm for p in structures],
        float(settings.confidence),
    )
    for i, n in enumerate(NAMES):
        log.info(
            "friction intervals: %s = %.4g, profile [%.4g, %.4g], model-form sd %.3g (cases) %.3g (structure)%s"
            " -> [%.4g, %.4g]",
            n,
            value[i],
            *profile[i],
            sd_c[i],
            sd_s[i],
            " on ln" if LOG_SCALE[i] else "",
            *interval[i],
        )
    for n, v in products.items():
        log.info(
            "friction intervals: %s = %.4g %s (what the data bind), model-form sd %.3g (cases) %.3g (structure) on ln"
            " -> [%.4g, %.4g]",
            n,
            v["value"],
            v["unit"],
            v["sd_cases"],
            v["sd_structure"],
            *v["interval"],
        )
    return FrictionUncertainty(
        value, profile, sd_c, sd_s, interval, float(settings.confidence), cases, structs, products
    )
