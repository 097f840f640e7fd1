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
from typing import TYPE_CHECKING, Iterable, Mapping, Sequence

import numpy as np

from ..contact_laws import stiction_shear_stiffness
from ..friction import PARAMETER_NAMES
from ..friction_fit import FitSettings, fit_friction_law
from .model import NONE, IdentifiedModel
from .records import RecordHarmonics
from .refit import identified_forces

if TYPE_CHECKING:
    from ..parameters import StructureParameters

log = logging.getLogger(__name__)

NAMES = (*PARAMETER_NAMES, "e0")  # the five law parameters and e_0 at the preload (Eq. 22)
LOG_SCALE = np.array([True, True, False, False, True, True])  # e_f, k_c, mu, e_0 spread on a log scale
# what the data bind when the lever arm is open: (name, parameter, power of a, unit); spread on a log scale
PRODUCTS = (("mu_a", "mu", 1, "m"), ("e0_a2", "e0", 2, "N m"))


@dataclass
class FrictionUncertainty:
    """The friction law's parameters with their profile-likelihood intervals and their intervals with model form.

    Per parameter of ``NAMES`` (e_f, k_c, e_t, kappa, mu and e_0 at the preload): the value, the profile-likelihood
    interval, the model-form standard deviations from the load cases and from the structure, the interval with model
    form, and the refits behind them; and the same for what the data bind (``PRODUCTS``).

    Attributes
    ----------
    value
        The fitted values [N/m, 1/m, N/m, -, -, N/m], shape (6,), in the order of ``NAMES``.
    profile
        The profile-likelihood intervals [N/m, 1/m, N/m, -, -, N/m], shape (6, 2): lower, upper end.
    sd_cases
        The model-form standard deviations over the other load cases, on each parameter's scale (ln for
        ``LOG_SCALE``'s e_f, k_c, mu and e_0, linear for e_t and kappa) [-, -, N/m, -, -, -], shape (6,).
    sd_structure
        The model-form standard deviations over the structures the random test allows, on the same scales
        [-, -, N/m, -, -, -], shape (6,).
    interval
        The intervals with model form [N/m, 1/m, N/m, -, -, N/m], shape (6, 2): lower, upper end.
    confidence
        The intervals' confidence level [-] (e.g. 0.95).
    case_fits
        {case: the refit on that load case's forces, a row of ``NAMES`` [N/m, 1/m, N/m, -, -, N/m] of shape (6,)}.
    structure_fits
        The refits on the calibration forces identified with each posterior structure, rows of ``NAMES`` of shape
        (6,), in +- pairs along the posterior's axes.
    products
        {``PRODUCTS`` name: {value, profile, sd_cases, sd_structure, interval, unit}}: mu a [m] and e_0 a^2 [N m]
        (``bound_products``).
    """

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
        """Return the interval with model form and the value of a name of NAMES or PRODUCTS.

        Parameters
        ----------
        n
            A name of ``NAMES`` or of ``PRODUCTS``.

        Returns
        -------
        interval : np.ndarray
            The interval with model form [unit of n] (``NAMES``: [N/m, 1/m, N/m, -, -, N/m]; mu_a [m], e0_a2 [N m]),
            shape (2,): lower, upper end.
        value : float
            The fitted value [unit of n].
        """
        if n in self.products:
            return self.products[n]["interval"], self.products[n]["value"]
        i = NAMES.index(n)
        return self.interval[i], self.value[i]

    def covers(self, truth: Mapping) -> dict:
        """Return whether each interval with model form holds the true value.

        Parameters
        ----------
        truth
            {name of NAMES or PRODUCTS: true value in that name's unit, or None where unknown}.

        Returns
        -------
        covered : dict
            {name: whether the interval holds the true value} for the names of ``truth`` with a value.
        """
        out = {}
        for n in (*NAMES, *self.products):
            if n in truth and truth[n] is not None:
                (lo, hi), _ = self.interval_of(n)
                out[n] = bool(lo <= float(truth[n]) <= hi)
        return out

    def relative_halfwidth(self, names: Iterable[str] = NAMES) -> dict:
        """Return half of each interval with model form over the value (a relative +- of the interval).

        Parameters
        ----------
        names
            Names of ``NAMES`` or ``PRODUCTS``.

        Returns
        -------
        halfwidth : dict
            {name: half the interval's width over the value's magnitude, a float [-]}.
        """
        out = {}
        for n in names:
            (lo, hi), v = self.interval_of(n)
            out[n] = float((hi - lo) / 2.0 / max(abs(v), 1e-300))
        return out

    def summary(self) -> dict:
        """Return the intervals JSON-ready.

        Returns
        -------
        summary : dict
            {name: {value, profile_interval, sd_cases, sd_structure, interval, scale}} for ``NAMES``, the same with
            ``unit`` for ``PRODUCTS``, and ``confidence``.
        """
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


def with_e0(params: np.ndarray, preload: float) -> np.ndarray:
    """Return the five law parameters followed by e_0 at the preload (Eq. 22).

    Parameters
    ----------
    params
        The law's parameters (e_f, k_c, e_t, kappa, mu) [N/m, 1/m, N/m, -, -], shape (5,).
    preload
        The static normal preload N0 [N].

    Returns
    -------
    values : np.ndarray
        (e_f, k_c, e_t, kappa, mu, e_0) [N/m, 1/m, N/m, -, -, N/m], shape (6,).
    """
    p = np.asarray(params, float)
    return np.append(p, float(stiction_shear_stiffness(preload, p[0], p[1])))


