"""Switchable unmodelled effects of the virtual rig (`rig: effects: {name: magnitude}`).

Each effect is off unless named in the config; its magnitude's meaning, unit,
allowed range and a typical value are listed here (and in config/README.md).
The raw files carry no trace of which effects were on.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping


@dataclass(frozen=True)
class EffectSpec:
    """One switchable effect.

    Attributes
    ----------
    name
        The effect's name (its key under ``rig.effects``).
    unit
        The unit of its magnitude ("1", "s", "s/m", "N s/m").
    meaning
        What it models.
    typical
        A typical magnitude [unit of unit].
    low
        The low end of the allowed range [unit of unit].
    high
        The high end of the allowed range [unit of unit].
    """

    name: str
    unit: str
    meaning: str
    typical: float
    low: float
    high: float


EFFECTS = {
    e.name: e
    for e in (
        EffectSpec(
            "structural_damping",
            "1",
            "extra modal damping ratio of the beam's modes in the dual-sine tests (amplitude-dependent "
            "damping that the low-level random test does not show)",
            0.005,
            0.0,
            0.1,
        ),
        EffectSpec(
            "normal_contact_damping",
            "s/m",
            "Hunt-Crossley coefficient alpha: N = N_el(eta) (1 - alpha d(eta)/dt), integrated implicitly",
            300.0,
            0.0,
            1.0e4,
        ),
        EffectSpec(
            "viscous_friction",
            "N s/m",
            "viscous friction coefficient sigma_2: S = S_Valanis + sigma_2 d(xi)/dt while in contact",
            300.0,
            0.0,
            1.0e5,
        ),
        EffectSpec(
            "multi_asperity_friction",
            "1",
            "share of the tangential contact carried by a parallel Iwan (Maxwell-slip) element of 16 "
            "sliders with spread slip limits, instead of the single Valanis element",
            1.0,
            0.0,
            1.0,
        ),
        EffectSpec(
            "transducer_mass_error",
            "1",
            "relative error of every transducer mass: the rig's masses are (1 + m) times the model's",
            0.3,
            -0.9,
            5.0,
        ),
        EffectSpec(
            "channel_time_skew",
            "s",
            "sampling delay of the acceleration channels relative to the force: channel k of n is late by "
            "m (k + 1) / n",
            2.0e-5,
            0.0,
            1.0e-3,
        ),
        EffectSpec(
            "channel_gain_error",
            "1",
            "sensitivity error of the acceleration channels (a calibration the analysis does not know): channel k "
            "of n reads 1 + m (-1)^k (k + 1) / n times its acceleration",
            0.03,
            -0.5,
            0.5,
        ),
        EffectSpec(
            "contact_separation",
            "1",
            "factor on every rig load case's target amplitudes A1, A2: the rig is driven hard enough to "
            "lose contact for part of each cycle (0 = off; at 7.2 the default lc1 just separates, above about 7.5 "
            "the impacts may keep the motion from settling into a periodic state)",
            7.2,
            0.0,
            20.0,
        ),
        EffectSpec(
            "preload_drift",
            "1",
            "relative change of the static normal preload over each dual-sine record (linear drift)",
            0.1,
            -0.9,
            5.0,
        ),
    )
}


def effect_magnitudes(effects_cfg: Mapping | None) -> dict[str, float]:
    """Return the validated {name: magnitude} with every known effect (0 = off).

    Parameters
    ----------
    effects_cfg
        The config's ``rig.effects`` {name: magnitude}, in each effect's unit; None: none.

    Returns
    -------
    magnitudes : dict[str, float]
        {name: magnitude} of every effect of ``EFFECTS``, each in its own unit [unit of EffectSpec.unit]; 0 where off.

    Raises
    ------
    ValueError
        When a name is not a known effect, a magnitude is not a number or lies outside its allowed range (the message
        names the key, the allowed range and the known names).
    """
    out = {name: 0.0 for name in EFFECTS}
    for name, value in (effects_cfg or {}).items():
        if name not in EFFECTS:
            raise ValueError(f"rig.effects.{name}: unknown effect; known effects: {', '.join(EFFECTS)}")
        spec = EFFECTS[name]
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"rig.effects.{name} = {value!r}: give a number ({spec.unit})") from None
        if not spec.low <= value <= spec.high:
            raise ValueError(
                f"rig.effects.{name} = {value}: allowed range [{spec.low}, {spec.high}] {spec.unit}; "
                f"typical {spec.typical}"
            )
        out[name] = value
    return out
