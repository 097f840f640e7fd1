"""The library of candidate effects that can be added to the identified model.

Each candidate is a physical effect with few parameters, mapped onto an ``Augmentation`` of the
identified model. The built-in library covers every effect the virtual rig can switch on (under
the same names), so the blind benchmark can score the diagnosis; the candidate's parametrisation
is generic, not the rig's (for example one delay per accelerometer channel, not the rig's skew
pattern).

Adding your own: write a module that builds a ``Candidate`` and calls ``register(candidate)``,
and list the module in ``gap.plugins`` (config); the rule imports it before the diagnosis. A
candidate maps its parameter vector theta onto any combination of the Augmentation fields.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable, Iterable, Sequence

import numpy as np

from .model import Augmentation


@dataclass(frozen=True)
class Parameter:
    """One parameter of a candidate: its name, unit, search range and start.

    A search over several parameters starts at ``start`` (the middle of the range by default), for example the value
    that leaves the identified model as it is. ``domain`` is the widest range a one-parameter search widens [low, high]
    to where its optimum ends at an end of the range (``extended``), so that an effect larger than its typical range is
    refitted, not cut at the range's end.

    Attributes
    ----------
    name
        The parameter's name.
    unit
        Its unit, as text ("1" for a dimensionless number, "s", "s/m", "N s/m").
    low
        Low end of the search range [unit of unit].
    high
        High end of the search range [unit of unit].
    start
        Where a search over several parameters starts [unit of unit]; None: the middle of the range.
    domain
        The widest range (low, high) a search may widen to [unit of unit]; None: the range is the parameter's whole
        domain.
    """

    name: str
    unit: str
    low: float
    high: float
    start: float | None = None
    domain: tuple[float, float] | None = None

    def extended(self, at_low: bool, at_high: bool) -> "Parameter | None":
        """Return the range widened past the ends an optimum reached, by three times its span, within ``domain``.

        Parameters
        ----------
        at_low
            Whether the optimum ended at the range's low end (widen it downwards).
        at_high
            Whether the optimum ended at the range's high end (widen it upwards).

        Returns
        -------
        parameter : Parameter | None
            The parameter with the wider range; None where the domain allows no wider range there.
        """
        lo_d, hi_d = self.domain or (self.low, self.high)
        span = self.high - self.low
        low = max(lo_d, self.low - 3.0 * span) if at_low else self.low
        high = min(hi_d, self.high + 3.0 * span) if at_high else self.high
        return replace(self, low=low, high=high) if (low, high) != (self.low, self.high) else None

    def covering(self, value: float) -> "Parameter":
        """Return this parameter starting at ``value``, its range widened until it holds ``value``.

        The range is widened as ``extended`` widens it. For a refit that ended beyond the library's range, searched
        again in a joint refit. Where the domain stops the widening short of ``value``, the start is the range's nearest
        end.

        Parameters
        ----------
        value
            The value the range must hold and the search start from [unit of unit].

        Returns
        -------
        parameter : Parameter
            The parameter with the (possibly wider) range and its start at ``value``.
        """
        p = self
        while value < p.low or value > p.high:
            wider = p.extended(value < p.low, value > p.high)
            if wider is None:
                break
            p = wider
        return replace(p, start=float(np.clip(value, p.low, p.high)))

    @property
    def off(self) -> float:
        """The value that leaves the model as it is: zero, or the range's low end where zero is outside it.

        Returns
        -------
        off : float
            The neutral value [unit of unit].
        """
        return 0.0 if self.low <= 0.0 <= self.high else self.low

    def is_off(self, value: float) -> bool:
        """Return whether ``value`` leaves the model as it is (within 1e-9 of the range's span).

        Parameters
        ----------
        value
            A value of the parameter [unit of unit].

        Returns
        -------
        bool
            True where ``value`` is the neutral value ``off``.
        """
        return abs(float(value) - self.off) <= 1e-9 * (self.high - self.low)


@dataclass(frozen=True)
class Candidate:
    """A candidate effect: its name, what it models, its parameters and theta -> Augmentation.

    Attributes
    ----------
    name
        The candidate's name, unique in the library.
    meaning
        What it models, in words.
    parameters
        Its ``Parameter`` objects, in the order of theta.
    augmentation
        theta -> the ``Augmentation`` of the identified model that the effect makes (theta: the parameters' values
        [units of Parameter.unit], shape (n_parameters,)).
    per_channel
        The one parameter is repeated for every accelerometer channel.
    acts_on
        The place of the gap it can explain (one of PLACES, or "any"): a winner must act where the localisation puts
        the gap.
    form
        The candidate changes the base model's form (its damping) rather than adding an effect at the contact or in
        the measurement: what it explains is the reference of what model-form differences leave on the records
        (``story_decisions.beyond_model_form``), and it is tried even where the library in use leaves it out.
    """

    name: str
    meaning: str
    parameters: tuple
    augmentation: Callable[[np.ndarray], Augmentation]
    per_channel: bool = False
    acts_on: str = "any"
    form: bool = False

    def n_parameters(self, n_channels: int) -> int:
        """Return the number of parameters the candidate fits.

        Parameters
        ----------
        n_channels
            Number of accelerometer channels.

        Returns
        -------
        int
            One per accelerometer channel where ``per_channel``, otherwise its parameters' count.
        """
        return n_channels if self.per_channel else len(self.parameters)


PLACES = ("structure_or_measurement", "normal_contact", "tangential_contact", "non_stationary")
LIBRARY: dict[str, Candidate] = {}


def register(candidate: Candidate) -> Candidate:
    """Add a candidate to the library (a user's plugin calls this); names must be unique.

    Parameters
    ----------
    candidate
        The candidate to add.

    Returns
    -------
    candidate : Candidate
        The same candidate.

    Raises
    ------
    ValueError
        When the name is taken (or is "none"), the candidate has no parameter, ``acts_on`` is not one of PLACES or
        "any", or a parameter's low end is not below its high end.
    """
    if candidate.name in LIBRARY or candidate.name == "none":
        raise ValueError(f"gap candidate {candidate.name!r}: the name is taken; choose another")
    if not candidate.parameters:
        raise ValueError(f"gap candidate {candidate.name!r}: give at least one parameter")
    if candidate.acts_on not in (*PLACES, "any"):
        raise ValueError(
            f"gap candidate {candidate.name!r}: acts_on = {candidate.acts_on!r}; give one of "
            f"{', '.join(PLACES)} or 'any'"
        )
    for p in candidate.parameters:
        if not p.low < p.high:
            raise ValueError(f"gap candidate {candidate.name!r}, parameter {p.name}: low must be below high")
    LIBRARY[candidate.name] = candidate
    return candidate


register(
    Candidate(
        "structural_damping",
        "extra modal damping of the beam's modes at test level",
        (Parameter("extra_damping_ratio", "1", 0.0, 0.05, domain=(0.0, 0.2)),),
        lambda th: Augmentation(extra_damping=float(th[0])),
        acts_on="structure_or_measurement",
        form=True,
    )
)
register(
    Candidate(
        "normal_contact_damping",
        "Hunt-Crossley damping of the normal contact, N (1 - alpha deta/dt)",
        (Parameter("alpha", "s/m", 0.0, 3000.0, domain=(0.0, 3.0e4)),),
        lambda th: Augmentation(hunt_crossley=float(th[0])),
        acts_on="normal_contact",
    )
)
register(
    Candidate(
        "viscous_friction",
        "velocity-dependent friction, S + sigma_2 dxi/dt",
        (Parameter("sigma_2", "N s/m", 0.0, 3000.0, domain=(0.0, 1.0e5)),),
        lambda th: Augmentation(viscous=float(th[0])),
        acts_on="tangential_contact",
    )
)
register(
    Candidate(
        "multi_asperity_friction",
        "share of the tangential contact carried by a 16-slider Iwan element (internal hysteresis loops)",
        (Parameter("iwan_share", "1", 0.0, 1.0),),
        lambda th: Augmentation(iwan_share=float(th[0])),
        acts_on="tangential_contact",
    )
)
register(
    Candidate(
        "transducer_mass_error",
        "every transducer mass wrong by the same factor 1 + m",
        (Parameter("mass_error", "1", -0.9, 3.0, domain=(-0.9, 9.0)),),
        lambda th: Augmentation(mass_error=float(th[0])),
        acts_on="structure_or_measurement",
    )
)
register(
    Candidate(
        "channel_time_skew",
        "each accelerometer channel late on the force by its own delay",
        (Parameter("delay", "s", -2.0e-4, 2.0e-4, domain=(-2.0e-3, 2.0e-3)),),
        lambda th: Augmentation(delays=tuple(float(x) for x in th)),
        per_channel=True,
        acts_on="structure_or_measurement",
    )
)
register(
    Candidate(
        "contact_separation",
        "unilateral hardening normal contact N0 ((delta0 - eta)/delta0)^p that opens "
        "(instead of Eq. 13's linear spring), delta0 = p N0 / (c k_n)",
        (
            Parameter("exponent", "1", 1.0, 3.0),
            # c = 1 keeps the identified k_n as the law's tangent stiffness at the preload
            Parameter("stiffness_factor", "1", 0.3, 3.0, start=1.0),
        ),
        lambda th: Augmentation(unilateral_exponent=float(th[0]), normal_stiffness_factor=float(th[1])),
        acts_on="normal_contact",
    )
)
register(
    Candidate(
        "preload_drift",
        "static normal preload drifting linearly over each record",
        (Parameter("relative_drift", "1", -0.5, 0.5, domain=(-0.9, 5.0)),),
        lambda th: Augmentation(preload_drift=float(th[0])),
        acts_on="non_stationary",
    )
)
register(
    Candidate(
        "beam_shortening",
        "the beam's shortening (Eq. 9's -1/2 int w'^2 dx) reaching the slip xi by 1 + s times the model's "
        "(s = -1: linear kinematics xi = u + a w')",
        (Parameter("shortening_change", "1", -1.0, 1.0),),
        lambda th: Augmentation(shortening_change=float(th[0])),
        # the slip's kinematics, but through the axial-force term of the equations of motion the records also show it
        # in the identified N: a rig without the shortening left 65 % of N unexplained by any elastic normal law
        # (place normal_contact), an independently written simulator's records the place "contact"
        acts_on="any",
    )
)
register(
    Candidate(
        "channel_gain_error",
        "each accelerometer channel read with its own sensitivity error, 1 + g times its acceleration: the gains "
        "relative to one another that the random test's residues show (applied as they are, not searched)",
        (Parameter("gain_error", "1", -0.2, 0.2),),
        lambda th: Augmentation(gains=tuple(1.0 + float(x) for x in th)),
        per_channel=True,
        acts_on="structure_or_measurement",
    )
)

BUILTIN = tuple(LIBRARY)


def merged_augmentation(steps: Iterable[tuple[Candidate, np.ndarray]]) -> Augmentation:
    """Return the augmentation of several effects together (later ones win a field).

    Parameters
    ----------
    steps
        (Candidate, theta) pairs, theta the candidate's parameter values [units of Parameter.unit],
        shape (n_parameters,).

    Returns
    -------
    augmentation : Augmentation
        The effects merged, in the order given.
    """
    aug = Augmentation()
    for c, th in steps:
        aug = aug.merge(c.augmentation(th))
    return aug


def joint_candidate(
    new: Candidate, earlier: Sequence[tuple[Candidate, np.ndarray]], n_channels: int
) -> tuple[Candidate, Callable]:
    """Return ``new`` refitted together with the explanation's earlier steps ``earlier``.

    A candidate whose parameters are new's (searched from their starts) followed by each earlier one's (starting at its
    refitted theta, per-channel ones repeated per channel), so that an earlier step that absorbed part of a second
    effect (viscous friction taking on a normal dashpot's dissipation) can give it back. Every parameter has a start
    (new's: off, zero or its range's low end, unless it gives one), so the search also starts from the earlier step's
    optimum itself (``calibration.calibrate``).

    Parameters
    ----------
    new
        The candidate added.
    earlier
        The explanation's earlier steps, (Candidate, theta) pairs, theta their refitted parameter values
        [units of Parameter.unit], shape (n_parameters,) (per-channel ones: (n_channels,)).
    n_channels
        Number of accelerometer channels (the per-channel parameters' count).

    Returns
    -------
    candidate : Candidate
        The joint candidate (new's name, meaning, place and form).
    split : Callable
        split(theta) -> [theta of new, theta of each earlier step]: the joint theta split into the steps' own.
    """

    def expand(c: Candidate, theta=None):
        params = c.parameters * (n_channels if c.per_channel else 1)
        if theta is None:  # the new effect starts off, at its own start where it gives one
            return tuple(replace(p, start=p.off if p.start is None else p.start) for p in params)
        # an earlier step refitted beyond its library range (``Parameter.extended``): searched in a range holding it
        return tuple(p.covering(float(t)) for p, t in zip(params, np.atleast_1d(theta)))

    parts = [expand(new)] + [expand(c, th) for c, th in earlier]
    sizes = np.cumsum([len(x) for x in parts])[:-1]
    cands = [new] + [c for c, _ in earlier]

    def split(theta):
        return np.split(np.atleast_1d(np.asarray(theta, float)), sizes)

    def augmentation(theta):
        return merged_augmentation(zip(cands, split(theta)))

    joint = Candidate(
        new.name, new.meaning, tuple(p for x in parts for p in x), augmentation, False, new.acts_on, new.form
    )
    return joint, split


def load_plugins(modules: Iterable[str] | None) -> None:
    """Import the users' candidate modules (``gap.plugins``); each calls ``register``.

    Parameters
    ----------
    modules
        Importable module names; None or empty: none.

    Raises
    ------
    ValueError
        When a module cannot be imported (the message says to put it on PYTHONPATH or under workflow/).
    """
    import importlib

    for name in modules or ():
        try:
            importlib.import_module(name)
        except ImportError as exc:
            raise ValueError(
                f"gap.plugins: cannot import {name!r} ({exc}); put the module on PYTHONPATH or under workflow/"
            ) from None
