"""The stiffness step's refusal of a random test the described structure cannot have come from.

Where the identified natural frequencies lie out of the structure's reach at every contact stiffness within the
search bounds (a sampling rate off by a factor, a structure described wrongly), or the random test's FRF amplitudes
lie far from the fitted structure's (a units error), the stiffness step refuses the record before linear_modes, the
contact forces, the model updating and the gap diagnosis build on it: the verdicts, their messages with the likely
causes in order, and the random test's file and sampling rate they name.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Mapping

import numpy as np

from .beam_modes import ContactFrequencyMap
from .parameters import StructureParameters
from .stiction import LN_SCALE_BOUNDS, quick_chi2

if TYPE_CHECKING:
    import xarray as xr


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

    Attributes
    ----------
    ranges_hz
        Each mode's lowest and highest frequency over the stiffness bounds (and the stiffness scale's where it is
        free) [Hz], shape (n_modes, 2).
    outside_sigmas
        How far each frequency lies beyond its range, in its standard uncertainties [-] (+ above, - below,
        0 within), shape (n_modes,).
    at_bound
        The stiffnesses whose best fit sits at a search bound, as text.
    chi2_min
        The stiffness fit's minimum chi^2 [-].
    dof
        The fit's degrees of freedom (the number of frequencies less 2, at least 1).
    factor_range
        Where refused: the factors c (low, high) [-] for which the lowest frequency divided by c lies within the
        first mode's range and every other within the structure's span; None: none does (or not refused).
    factor
        The simplest such factor [-] (``_SIMPLE_FACTORS`` or its reciprocal); None: none.
    chi2_factor
        The fit's misfit chi^2 at f / factor [-]; None where there is no factor.
    reasons
        Why the record is refused (empty: reachable).
    """

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
    params: StructureParameters | ContactFrequencyMap,
    n_modes: int,
    k_t_bounds: tuple[float, float],
    k_n_bounds: tuple[float, float],
    scale_bounds: tuple[float, float] = (1.0, 1.0),
) -> np.ndarray:
    """Return the range of each structural mode's frequency the structure can have between the stiffness bounds.

    Each mode's frequency with both contact springs at their lower bounds (and Young's modulus at
    ``scale_bounds[0]`` times the structure's) and at their upper bounds (``scale_bounds[1]``): the range the
    structure can have, every natural frequency rising with every stiffness (Rayleigh).

    Parameters
    ----------
    params
        The described structure, or its ``ContactFrequencyMap`` (then used as it is).
    n_modes
        Number of structural modes (where ``params`` is a structure).
    k_t_bounds
        Bounds of k_t (low, high) [N/m].
    k_n_bounds
        Bounds of k_n (low, high) [N/m].
    scale_bounds
        Bounds of Young's modulus over the structure's (low, high) [-].

    Returns
    -------
    ranges : np.ndarray
        Each mode's lowest and highest frequency [Hz], shape (n_modes, 2).
    """
    fmap = params if isinstance(params, ContactFrequencyMap) else ContactFrequencyMap(params, int(n_modes))
    lo = fmap(float(k_t_bounds[0]), float(k_n_bounds[0]), float(scale_bounds[0]))
    hi = fmap(float(k_t_bounds[1]), float(k_n_bounds[1]), float(scale_bounds[1]))
    return np.column_stack([np.minimum(lo, hi), np.maximum(lo, hi)])


def reachability(
    params: StructureParameters,
    f_id_hz: np.ndarray,
    sigma_hz: np.ndarray,
    k_t: float,
    k_n: float,
    chi2_min: float,
    k_t_bounds: tuple[float, float] = (1e5, 1e9),
    k_n_bounds: tuple[float, float] = (1e5, 1e11),
    stiffness_scale_sd: float = 0.0,
) -> Reachability:
    """Judge whether the described structure can have the identified frequencies at any stiffness within the bounds.

    Any contact stiffness within the bounds and, where the fit frees it, Young's modulus within ``LN_SCALE_BOUNDS``.
    Refused (``reasons``) where a frequency lies more than ``UNREACHABLE_SIGMAS`` sigma beyond the range the
    structure has between its bounds (``frequency_ranges``), or where the best fit (k_t, k_n, ``chi2_min``) sits at
    a search bound with a misfit per degree of freedom above ``UNREACHABLE_SIGMAS`` squared. Where refused, the
    factors that would bring the frequencies within the structure's ranges (a sampling rate off by a factor moves
    them all by it) and the simplest of them.

    Parameters
    ----------
    params
        The described structure.
    f_id_hz
        Identified natural frequencies [Hz], shape (n_modes,).
    sigma_hz
        Their standard uncertainties [Hz], shape (n_modes,) (``frequency_sigma``).
    k_t
        The fit's tangential contact stiffness [N/m].
    k_n
        The fit's normal contact stiffness [N/m].
    chi2_min
        The fit's minimum chi^2 [-].
    k_t_bounds
        Search bounds of k_t (low, high) [N/m].
    k_n_bounds
        Search bounds of k_n (low, high) [N/m].
    stiffness_scale_sd
        Standard deviation of the fit's prior on ln s [-]; > 0: Young's modulus free within ``LN_SCALE_BOUNDS``.

    Returns
    -------
    reach : Reachability
        The verdict, its reasons and, where refused, the factors.
    """
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
                chi2_factor = quick_chi2(fmap, f_id / factor, sigma / factor, lt, ln, s_sd)
    return Reachability(
        ranges, outside, tuple(at_bound), float(chi2_min), dof, factor_range, factor, chi2_factor, tuple(reasons)
    )


