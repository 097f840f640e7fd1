"""The structure model updating fits: its factors, their priors and its modal predictions.

``FACTORS`` says what each factor scales, its prior spread and its further starts, ``apply_factors`` applies them to
the nominal structure, and ``modal_predictions`` gives the natural frequencies and the residue magnitudes of the
driving-point accelerance that the update compares with the random test's modal fit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .beam_model import assemble
from .beam_modes import structural_modes
from .parameters import StructureParameters


@dataclass(frozen=True)
class StructuralFactor:
    """A structural parameter of the updating: a factor theta on a nominal property of the structure.

    Attributes
    ----------
    name
        The factor's name (its key in ``FACTORS``).
    description
        What it scales, in words.
    prior_sd
        The prior's relative spread s, the standard deviation of ln theta [-].
    apply
        How it changes the structure: the structure and the factor's value (a multiplier of the nominal value [-])
        to the changed structure.
    starts
        Further starts of the MAP fit (values of the factor): a factor whose effect vanishes at its nominal value (a
        rigid clamp's compliance) has no gradient there, and a fit from the nominal value alone would not move it.
    max_prior_sd
        The largest prior spread (of ln theta) gap.model_updating.prior_sd may give it [-].
    needs_starts
        Whether the nominal structure needs the further starts (None: always); a finite clamp has a gradient
        already.
    """

    name: str
    description: str
    prior_sd: float
    apply: Callable[[StructureParameters, float], StructureParameters]
    # further starts of the MAP fit (values of the factor): a factor whose effect vanishes at its nominal value (a
    # rigid clamp's compliance) has no gradient there, and a fit from the nominal value alone would not move it
    starts: tuple = ()
    max_prior_sd: float = 2.0  # the largest prior spread gap.model_updating.prior_sd may give it
    # whether the nominal structure needs the further starts (None: always); a finite clamp has a gradient already
    needs_starts: Callable[[StructureParameters], bool] | None = None


def _scale_masses(p: StructureParameters, m: float) -> StructureParameters:
    return p.replace(
        sensor_masses=tuple(m * x for x in p.sensor_masses), force_transducer_mass=m * p.force_transducer_mass
    )


def _scale_clamp_compliance(p: StructureParameters, m: float) -> StructureParameters:
    """Return the structure with the clamp's rotational compliance 1 / k_c times m.

    A rigid clamp (k_c infinite) is taken as CLAMP_RIGID, and stays rigid at m = 1 (the nominal structure, as every
    other factor leaves it at 1).
    """
    if m == 1.0:
        return p
    k_c = p.clamp_rotational_stiffness if math.isfinite(p.clamp_rotational_stiffness) else CLAMP_RIGID
    return p.replace(clamp_rotational_stiffness=k_c / m)


# N m/rad: the rotational stiffness of a rigid clamp (structure.clamp_rotational_stiffness_nm_per_rad null) when its
# compliance is updated: about 1e6 x the beam's EI / L (146 N m), the first three natural frequencies within 3e-6 of
# the rigid clamp's. A clamp of 2e5 N m/rad (m = 500) lowers them by 0.14 %, one of 2e4 by 1.4 %, and it shows most in
# the residues of the sensor nearest the clamp
CLAMP_RIGID = 1.0e8

FACTORS = {
    f.name: f
    for f in (
        StructuralFactor(
            "stiffness_scale",
            "Young's modulus E (the beam's bending and axial stiffness)",
            0.05,
            lambda p, m: p.replace(youngs_modulus=m * p.youngs_modulus),
        ),
        StructuralFactor("mass_scale", "the beam's density", 0.03, lambda p, m: p.replace(density=m * p.density)),
        StructuralFactor(
            "transducer_mass_scale", "every transducer mass (accelerometers and force transducer)", 0.5, _scale_masses
        ),
        # the force transducer against the accelerometers: transducer_mass_scale moves them together, this one the force
        # transducer's alone (at the drive point; the residues tell it from the accelerometers' to about half its prior)
        StructuralFactor(
            "force_transducer_mass_scale",
            "the force transducer's mass, beyond transducer_mass_scale (the accelerometers' and its own)",
            0.5,
            lambda p, m: p.replace(force_transducer_mass=m * p.force_transducer_mass),
        ),
        StructuralFactor(
            "tangential_lever_arm_scale",
            "the tangential lever arm (height of the contact line)",
            0.1,
            lambda p, m: p.replace(tangential_lever_arm=m * p.tangential_lever_arm),
        ),
        # a log-normal prior about the nominal clamp (rigid: CLAMP_RIGID) with a spread of e^5 (x 150 at one sd):
        # clamps from rigid to about 1e4 N m/rad; the second start, 1e5 N m/rad from a rigid one, gives the fit a
        # gradient where the rigid clamp has none
        StructuralFactor(
            "clamp_compliance_scale",
            "the clamp's rotational compliance 1 / k_c (a rigid clamp taken as 1e8 N m/rad)",
            5.0,
            _scale_clamp_compliance,
            starts=(1.0e3,),
            max_prior_sd=10.0,
            needs_starts=lambda p: not math.isfinite(p.clamp_rotational_stiffness),
        ),
    )
}
DEFAULT_FACTORS = tuple(FACTORS)
# factors whose profile is also taken together (``identifiability[f]["group_profile_chi2_increase"]``): each of the two
# transducer-mass factors alone is partly taken up by the other (the masses +40 % held at nominal: 1.8 where the
# five factors without the force transducer's gave more than 4)
PROFILE_GROUPS = {"transducer_masses": ("transducer_mass_scale", "force_transducer_mass_scale")}


def apply_factors(params: StructureParameters, factors: dict) -> StructureParameters:
    """Return the structure with each named factor applied.

    Parameters
    ----------
    params
        The nominal structure.
    factors
        {name in ``FACTORS``: the factor, a multiplier of the nominal value [-]}, applied in this order.

    Returns
    -------
    structure : StructureParameters
        The structure with the factors applied.
    """
    for name, value in factors.items():
        params = FACTORS[name].apply(params, float(value))
    return params


def modal_predictions(params: StructureParameters, n_modes: int) -> tuple[np.ndarray, np.ndarray]:
    """Return the natural frequencies and the accelerance residue magnitudes of the first structural modes.

    The residues are |phi_i(x_s) phi_i(x_d)| / (2 omega_i) of the driving-point force's accelerance, with the
    mass-normalised modes phi_i: the magnitudes of the modal fit's LSFD residues (``modal_fit.lsfd_fit``'s
    convention, H = sum (i w)^2 R / (i w - s) + ..., undamped). A structure with fewer structural modes raises
    ValueError (``beam_modes.structural_modes``).

    Parameters
    ----------
    params
        The structure.
    n_modes
        How many structural modes, lowest first.

    Returns
    -------
    frequencies : np.ndarray
        Natural frequencies [Hz], shape (n_modes,).
    residues : np.ndarray
        Residue magnitudes [s/kg] (m/N times rad/s), shape (n_sensors, n_modes), n_sensors the accelerometers.
    """
    model = assemble(params)
    modes = structural_modes(model, n_modes)
    phi_s = model.sensor_vectors @ modes.shapes
    phi_d = model.force_vector @ modes.shapes
    w = 2 * np.pi * modes.frequencies_hz
    return modes.frequencies_hz, np.abs(phi_s * phi_d[None, :]) / (2 * w[None, :])
