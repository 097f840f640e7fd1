"""The gap diagnosis's settings (config ``gap``), read once from the config.

What is compared, the candidates, the thresholds of every decision, the bootstrap, model updating's priors and the
numerical choices (``numerics.Numerics``), read once from the config (``GapSettings.from_config``, the schema's defaults
where keys are left out).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

from .candidates import LIBRARY
from .numerics import DEFAULT, Numerics
from .place import DEFAULT_PLACE, PlaceThresholds


@dataclass(frozen=True)
class GapSettings:
    """Settings of the gap diagnosis (config ``gap``).

    Attributes
    ----------
    n_harmonics
        Harmonics of the test frequency compared between the model's simulation and the records (the gap).
    identification_harmonics
        K, the harmonics of the inverse identification (``nonlinear.n_harmonics``).
    candidates
        The candidates' names (None: the whole library).
    min_gap
        A held-out gap below this (relative) is what the chain's own identification leaves and is not explained [-].
    min_reduction
        The held-out gap must shrink at least this much (relative) for a verdict [-].
    separation
        The winner's held-out gap must be at least this factor below the runner-up's [-].
    noise_factor
        The gap before must exceed this many bootstrap standard deviations of the records' scatter [-].
    n_bootstrap
        Resamples of the record blocks.
    seed
        Seed of the run (the bootstrap's random stream, "gap/bootstrap").
    max_evaluations
        The calibration refit's budget of simulations (config ``gap.max_evaluations``; how each search uses it:
        ``calibration.calibrate``).
    model_updating
        Update the base structure from the random test before the candidates (``contactid.updating``).
    eta_observability_limit
        The normal motion eta counts as observable when it moves by at most this (relative) over the structures the
        random test allows (``eta_model_spread``), else the place cannot be the normal or the tangential contact
        alone [-].
    updating_parameters
        The structural factors model updating fits (``contactid.updating_model.FACTORS``' names).
    residue_accuracy
        The residues' relative standard error [-].
    frequency_floor
        The relative model-form uncertainty added to each frequency's standard error [-].
    updating_confidence
        The significance an update needs to be accepted [-].
    updating_prior_sd
        ((factor, prior sd of its ln), ...) replacing ``contactid.updating_model.FACTORS``' priors (ln of a factor:
        [-]).
    updating_records_test
        An update the chi^2 test did not accept is accepted when the dual-sine records' held-out gap shrinks with it
        (``verdict.records_accept_update``).
    updating_gain_sd
        Prior sd of ln of each channel's sensitivity on the residues (0: the channels calibrated) [-].
    joint_refit
        The explanation's later steps refit the earlier steps' parameters with theirs.
    numerics
        How the steady states are found and the candidates' searches run (``numerics.Numerics``; the config sets its
        polish_searches, gap.polish_searches, and leaves the rest at their defaults).
    pair_lookahead
        Where no candidate shrinks a gap above this many ``min_gap`` materially, a pair is tried [-].
    retry_unmoved
        Later passes also try the candidates whose refit alone left them off.
    place
        The localisation's thresholds (gap.place).
    """

    n_harmonics: int = 9
    identification_harmonics: int = 25
    candidates: tuple | None = None
    min_gap: float = 0.006
    min_reduction: float = 0.5
    separation: float = 1.5
    noise_factor: float = 3.0
    n_bootstrap: int = 200
    seed: int = 0
    max_evaluations: int = 10
    model_updating: bool = True
    eta_observability_limit: float = 0.1
    updating_parameters: tuple = (
        "stiffness_scale",
        "mass_scale",
        "transducer_mass_scale",
        "force_transducer_mass_scale",
        "tangential_lever_arm_scale",
        "clamp_compliance_scale",
    )
    residue_accuracy: float = 0.01
    frequency_floor: float = 0.001
    updating_confidence: float = 0.95
    updating_prior_sd: tuple = ()  # ((factor, sd of its ln), ...) replacing contactid.updating_model.FACTORS' priors
    updating_records_test: bool = True  # the records may accept an update the random test's chi^2 did not
    updating_gain_sd: float = 0.03  # prior sd of ln of each channel's sensitivity on the residues (0: calibrated)
    joint_refit: bool = True  # the explanation's later steps refit the earlier steps' parameters with theirs
    # how the steady states are found and the searches run (numerics.Numerics; polish_searches from gap.polish_searches)
    numerics: Numerics = DEFAULT
    pair_lookahead: float = 3.0  # where no candidate shrinks a gap above this many min_gap materially, try a pair
    retry_unmoved: bool = False  # later passes also try the candidates whose refit alone left them off
    place: PlaceThresholds = DEFAULT_PLACE  # the localisation's thresholds (gap.place)

    @classmethod
    def from_config(cls, gap_cfg: Mapping | None, seed: int, n_harmonics_id: int) -> "GapSettings":
        """Return the settings from config ``gap``, the run's seed and the identification's number of harmonics.

        Keys left out take the schema's defaults.

        Parameters
        ----------
        gap_cfg
            The config's ``gap`` section (None: every key at its default): n_harmonics, candidates, min_gap,
            min_reduction, separation, noise_factor, n_bootstrap, max_evaluations, eta_observability_limit,
            joint_refit, polish_searches, pair_lookahead, retry_unmoved, place and model_updating (enabled,
            parameters, residue_accuracy, confidence, frequency_floor, channel_gain_sd, prior_sd, records_test).
        seed
            The run's seed (config ``seed``).
        n_harmonics_id
            The number of harmonics the identification used (``nonlinear.n_harmonics``).

        Returns
        -------
        settings : GapSettings
            The settings.

        Raises
        ------
        ValueError
            For a candidate the library does not have, a min_reduction outside (0, 1), a separation below 1, or
            n_harmonics outside 3 .. ``n_harmonics_id`` (and, through the model_updating block, for an unknown
            factor or a prior sd out of range).
        """
        from ..schema import schema_defaults

        defaults = schema_defaults("gap")  # keys left out take the schema's defaults
        g = {**defaults, **dict(gap_cfg or {})}
        cands = g.get("candidates")
        if cands is not None:
            unknown = [c for c in cands if c not in LIBRARY]
            if unknown:
                raise ValueError(f"gap.candidates: unknown {unknown}; the library has {', '.join(LIBRARY)}")
        s = cls(
            n_harmonics=int(g["n_harmonics"]),
            identification_harmonics=int(n_harmonics_id),
            candidates=tuple(cands) if cands is not None else None,
            min_gap=float(g["min_gap"]),
            min_reduction=float(g["min_reduction"]),
            separation=float(g["separation"]),
            noise_factor=float(g["noise_factor"]),
            n_bootstrap=int(g["n_bootstrap"]),
            seed=int(seed),
            max_evaluations=int(g["max_evaluations"]),
            eta_observability_limit=float(g["eta_observability_limit"]),
            joint_refit=bool(g["joint_refit"]),
            numerics=Numerics(polish_searches=bool(g["polish_searches"])),
            pair_lookahead=float(g["pair_lookahead"]),
            retry_unmoved=bool(g["retry_unmoved"]),
            place=PlaceThresholds.from_config(g.get("place")),
            **_updating_settings({**defaults["model_updating"], **(g.get("model_updating") or {})}),
        )
        if not 0.0 < s.min_reduction < 1.0:
            raise ValueError(f"gap.min_reduction = {s.min_reduction}: give a fraction in (0, 1)")
        if s.separation < 1.0:
            raise ValueError(f"gap.separation = {s.separation}: give a factor >= 1")
        if s.n_harmonics < 3 or s.n_harmonics > s.identification_harmonics:
            raise ValueError(
                f"gap.n_harmonics = {s.n_harmonics}: give 3 .. nonlinear.n_harmonics ({s.identification_harmonics})"
            )
        return s


def _updating_settings(b: Mapping) -> dict:
    """Return the GapSettings fields of the config block gap.model_updating (its defaults filled in)."""
    from ..updating_model import FACTORS

    params = tuple(b["parameters"])
    unknown = [x for x in params if x not in FACTORS]
    if unknown:
        raise ValueError(f"gap.model_updating.parameters: unknown {unknown}; choose from {', '.join(FACTORS)}")
    return {
        "model_updating": bool(b["enabled"]),
        "updating_parameters": params,
        "residue_accuracy": float(b["residue_accuracy"]),
        "updating_confidence": float(b["confidence"]),
        "frequency_floor": float(b["frequency_floor"]),
        "updating_gain_sd": float(b["channel_gain_sd"]),
        "updating_prior_sd": _prior_sd(b.get("prior_sd"), FACTORS),
        "updating_records_test": bool(b.get("records_test", True)),
    }


def _prior_sd(block, factors) -> tuple:
    """Return ((factor, prior sd of its ln), ...) of gap.model_updating.prior_sd, checked."""
    out = []
    for name, v in dict(block or {}).items():
        if name not in factors:
            raise ValueError(f"gap.model_updating.prior_sd: unknown factor {name!r}; choose from {', '.join(factors)}")
        top = factors[name].max_prior_sd
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not 0.0 < float(v) <= top:
            raise ValueError(
                f"gap.model_updating.prior_sd.{name} = {v!r}: give the relative spread of the factor "
                f"(sd of its ln) as a number in (0, {top:g}], for example 0.02 for a value known to 2 %"
            )
        out.append((str(name), float(v)))
    return tuple(sorted(out))