def _scaled(p: np.ndarray) -> np.ndarray:
    p = np.asarray(p, float)
    return np.where(LOG_SCALE, np.log(np.maximum(np.abs(p), 1e-300)), p)


def spread_sd(best: np.ndarray, alternatives: Iterable[np.ndarray], pairs: bool = False) -> np.ndarray:
    """Return the model-form sd of each parameter on its scale (ln for ``LOG_SCALE``, else linear).

    It is the rms change of ``alternatives`` from ``best``, or with ``pairs`` (rows in +-pairs along axes)
    sqrt(sum ((plus - minus) / 2)^2). Zeros without alternatives.

    Parameters
    ----------
    best
        The best fit, a row of ``NAMES`` [N/m, 1/m, N/m, -, -, N/m], shape (6,) (``bound_products`` gives mu
        times a [m] and e_0 times a^2 [N m] in their places).
    alternatives
        The refits, rows in the units of ``best`` ([N/m, 1/m, N/m, -, -, N/m] for NAMES), each of shape (6,).
    pairs
        Whether the rows come in +- pairs along axes (minus first).

    Returns
    -------
    sd : np.ndarray
        The standard deviations on each parameter's scale [-, -, N/m, -, -, -], shape (6,).
    """
    alt = [np.asarray(a, float) for a in alternatives]
    if not alt:
        return np.zeros(len(NAMES))
    z = np.array([_scaled(a) for a in alt])
    if pairs:
        half = (z[1::2] - z[0::2]) / 2.0
        return np.sqrt(np.sum(half**2, axis=0))
    return np.sqrt(np.mean((z - _scaled(best)) ** 2, axis=0))


def widened_interval(
    profile: np.ndarray, sd: np.ndarray, confidence: float, bounds: Sequence[tuple[float, float]]
) -> np.ndarray:
    """Return the profile interval widened by z sd on each side, on each parameter's scale.

    z is the normal quantile of ``confidence``; the ends are clipped to the search ``bounds`` (e_0 unclipped).

    Parameters
    ----------
    profile
        The profile-likelihood intervals [N/m, 1/m, N/m, -, -, N/m], shape (6, 2): lower, upper end
        (``bound_products``: with the products in the places of mu and e_0).
    sd
        The model-form standard deviations on each parameter's scale [-, -, N/m, -, -, -], shape (6,).
    confidence
        The confidence level [-] (e.g. 0.95).
    bounds
        The law's search bounds (low, high) of e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -], five pairs
        (``FitSettings.bounds``; ``bound_products``: unbounded).

    Returns
    -------
    interval : np.ndarray
        The widened intervals [N/m, 1/m, N/m, -, -, N/m], shape (6, 2).
    """
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
    structure_fits: Sequence[np.ndarray],
    structure_arms: Sequence[float],
    confidence: float,
) -> dict:
    """Return what the data bind, the ``PRODUCTS`` mu a and e_0 a^2, with their spreads and intervals.

    ``value``, ``profile`` and ``sd_cases`` of NAMES are taken times ``lever_arm`` to the product's power (the load
    cases share one structure), the structure spread (``spread_sd``) over ``structure_fits`` each times its own
    arm, and the interval widened by ``widened_interval`` (log scale, unbounded).

    Parameters
    ----------
    value
        The fitted values [N/m, 1/m, N/m, -, -, N/m], shape (6,).
    profile
        The profile-likelihood intervals [N/m, 1/m, N/m, -, -, N/m], shape (6, 2).
    sd_cases
        The model-form standard deviations over the load cases [-, -, N/m, -, -, -], shape (6,) (on ln for mu and
        e_0, so the same for the products).
    lever_arm
        The tangential lever arm a of the structure the values were fitted with [m].
    structure_fits
        The refits on the posterior structures, rows of ``NAMES`` [N/m, 1/m, N/m, -, -, N/m] of shape (6,), in +- pairs.
    structure_arms
        Each posterior structure's lever arm [m], one per row of ``structure_fits``.
    confidence
        The confidence level [-] (e.g. 0.95).

    Returns
    -------
    products : dict
        {name: {value, profile, sd_cases, sd_structure, interval, unit}} of PRODUCTS: mu_a in m, e0_a2 in N m, the
        standard deviations on ln.
    """

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
    model: IdentifiedModel,
    records: Mapping[str, RecordHarmonics],
    calibration: str,
    settings: FitSettings,
    seed: int,
    structures: Iterable[StructureParameters] = (),
) -> FrictionUncertainty:
    """Return the friction law of ``model`` with its profile intervals and its model-form spreads (see the module).

    The law is refitted (polished from ``model``'s law) on ``records[calibration]`` with profile intervals, on each
    other load case of ``records`` and on the calibration record with each structure of ``structures``.

    Parameters
    ----------
    model
        The identified model whose friction law was fitted on the calibration record.
    records
        {case: the record's harmonics}, the calibration case's and the other load cases'.
    calibration
        The calibration case's name.
    settings
        The friction fit's settings (bounds, confidence, ...).
    seed
        The fits' random seed.
    structures
        The structures the random test allows (``UpdatingResult.posterior_structures``, in +- pairs); none: no
        structure spread.

    Returns
    -------
    uncertainty : FrictionUncertainty
        The law's values, intervals and spreads.
    """
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
