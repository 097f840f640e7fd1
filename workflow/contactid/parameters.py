"""Frozen parameter sets of the test structure (Sections 2-3 of the paper).

All quantities in SI units. Values the paper does not give (E, transducer masses,
pin inertia, block inertia, string length and stiffness, lever arms) come from
the configuration, where each default is documented with its reasoning
(`config/README.md`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Mapping

STANDARD_GRAVITY = 9.80665  # m/s^2


@dataclass(frozen=True)
class StructureParameters:
    """The fixed-frictionally supported beam of Fig. 1 with its transducers.

    All quantities in SI units. No field has a default: the configured structure (``structure_from_config``) is the
    one source of the values, and a structure built in code names every one of them.

    Attributes
    ----------
    length
        Beam length L [m].
    width
        Beam width b [m].
    thickness
        Beam thickness h [m].
    youngs_modulus
        Young's modulus E [Pa].
    density
        Density rho [kg/m^3].
    pin_radius
        Pin radius r [m]. The pin is welded to the beam end; its contact line sits ``normal_lever_arm`` beyond the
        end along x (Eq. 8) and ``tangential_lever_arm`` below the beam mid-plane (Eq. 9).
    pin_mass
        Pin mass m_p [kg].
    pin_inertia
        Pin rotary inertia J_p about the pin axis [kg m^2].
    tangential_lever_arm
        Height a of the contact line below the beam mid-plane, in xi = u + a w'(L) (Eq. 9; the paper uses r) [m].
    normal_lever_arm
        Distance r of the contact line beyond the beam end along x, in eta = w(L) + r w'(L) (Eq. 8) [m].
    hanger_lever_arm
        Height of the string's attachment above the beam mid-plane [m]; the paper's Eq. (2) uses
        xi - 2 r w'(L) = u - r w'(L), i.e. r above the axis.
    shortening_scale
        How much of the beam's shortening -1/2 int_0^L w'^2 dx (Eq. 9) enters the contact's slip xi (and, by virtual
        work, the axial-force term of the equations of motion) [-]: 1 as Eq. 9 prints it, 0 for linear kinematics
        xi = u + a w'(L).
    block_mass
        Mass m_s of the hanging block [kg].
    block_inertia
        Rotary inertia J_s of the hanging block [kg m^2].
    string_length
        Length l_s of the string the block hangs from [m].
    string_stiffness
        Stiffness k_s of the string [N/m].
    gravity
        Gravitational acceleration g [m/s^2].
    excitation_position
        Excitation (force transducer) position d_p, measured from the clamp [m].
    force_transducer_mass
        Mass added at d_p by the force transducer [kg].
    sensor_positions
        Accelerometer positions x_1..x_j, measured from the clamp [m], one per sensor.
    sensor_masses
        Accelerometer masses [kg], one per sensor, in the order of ``sensor_positions``.
    k_t
        Linear tangential contact stiffness of Eq. (13) [N/m].
    k_n
        Linear normal contact stiffness of Eq. (13) [N/m].
    clamp_rotational_stiffness
        Rotational stiffness of the clamp [N m/rad]; ``math.inf`` for a rigid clamp.
    axial_inertia
        Whether the beam's (rho A L / 3) and the pin's axial inertia on u are included (the paper neglects axial
        inertia).
    n_elements
        Target number of beam finite elements.
    """

    length: float
    width: float
    thickness: float
    youngs_modulus: float
    density: float
    pin_radius: float
    pin_mass: float
    pin_inertia: float
    tangential_lever_arm: float
    normal_lever_arm: float
    hanger_lever_arm: float
    shortening_scale: float
    block_mass: float
    block_inertia: float
    string_length: float
    string_stiffness: float
    gravity: float
    excitation_position: float
    force_transducer_mass: float
    sensor_positions: tuple[float, ...]
    sensor_masses: tuple[float, ...]
    k_t: float
    k_n: float
    clamp_rotational_stiffness: float
    axial_inertia: bool
    n_elements: int

    @property
    def area(self) -> float:
        """Cross-section area A = b h.

        Returns
        -------
        area : float
            Cross-section area [m^2].
        """
        return self.width * self.thickness

    @property
    def second_moment(self) -> float:
        """Second moment of area I = b h^3 / 12 of the cross-section.

        Returns
        -------
        second_moment : float
            Second moment of area [m^4].
        """
        return self.width * self.thickness**3 / 12.0

    @property
    def bending_stiffness(self) -> float:
        """Bending stiffness EI of the beam.

        Returns
        -------
        bending_stiffness : float
            Bending stiffness [N m^2].
        """
        return self.youngs_modulus * self.second_moment

    @property
    def mass_per_length(self) -> float:
        """Mass per unit length rho A of the beam.

        Returns
        -------
        mass_per_length : float
            Mass per unit length [kg/m].
        """
        return self.density * self.area

    @property
    def axial_stiffness(self) -> float:
        """Axial stiffness k_b = E A / L of the beam (Section 2).

        Returns
        -------
        axial_stiffness : float
            Axial stiffness [N/m].
        """
        return self.youngs_modulus * self.area / self.length

    def with_contact(self, k_t: float, k_n: float) -> "StructureParameters":
        """Return the same structure with other contact stiffnesses.

        Parameters
        ----------
        k_t
            Linear tangential contact stiffness [N/m].
        k_n
            Linear normal contact stiffness [N/m].

        Returns
        -------
        structure : StructureParameters
            A copy with ``k_t`` and ``k_n`` replaced.
        """
        return replace(self, k_t=float(k_t), k_n=float(k_n))

    def replace(self, **changes: Any) -> "StructureParameters":
        """Return the same structure with the named fields changed.

        Parameters
        ----------
        **changes
            New values by field name, in the fields' units (see the class's attributes).

        Returns
        -------
        structure : StructureParameters
            A copy with the named fields replaced.
        """
        return replace(self, **changes)


def structure_from_config(
    cfg: Mapping[str, Any], k_t: float, k_n: float, n_elements: int | None = None
) -> StructureParameters:
    """Build :class:`StructureParameters` from the ``structure`` block of the config.

    Parameters
    ----------
    cfg
        The config's ``structure`` mapping (validated by the schema, which fills its defaults); reads ``beam``,
        ``pin``, ``contact_geometry``, ``block``, ``sensors`` (``positions_m``, ``masses_kg``),
        ``clamp_rotational_stiffness_nm_per_rad`` (absent or None: a rigid clamp), ``gravity_m_per_s2``,
        ``excitation_position_m``, ``force_transducer_mass_kg`` and ``fe_elements``.
    k_t
        Linear tangential contact stiffness [N/m].
    k_n
        Linear normal contact stiffness [N/m].
    n_elements
        Target number of beam finite elements, overriding ``fe_elements`` (the rig uses a finer mesh); None: the
        config's.

    Returns
    -------
    structure : StructureParameters
        The structure, with axial inertia included.
    """
    beam = cfg["beam"]
    pin = cfg["pin"]
    geo = cfg["contact_geometry"]
    block = cfg["block"]
    sensors = cfg["sensors"]
    clamp = cfg.get("clamp_rotational_stiffness_nm_per_rad")
    return StructureParameters(
        length=float(beam["length_m"]),
        width=float(beam["width_m"]),
        thickness=float(beam["thickness_m"]),
        youngs_modulus=float(beam["youngs_modulus_pa"]),
        density=float(beam["density_kg_per_m3"]),
        pin_radius=float(pin["radius_m"]),
        pin_mass=float(pin["mass_kg"]),
        pin_inertia=float(pin["rotary_inertia_kg_m2"]),
        tangential_lever_arm=float(geo["tangential_lever_arm_m"]),
        normal_lever_arm=float(geo["normal_lever_arm_m"]),
        hanger_lever_arm=float(geo["hanger_lever_arm_m"]),
        shortening_scale=float(geo.get("shortening_scale", 1.0)),
        block_mass=float(block["mass_kg"]),
        block_inertia=float(block["rotary_inertia_kg_m2"]),
        string_length=float(block["string_length_m"]),
        string_stiffness=float(block["string_stiffness_n_per_m"]),
        gravity=float(cfg["gravity_m_per_s2"]),
        excitation_position=float(cfg["excitation_position_m"]),
        force_transducer_mass=float(cfg["force_transducer_mass_kg"]),
        sensor_positions=tuple(float(x) for x in sensors["positions_m"]),
        sensor_masses=tuple(float(x) for x in sensors["masses_kg"]),
        k_t=float(k_t),
        k_n=float(k_n),
        clamp_rotational_stiffness=math.inf if clamp is None else float(clamp),
        axial_inertia=True,  # always in the model (a switch for the analytic checks of the bare beam)
        n_elements=int(n_elements if n_elements is not None else cfg["fe_elements"]),
    )


def identified_structure(cfg: Mapping[str, Any], linear_modes: Mapping[str, Any]) -> StructureParameters:
    """Return the linear structure the chain identified.

    The config's ``structure`` block with the identified contact stiffnesses k_t, k_n and, where the identification
    has one, its ``stiffness_scale``: Young's modulus times the scale the stiffness fit found
    (``stiction.stiffness_scale_sd``; 1 where the fit kept the model's E).

    Parameters
    ----------
    cfg
        The config's ``structure`` mapping (as for ``structure_from_config``).
    linear_modes
        The linear chain's result (the linear_modes.nc dataset, or any mapping with those keys): ``k_t`` and ``k_n``
        [N/m], and optionally ``stiffness_scale`` [-].

    Returns
    -------
    structure : StructureParameters
        The identified structure.
    """
    p = structure_from_config(cfg, float(linear_modes["k_t"]), float(linear_modes["k_n"]))
    scale = float(linear_modes["stiffness_scale"]) if "stiffness_scale" in linear_modes else 1.0
    return p if scale == 1.0 else p.replace(youngs_modulus=scale * p.youngs_modulus)
