"""Fit the modified Valanis law (Eqs. 21-22) to identified contact forces (Section 5, Table 4).

A seeded DEAP genetic algorithm over (e_f, k_c, e_t, kappa, mu), a local least-squares polish, grid refinement until the
fit no longer moves, and profile-likelihood intervals that mark parameters the data only bound.

The least-squares problem and its polish are in ``contactid.friction_problem``; the datasets of the rule scripts (the
fit's and the validation's) are in ``contactid.friction_datasets``.
"""

from __future__ import annotations

import logging
import random
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from .contact_laws import stiction_shear_stiffness
from .friction import PARAMETER_NAMES
from .friction_problem import FitProblem, least_squares_polish
from .harmonics import periodic_grid
from .random_streams import generator

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class FitSettings:
    """Settings of the friction fit.

    The search bounds, the GA's population, generations, crossover and mutation probabilities, the first grid size and
    the largest, the relative parameter change that stops the refinement, the confidence level, the relative rms
    accuracy assumed for the identified S (a floor on the misfit scale of the profile likelihood, since the
    identification's own error is not noise), and how Eq. 21 is read.

    Attributes
    ----------
    bounds
        Search bounds, five (low, high) pairs in the order e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -].
    population
        GA population (individuals per generation).
    generations
        GA generations.
    crossover
        Probability that a pair of offspring is crossed [-].
    mutation
        Probability that an offspring is mutated [-].
    grid_points
        Points per period of the first grid the law is evaluated on.
    max_grid_points
        Largest grid the refinement may double to.
    refine_tolerance
        Relative change of the parameters (e_f, k_c, kappa, mu) below which the grid refinement stops [-].
    confidence
        Confidence level of the profile-likelihood intervals [-].
    misfit_floor
        Relative rms accuracy assumed for the identified S, a floor on the profile likelihood's misfit scale [-].
    regularization
        How Eq. 21 is read: ``none`` as printed, or ``slip_limit`` (see ``contactid.friction``).
    """

    bounds: tuple = ((1e6, 1e9), (1e4, 1e7), (0.0, 1e6), (0.0, 0.95), (0.05, 1.5))
    population: int = 64
    generations: int = 40
    crossover: float = 0.7
    mutation: float = 0.3
    grid_points: int = 256
    max_grid_points: int = 4096
    refine_tolerance: float = 1e-3
    confidence: float = 0.95
    misfit_floor: float = 0.01
    regularization: str = "none"


@dataclass
class FitResult:
    """Result of the friction fit.

    Attributes
    ----------
    params
        Best-fit e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -], shape (5,).
    misfit
        NRMSE of S: the rms residual of the mean-removed S over the rms of the identified S [-].
    e0_at_preload
        Shear stiffness at stiction e_0 at the preload (Eq. 22) [N/m].
    logbook
        The GA's logbook: (generation, min misfit, mean misfit) per generation, misfits as ``misfit`` [-].
    grid_history
        The grid refinement's history: (grid points, e_f, k_c, e_t, kappa, mu, misfit) per grid.
    intervals
        Profile-likelihood confidence intervals (low, high) of each parameter [N/m, 1/m, N/m, -, -] by row,
        shape (5, 2); NaN when not profiled.
    bounded
        Whether each side of each interval closes inside the search bounds (True where the data bound it) [-],
        shape (5, 2).
    e0_interval
        Range (low, high) of e_0 at the preload over the profile points inside the intervals and the optimum [N/m].
    correlation
        Correlation of the parameters from the polish's Jacobian [-], shape (5, 5); NaN for the insensitive ones.
    grid_points
        Size of the final grid (points per period).
    profiles
        The profiles per parameter: {name: rows of (value in the parameter's unit, SSR)}.
    warnings
        The fit's warnings (parameters at a search bound).
    """

    params: np.ndarray
    misfit: float
    e0_at_preload: float
    logbook: list
    grid_history: list
    intervals: np.ndarray
    bounded: np.ndarray  # (5, 2): is the interval closed below / above inside the search bounds
    e0_interval: tuple
    correlation: np.ndarray
    grid_points: int
    profiles: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)


