"""Contact stiffness at stiction (Section 4, Table 3): k_t and k_n of Eq. (13)
fitted to identified natural frequencies by weighted least squares, with
profile-likelihood confidence intervals that say when the data bound a
parameter from one side only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .beam_model import ContactFrequencyMap
from .parameters import StructureParameters


@dataclass(frozen=True)
class StiffnessFit:
    """Result of the stiction-stiffness fit (N/m).

    k_t, k_n: best fit; k_t_interval, k_n_interval: profile-likelihood
    confidence intervals (lower, upper), with ``inf`` / the search bound where
    the data do not bound the parameter; k_n_bounded_above: False when the
    data only give a lower bound on k_n (then ``k_n_lower_bound`` holds it);
    model_frequencies_hz: frequencies at the best fit; chi2_min: minimum of the
    weighted misfit; profiles: dict of (grid, chi2) arrays per parameter;
    notes: {parameter: why a side is not bounded} (empty where both are);
    stiffness_scale: the structure's Young's modulus over the model's at the best fit (1 where the fit
    keeps the structure, ``stiffness_scale_sd`` 0).
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
        """Lower end of the k_n interval (N/m)."""
        return self.k_n_interval[0]


def frequency_sigma(freqs_hz: np.ndarray, stat_sigma_hz: np.ndarray, relative_floor: float) -> np.ndarray:
    """Standard uncertainty of each identified frequency (Hz): the statistical
    part combined with a relative floor for model and estimator bias. A frequency without a statistical
    estimate (NaN: an imported FRF has no sub-records to compare) has the floor alone."""
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
    """Weighted frequency residuals at (log10 k_t, log10 k_n), and with ``ln_s`` (the log stiffness scale) the
    prior's residual ln s / ``s_sd`` after them."""
    if ln_s is None:
        return (fmap(10.0**log_kt, 10.0**log_kn) - f_id) / sigma
    r = (fmap(10.0**log_kt, 10.0**log_kn, float(np.exp(ln_s))) - f_id) / sigma
    return np.append(r, ln_s / s_sd)


def _fit_one(params, f_id, sigma, fixed_name, fixed_log, start, bounds, s_sd=0.0, start_s=0.0):
    """Fit the free log-stiffness (and, with ``s_sd`` > 0, the log stiffness scale from ``start_s``) with the other
    stiffness fixed; returns (the free stiffness's log10, chi2, ln s)."""
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
    """Least-squares fit of (log10 k_t, log10 k_n) from x0, and with ``s_sd`` > 0 of the log stiffness scale too
    (x0 then has three entries); returns (x, chi2)."""
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
    """Profile misfit of each parameter on a log grid (the other, and the stiffness scale where it is free, refitted
    from the joint best): {name: (log grid, chi2, the other parameter's fitted log value, the fitted ln s)}."""
    out = {}
    ln_s = float(best[2]) if s_sd > 0 else 0.0
    for name, rng, idx, other_rng in (("k_n", ln, 1, lt), ("k_t", lt, 0, ln)):
        grid = np.unique(np.concatenate([np.linspace(rng[0], rng[1], n_profile), [best[idx]]]))
        fits = [_fit_one(params, f_id, sigma, name, x, best[1 - idx], other_rng, s_sd, ln_s) for x in grid]
        other, chi2, ln_s_fit = (np.array(column) for column in zip(*fits))
        out[name] = (grid, chi2, other, ln_s_fit)
    return out


