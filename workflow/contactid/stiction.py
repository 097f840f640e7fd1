"""Contact stiffness at stiction (Section 4, Table 3): k_t and k_n of Eq. (13) fitted to natural frequencies.

k_t and k_n are fitted to identified natural frequencies by weighted least squares, with profile-likelihood
confidence intervals that say when the data bound a parameter from one side only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from .beam_modes import ContactFrequencyMap
from .parameters import StructureParameters


@dataclass(frozen=True)
class StiffnessFit:
    """Result of the stiction-stiffness fit.

    Attributes
    ----------
    k_t
        Tangential contact stiffness, best fit [N/m].
    k_n
        Normal contact stiffness, best fit [N/m].
    k_t_interval
        Profile-likelihood confidence interval of k_t, (lower, upper) [N/m]: the search bound (lower) or ``inf``
        (upper) where the data do not bound it on that side.
    k_n_interval
        Profile-likelihood confidence interval of k_n, (lower, upper) [N/m], as ``k_t_interval``.
    k_t_bounded
        Whether the data bound k_t on both sides.
    k_n_bounded_above
        False when the data only give a lower bound on k_n (then ``k_n_lower_bound`` holds it).
    k_n_bounded_below
        Whether the data bound k_n from below.
    model_frequencies_hz
        The model's natural frequencies at the best fit [Hz], shape (n_modes,): n_modes the number of identified
        frequencies.
    chi2_min
        Minimum of the weighted misfit chi^2 [-].
    confidence
        Confidence level of the intervals [-] (config ``stiction.confidence``).
    profiles
        {parameter: (grid [N/m], profiled chi^2 [-])}, each array of shape (n_grid,), for "k_t" and "k_n".
    notes
        {parameter: why a side is not bounded} (empty where both are).
    stiffness_scale
        The structure's Young's modulus over the model's at the best fit [-] (1 where the fit keeps the structure,
        ``stiffness_scale_sd`` 0).
    """

    k_t: float
    k_n: float
    k_t_interval: tuple[float, float]
    k_n_interval: tuple[float, float]
    k_t_bounded: bool
    k_n_bounded_above: bool
    k_n_bounded_below: bool
    model_frequencies_hz: np.ndarray
    chi2_min: float
    confidence: float
    profiles: dict
    notes: dict
    stiffness_scale: float = 1.0

    @property
    def k_n_lower_bound(self) -> float:
        """Lower end of the k_n interval.

        Returns
        -------
        k_n_lower : float
            The interval's lower end [N/m].
        """
        return self.k_n_interval[0]


def frequency_sigma(freqs_hz: np.ndarray, stat_sigma_hz: np.ndarray, relative_floor: float) -> np.ndarray:
    """Return the standard uncertainty of each identified frequency.

    The statistical part combined (in quadrature) with a relative floor for model and estimator bias. A frequency
    without a statistical estimate (NaN: an imported FRF has no sub-records to compare) has the floor alone.

    Parameters
    ----------
    freqs_hz
        Identified natural frequencies [Hz], shape (n_modes,).
    stat_sigma_hz
        Their statistical standard uncertainties [Hz], shape (n_modes,); NaN where there is none.
    relative_floor
        The floor, relative to the frequency [-] (config ``stiction.frequency_uncertainty_floor``).

    Returns
    -------
    sigma : np.ndarray
        Standard uncertainty of each frequency [Hz], shape (n_modes,).
    """
    stat = np.nan_to_num(np.asarray(stat_sigma_hz, dtype=float), nan=0.0)
    return np.sqrt(stat**2 + (relative_floor * np.asarray(freqs_hz)) ** 2)


# the fits' Jacobian: central differences with steps of 1e-5 relative to log10 k (scipy's diff_step scales with |x|:
# 7e-5 at log10 k_t = 7; the variables never come near zero, unlike the updating's log factors, which take absolute
# steps, contactid.finite_differences). scipy's default forward steps of
# 1.5e-8 lie within the eigensolver's rounding of the frequencies: a 1e-8 change in the identified frequencies moved
# the fitted log10 k_t by up to 0.67 and a profile point's by up to 0.09 (docs/measurements.md, "The stiction fits'
# Jacobian")
JACOBIAN = {"jac": "3-point", "diff_step": 1e-5}


# the structure's stiffness scale s (Young's modulus over the model's), where the fit frees it: ln s searched within
# these bounds, with a Gaussian prior of sd ``stiffness_scale_sd`` on ln s (one more residual, ln s / sd)
LN_SCALE_BOUNDS = (float(np.log(0.5)), float(np.log(2.0)))


def _residuals(fmap: ContactFrequencyMap, f_id, sigma, log_kt, log_kn, ln_s=None, s_sd=0.0):
    """Return the weighted frequency residuals at (log10 k_t, log10 k_n).

    With ``ln_s`` (the log stiffness scale), the prior's residual ln s / ``s_sd`` after them.
    """
    if ln_s is None:
        return (fmap(10.0**log_kt, 10.0**log_kn) - f_id) / sigma
    r = (fmap(10.0**log_kt, 10.0**log_kn, float(np.exp(ln_s))) - f_id) / sigma
    return np.append(r, ln_s / s_sd)


def _fit_one(params, f_id, sigma, fixed_name, fixed_log, start, bounds, s_sd=0.0, start_s=0.0):
    """Fit the free log-stiffness with the other stiffness fixed.

    With ``s_sd`` > 0, the log stiffness scale too, from ``start_s``. Returns (the free stiffness's log10, chi2, ln s).
    """
    scaled = s_sd > 0

    def res(x):
        ln_s = x[1] if scaled else None
        if fixed_name == "k_n":
            return _residuals(params, f_id, sigma, x[0], fixed_log, ln_s, s_sd)
        return _residuals(params, f_id, sigma, fixed_log, x[0], ln_s, s_sd)

    from scipy.optimize import least_squares  # here, not at the top: see _joint_fit

    lo, hi = LN_SCALE_BOUNDS
    r = least_squares(
        res,
        [start, start_s] if scaled else [start],
        bounds=([bounds[0], lo], [bounds[1], hi]) if scaled else ([bounds[0]], [bounds[1]]),
        x_scale=[0.1, 0.01] if scaled else [0.1],
        xtol=1e-10,
        ftol=1e-12,
        **JACOBIAN,
    )
    return r.x[0], float(2 * r.cost), float(r.x[1]) if scaled else 0.0


def _joint_fit(params, f_id, sigma, x0, lt, ln, s_sd=0.0):
    """Fit (log10 k_t, log10 k_n) from x0 by least squares.

    With ``s_sd`` > 0, the log stiffness scale too (x0 then has three entries); returns (x, chi2).
    """
    # scipy.optimize (0.3 s to import) where the fits use it: most jobs of the linear chain (the FRFs, the modal fit,
    # the raw checks) import this module through contactid.linear_chain without fitting anything
    from scipy.optimize import least_squares

    scaled = s_sd > 0
    lo, hi = LN_SCALE_BOUNDS
    r = least_squares(
        lambda x: _residuals(params, f_id, sigma, x[0], x[1], x[2] if scaled else None, s_sd),
        x0,
        bounds=([lt[0], ln[0], lo], [lt[1], ln[1], hi]) if scaled else ([lt[0], ln[0]], [lt[1], ln[1]]),
        x_scale=[0.1, 1.0, 0.01] if scaled else [0.1, 1.0],
        xtol=1e-12,
        ftol=1e-14,
        **JACOBIAN,
    )
    return r.x, float(2 * r.cost)


def _profiles(params, f_id, sigma, best, lt, ln, n_profile, s_sd=0.0):
    """Return the profile misfit of each parameter on a log grid.

    The other parameter, and the stiffness scale where it is free, are refitted from the joint best:
    {name: (log grid, chi2, the other parameter's fitted log value, the fitted ln s)}.
    """
    out = {}
    ln_s = float(best[2]) if s_sd > 0 else 0.0
    for name, rng, idx, other_rng in (("k_n", ln, 1, lt), ("k_t", lt, 0, ln)):
        grid = np.unique(np.concatenate([np.linspace(rng[0], rng[1], n_profile), [best[idx]]]))
        fits = [_fit_one(params, f_id, sigma, name, x, best[1 - idx], other_rng, s_sd, ln_s) for x in grid]
        other, chi2, ln_s_fit = (np.array(column) for column in zip(*fits))
        out[name] = (grid, chi2, other, ln_s_fit)
    return out


def interval_edge(
    profile: Callable[[float], float],
    grid: np.ndarray,
    chi2_prof: np.ndarray,
    i_min: int,
    direction: int,
    chi2_min: float,
    threshold: float,
) -> tuple[float | None, str]:
    """Return one edge of a profile-likelihood interval, or why the data do not bound that side.

    The edge is where the profiled chi2 crosses ``chi2_min + threshold``, walking from grid point ``i_min`` in
    ``direction``; it is bracketed on the grid and then found by Brent's method on ``profile``. The data do not bound
    the parameter on that side either because the crossing lies beyond the search range or because no crossing can
    be bracketed (the profile does not come down to the threshold there).

    Parameters
    ----------
    profile
        The profiled chi2 [-] as a function of the parameter's log10 (log10 of a stiffness in N/m in the stiffness
        fit).
    grid
        The parameter's log10 on the grid [-], shape (n_grid,), ascending.
    chi2_prof
        The profiled chi2 on the grid [-], shape (n_grid,).
    i_min
        Index of the grid point to walk from (the profile's minimum).
    direction
        -1 (the lower edge) or +1 (the upper edge).
    chi2_min
        The fit's minimum chi2 [-].
    threshold
        The chi2 rise that bounds the interval [-] (chi2_1(confidence)).

    Returns
    -------
    edge : float | None
        The edge, the parameter's log10 [-]; None where the data do not bound that side.
    reason : str
        Why the side is not bounded; empty where it is.
    """
    j = i_min
    while 0 <= j + direction < len(grid) and chi2_prof[j + direction] - chi2_min <= threshold:
        j += direction
    if not 0 <= j + direction < len(grid):
        return None, "the interval reaches the search bound"
    a, b = sorted((grid[j], grid[j + direction]))
    fa, fb = profile(a) - chi2_min - threshold, profile(b) - chi2_min - threshold
    if not (np.isfinite(fa) and np.isfinite(fb)) or fa * fb > 0:
        return None, (
            f"the profile misfit does not cross the threshold between 10^{a:.3f} and 10^{b:.3f} "
            f"({fa + threshold:.3g} and {fb + threshold:.3g} above the minimum, threshold {threshold:.3g}): "
            "the data do not bound this side"
        )
    if fa == 0.0 or fb == 0.0:
        return (a if fa == 0.0 else b), ""
    from scipy.optimize import brentq

    return brentq(lambda x: profile(x) - chi2_min - threshold, a, b, xtol=1e-6), ""


def stiction_stiffness(
    params: StructureParameters,
    f_id_hz: np.ndarray,
    sigma_hz: np.ndarray,
    k_t_bounds: tuple[float, float] = (1e5, 1e9),
    k_n_bounds: tuple[float, float] = (1e5, 1e11),
    confidence: float = 0.95,
    n_profile: int = 25,
    stiffness_scale_sd: float = 0.0,
) -> StiffnessFit:
    """Fit k_t and k_n of Eq. (13) to the identified natural frequencies.

    Misfit chi2 = sum_i ((f_i(k_t, k_n) - f_id,i) / sigma_i)^2 over the first
    len(f_id) structural modes. A parameter's confidence interval is the set
    of values whose profiled chi2 lies within chi2_1(confidence) of the
    minimum; an interval reaching a search bound, or one whose edge cannot be
    bracketed, means the data do not bound the parameter on that side (the
    reason is in ``notes``). Where a profile finds a lower misfit than the joint
    fit (a second minimum), the joint fit is restarted from there.

    ``stiffness_scale_sd`` > 0 frees the structure's Young's modulus too: a scale s (the structure's E over the
    model's) with a Gaussian prior of that sd on ln s adds ln s / sd to the residuals, and every profile refits it.
    The frequencies' errors of a structure whose stiffness is uncertain are correlated (every mode moves with
    sqrt(s)); held at s = 1, the fit gives that error to k_t and k_n: on a beam 3 % softer than the model, k_t 20 %
    low and k_n 6.6 times too soft with an interval that excluded the truth (docs/measurements.md, "A rig whose beam
    is softer than the model"). With sd 0 the structure is the model's (s = 1), the fit as before.

    Parameters
    ----------
    params
        The described structure (its k_t and k_n are not used).
    f_id_hz
        Identified natural frequencies [Hz], shape (n_modes,): the first n_modes structural modes.
    sigma_hz
        Their standard uncertainties, the weights [Hz], shape (n_modes,) (``frequency_sigma``).
    k_t_bounds
        Search bounds of k_t (low, high) [N/m].
    k_n_bounds
        Search bounds of k_n (low, high) [N/m].
    confidence
        Confidence level of the intervals [-].
    n_profile
        Number of grid points of each profile (the best fit is added).
    stiffness_scale_sd
        Standard deviation of the Gaussian prior on ln s [-]; 0: the model's Young's modulus.

    Returns
    -------
    fit : StiffnessFit
        The best fit, its intervals, profiles and notes.

    Raises
    ------
    ValueError
        When ``stiffness_scale_sd`` is negative or NaN.
    """
    f_id = np.asarray(f_id_hz, dtype=float)
    sigma = np.asarray(sigma_hz, dtype=float)
    s_sd = float(stiffness_scale_sd)
    if not s_sd >= 0:
        raise ValueError(f"stiffness_scale_sd = {stiffness_scale_sd}: give a relative sd >= 0 (0: the model's E)")
    scaled = s_sd > 0
    params = ContactFrequencyMap(params, len(f_id))
    lt, ln = np.log10(k_t_bounds), np.log10(k_n_bounds)
    # start: a coarse scan in k_t with k_n at the geometric mid of its range
    grid_t = np.linspace(lt[0], lt[1], 17)
    c0 = [np.sum(_residuals(params, f_id, sigma, g, ln.mean()) ** 2) for g in grid_t]
    x0 = [grid_t[int(np.argmin(c0))], ln.mean()] + ([0.0] if scaled else [])
    best, chi2_min = _joint_fit(params, f_id, sigma, x0, lt, ln, s_sd)
    prof = _profiles(params, f_id, sigma, best, lt, ln, n_profile, s_sd)
    # a profile below the joint fit: the joint fit stopped in a second minimum; restart from the lowest point
    name, (grid, chi2_p, other, ln_s) = min(prof.items(), key=lambda kv: kv[1][1].min())
    i = int(np.argmin(chi2_p))
    if chi2_p[i] < chi2_min - 1e-9 * (1.0 + chi2_min):
        x0 = [other[i], grid[i]] if name == "k_n" else [grid[i], other[i]]
        x1, c1 = _joint_fit(params, f_id, sigma, x0 + ([ln_s[i]] if scaled else []), lt, ln, s_sd)
        if c1 < chi2_min:
            best, chi2_min = x1, c1
            prof = _profiles(params, f_id, sigma, best, lt, ln, n_profile, s_sd)
    chi2_min = min([chi2_min] + [float(p[1].min()) for p in prof.values()])
    from scipy.stats import chi2  # here: scipy.stats takes 0.3 s to import

    thr = chi2.ppf(confidence, 1)

    profiles, lo_hi, flags, notes = {}, {}, {}, {}
    for name, rng, idx, other_rng in (("k_n", ln, 1, lt), ("k_t", lt, 0, ln)):

        def profile(x, name=name, other_rng=other_rng, idx=idx):
            return _fit_one(params, f_id, sigma, name, x, best[1 - idx], other_rng, s_sd, best[2] if scaled else 0.0)[1]

        grid, chi2_p, _, _ = prof[name]
        profiles[name] = (10.0**grid, chi2_p)
        i_min = int(np.argmin(chi2_p))
        (lo, why_lo), (hi, why_hi) = (interval_edge(profile, grid, chi2_p, i_min, d, chi2_min, thr) for d in (-1, +1))
        flags[name] = (lo is not None, hi is not None)
        notes[name] = tuple(
            w for w in (f"lower: {why_lo}" if lo is None else "", f"upper: {why_hi}" if hi is None else "") if w
        )
        lo_hi[name] = (10.0 ** (lo if lo is not None else rng[0]), 10.0**hi if hi is not None else np.inf)
    scale = float(np.exp(best[2])) if scaled else 1.0
    f_best = params(10.0 ** best[0], 10.0 ** best[1], scale)
    return StiffnessFit(
        k_t=float(10.0 ** best[0]),
        k_n=float(10.0 ** best[1]),
        k_t_interval=lo_hi["k_t"],
        k_n_interval=lo_hi["k_n"],
        k_t_bounded=all(flags["k_t"]),
        k_n_bounded_above=flags["k_n"][1],
        k_n_bounded_below=flags["k_n"][0],
        model_frequencies_hz=f_best,
        chi2_min=chi2_min,
        confidence=confidence,
        profiles=profiles,
        notes=notes,
        stiffness_scale=scale,
    )


def quick_chi2(
    fmap: ContactFrequencyMap, f_id: np.ndarray, sigma: np.ndarray, lt: np.ndarray, ln: np.ndarray, s_sd: float
) -> float:
    """Return the stiffness fit's misfit minimum from its coarse start (no profiles).

    What a factor on the frequencies would leave (``stiction_refusal.reachability``): the joint fit of
    ``stiction_stiffness`` from the same coarse scan in k_t, without its profiles and intervals.

    Parameters
    ----------
    fmap
        The structure's natural frequencies as a function of the contact stiffnesses.
    f_id
        Identified natural frequencies [Hz], shape (n_modes,).
    sigma
        Their standard uncertainties, the weights [Hz], shape (n_modes,).
    lt
        Search bounds of log10 k_t (low, high) [-], shape (2,): log10 of a stiffness in N/m.
    ln
        Search bounds of log10 k_n (low, high) [-], shape (2,), as ``lt``.
    s_sd
        Standard deviation of the Gaussian prior on the log stiffness scale ln s [-]; 0: the model's Young's modulus.

    Returns
    -------
    chi2_min : float
        The joint fit's minimum chi^2 [-].
    """
    grid_t = np.linspace(lt[0], lt[1], 17)
    c0 = [np.sum(_residuals(fmap, f_id, sigma, g, ln.mean()) ** 2) for g in grid_t]
    x0 = [grid_t[int(np.argmin(c0))], ln.mean()] + ([0.0] if s_sd > 0 else [])
    return _joint_fit(fmap, f_id, sigma, x0, lt, ln, s_sd)[1]