def _ga(problem: FitProblem, settings: FitSettings, seed: int, label: str = "friction fit"):
    from deap import base, creator, tools

    if not hasattr(creator, "ValanisFitness"):
        creator.create("ValanisFitness", base.Fitness, weights=(-1.0,))
        creator.create("ValanisIndividual", list, fitness=creator.ValanisFitness)
    if settings.population < 2:
        raise ValueError(
            f"friction.population = {settings.population}: the genetic algorithm needs at least 2 individuals"
        )
    py_rng = random.Random(int(generator(seed, "friction/ga").integers(2**31)))
    state = random.getstate()
    random.seed(py_rng.random())  # DEAP's operators draw from the module-level generator
    try:
        tb = base.Toolbox()
        tb.register("mate", tools.cxBlend, alpha=0.3)
        tb.register("mutate", tools.mutGaussian, mu=0.0, sigma=0.1, indpb=0.4)
        tb.register("select", tools.selTournament, tournsize=3)
        pop = [creator.ValanisIndividual([py_rng.random() for _ in range(5)]) for _ in range(settings.population)]

        def evaluate(inds):
            u = np.clip(np.array(inds, dtype=float), 0.0, 1.0)
            for ind, val in zip(inds, problem.misfit(problem.physical(u))):
                ind.fitness.values = (float(val),)

        evaluate(pop)
        hof = tools.HallOfFame(1)
        hof.update(pop)
        logbook = []
        every = max(1, settings.generations // 8)  # about eight progress lines per run
        log.info(
            "%s: GA, %d individuals, %d generations, %d points per period; best misfit at start %.4g",
            label,
            settings.population,
            settings.generations,
            problem.S.size,
            hof[0].fitness.values[0],
        )
        for gen in range(settings.generations):
            offspring = [creator.ValanisIndividual(list(ind)) for ind in tb.select(pop, len(pop))]
            for a, b in zip(offspring[::2], offspring[1::2]):
                if random.random() < settings.crossover:
                    tb.mate(a, b)
                    del a.fitness.values, b.fitness.values
            for ind in offspring:
                if random.random() < settings.mutation:
                    tb.mutate(ind)
                    del ind.fitness.values
                ind[:] = list(np.clip(ind, 0.0, 1.0))
            invalid = [ind for ind in offspring if not ind.fitness.valid]
            if invalid:
                evaluate(invalid)
            offspring[0] = creator.ValanisIndividual(list(hof[0]))  # elitism
            offspring[0].fitness.values = hof[0].fitness.values
            pop = offspring
            hof.update(pop)
            vals = np.array([ind.fitness.values[0] for ind in pop])
            logbook.append((gen, float(vals.min()), float(vals.mean())))
            if (gen + 1) % every == 0 or gen + 1 == settings.generations:
                log.info(
                    "%s: GA generation %d/%d: best misfit %.4g, mean %.4g",
                    label,
                    gen + 1,
                    settings.generations,
                    vals.min(),
                    vals.mean(),
                )
        return np.array(hof[0]), logbook
    finally:
        random.setstate(state)


def _refined_fit(
    coef_xi, coef_n, coef_s, f0: float, preload: float, settings: FitSettings, seed: int, label: str, start=None
):
    """Fit the law by the GA (or from ``start``) and polish it, the grid doubled until the parameters settle.

    The harmonics are synthesised on a grid of one period; the grid is doubled until the parameters move by less than
    ``settings.refine_tolerance``. Returns (problem on the last grid, optimum in the unit cube, its SSR, the polish's
    least-squares result, the grid's points, history, GA logbook).
    """
    m = settings.grid_points
    history = []
    u_best = None
    logbook = []
    prev = None
    while True:
        xi = periodic_grid(coef_xi, f0, m)[0]
        n = preload + periodic_grid(coef_n, f0, m)[0]
        s = periodic_grid(coef_s, f0, m)[0]
        problem = FitProblem(xi, n, s, settings.bounds, settings.regularization)
        if u_best is None and start is not None:
            u_best = np.clip(problem.unit(np.asarray(start, float))[0], 0.0, 1.0)
        elif u_best is None:
            u_ga, logbook = _ga(problem, settings, seed, label)
            u_best = u_ga
        u_best, ssr, res = least_squares_polish(problem, u_best)
        p = problem.physical(u_best)[0]
        history.append((m, *p, float(np.sqrt(ssr / m))))
        log.info(
            "%s: polished on %d points: misfit %.4g, %s",
            label,
            m,
            np.sqrt(ssr / m),
            ", ".join(f"{name} = {v:.4g}" for name, v in zip(PARAMETER_NAMES, p)),
        )
        if (
            prev is not None
            and np.max(np.abs(p / np.where(prev == 0, 1, prev) - 1)[[0, 1, 3, 4]]) < settings.refine_tolerance
        ):
            break
        if 2 * m > settings.max_grid_points:
            log.warning("friction fit: the grid reached %d points without the parameters settling", m)
            break
        prev = p
        m *= 2
    return problem, u_best, ssr, res, m, history, logbook


def profile_intervals(
    problem: FitProblem,
    u_best: np.ndarray,
    ssr_min: float,
    n_data: int,
    settings: FitSettings,
    preload: float,
    label: str = "friction fit",
) -> tuple[np.ndarray, np.ndarray, dict, list]:
    """Return the profile-likelihood intervals of the 5 parameters at ``settings.confidence``.

    Each parameter is stepped away from the optimum ``u_best`` (unit cube) with the others repolished, until the SSR
    crosses the threshold chi2 = (n_data / M) SSR / sigma^2 (``n_data`` = 2K independent Fourier coefficients; sigma,
    the relative rms misfit per point, the larger of the fit's own residual and ``settings.misfit_floor``); the crossing
    is bisected. A side that reaches its search bound inside the threshold is not bounded by the data.

    Parameters
    ----------
    problem
        The fit's problem on the final grid (M points).
    u_best
        The optimum in unit-cube coordinates [-], shape (5,).
    ssr_min
        Sum of squared residuals at the optimum (relative to the rms of the identified S) [-].
    n_data
        Number of independent data: 2K for K fitted harmonics.
    settings
        The fit's settings (confidence, misfit_floor).
    preload
        Static normal force N0 at which e_0 is evaluated [N].
    label
        Start of the progress lines logged.

    Returns
    -------
    intervals : np.ndarray
        Interval (low, high) of each parameter e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -] by row, shape (5, 2).
    bounded : np.ndarray
        Whether the data bound each side inside the search bounds [-], shape (5, 2).
    profiles : dict
        {name: array of (value in the parameter's unit, SSR) rows, sorted} of every profile point.
    e0_values : list
        e_0 at the preload of every profile point inside the threshold [N/m].
    """
    m_pts = problem.S.size
    sigma2 = max(ssr_min / m_pts * n_data / max(n_data - 5, 1), settings.misfit_floor**2)
    from scipy.stats import chi2 as chi2_dist  # here: scipy.stats takes 0.3 s to import

    thr = ssr_min + chi2_dist.ppf(settings.confidence, 1) * sigma2 * m_pts / n_data
    intervals = np.full((5, 2), np.nan)
    bounded = np.zeros((5, 2), dtype=bool)
    profiles = {}
    e0_vals = []

    def profile(i, value, start):
        u, s_j, _ = least_squares_polish(problem, start, {i: value})
        if s_j <= thr:
            pp = problem.physical(u)[0]
            e0_vals.append(float(stiction_shear_stiffness(preload, pp[0], pp[1])))
        profiles.setdefault(PARAMETER_NAMES[i], []).append((float(problem.physical(u)[0][i]), s_j))
        return u, s_j

    log.info(
        "%s: profile-likelihood intervals of the 5 parameters (%.0f %% confidence)", label, 100 * settings.confidence
    )
    for i in range(5):
        for side, direction in ((0, -1.0), (1, +1.0)):
            edge = 0.0 if direction < 0 else 1.0
            inside_v, start = u_best[i], u_best.copy()
            step = 1e-3
            outside_v = None
            while True:
                v = float(np.clip(inside_v + direction * step, 0.0, 1.0))
                u, s_v = profile(i, v, start)
                if s_v > thr:
                    outside_v = v
                    break
                inside_v, start = v, u
                if v == edge:
                    break
                step *= 2.0
            if outside_v is None:
                bounded[i, side] = False
                crossing = edge
            else:
                bounded[i, side] = True
                for _ in range(8):  # bisection of the threshold crossing
                    mid = 0.5 * (inside_v + outside_v)
                    u, s_m = profile(i, mid, start)
                    if s_m <= thr:
                        inside_v, start = mid, u
                    else:
                        outside_v = mid
                crossing = inside_v
            unit = u_best.copy()
            unit[i] = crossing
            intervals[i, side] = problem.physical(unit)[0][i]
        unbounded = [f"not bounded {end} by the data" for end, b in zip(("below", "above"), bounded[i]) if not b]
        log.info(
            "%s: %s in [%.4g, %.4g]%s",
            label,
            PARAMETER_NAMES[i],
            intervals[i, 0],
            intervals[i, 1],
            f" ({' and '.join(unbounded)})" if unbounded else "",
        )
    return intervals, bounded, {k: np.array(sorted(v)) for k, v in profiles.items()}, e0_vals


def parameter_correlation(jacobian: np.ndarray) -> np.ndarray:
    """Return the correlation of the parameters from the least-squares Jacobian at the optimum.

    The Jacobian is in unit-cube coordinates; NaN for the parameters the misfit is not sensitive to.

    Parameters
    ----------
    jacobian
        Jacobian of the relative residuals with respect to the unit-cube coordinates [-], shape (n_samples, 5).

    Returns
    -------
    correlation : np.ndarray
        Correlation matrix of e_f, k_c, e_t, kappa, mu [-], shape (5, 5).
    """
    corr = np.full((5, 5), np.nan)
    norms = np.linalg.norm(jacobian, axis=0)
    sens = norms > 1e-8 * np.max(norms)
    if sens.sum() >= 2:
        cov = np.linalg.pinv(jacobian[:, sens].T @ jacobian[:, sens])
        d = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
        corr[np.ix_(sens, sens)] = cov / np.outer(d, d)
    return corr


def bound_warnings(u_best: np.ndarray, params: np.ndarray, settings: FitSettings) -> list:
    """Return a warning for each parameter at a search bound.

    A parameter within 1e-3 of the unit cube's side sits at its bound, where the bounds may exclude the best value; e_t
    at a lower bound of zero is its natural value, not a warning.

    Parameters
    ----------
    u_best
        The optimum in unit-cube coordinates [-], shape (5,).
    params
        The optimum e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -], shape (5,).
    settings
        The fit's settings (its bounds).

    Returns
    -------
    warnings : list
        One sentence per parameter at a bound, naming the bound and the key to widen.
    """
    warnings = []
    for i, name in enumerate(PARAMETER_NAMES):
        for edge, which in ((0.0, "lower"), (1.0, "upper")):
            if abs(u_best[i] - edge) < 1e-3 and not (name == "e_t" and edge == 0.0 and settings.bounds[2][0] == 0.0):
                warnings.append(
                    f"{name} = {params[i]:.4g} sits at its {which} search bound {settings.bounds[i][int(edge)]:.4g}: "
                    f"the bounds may exclude the best value; widen friction.bounds.{name}"
                )
    return warnings


def fit_friction_law(
    coef_xi: np.ndarray,
    coef_n: np.ndarray,
    coef_s: np.ndarray,
    f0: float,
    preload: float,
    settings: FitSettings,
    seed: int,
    n_harmonics_data: int | None = None,
    intervals: bool = True,
    label: str = "friction fit",
    start: np.ndarray | Sequence[float] | None = None,
) -> FitResult:
    """Fit the friction law to the calibration case's xi, N and S harmonics.

    GA and polish, with the grid refined until the parameters move by less than ``refine_tolerance`` (``_refined_fit``);
    then the profile-likelihood intervals (``profile_intervals``; skipped with ``intervals`` False: NaN intervals). N is
    the total force, the preload plus the dynamic part the harmonics give.

    Parameters
    ----------
    coef_xi
        Complex harmonic coefficients of the tangential motion xi (harmonics 1..K of ``f0``, x ~ sum Im(c_h
        e^{i h w t})) [m], shape (n_harmonics,) or (1, n_harmonics).
    coef_n
        Complex harmonic coefficients of the dynamic normal force [N], shape (n_harmonics,) or (1, n_harmonics) as
        ``coef_xi``.
    coef_s
        Complex harmonic coefficients of the friction force S [N], shape (n_harmonics,) or (1, n_harmonics) as
        ``coef_xi``.
    f0
        Fundamental (drive) frequency [Hz].
    preload
        Static normal force N0 added to the dynamic one [N].
    settings
        The fit's settings.
    seed
        Seed of the GA's random stream.
    n_harmonics_data
        Number K of harmonics the data hold (2K independent data for the intervals); None: the columns of ``coef_s``.
    intervals
        Whether to profile the intervals.
    label
        Start of the progress lines it logs.
    start
        The 5 parameters e_f, k_c, e_t, kappa, mu [N/m, 1/m, N/m, -, -], shape (5,), to start the polish from, skipping
        the GA (a refit of a known optimum on other forces, for example the model-form spread of
        ``contactid.gap.uncertainty``); None: the GA.

    Returns
    -------
    result : FitResult
        The fit, its intervals, correlation, histories and warnings.
    """
    K = np.atleast_2d(coef_s).shape[1] if n_harmonics_data is None else n_harmonics_data
    problem, u_best, ssr_min, res, m, history, logbook = _refined_fit(
        coef_xi, coef_n, coef_s, f0, preload, settings, seed, label, start
    )
    if intervals:
        bounds, bounded, profiles, e0_vals = profile_intervals(
            problem, u_best, ssr_min, 2 * K, settings, preload, label
        )
    else:
        bounds, bounded, profiles, e0_vals = np.full((5, 2), np.nan), np.zeros((5, 2), dtype=bool), {}, []
    p = problem.physical(u_best)[0]
    e0 = float(stiction_shear_stiffness(preload, p[0], p[1]))
    e0_vals.append(e0)
    warnings = bound_warnings(u_best, p, settings)
    for w in warnings:
        log.warning("friction fit: %s", w)
    return FitResult(
        p,
        float(np.sqrt(ssr_min / problem.S.size)),
        e0,
        logbook,
        history,
        bounds,
        bounded,
        (min(e0_vals), max(e0_vals)),
        parameter_correlation(res.jac),
        m,
        profiles,
        warnings,
    )


def settings_from_config(cfg: Mapping[str, Any] | None) -> FitSettings:
    """Return the FitSettings of the ``friction`` config block.

    Keys left out take the schema's defaults; the search bounds left out take Table 4's neighbourhood
    (``FitSettings.bounds``).

    Parameters
    ----------
    cfg
        The ``friction`` config block; read: bounds (e_f_n_per_m, k_c_per_m, e_t_n_per_m, kappa, mu), population,
        generations, grid_points, max_grid_points, confidence, misfit_floor, regularization. None: every default.

    Returns
    -------
    settings : FitSettings
        The settings; crossover, mutation and refine_tolerance at FitSettings' defaults.

    Raises
    ------
    ValueError
        When a parameter's bounds are not low < high.
    """
    from .schema import schema_defaults

    d = FitSettings()
    cfg = {**schema_defaults("friction"), **dict(cfg or {})}
    b = cfg.get("bounds") or {}
    names = {"e_f": "e_f_n_per_m", "k_c": "k_c_per_m", "e_t": "e_t_n_per_m", "kappa": "kappa", "mu": "mu"}
    bounds = []
    for (name, key), default in zip(names.items(), d.bounds):
        lo, hi = b.get(key, default)
        if not lo < hi:
            raise ValueError(f"friction.bounds.{key} = [{lo}, {hi}]: the lower bound must be below the upper")
        bounds.append((float(lo), float(hi)))
    return FitSettings(
        bounds=tuple(bounds),
        population=int(cfg["population"]),
        generations=int(cfg["generations"]),
        grid_points=int(cfg["grid_points"]),
        max_grid_points=int(cfg["max_grid_points"]),
        confidence=float(cfg["confidence"]),
        misfit_floor=float(cfg["misfit_floor"]),
        regularization=str(cfg["regularization"]),
    )