def interval_edge(profile, grid, chi2_prof, i_min, direction, chi2_min, threshold):
    """One edge (log10) of a profile-likelihood interval: where the profiled chi2 crosses
    ``chi2_min + threshold``, walking from grid point ``i_min`` in ``direction`` (-1 or +1).

    Returns (edge, reason): edge None with the reason where the data do not bound the parameter
    on that side, either because the crossing lies beyond the search range or because no
    crossing can be bracketed (the profile does not come down to the threshold there)."""
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
    f_id_hz,
    sigma_hz,
    k_t_bounds=(1e5, 1e9),
    k_n_bounds=(1e5, 1e11),
    confidence: float = 0.95,
    n_profile: int = 25,
    stiffness_scale_sd: float = 0.0,
) -> StiffnessFit:
    """Fit k_t and k_n (N/m) of Eq. (13) to the identified natural frequencies.

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


# A record the described structure cannot have come from (a sampling rate off by a factor, a structure described
# wrongly): refused by the stiffness step before anything downstream is overwritten
UNREACHABLE_SIGMAS = 5.0
"""How far, in the frequencies' standard uncertainties (``frequency_sigma``: the statistical part and the relative
floor), the identified frequencies may lie from every state the described structure can reach before the stiffness
step refuses the record (``reachability``): a frequency beyond the range the structure has between its stiffness
bounds (and Young's modulus between ``LN_SCALE_BOUNDS`` where the fit frees it) by more than this many sigma, or a best
fit pinned at a search bound whose misfit, per degree of freedom, is above its square (the fit's rms residual more
than this many sigma from the nearest reachable state). Five sigma: a 3e-7 chance for a Gaussian error. The
legitimate records lie far inside: the foreign records' and the rig's fits end inside the bounds with chi^2 below
0.05, every frequency within the ranges; a random test whose sampling rate was doubled lies 170 sigma outside."""

# the simple factors a sampling rate is likeliest off by (a doubled or halved rate, kHz read as Hz), in that order
_SIMPLE_FACTORS = (2, 3, 4, 5, 8, 10, 1000)


@dataclass(frozen=True)
class Reachability:
    """Whether the identified frequencies are ones the described structure can have (``reachability``).

    ranges_hz (n, 2): each mode's lowest and highest frequency over the stiffness bounds (and the stiffness scale's
    where it is free); outside_sigmas (n,): how far each frequency lies beyond its range, in sigma (+ above, - below,
    0 within); at_bound: the stiffnesses whose best fit sits at a search bound, as text; chi2_min and dof of the
    fit; where refused, factor_range: the factors c for which the lowest frequency divided by c lies within the
    first mode's range and every other within the structure's span (None: none does), factor: the simplest such
    factor (``_SIMPLE_FACTORS`` or its reciprocal; None) with chi2_factor, the fit's misfit at f / factor; reasons:
    why the record is refused (empty: reachable)."""

    ranges_hz: np.ndarray
    outside_sigmas: np.ndarray
    at_bound: tuple
    chi2_min: float
    dof: int
    factor_range: tuple | None
    factor: float | None
    chi2_factor: float | None
    reasons: tuple

    @property
    def reachable(self) -> bool:
        """Whether the record is accepted (no reasons to refuse it)."""
        return not self.reasons


def frequency_ranges(
    params: StructureParameters, n_modes: int, k_t_bounds, k_n_bounds, scale_bounds=(1.0, 1.0)
) -> np.ndarray:
    """(n_modes, 2): each structural mode's frequency (Hz) with both contact springs at their lower bounds (and
    Young's modulus at ``scale_bounds[0]`` times the structure's) and at their upper bounds (``scale_bounds[1]``):
    the range the structure can have, every natural frequency rising with every stiffness (Rayleigh)."""
    fmap = params if isinstance(params, ContactFrequencyMap) else ContactFrequencyMap(params, int(n_modes))
    lo = fmap(float(k_t_bounds[0]), float(k_n_bounds[0]), float(scale_bounds[0]))
    hi = fmap(float(k_t_bounds[1]), float(k_n_bounds[1]), float(scale_bounds[1]))
    return np.column_stack([np.minimum(lo, hi), np.maximum(lo, hi)])


def _quick_chi2(fmap, f_id, sigma, lt, ln, s_sd) -> float:
    """The stiffness fit's misfit minimum from its coarse start (no profiles): what a factor on the frequencies
    would leave."""
    grid_t = np.linspace(lt[0], lt[1], 17)
    c0 = [np.sum(_residuals(fmap, f_id, sigma, g, ln.mean()) ** 2) for g in grid_t]
    x0 = [grid_t[int(np.argmin(c0))], ln.mean()] + ([0.0] if s_sd > 0 else [])
    return _joint_fit(fmap, f_id, sigma, x0, lt, ln, s_sd)[1]


def reachability(
    params: StructureParameters,
    f_id_hz,
    sigma_hz,
    k_t: float,
    k_n: float,
    chi2_min: float,
    k_t_bounds=(1e5, 1e9),
    k_n_bounds=(1e5, 1e11),
    stiffness_scale_sd: float = 0.0,
) -> Reachability:
    """Whether the described structure can have the identified frequencies at any contact stiffness within the
    bounds (and, where the fit frees it, Young's modulus within ``LN_SCALE_BOUNDS``): refused (``reasons``) where a
    frequency lies more than ``UNREACHABLE_SIGMAS`` sigma beyond the range the structure has between its bounds
    (``frequency_ranges``), or where the best fit (k_t, k_n, ``chi2_min``) sits at a search bound with a misfit per
    degree of freedom above ``UNREACHABLE_SIGMAS`` squared. Where refused, the factors that would bring the
    frequencies within the structure's ranges (a sampling rate off by a factor moves them all by it) and the
    simplest of them."""
    f_id = np.asarray(f_id_hz, dtype=float)
    sigma = np.asarray(sigma_hz, dtype=float)
    s_sd = float(stiffness_scale_sd)
    fmap = ContactFrequencyMap(params, len(f_id))
    scale = tuple(np.exp(LN_SCALE_BOUNDS)) if s_sd > 0 else (1.0, 1.0)
    ranges = frequency_ranges(fmap, len(f_id), k_t_bounds, k_n_bounds, scale)
    outside = np.where(
        f_id > ranges[:, 1],
        (f_id - ranges[:, 1]) / sigma,
        np.where(f_id < ranges[:, 0], (f_id - ranges[:, 0]) / sigma, 0.0),
    )
    at_bound = []
    for name, k, (lo, hi) in (("k_t", k_t, k_t_bounds), ("k_n", k_n, k_n_bounds)):
        for side, b in (("lower", lo), ("upper", hi)):
            if abs(np.log10(k) - np.log10(b)) < 0.01:
                at_bound.append(f"{name} at its {side} search bound ({b:.3g} N/m)")
    dof = max(len(f_id) - 2, 1)
    reasons = []
    worst = int(np.argmax(np.abs(outside)))
    if abs(outside[worst]) > UNREACHABLE_SIGMAS:
        word, edge = (
            ("above its highest", ranges[worst, 1]) if outside[worst] > 0 else ("below its lowest", ranges[worst, 0])
        )
        reasons.append(
            f"mode {worst + 1} at {f_id[worst]:.4g} Hz lies {abs(outside[worst]):.3g} sigma {word} reachable frequency "
            f"{edge:.4g} Hz"
        )
    if at_bound and chi2_min / dof > UNREACHABLE_SIGMAS**2:
        reasons.append(
            f"the stiffness fit ends with {' and '.join(at_bound)} and chi^2 = {chi2_min:.3g} for {dof} degree"
            f"{'s' if dof > 1 else ''} of freedom (a misfit of {np.sqrt(chi2_min / dof):.3g} sigma rms where "
            f"{UNREACHABLE_SIGMAS:g} is the most a reachable state leaves)"
        )
    factor_range = factor = chi2_factor = None
    if reasons:
        # a sampling rate off by c moves every frequency by it: the c that bring the lowest frequency within the first
        # mode's range and every other within the structure's span (the identified modes need not be its first n:
        # the analysis band moves with them)
        span = (float(ranges[:, 0].min()), float(ranges[:, 1].max()))
        c_lo = max(f_id[0] / ranges[0, 1], float(np.max(f_id)) / span[1])
        c_hi = min(f_id[0] / ranges[0, 0], float(np.min(f_id)) / span[0])
        if c_lo <= c_hi:
            factor_range = (float(c_lo), float(c_hi))
            simple = [c for n in _SIMPLE_FACTORS for c in (n, 1.0 / n)]
            inside = [c for c in simple if c_lo <= c <= c_hi]
            if inside:
                factor = float(inside[0])
                lt, ln = np.log10(k_t_bounds), np.log10(k_n_bounds)
                chi2_factor = _quick_chi2(fmap, f_id / factor, sigma / factor, lt, ln, s_sd)
    return Reachability(
        ranges, outside, tuple(at_bound), float(chi2_min), dof, factor_range, factor, chi2_factor, tuple(reasons)
    )


def _factor_text(c: float) -> str:
    return f"{c:g}" if c >= 1 else f"1/{1 / c:g}"


def unreachable_message(reach: Reachability, f_id_hz, source: str, sampling_rate_hz: float | None = None) -> str:
    """The stiffness step's refusal of a random test (``source``: its file) whose frequencies the structure cannot
    have (``reachability``): the frequencies, the ranges the structure allows, why, and the likely causes in order."""
    f_id = np.asarray(f_id_hz, dtype=float)
    ranges = ", ".join(f"{lo:.4g}-{hi:.4g}" for lo, hi in reach.ranges_hz)
    freqs = ", ".join(f"{f:.4g}" for f in f_id)
    head = (
        f"random test {source}: its natural frequencies {freqs} Hz are not ones the described structure can have at "
        f"any contact stiffness within the search bounds (between them the structure allows {ranges} Hz): "
        + "; ".join(reach.reasons)
        + ". results/linear/stiction.nc is not written. Likely causes, most likely first: "
    )
    rate = f" ({sampling_rate_hz:g} Hz)" if sampling_rate_hz else ""
    limit = UNREACHABLE_SIGMAS**2 * reach.dof
    if reach.factor is not None:
        c = reach.factor
        fixed = f", {sampling_rate_hz / c:g} Hz" if sampling_rate_hz else ""
        fit = (
            f", where the stiffness fit's chi^2 falls to {reach.chi2_factor:.3g}"
            if reach.chi2_factor is not None and reach.chi2_factor <= limit
            else ""
        )
        first = (
            f"(1) the random test's sampling_rate_hz{rate} off by a factor, with its time axis: divided by "
            f"{_factor_text(c)}, the frequencies ({', '.join(f'{f / c:.4g}' for f in f_id)} Hz) come within the "
            f"structure's ranges{fit} (a sampling rate {_factor_text(c)} times too high{fixed}; any factor between "
            f"{reach.factor_range[0]:.3g} and {reach.factor_range[1]:.3g} would bring them there)"
        )
    elif reach.factor_range is not None:
        first = (
            f"(1) the random test's sampling_rate_hz{rate} off by a factor: any factor between "
            f"{reach.factor_range[0]:.3g} and {reach.factor_range[1]:.3g} would bring the frequencies within the "
            "structure's ranges"
        )
    else:
        first = (
            f"(1) the random test's sampling_rate_hz{rate} off by a factor (no single factor brings every frequency "
            "within range, so this is less likely here)"
        )
    return (
        head
        + first
        + "; (2) the structure's description (structure: Young's modulus, the beam's dimensions and density, the "
        "block's, the force transducer's and the sensors' masses, the contact's lever arms); (3) the sensor positions' "
        "units (structure.sensors.positions_m, in m from the clamp)"
    )


def refuse_unreachable(
    params: StructureParameters,
    stiction,
    stiction_cfg,
    source: str,
    sampling_rate_hz: float | None = None,
    residue_abs=None,
) -> Reachability:
    """Raise ``io.RawDataError`` where the stiffness fit's dataset (stiction.nc's variables) holds frequencies the
    structure cannot have (``reachability``, with the config's bounds and stiffness scale prior as
    ``linear_chain.stiction_dataset`` fits them; ``unreachable_message``), or where the random test's FRF amplitudes
    (``residue_abs``, modal.nc's (sensor, mode) residues; None: not checked) lie beyond ``AMPLITUDE_FACTOR_LIMIT``
    of the fitted structure's (``amplitude_ratio``; ``amplitude_message``); otherwise return the Reachability."""
    reach = reachability(
        params,
        stiction["identified_frequency"].values,
        stiction["frequency_sigma"].values,
        float(stiction["k_t"]),
        float(stiction["k_n"]),
        float(stiction.attrs["chi2_min"]),
        tuple(stiction_cfg.get("k_t_bounds_n_per_m", (1e5, 1e9))),
        tuple(stiction_cfg.get("k_n_bounds_n_per_m", (1e5, 1e11))),
        float(stiction_cfg.get("stiffness_scale_sd", 0.0)),
    )
    if not reach.reachable:
        from .io import RawDataError

        raise RawDataError(
            unreachable_message(reach, stiction["identified_frequency"].values, source, sampling_rate_hz)
        )
    if residue_abs is not None:
        scale = float(stiction["stiffness_scale"]) if "stiffness_scale" in stiction else 1.0
        ratio = amplitude_ratio(params, residue_abs, float(stiction["k_t"]), float(stiction["k_n"]), scale)
        if ratio is not None and abs(np.log(ratio)) > np.log(AMPLITUDE_FACTOR_LIMIT):
            from .io import RawDataError

            raise RawDataError(amplitude_message(ratio, source))
    return reach


AMPLITUDE_FACTOR_LIMIT = 3.0
"""How far (a factor, either way) the random test's FRF amplitudes may lie from what the described structure gives
before the stiffness step refuses the record (``amplitude_ratio``): the modal residues |phi_i(x_s) phi_i(x_d)| /
(2 omega_i) of the fitted structure scale with the inverse of its masses, which a described structure knows within a
few per cent (the model updating's priors: 3 % on the beam's mass, 50 % on the transducers' few per cent of it), so
its residues and the measured ones agree within some per cent: 1.000-1.018 (median over sensors and modes) on the
five foreign record sets. The smallest common unit confusion, accelerations in g read as m/s^2 (or sensitivities per
g taken per m/s^2), makes 9.81, a kN force 1000; a factor 3 lies far from both."""


def amplitude_ratio(params: StructureParameters, residue_abs, k_t: float, k_n: float, stiffness_scale: float = 1.0):
    """The median over sensors and modes of the measured residues (``residue_abs`` (sensor, mode), modal.nc's) over
    those of the described structure at the fitted k_t, k_n and stiffness scale (``updating_model.modal_predictions``);
    None where the shapes do not match (another sensor layout)."""
    from .updating_model import modal_predictions

    measured = np.asarray(residue_abs, dtype=float)
    fitted = params.with_contact(float(k_t), float(k_n))
    fitted = fitted.replace(youngs_modulus=fitted.youngs_modulus * float(stiffness_scale))
    with np.errstate(divide="ignore", invalid="ignore"):
        model = modal_predictions(fitted, measured.shape[1])[1]
        if model.shape != measured.shape:
            return None
        ratio = measured / model
    ratio = ratio[np.isfinite(ratio) & (ratio > 0)]
    return float(np.median(ratio)) if ratio.size else None


def amplitude_message(ratio: float, source: str) -> str:
    """The stiffness step's refusal of a random test whose FRF amplitudes are ``ratio`` times the structure's."""
    from .units_factors import units_error

    causes = []
    hit = units_error(ratio, 0.15)
    if hit is not None:
        causes.append(f"{hit[1]}: a factor {hit[0]:.4g}")
    causes.append("wrong sensitivities of the acceleration or force channels (the same factor on every channel)")
    causes.append("the structure's masses (structure: density, dimensions, block, transducer and sensor masses)")
    return (
        f"random test {source}: its FRFs' amplitudes are {ratio:.3g} times what the described structure gives (the "
        "median over sensors and modes of the measured modal residues over the fitted structure's, whose natural "
        f"frequencies it reproduces), beyond a factor {AMPLITUDE_FACTOR_LIMIT:g} either way "
        "(contactid.stiction.AMPLITUDE_FACTOR_LIMIT; no error in a structure's described masses comes near it, and "
        "the model updating would take it for masses and contact stiffnesses that no rig has). "
        "results/linear/stiction.nc is not written. Likely causes, most likely first: "
        + "; ".join(f"({i + 1}) {c}" for i, c in enumerate(causes))
    )


def random_test_source(modal, block) -> tuple[str, float | None]:
    """(the random test's file as the user gave it in its config ``block``, and as the chain read it where that
    differs; its sampling rate in Hz or None), from the provenance modal.nc -> frf.nc keeps: for the refusal's
    message."""
    import os

    import xarray as xr

    from .io import ENGINE

    given = block.get("file") if block.get("source") == "measured" else None
    read, rate = None, None
    frf = modal.attrs.get("input_frf")
    if frf and os.path.exists(frf):
        with xr.open_dataset(frf, engine=ENGINE) as ds:
            read = ds.attrs.get("input_raw") or ds.attrs.get("input_file")
            rate = ds.attrs.get("sampling_rate_hz")
    name = given or read or "data/raw/random_test.nc"
    if read and given and os.path.normpath(read) != os.path.normpath(given):
        name += f" (read as {read})"
    return name, float(rate) if rate is not None else None
