"""Where the gap lies and where an effect acts, as pure functions of plain numbers, testable without the rig.

The place's thresholds (``PlaceThresholds``, config ``gap.place``) and the place itself (``place``): the records drift,
the structure and sensor model misfits them, or the normal or the tangential contact is where the gap lies. Beside it,
whether a candidate acts there (``acts_where``), the share of the cycle the contact is open (``open_fraction``) and a
contact-separation step that never opened it (``never_opens``).

``localise.localise`` computes the numbers (drift, stage gaps, sensor misfits) and calls ``place``; whether a step
explains the held-out gap is decided in ``verdict``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from .verdict import percent


@dataclass(frozen=True)
class PlaceThresholds:
    """Thresholds of the place where the gap lies (config ``gap.place``).

    Measured on rig data with each effect (docs/gap.md); the schema holds the same defaults, which tests/test_config.py
    checks. A record whose response is more than ``aperiodic_limit`` not periodic at the drive
    (``harmonics.aperiodic_share``, the worst accelerometer) does not settle: the localisation reports it
    (``where.periodicity``), the place does not use it.

    Attributes
    ----------
    drift_z
        The records drift when their trend exceeds this many standard errors [-].
    residual_factor
        The structure and sensor model disagrees with the records when the inverse identification's sensor misfit
        exceeds this many times its scatter [-].
    normal_limit
        The normal contact is not elastic when the best elastic normal law leaves more than this share of N [-].
    open_limit
        The contact is open where the identified N is at or below this fraction of the preload N0 [-].
    aperiodic_limit
        Share of a record's response not periodic at the drive above which it does not settle [-].
    """

    drift_z: float = 8.0
    residual_factor: float = 20.0
    normal_limit: float = 0.25
    open_limit: float = 0.02
    aperiodic_limit: float = 0.1

    @classmethod
    def from_config(cls, block: Mapping | None) -> "PlaceThresholds":
        """Return the thresholds of the ``gap.place`` block.

        Parameters
        ----------
        block
            The ``gap.place`` config block (drift_z, residual_factor, normal_limit, open_limit, aperiodic_limit; keys
            left out: the defaults); None: every default.

        Returns
        -------
        thresholds : PlaceThresholds
            The thresholds.
        """
        return cls(**{k: float(v) for k, v in (block or {}).items()})


DEFAULT_PLACE = PlaceThresholds()


def open_fraction(normal_force: np.ndarray, preload: float, open_limit: float = DEFAULT_PLACE.open_limit) -> float:
    """Return the share of the cycle's samples where the contact is open: N at or below ``open_limit`` x the preload N0.

    Parameters
    ----------
    normal_force
        Total normal force N over one cycle [N], shape (n_samples,).
    preload
        The static preload N0 [N].
    open_limit
        Fraction of the preload at or below which the contact is open [-].

    Returns
    -------
    fraction : float
        Share of the samples where the contact is open [-].
    """
    return float(np.mean(np.asarray(normal_force) <= open_limit * preload))


def never_opens(step: Mapping) -> bool:
    """Return whether an explanation step is a contact-separation law that never opened the contact.

    Such a step (``explanation[k].contact_opens`` false in its simulations) stands for a stiffer or harder normal law,
    model form.

    Parameters
    ----------
    step
        An explanation step; read: effect, contact_opens.

    Returns
    -------
    never : bool
        True for a contact-separation step whose simulations never opened the contact.
    """
    return step.get("effect") == "contact_separation" and step.get("contact_opens") is False


def acts_where(acts_on: str, place: str) -> bool:
    """Return whether a candidate acting on ``acts_on`` acts where the gap lies.

    The same place, "any", or either contact direction when the place is "contact" (the normal motion not observable).

    Parameters
    ----------
    acts_on
        Where the candidate acts (``Candidate.acts_on``).
    place
        Where the gap lies (``place``).

    Returns
    -------
    acts : bool
        True where the candidate acts at the place.
    """
    return acts_on in ("any", place) or (place == "contact" and acts_on in ("normal_contact", "tangential_contact"))


def place(
    drift: Mapping[str, Mapping],
    stage: Mapping[str, float],
    id_res: np.ndarray | Sequence[float],
    scatter: np.ndarray | Sequence[float],
    eta_observable: bool = True,
    eta_spread: float = 0.0,
    thresholds: PlaceThresholds = DEFAULT_PLACE,
) -> tuple[str, str]:
    """Return where the gap lies, with the reason: (place, reason).

    The first that holds of: the records drift (median z > thresholds.drift_z) -> "non_stationary"; the structure and
    sensor model misfits the records (median id_res / scatter > thresholds.residual_factor) ->
    "structure_or_measurement"; the contact opens (the identified N, observable, reaches zero) -> "normal_contact"; the
    normal motion eta is not observable (``eta_observable`` False: the identified eta moves by ``eta_spread`` over the
    structures the data allow), so the normal law cannot be tested and the directions cannot be told apart -> "contact";
    no elastic normal law fits N(eta) (contact_force_N > thresholds.normal_limit) -> "normal_contact"; otherwise
    "tangential_contact".

    Parameters
    ----------
    drift
        Per load case {"change": relative change over the record, "z": its size in standard errors}.
    stage
        The stage gaps, at least "open_fraction", "contact_force_N" and "contact_force_S" (relative gaps and the share
        of the cycle the contact is open) [-].
    id_res
        Per load case, the inverse identification's relative sensor misfit [-], shape (n_cases,).
    scatter
        Per load case, the standard error of ``id_res`` [-], shape (n_cases,).
    eta_observable
        Whether the identified normal motion eta is observable.
    eta_spread
        Largest relative change of the identified eta over the structures the data allow [-].
    thresholds
        The place's thresholds.

    Returns
    -------
    place : str
        "non_stationary", "structure_or_measurement", "normal_contact", "contact" or "tangential_contact".
    reason : str
        The reason, a sentence with its numbers.
    """
    id_res, scatter = np.asarray(id_res, float), np.asarray(scatter, float)
    z = np.array([v["z"] for v in drift.values()])
    if np.median(z) > thresholds.drift_z:
        change = np.median([v["change"] for v in drift.values()])
        return "non_stationary", (
            f"the records' harmonics drift by {percent(change, 2)} over a record ({np.median(z):.0f} standard errors)"
        )
    if np.median(id_res / scatter) > thresholds.residual_factor:
        return "structure_or_measurement", (
            f"the linear structure and sensor model cannot fit the records at w "
            f"and 3w (sensor misfit {percent(np.median(id_res), 2)}, "
            f"{np.median(id_res / scatter):.0f} x the scatter)"
        )
    if stage["open_fraction"] > 0:
        return "normal_contact", (
            f"the identified normal force falls to zero over {stage['open_fraction']:.0%} of the "
            "cycle in the hardest load case: the contact opens"
        )
    if not eta_observable:
        return "contact", (
            f"the identified normal motion eta is not observable (it moves by {eta_spread:.0%} over "
            "the structures the random test allows), so no normal law can be tested against it and the "
            "normal and the tangential contact cannot be told apart"
        )
    if stage["contact_force_N"] > thresholds.normal_limit:
        return "normal_contact", (
            f"no elastic normal law fits the identified N(eta): {stage['contact_force_N']:.0%} "
            "of N is left (dissipation or opening in the normal direction)"
        )
    return "tangential_contact", (
        f"structure, sensors and normal contact are consistent with the records; the "
        f"friction law leaves {stage['contact_force_S']:.1%} of S"
    )
