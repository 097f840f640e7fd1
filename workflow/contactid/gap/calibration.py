"""A candidate's calibration: the search for the theta that minimises the calibration case's gap.

The chain is redone (``refit.evaluate``) at every theta the search tries: theta minimises the calibration gap, with the
friction law refitted at each theta. The held-out load cases are then predicted with theta and the refitted friction
law, never fitted.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import minimize_scalar

from ..friction_fit import FitSettings
from .candidates import Candidate
from .model import NONE, Augmentation, IdentifiedModel
from .numerics import DEFAULT, Numerics
from .records import RecordHarmonics
from .refit import evaluate, gap_residual
from .search import residual_line_search, stacked
from .simulation import SimResult

log = logging.getLogger(__name__)


@dataclass
class Calibration:
    """A candidate calibrated on the calibration case.

    Theta, the refitted friction law, the calibration gap, the model and augmentation to predict with, and the number of
    simulations.

    Attributes
    ----------
    candidate
        The candidate's name.
    theta
        The candidate's parameters, each in its own unit (``Parameter.unit``) [units of Candidate.parameters],
        shape (n_parameters,) (one per accelerometer channel for a per-channel candidate).
    friction
        The refitted friction law (e_f, k_c, e_t, kappa, mu) [N/m, 1/m, N/m, -, -], shape (5,).
    gap
        The calibration gap: the calibration case's relative misfit of the sensors' harmonics [-].
    model
        The identified model with the refitted friction law, to predict with.
    augmentation
        The effects added to the model (the earlier steps' and the candidate's at theta), to predict with.
    evaluations
        The number of distinct simulations the calibration ran.
    friction_misfit
        The refitted law's NRMSE on the identified tangential force S [-] (NaN where the law or the simulation
        failed).
    simulation
        The calibration case's simulation at theta (polished by the integrator), or None where it could not be
        simulated.
    steps
        ((name, theta), ...) of every effect in the augmentation, in the explanation's order.
    """

    candidate: str
    theta: np.ndarray
    friction: np.ndarray
    gap: float
    model: IdentifiedModel
    augmentation: Augmentation
    evaluations: int
    friction_misfit: float
    simulation: SimResult | None = None
    steps: tuple = ()  # ((name, theta), ...) of every effect in the augmentation, the explanation's order


class _CandidateRuns:
    """The chain redone (``evaluate``) at the thetas a calibration tries, each once.

    Called with theta, it returns (gap, model with refitted friction, simulation, friction misfit, augmentation), every
    simulation starting from the previous one's steady state; a theta the law or the simulation fails at gets an
    infinite gap (and is logged). Every theta is run polished by the integrator where ``numerics.polish_searches``
    (True: every state of the search, so that it sees the reference's gaps to its settling tolerance: held-out gaps
    within 0.01-0.08 % of the time-marching diagnosis's on benchmarks/gap_diagnosis.py's four data sets, against 2.4-8.6
    % with the periodic states alone, same verdicts and, but for near ties, rankings; for 25-90 % more diagnosis time, a
    contact that may open marching from the linear state then, as the reference does), otherwise only where called with
    ``polish``. ``evaluations`` counts the distinct runs.

    Parameters
    ----------
    model
        The identified model the candidate is added to.
    cand
        The candidate.
    rec
        The calibration case's record harmonics.
    bounds
        The friction law's search bounds (``FitSettings.bounds``: 5 x (low, high) of e_f, k_c, e_t, kappa, mu).
    n_harmonics
        Harmonics compared in the gap.
    start
        The simulation the first run starts from (its steady state), or None.
    base
        The effects already added (the explanation's earlier steps); the candidate's are added to them.
    numerics
        How the steady states are found and the searches run.
    """

    def __init__(
        self,
        model: IdentifiedModel,
        cand: Candidate,
        rec: RecordHarmonics,
        bounds: tuple,
        n_harmonics: int,
        start: SimResult | None,
        base: Augmentation,
        numerics: Numerics = DEFAULT,
    ):
        self.model, self.cand, self.rec, self.base = model, cand, rec, base
        self.bounds, self.n_harmonics, self.numerics = bounds, n_harmonics, numerics
        self.last_sim = start
        self.evaluations = 0
        self.cache = {}

    def __call__(self, theta, polish=False):
        polish = polish or self.numerics.polish_searches  # the key holds what is run: a polished optimum is not rerun
        key = (*np.round(np.atleast_1d(theta), 12), polish)
        if key not in self.cache:
            self.evaluations += 1
            aug = self.base.merge(self.cand.augmentation(np.atleast_1d(theta)))
            try:
                out = evaluate(
                    self.model,
                    aug,
                    self.rec,
                    self.bounds,
                    self.n_harmonics,
                    start=self.last_sim,
                    polish=polish,
                    numerics=self.numerics,
                )
                self.last_sim = out[2]  # the next theta is a neighbour: start from here
                if not np.isfinite(out[0]):
                    raise FloatingPointError("the simulation diverged")
                self.cache[key] = (*out, aug)
            except (ValueError, FloatingPointError) as exc:  # e.g. the law is undefined there
                log.info("%s at %s: %s", self.cand.name, theta, exc)
                self.cache[key] = (np.inf, self.model, None, np.nan, aug)
        return self.cache[key]

    def residual(self, theta: np.ndarray | float) -> np.ndarray | None:
        """Return the calibration gap's residual vector at ``theta`` (``gap_residual``), None where not simulated.

        Parameters
        ----------
        theta
            The candidate's parameters [units of Candidate.parameters], shape (n_parameters,) (a scalar for one
            parameter).

        Returns
        -------
        residual : np.ndarray | None
            The residual vector (complex, relative to the record's acceleration harmonics) [-], shape (n_residual,),
            or None.
        """
        g, _, sim, _, _ = self(np.atleast_1d(theta))
        return gap_residual(sim, self.rec, self.n_harmonics) if sim is not None and np.isfinite(g) else None


def _per_channel_theta(
    run: _CandidateRuns, cand: Candidate, rec: RecordHarmonics, max_evaluations: int, common=None
) -> np.ndarray:
    """Return theta of a per-channel candidate (a parameter per accelerometer channel); zero where that is no worse.

    ``common`` (j,): per-channel values measured elsewhere (channel delays: the random test's residue phases,
    ``modal_fit.residue_phase_delays``). Their mean is held and Nelder-Mead searches the channels' differences from them
    (j - 1 parameters; simplex steps of 2.5 % of the range, at most 3 x max_evaluations simulations). The calibration
    gap does not bind a delay common to every channel: the forces identified from the record and the refitted friction
    law take it up. From zero, the search put the ladder's skews of 20 us at 12.5-15.6 us and of 6.7 us at 12 us (a
    common shift of about -5 us); from the random test's delays, at 19.8-20.0 us and 6.4 us, with the same calibration
    gap and 30 simulations instead of 50 (docs/measurements.md).

    Without ``common``: Nelder-Mead on the gap from zero, simplex steps of 10 % of the range. (Least squares on the
    residual vector found a skew's delays more exactly, but also a common delay on every channel, -28 us, that stood in
    for a normal dashpot's dissipation: a compound benchmark item named the channel skew instead of the dashpot;
    docs/measurements.md.)
    """
    from scipy.optimize import minimize

    j = rec.acceleration.shape[0]
    p = cand.parameters[0]
    span = p.high - p.low
    if common is not None and np.size(common) == j and j > 1 and np.all(np.isfinite(common)):
        # delays the random test measured beyond the library's range (a DAQ's filter delays): a range that holds them
        p = p.covering(float(np.max(common))).covering(float(np.min(common)))
        span = p.high - p.low
        x0 = np.clip(np.asarray(common, dtype=float), p.low, p.high)
        # an orthonormal basis of the channels' differences (the plane where the values sum to zero)
        B = np.linalg.qr(np.vstack([np.ones(j), np.eye(j)[: j - 1]]).T)[0][:, 1:]
        step, maxfev = 0.025, 3 * max_evaluations
    else:  # every channel's value, from zero
        x0, B, step, maxfev = np.zeros(j), np.eye(j), 0.1, 5 * max_evaluations
    n = B.shape[1]
    res = minimize(
        lambda y: run(np.clip(x0 + B @ y, p.low, p.high))[0],
        np.zeros(n),
        method="Nelder-Mead",
        options={
            "initial_simplex": np.vstack([np.zeros(n), step * span * np.eye(n)]),
            "maxfev": maxfev,
            "xatol": 1e-3 * span,
            "fatol": 1e-6,
        },
    )
    theta = np.clip(x0 + B @ res.x, p.low, p.high)
    # every channel within the search's tolerance of zero is not resolved from zero (``_unresolved_from_off``): the
    # default data's delays came out at 0.01-0.26 us (tolerance 0.4 us) in one diagnosis and at zero in the other,
    # held-out gaps 5.4 % apart
    unresolved = all(_unresolved_from_off(x, p, 1e-3 * span) or p.is_off(x) for x in theta)
    if unresolved or run(np.zeros(j))[0] <= run(theta)[0]:
        theta = np.zeros(j)
    return theta


def _held_gains(channel_gains, j: int) -> np.ndarray:
    """Return the channel-gain candidate's theta (gain errors g - 1) from the random test's relative gains.

    Zeros where they are not known for these j channels.
    """
    g = None if channel_gains is None else np.asarray(channel_gains, dtype=float)
    if g is None or g.size != j or not np.all(np.isfinite(g)) or np.any(g <= 0):
        return np.zeros(j)
    return g - 1.0


def _least_squares_unit(
    run: _CandidateRuns, lo: np.ndarray, hi: np.ndarray, x0: np.ndarray, max_evaluations: int
) -> np.ndarray:
    """Return x in the unit cube of [lo, hi] minimising the residual vector's norm.

    By trust-region reflective least squares from x0 (finite-difference steps of 1e-3 of each range; at most max(3,
    max_evaluations // 2) steps, each one simulation plus one per parameter for the Jacobian; a point that cannot be
    simulated counts as a large residual).
    """
    from scipy.optimize import least_squares

    from ..finite_differences import forward_difference_jacobian

    size = stacked(run.residual(lo + x0 * (hi - lo))).size

    def residual(x):
        r = run.residual(lo + np.clip(x, 0.0, 1.0) * (hi - lo))
        return np.full(size, 1e3) if r is None else stacked(r)

    # absolute steps of 1e-3 of the range: scipy's diff_step is relative to x, 1e-6 of the range at x = 0.001,
    # below the time-marched residuals' rounding near the low end where small effects lie
    fun, jac = forward_difference_jacobian(residual, 1e-3, 0.0, 1.0)
    res = least_squares(
        fun,
        x0,
        jac=jac,
        bounds=(0.0, 1.0),
        method="trf",
        xtol=1e-3,
        ftol=1e-6,
        max_nfev=max(3, max_evaluations // 2),
    )
    return np.clip(res.x, 0.0, 1.0)


def _unresolved_from_off(value: float, p, xatol: float) -> bool:
    """Return whether a search's optimum ``value`` of parameter ``p`` is not resolved from "off".

    It is not where it lies within the search's tolerance ``xatol`` of the value that leaves the model as it is (and is
    not that value), and is then taken as "off". On the effect-free default data the transducer-mass search ended at
    -1.07e-5 (tolerance 3.9e-3) in one diagnosis and at "off" in the other: a mass change however small refits k_t and
    k_n to the frequencies (``model._refit_contact``), whose k_n is flat there and moved k_t by 1e-5, and the held-out
    gaps of the two diagnoses stood 0.88 % apart (docs/measurements.md, "The searches stop where time marching stops").
    """
    return not p.is_off(value) and abs(float(value) - p.off) <= xatol


def _scalar_theta(
    run: _CandidateRuns, cand: Candidate, max_evaluations: int, numerics: Numerics = DEFAULT
) -> np.ndarray:
    """Return theta (1,) of a one-parameter candidate.

    A scan of the range, the search between the best point's neighbours (``numerics.search``: on the residual vector, or
    on the gap alone), and "off" where that is better.
    """
    # a scan of the range (1/32, 1/8, 1/4, 1/2, 3/4), then the bounded search between the best point's neighbours:
    # a search over the whole range from its middle can settle in a side basin (the blind benchmark's
    # transducer-mass items: theta 0.35 instead of 0.22, a held-out gap four times larger)
    # the scan also halves towards the low end twice more: an effect at a few per cent of its range (structural
    # damping 0.0017 of 0-0.05) otherwise lies below the first point, and the search between the low end and
    # the middle settled in a side basin (0.013; the detection ladder's items at a third of the typical value)
    # the search between the neighbours then models the residual vector by quadratics (``search``): two to four
    # evaluations where Brent's bounded search on the gap alone took eight to twelve for the same tolerance
    p = cand.parameters[0]
    grid = p.low + (p.high - p.low) * np.array([0.0, 1 / 32, 1 / 8, 1 / 4, 1 / 2, 3 / 4, 1.0])
    best = min(range(1, 6), key=lambda i: run(np.array([grid[i]]))[0])
    xatol = 1e-3 * (p.high - p.low)
    trio = {float(grid[i]): run.residual(grid[i]) for i in (best - 1, best, best + 1)}
    if numerics.search == "residual" and all(r is not None for r in trio.values()):
        x = residual_line_search(run.residual, trio, grid[best - 1], grid[best + 1], xatol, max_evaluations)
    else:
        x = minimize_scalar(
            lambda x: run(np.array([x]))[0],
            bounds=(grid[best - 1], grid[best + 1]),
            method="bounded",
            options={"xatol": xatol, "maxiter": max_evaluations},
        ).x
    theta = np.array([x]) if run(np.array([x]))[0] <= run(np.array([grid[best]]))[0] else np.array([grid[best]])
    # the bounded search never tries the ends: compare with "off" (the low end or zero)
    off = np.array([p.off])
    if run(off)[0] < run(theta)[0] or _unresolved_from_off(theta[0], p, xatol):
        theta = off
    # an optimum at an end of the range that the parameter's domain goes beyond: the effect is larger than the
    # library's typical range (a normal dashpot of 5000 s/m was refitted to the range's 3000 and left a quarter of its
    # gap to a transducer mass): search again in the range widened there (``Parameter.extended``)
    wider = p.extended(theta[0] - p.low <= xatol and not p.is_off(p.low), p.high - theta[0] <= xatol)
    if wider is not None:
        log.info(
            "%s: refitted at the end of its range, %s = %.4g; searching %.4g-%.4g",
            cand.name,
            p.name,
            theta[0],
            wider.low,
            wider.high,
        )
        return _scalar_theta(run, replace(cand, parameters=(wider,)), max_evaluations, numerics)
    return theta


def _simplex_theta(
    run: _CandidateRuns, cand: Candidate, max_evaluations: int, starts, numerics: Numerics = DEFAULT
) -> np.ndarray:
    """Return theta of a candidate with several parameters.

    From the best of a scan of the first parameter (and of the earlier optimum and ``starts``): a joint refit by least
    squares on the residual vector (``numerics.search`` "residual"; smooth near the earlier optimum), otherwise
    Nelder-Mead on the gap in the unit cube of their ranges (a contact that opens makes the gap kinked).
    """
    from scipy.optimize import minimize

    lo = np.array([p.low for p in cand.parameters])
    hi = np.array([p.high for p in cand.parameters])
    x0 = np.array([0.5 if p.start is None else (p.start - p.low) / (p.high - p.low) for p in cand.parameters])
    # the first parameter scanned at the others' starts (its quarter points), Nelder-Mead from the best:
    # a gap that jumps where the contact starts to open has more than one basin (the blind benchmark's
    # contact-separation items: found from the middle of the range in 2 of 6)
    scan = [np.concatenate([[q], x0[1:]]) for q in (0.125, 0.375, 0.625, 0.875)]
    joint = all(p.start is not None for p in cand.parameters)
    if joint:  # a joint refit: also from the earlier optimum itself, with a finer simplex (an oblique valley)
        scan.append(x0)
    scan += [np.clip((np.asarray(t, float) - lo) / (hi - lo), 0.0, 1.0) for t in starts]
    x0 = min(scan, key=lambda x: run(lo + x * (hi - lo))[0])
    if joint and numerics.search == "residual" and run.residual(lo + x0 * (hi - lo)) is not None:
        # a joint refit (smooth near the earlier optimum): least squares on the residual vector from the scan's best
        return lo + _least_squares_unit(run, lo, hi, x0, max_evaluations) * (hi - lo)
    size = 0.1 if joint else 0.25
    step = np.where(x0 + size <= 1.0, size, -size)
    simplex = np.vstack([x0, x0 + np.diag(step)])
    res = minimize(
        lambda x: run(lo + np.clip(x, 0, 1) * (hi - lo))[0],
        x0,
        method="Nelder-Mead",
        options={"initial_simplex": simplex, "maxfev": max_evaluations * lo.size, "xatol": 1e-3, "fatol": 1e-6},
    )
    return lo + np.clip(res.x, 0, 1) * (hi - lo)


def calibrate(
    model: IdentifiedModel,
    cand: Candidate,
    rec: RecordHarmonics,
    settings: FitSettings,
    n_harmonics: int,
    max_evaluations: int = 12,
    start: SimResult | None = None,
    base: Augmentation = NONE,
    starts: Sequence[np.ndarray] = (),
    channel_delays: np.ndarray | None = None,
    channel_gains: np.ndarray | None = None,
    numerics: Numerics = DEFAULT,
) -> Calibration:
    """Return the calibration of ``cand``: the theta minimising the calibration case's gap.

    The friction law is refitted at each theta; each simulation starts from the previous one's steady state (``start``:
    the model's own). A per-channel candidate that sets delays holds the common part of ``channel_delays``
    (``_per_channel_theta``); the channel-gain candidate applies ``channel_gains`` as they are (``_held_gains``). With
    ``numerics.polish_searches`` (the default, the diagnosis's) every state the search compares is polished by the
    integrator; False: the search compares harmonic-balance states (within 5e-4 of the integrator's orbit) and only the
    optimum is evaluated again with the integrator's polish, so its gap and simulation are the reference's (same optimum
    within 1 %, a quarter to a third less diagnosis time, measured on 10 benchmark items). Where nothing in the range
    can be simulated, the effect is off.

    Parameters
    ----------
    model
        The identified model the candidate is added to.
    cand
        The candidate.
    rec
        The calibration case's record harmonics.
    settings
        The friction fit's settings (its ``bounds`` bound the refitted law).
    n_harmonics
        Harmonics compared in the gap.
    max_evaluations
        The search's budget of simulations (how each search uses it: config/README.md, ``gap.max_evaluations``).
    start
        The simulation the first run starts from (the model's own steady state), or None.
    base
        Effects already added (the additive explanation's earlier steps); the candidate's are added to them.
    starts
        More points (theta) a search over several parameters starts from if they are better than its scan's best
        [units of Candidate.parameters], each of shape (n_parameters,).
    channel_delays
        The random test's per-channel delays [s], shape (n_sensors,), where known (else None).
    channel_gains
        The channels' gains relative to one another as the random test's residues show them
        (``UpdatingResult.channel_gains``) [-], shape (n_sensors,), or None.
    numerics
        How the steady states are found and the search runs (``numerics.Numerics``).

    Returns
    -------
    calibration : Calibration
        The candidate at its optimum, its simulation polished by the integrator.
    """
    run = _CandidateRuns(model, cand, rec, settings.bounds, n_harmonics, start, base, numerics)
    if cand.per_channel:
        j = rec.acceleration.shape[0]
        sets_delays = channel_delays is not None and bool(cand.augmentation(np.ones(j)).delays)
        if cand.augmentation(np.zeros(j)).gains:
            # a channel's sensitivity is the same in every test: the random test's residues bind the channels' gains
            # relative to one another (0.5-0.7 %), and the candidate applies them, searching nothing. Searched on the
            # dual-sine records (every channel from zero) the gains were an amplitude scale that took up half of a
            # normal dashpot's or viscous friction's gap (common gains of -4 to -6 %) and named a channel skew's
            theta = _held_gains(channel_gains, j)
        else:
            theta = _per_channel_theta(run, cand, rec, max_evaluations, channel_delays if sets_delays else None)
    elif len(cand.parameters) == 1:
        theta = _scalar_theta(run, cand, max_evaluations, numerics)
    else:
        theta = _simplex_theta(run, cand, max_evaluations, starts, numerics)
    cal = _calibration_at(run, theta)
    if not np.isfinite(cal.gap):  # nothing in the range could be simulated: the effect off
        theta = (
            np.array([p.off for p in cand.parameters]) if not cand.per_channel else np.zeros_like(np.atleast_1d(theta))
        )
        cal = _calibration_at(run, theta)
    return cal


def _calibration_at(run: _CandidateRuns, theta) -> Calibration:
    """Return the Calibration of ``run``'s candidate at ``theta``: its simulation polished by the integrator."""
    theta = np.atleast_1d(theta)
    g, m2, sim, misfit, aug = run(theta, polish=True)
    name = run.cand.name
    return Calibration(name, theta, np.asarray(m2.friction), g, m2, aug, run.evaluations, misfit, sim, ((name, theta),))


def held(
    model: IdentifiedModel,
    cand: Candidate,
    rec: RecordHarmonics,
    settings: FitSettings,
    n_harmonics: int,
    theta: np.ndarray,
    start: SimResult | None = None,
    base: Augmentation = NONE,
    numerics: Numerics = DEFAULT,
) -> Calibration:
    """Return ``cand`` at a ``theta`` measured elsewhere, not searched.

    The theta comes from elsewhere (channel delays: the random test's residue phases). The friction law is refitted to
    the calibration case's forces with it, the simulation polished by the integrator.

    Parameters
    ----------
    model
        The identified model the candidate is added to.
    cand
        The candidate.
    rec
        The calibration case's record harmonics.
    settings
        The friction fit's settings (its ``bounds`` bound the refitted law).
    n_harmonics
        Harmonics compared in the gap.
    theta
        The candidate's parameters as measured [units of Candidate.parameters], shape (n_parameters,).
    start
        The simulation the run starts from (the model's own steady state), or None.
    base
        Effects already added (the additive explanation's earlier steps); the candidate's are added to them.
    numerics
        How the steady states are found (``numerics.Numerics``).

    Returns
    -------
    calibration : Calibration
        The candidate at ``theta``.
    """
    run = _CandidateRuns(model, cand, rec, settings.bounds, n_harmonics, start, base, numerics)
    return _calibration_at(run, np.asarray(theta, dtype=float))