def _factor_text(c: float) -> str:
    return f"{c:g}" if c >= 1 else f"1/{1 / c:g}"


def unreachable_message(
    reach: Reachability, f_id_hz: np.ndarray, source: str, sampling_rate_hz: float | None = None
) -> str:
    """Return the stiffness step's refusal of a random test whose frequencies the structure cannot have.

    The message names the frequencies, the ranges the structure allows, why (``reachability``), and the likely causes
    in order.

    Parameters
    ----------
    reach
        The refusing ``reachability``.
    f_id_hz
        Identified natural frequencies [Hz], shape (n_modes,).
    source
        The random test's file, as the message names it.
    sampling_rate_hz
        The random test's sampling rate [Hz]; None: not known.

    Returns
    -------
    message : str
        The refusal.
    """
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
    stiction: xr.Dataset,
    stiction_cfg: Mapping,
    source: str,
    sampling_rate_hz: float | None = None,
    residue_abs: np.ndarray | None = None,
) -> Reachability:
    """Refuse a random test whose frequencies or FRF amplitudes the described structure cannot have.

    Refused where the stiffness fit's dataset holds frequencies the structure cannot have (``reachability``, with the
    config's bounds and stiffness scale prior as ``linear_chain.stiction_dataset`` fits them;
    ``unreachable_message``), or where the random test's FRF amplitudes lie beyond ``AMPLITUDE_FACTOR_LIMIT`` of the
    fitted structure's (``amplitude_ratio``; ``amplitude_message``).

    Parameters
    ----------
    params
        The described structure.
    stiction
        The stiffness fit's dataset (stiction.nc's variables): reads ``identified_frequency`` and
        ``frequency_sigma`` [Hz], ``k_t``, ``k_n`` [N/m], ``stiffness_scale`` and the attribute ``chi2_min``.
    stiction_cfg
        The config's ``stiction`` block: reads ``k_t_bounds_n_per_m``, ``k_n_bounds_n_per_m`` [N/m] and
        ``stiffness_scale_sd``.
    source
        The random test's file, as the messages name it.
    sampling_rate_hz
        The random test's sampling rate [Hz]; None: not known.
    residue_abs
        modal.nc's residue magnitudes, accelerance (m/s^2/N) over rad/s [m/(N*s)], shape (n_sensors, n_modes);
        None: the amplitudes are not checked.

    Returns
    -------
    reach : Reachability
        The frequencies' ``reachability`` (reachable).

    Raises
    ------
    RawDataError
        When the frequencies are out of the structure's reach, or the amplitudes beyond ``AMPLITUDE_FACTOR_LIMIT``.
    """
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


def amplitude_ratio(
    params: StructureParameters, residue_abs: np.ndarray, k_t: float, k_n: float, stiffness_scale: float = 1.0
) -> float | None:
    """Return the measured residues over those of the described structure: the median over sensors and modes.

    The structure's at the fitted k_t, k_n and stiffness scale (``updating_model.modal_predictions``).

    Parameters
    ----------
    params
        The described structure.
    residue_abs
        modal.nc's residue magnitudes, accelerance (m/s^2/N) over rad/s [m/(N*s)], shape (n_sensors, n_modes).
    k_t
        The fitted tangential contact stiffness [N/m].
    k_n
        The fitted normal contact stiffness [N/m].
    stiffness_scale
        The fitted Young's modulus over the structure's [-].

    Returns
    -------
    ratio : float | None
        The median ratio [-] over the finite, positive ones; None where the shapes do not match (another sensor
        layout) or no ratio is finite and positive.
    """
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
    """Return the stiffness step's refusal of a random test whose FRF amplitudes are off the structure's.

    Parameters
    ----------
    ratio
        The amplitudes over the structure's (``amplitude_ratio``) [-].
    source
        The random test's file, as the message names it.

    Returns
    -------
    message : str
        The refusal, with the likely causes in order (a units error ``units_factors`` names first, where one fits).
    """
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
        "(contactid.stiction_refusal.AMPLITUDE_FACTOR_LIMIT; no error in a structure's described masses comes near "
        "it, and the model updating would take it for masses and contact stiffnesses that no rig has). "
        "results/linear/stiction.nc is not written. Likely causes, most likely first: "
        + "; ".join(f"({i + 1}) {c}" for i, c in enumerate(causes))
    )


def random_test_source(modal: xr.Dataset, block: Mapping) -> tuple[str, float | None]:
    """Return the random test's file and sampling rate, for the refusal's message.

    From the provenance modal.nc -> frf.nc keeps.

    Parameters
    ----------
    modal
        The modal dataset: reads its attribute ``input_frf`` (the FRF file, opened where it exists for its
        ``input_raw`` or ``input_file`` and ``sampling_rate_hz``).
    block
        The config's ``random_test`` block: reads ``source`` and ``file``.

    Returns
    -------
    name : str
        The file as the user gave it in the config (and as the chain read it, where that differs), else as the
        chain read it, else data/raw/random_test.nc.
    sampling_rate_hz : float | None
        Its sampling rate [Hz]; None where the FRF file does not tell.
    """
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
