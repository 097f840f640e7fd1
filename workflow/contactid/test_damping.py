"""The structure's damping at test level.

The random test's damping ratios scaled by the factor the calibration record binds, the driven mode's alone or every
mode's.

The inverse identification subtracts the structure's damping from the measured response; what is left is the contact
force S. The damping ratios come from the random test, at 0.02-0.5 N rms with the contact stuck, through a windowed FRF
estimate; the dual-sine tests run at other amplitudes, with the contact slipping. Where the structure's damping at test
level differs from the random test's, the identified S carries a viscous term c dxi/dt that the friction law (Eqs.
21-22) cannot represent: the law's misfit grows, and its kappa and mu move to absorb what they can. So the law's misfit
on the calibration record, profiled over one factor, binds it: the law fitted (GA, as rule friction_fit fits it) at each
factor of ``nonlinear.test_damping_scales`` (and 1), the minimum refined by a parabola in log(factor), the interval
where the misfit stays within the friction fit's own profile-likelihood threshold (``friction_fit.profile_intervals``'s,
at ``FitSettings.confidence``). Two forms (``FORMS``) are profiled: the factor on the ratio of the mode the test drives
near resonance alone (where the random test's estimate of that lightly damped mode is off, the others right), and on
every mode's ratio (a damping that changes with level everywhere; the drive's harmonics sit near the higher modes, the
third near the second mode); the held-out load cases choose between them (``gap.damping.chosen_test_damping``).

A factor away from 1 is a change of the base model suggested by one record, and a stand-in for anything else the law
cannot represent takes the same road (a viscous friction at the contact, a clamp, transducer masses: on such rigs the
least misfit wanders and the law with it). So the identification chain keeps the random test's ratios, and the factor
is weighed twice. First by the load cases it was not fitted on, as an update of the structure is
(``contactid.gap.damping.confirmed_test_damping``, the records' test of ``contactid.gap.evidence.
records_test_of_update``): the model at the factor, its law refitted, leaves a held-out gap smaller than the model at
the random test's ratios by min_reduction of it and by more than noise_factor x the records' scatter. Then by the gap
diagnosis, whose candidates compete for the same gap: only where it explains no effect (a viscous friction at the
contact is confirmed by the held-out records as readily as a damping factor, and the diagnosis tells them apart) does
the model it arrives at (results/gap/updated_model.json, ``contactid.gap.explain.with_damping_at_test_level``) carry
the factor and the law fitted with it.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import TYPE_CHECKING, Iterable, Sequence

import numpy as np
import xarray as xr

from .friction_fit import FitSettings, fit_friction_law
from .friction_parameters import PARAMETER_NAMES, PARAMETER_UNITS
from .identification import inverse_harmonics
from .modal_damping import modal_damping_vector

if TYPE_CHECKING:
    from .beam_model import FEModel

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class DampingProfile:
    """The law's misfit profiled over the damping factor, and the friction law fitted at each factor.

    The factor scales the damping ratio of identified mode ``mode`` (form "driven") or of every mode (form "all").

    Attributes
    ----------
    scales
        The factors profiled [-], shape (n_scales,), ascending (1, ``nonlinear.test_damping_scales`` and the
        parabola's refined least).
    misfits
        The law's misfit at each factor, the relative rms of S (``FitResult.misfit``) [-], shape (n_scales,).
    laws
        The friction law fitted at each factor, shape (n_scales, 5), its columns e_f [N/m], k_c [1/m], e_t [N/m],
        kappa [-] and mu [-].
    scale
        The factor where the misfit is least [-].
    interval
        (low, high): the factors whose misfit stays within the threshold around ``scale`` [-].
    bounded
        (low, high): whether each side of the interval is bound inside the profiled grid (a side at the grid's end:
        not bound there, false).
    threshold
        The threshold misfit [-].
    mode
        The driven mode's index among the identified modes (from 0).
    form
        "driven": the driven mode's ratio scaled; "all": every identified mode's (``FORMS``).
    check
        The held-out records' test (``records_test_of_update``'s result), None: not taken.
    law_intervals
        Profile-likelihood intervals of the law at ``scale`` (``with_intervals``), shape (5, 2) (low, high) per
        parameter, each in its unit: e_f [N/m], k_c [1/m], e_t [N/m], kappa [-], mu [-]; None: not computed.
    e0_interval
        (low, high) of e_0 at the preload for the law at ``scale`` [N/m]; None: not computed.
    """

    scales: np.ndarray
    misfits: np.ndarray
    laws: np.ndarray
    scale: float
    interval: tuple
    bounded: tuple
    threshold: float
    mode: int = 0
    form: str = "driven"  # "driven": the driven mode's ratio scaled; "all": every identified mode's (FORMS)
    check: dict | None = None  # the held-out records' test (records_test_of_update's result), None: not taken
    law_intervals: np.ndarray | None = (
        None  # (5, 2) profile-likelihood intervals of the law at ``scale`` (with_intervals)
    )
    e0_interval: tuple | None = None

    @property
    def accepted(self) -> bool:
        """Whether the factor is applied: the held-out records confirmed it (``check``'s ``accepted``).

        Returns
        -------
        accepted : bool
            Whether the held-out records' test accepted the factor.
        """
        return bool(self.check is not None and self.check.get("accepted"))

    @property
    def applied_scale(self) -> float:
        """The factor applied: ``scale`` where the held-out records confirmed it, else 1 (the random test's ratio).

        Returns
        -------
        applied_scale : float
            The factor applied [-].
        """
        return self.scale if self.accepted else 1.0

    def scaled_ratios(self, damping_ratios: Sequence[float] | np.ndarray, scale: float | None = None) -> np.ndarray:
        """Return ``damping_ratios`` with the ``form``'s modes (mode ``mode``, or all) times ``scale``.

        Parameters
        ----------
        damping_ratios
            The identified modes' damping ratios [-], shape (n_modes,).
        scale
            The factor [-]; None: the least-misfit factor ``scale``.

        Returns
        -------
        ratios : np.ndarray
            The scaled damping ratios [-], shape (n_modes,).
        """
        return scaled(damping_ratios, self.scale if scale is None else scale, self.mode, self.form)

    def ratios(self, damping_ratios: Sequence[float] | np.ndarray) -> np.ndarray:
        """Return the identified modes' damping ratios at test level.

        That is ``damping_ratios`` with the ``form``'s modes (mode ``mode``, or all) times ``applied_scale``.

        Parameters
        ----------
        damping_ratios
            The identified modes' damping ratios from the random test [-], shape (n_modes,).

        Returns
        -------
        ratios : np.ndarray
            The damping ratios at test level [-], shape (n_modes,).
        """
        return self.scaled_ratios(damping_ratios, self.applied_scale)

    def law_at(self, scale: float) -> np.ndarray:
        """Return the friction law fitted at the profiled factor nearest ``scale`` (nearest in log(factor)).

        Parameters
        ----------
        scale
            The factor [-], positive.

        Returns
        -------
        law : np.ndarray
            (e_f [N/m], k_c [1/m], e_t [N/m], kappa [-], mu [-]), shape (5,).
        """
        return self.laws[int(np.argmin(np.abs(np.log(self.scales / scale))))]

    def law_at_scale(self) -> np.ndarray:
        """Return the friction law fitted at the least-misfit factor ``scale``.

        Returns
        -------
        law : np.ndarray
            (e_f [N/m], k_c [1/m], e_t [N/m], kappa [-], mu [-]), shape (5,).
        """
        return self.law_at(self.scale)


def unprofiled() -> DampingProfile:
    """Return the profile of a configuration that profiles nothing (``nonlinear.test_damping_scales`` [1.0]).

    It keeps the random test's ratios: the factor 1, no misfit and no law.

    Returns
    -------
    profile : DampingProfile
        The profile at the factor 1 alone (misfit and law NaN).
    """
    return DampingProfile(
        np.ones(1), np.full(1, np.nan), np.full((1, 5), np.nan), 1.0, (1.0, 1.0), (False, False), np.nan
    )


def _threshold(misfit_min: float, n_data: int, settings: FitSettings) -> float:
    """Return the misfit a factor may reach and stay inside the interval.

    The friction fit's profile threshold (``profile_intervals``) in misfit terms, n_data = 2K Fourier coefficients,
    five law parameters and the factor.
    """
    from scipy.stats import chi2

    sigma2 = max(misfit_min**2 * n_data / max(n_data - 6, 1), settings.misfit_floor**2)
    return float(np.sqrt(misfit_min**2 + chi2.ppf(settings.confidence, 1) * sigma2 / n_data))


FORMS = ("driven", "all")


def scaled(damping_ratios: Sequence[float] | np.ndarray, scale: float, mode: int, form: str) -> np.ndarray:
    """Return ``damping_ratios`` with mode ``mode``'s times ``scale`` (``form`` "driven") or every mode's ("all").

    Parameters
    ----------
    damping_ratios
        The identified modes' damping ratios [-], shape (n_modes,).
    scale
        The factor [-].
    mode
        The driven mode's index (from 0).
    form
        "driven" or "all" (``FORMS``).

    Returns
    -------
    ratios : np.ndarray
        The scaled damping ratios [-], shape (n_modes,), a new array.

    Raises
    ------
    ValueError
        When ``form`` is not one of ``FORMS``.
    """
    if form not in FORMS:
        raise ValueError(f"damping at test level: form {form!r}; give one of {FORMS}")
    out = np.array(damping_ratios, dtype=float)
    if form == "all":
        return out * scale
    out[mode] *= scale
    return out


def ratio_words(form: str, driven_mode: int) -> str:
    """Return the damping ratios a factor of ``form`` scales, in words.

    Parameters
    ----------
    form
        "driven" or "all".
    driven_mode
        The driven mode's number (from 1).

    Returns
    -------
    words : str
        "mode 1's damping ratio" (form "driven") or "every mode's damping ratio".
    """
    return f"mode {driven_mode}'s damping ratio" if form == "driven" else "every mode's damping ratio"


def driven_mode(frequencies_hz: Sequence[float] | np.ndarray, f0: float) -> int:
    """Return the identified mode nearest the drive: the one the dual-sine test drives near resonance.

    Parameters
    ----------
    frequencies_hz
        The identified modes' natural frequencies [Hz], shape (n_modes,).
    f0
        The drive's frequency [Hz].

    Returns
    -------
    mode : int
        The mode's index (from 0).
    """
    return int(np.argmin(np.abs(np.asarray(frequencies_hz, dtype=float) - f0)))


def damping_profile(
    model: FEModel,
    damping_ratios: Sequence[float] | np.ndarray,
    frequencies_hz: Sequence[float] | np.ndarray,
    F_coef: np.ndarray,
    A_coef: np.ndarray,
    f0: float,
    preload: float,
    settings: FitSettings,
    seed: int,
    scales: Iterable[float],
    form: str = "driven",
) -> DampingProfile:
    """Profile the law's misfit over the damping factor on the calibration record's harmonics.

    The law is fitted at each factor (and at 1) from the same ``seed``; the least is refined by a parabola in
    log(factor) through it and its neighbours, and the interval is where the misfit stays within the friction fit's
    profile threshold.

    Parameters
    ----------
    model
        The FE model of the identified linear model.
    damping_ratios
        The random test's damping ratios of the identified modes [-], shape (n_modes,).
    frequencies_hz
        The identified modes' natural frequencies [Hz], shape (n_modes,).
    F_coef
        The calibration record's force harmonics 1..K [N], complex, shape (K,).
    A_coef
        Its acceleration harmonics [m/s^2], complex, shape (n_sensors, K).
    f0
        The drive's frequency [Hz].
    preload
        The static normal preload [N].
    settings
        The friction fit's settings.
    seed
        The GA's random seed.
    scales
        The factors to profile [-] (1 is added).
    form
        "driven" (the driven mode's ratio) or "all" (every mode's).

    Returns
    -------
    profile : DampingProfile
        The profile, its least-misfit factor, interval and threshold, and the law at each factor.
    """
    K = A_coef.shape[1]
    ratios = np.asarray(damping_ratios, dtype=float)
    mode = driven_mode(frequencies_hz, f0)

    def at(s: float):
        r = scaled(ratios, s, mode, form)
        h = inverse_harmonics(model, modal_damping_vector(model, r), F_coef, A_coef, f0)
        fit = fit_friction_law(
            h.xi, h.N_dyn, h.S, f0, preload, settings, seed, K, intervals=False, label=f"damping x{s:.3g}"
        )
        return float(fit.misfit), np.asarray(fit.params, dtype=float)

    pts = {float(s): at(float(s)) for s in sorted({1.0, *(float(s) for s in scales)})}  # 1: the random test's
    grid = np.array(sorted(pts))
    i = int(np.argmin([pts[s][0] for s in grid]))
    if 0 < i < grid.size - 1:  # a parabola in log(factor) through the least and its neighbours
        x = np.log(grid[i - 1 : i + 2])
        y = np.array([pts[s][0] for s in grid[i - 1 : i + 2]])
        a, b, _ = np.polyfit(x, y, 2)
        if a > 0:
            s_ref = float(np.exp(np.clip(-b / (2 * a), x[0], x[2])))
            if all(abs(np.log(s_ref / g)) > 1e-3 for g in grid):
                pts[s_ref] = at(s_ref)
    scales_all = np.array(sorted(pts))
    misfits = np.array([pts[s][0] for s in scales_all])
    laws = np.array([pts[s][1] for s in scales_all])
    j = int(np.argmin(misfits))
    thr = _threshold(float(misfits[j]), 2 * K, settings)
    inside = misfits <= thr
    lo = j
    while lo > 0 and inside[lo - 1]:
        lo -= 1
    hi = j
    while hi < scales_all.size - 1 and inside[hi + 1]:
        hi += 1
    profile = DampingProfile(
        scales_all,
        misfits,
        laws,
        float(scales_all[j]),
        (float(scales_all[lo]), float(scales_all[hi])),
        (lo > 0, hi < scales_all.size - 1),
        thr,
        mode,
        form,
    )
    log.info(
        "damping at test level, profiled: the law's misfit is least (%.4g) with %s x %.3g, within "
        "the threshold %.4g over [%.3g, %.3g]%s",
        misfits[j],
        ratio_words(form, mode + 1),
        profile.scale,
        thr,
        *profile.interval,
        "" if all(profile.bounded) else " (not bound at the profiled range's end)",
    )
    return profile


def with_intervals(
    profile: DampingProfile,
    model: FEModel,
    damping_ratios: Sequence[float] | np.ndarray,
    F_coef: np.ndarray,
    A_coef: np.ndarray,
    f0: float,
    preload: float,
    settings: FitSettings,
    seed: int,
) -> DampingProfile:
    """Return ``profile`` with the profile-likelihood intervals of the law fitted at its factor.

    As rule friction_fit gives them: the fit polished from the law ``damping_profile`` found there (no second GA),
    then profiled.

    Parameters
    ----------
    profile
        The profile (``damping_profile``).
    model
        The FE model of the identified linear model.
    damping_ratios
        The random test's damping ratios of the identified modes [-], shape (n_modes,).
    F_coef
        The calibration record's force harmonics 1..K [N], complex, shape (K,).
    A_coef
        Its acceleration harmonics [m/s^2], complex, shape (n_sensors, K).
    f0
        The drive's frequency [Hz].
    preload
        The static normal preload [N].
    settings
        The friction fit's settings.
    seed
        The random seed.

    Returns
    -------
    profile : DampingProfile
        ``profile`` with ``law_intervals`` and ``e0_interval``.
    """
    import dataclasses

    r = profile.scaled_ratios(damping_ratios)
    h = inverse_harmonics(model, modal_damping_vector(model, r), F_coef, A_coef, f0)
    fit = fit_friction_law(
        h.xi,
        h.N_dyn,
        h.S,
        f0,
        preload,
        settings,
        seed,
        A_coef.shape[1],
        label=f"damping x{profile.scale:.3g}",
        start=profile.law_at_scale(),
    )
    return dataclasses.replace(
        profile, law_intervals=np.asarray(fit.intervals, dtype=float), e0_interval=tuple(map(float, fit.e0_interval))
    )


def profile_dataset(profile: DampingProfile, damping_ratios: Sequence[float] | np.ndarray) -> xr.Dataset:
    """Build the dataset of results/friction/test_damping.nc.

    It holds the least-misfit factor, its interval, the profile, the held-out records' test (attributes
    ``heldout_gap_*``, ``record_scatter``, ``accepted``, ``reason``), the factor applied and the ratios at test level.

    Parameters
    ----------
    profile
        The profile, with the held-out records' test where taken.
    damping_ratios
        The random test's damping ratios of the identified modes [-], shape (n_modes,).

    Returns
    -------
    ds : xr.Dataset
        The dataset (every variable with ``units`` and ``long_name``).
    """
    check = profile.check or {}
    attrs = {
        "misfit_threshold": profile.threshold,
        "driven_mode": profile.mode + 1,
        "form": profile.form,
        "accepted": int(profile.accepted),
    }
    for key in ("heldout_gap_chain", "heldout_gap_updated", "record_scatter"):
        if key in check:
            attrs[key.replace("chain", "random_test_damping").replace("updated", "test_damping")] = float(check[key])
    attrs["reason"] = check_reason(profile)
    return xr.Dataset(
        {
            "damping_scale": (
                (),
                profile.scale,
                {
                    "units": "1",
                    "long_name": "factor on the driven mode's random-test damping ratio where the law misfits least",
                },
            ),
            "damping_scale_applied": (
                (),
                profile.applied_scale,
                {"units": "1", "long_name": "the factor applied: damping_scale where the held-out records confirm it"},
            ),
            "damping_scale_interval": (
                "end",
                np.array(profile.interval),
                {"units": "1", "long_name": "factors whose law misfit is within the profile threshold"},
            ),
            "damping_scale_bounded": (
                "end",
                np.array(profile.bounded, dtype=np.int8),
                {"units": "1", "long_name": "1: the interval's end is bound by the records; 0: the profiled range's"},
            ),
            "profile_misfit": (
                "scale",
                profile.misfits,
                {"units": "1", "long_name": "friction law's relative rms misfit of S"},
            ),
            **{
                f"profile_{name}": (
                    "scale",
                    profile.laws[:, i],
                    {"units": unit, "long_name": f"the friction law's {name} fitted at each factor"},
                )
                for i, (name, unit) in enumerate(zip(PARAMETER_NAMES, PARAMETER_UNITS))
            },
            **(
                {}
                if profile.law_intervals is None
                else {
                    **{
                        f"law_interval_{name}": (
                            "end",
                            profile.law_intervals[i],
                            {"units": unit, "long_name": f"profile-likelihood interval of {name} at damping_scale"},
                        )
                        for i, (name, unit) in enumerate(zip(PARAMETER_NAMES, PARAMETER_UNITS))
                    },
                    "e0_interval": (
                        "end",
                        np.array(profile.e0_interval),
                        {"units": "N m-1", "long_name": "interval of e_0 at the preload, the law at damping_scale"},
                    ),
                }
            ),
            "damping_ratio_test": (
                "mode",
                profile.ratios(damping_ratios),
                {"units": "1", "long_name": "identified modes' damping ratios at test level"},
            ),
        },
        coords={
            "scale": ("scale", profile.scales, {"units": "1", "long_name": "damping factor profiled"}),
            "end": ["low", "high"],
        },
        attrs=attrs,
    )


def check_reason(profile: DampingProfile) -> str:
    """Return one sentence on why the factor is applied or not (from the held-out records' test).

    Parameters
    ----------
    profile
        The profile, with the held-out records' test where taken (``heldout_gap_chain``, ``heldout_gap_updated`` and
        ``record_scatter`` are read).

    Returns
    -------
    reason : str
        The sentence.
    """
    check = profile.check
    if abs(profile.scale - 1.0) < 1e-9:
        return "the law misfits least at the random test's ratio"
    if check is None:
        return "no load case besides the calibration case to confirm the factor: the random test's ratios kept"
    gaps = (
        f"held-out gap {100 * check['heldout_gap_chain']:.3g} % at the random test's ratio, "
        f"{100 * check['heldout_gap_updated']:.3g} % at x{profile.scale:.3g} (records' scatter "
        f"{100 * check['record_scatter']:.2g} %)"
    )
    if profile.accepted:
        return f"confirmed by the held-out load cases: {gaps}"
    return f"not confirmed by the held-out load cases ({gaps}): the random test's ratios kept"


def damping_summary(ds: xr.Dataset) -> dict:
    """Return summary.json's ``friction.test_damping`` from a test_damping.nc.

    Parameters
    ----------
    ds
        The dataset of test_damping.nc (``profile_dataset``).

    Returns
    -------
    summary : dict
        The form, the driven mode, the least-misfit factor and its interval, the factor applied, whether accepted,
        the reason, the held-out records' gaps, and where stored the law at the factor and its intervals.
    """
    out = {
        "form": str(ds.attrs.get("form", "driven")),
        "driven_mode": int(ds.attrs["driven_mode"]),
        "scale": float(ds["damping_scale"]),
        "interval": [float(v) for v in ds["damping_scale_interval"].values],
        "applied_scale": float(ds["damping_scale_applied"]),
        "accepted": bool(ds.attrs["accepted"]),
        "reason": str(ds.attrs["reason"]),
    }
    for key in ("heldout_gap_random_test_damping", "heldout_gap_test_damping", "record_scatter"):
        if key in ds.attrs:
            out[key] = float(ds.attrs[key])
    if f"profile_{PARAMETER_NAMES[0]}" in ds:  # the law fitted at the least-misfit factor
        i = int(np.argmin(np.abs(np.log(ds["scale"].values / out["scale"]))))
        out["law"] = {n: float(ds[f"profile_{n}"].values[i]) for n in PARAMETER_NAMES}
    if f"law_interval_{PARAMETER_NAMES[0]}" in ds:
        out["law_intervals"] = {n: [float(v) for v in ds[f"law_interval_{n}"].values] for n in PARAMETER_NAMES}
        out["e0_interval"] = [float(v) for v in ds["e0_interval"].values]
    return out
