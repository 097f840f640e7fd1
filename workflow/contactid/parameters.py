"""Frozen parameter sets of the test structure (Sections 2-3 of the paper).

All quantities in SI units. Values the paper does not give (E, transducer masses,
pin inertia, block inertia, string length and stiffness, lever arms) come from
the configuration, where each default is documented with its reasoning
(`config/README.md`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Mapping

STANDARD_GRAVITY = 9.80665  # m/s^2


@dataclass(frozen=True)
class StructureParameters:
    """The fixed-frictionally supported beam of Fig. 1 with its transducers.

    Attributes (SI units):
        length, width, thickness: beam dimensions L, b, h (m).
        youngs_modulus: E (Pa); density: rho (kg/m^3).
        pin_radius: r (m). The pin is welded to the beam end; its contact line
            sits ``normal_lever_arm`` beyond the end along x (Eq. 8) and
            ``tangential_lever_arm`` below the beam mid-plane (Eq. 9).
        pin_mass, pin_inertia: m_p (kg), J_p (kg m^2, about the pin axis).
        hanger_lever_arm: height of the string's attachment above the beam
            mid-plane (m); the paper's Eq. (2) uses xi - 2 r w'(L) = u - r w'(L),
            i.e. r above the axis.
        shortening_scale: how much of the beam's shortening -1/2 int_0^L w'^2 dx (Eq. 9) enters the
            contact's slip xi (and, by virtual work, the axial-force term of the equations of motion):
            1 as Eq. 9 prints it, 0 for linear kinematics xi = u + a w'(L).
        block_mass, block_inertia: m_s (kg), J_s (kg m^2).
        string_length, string_stiffness: l_s (m), k_s (N/m).
        excitation_position: d_p (m from the clamp).
        force_transducer_mass: mass added at d_p (kg).
        sensor_positions, sensor_masses: accelerometers x_1..x_j (m) and their
            masses (kg).
        k_t, k_n: linear contact stiffnesses of Eq. (13) (N/m).
        clamp_rotational_stiffness: N m/rad; ``math.inf`` for a rigid clamp.
        axial_inertia: include the beam's (rho A L / 3) and the pin's axial
            inertia on u (the paper neglects axial inertia).
        n_elements: target number of beam finite elements.

    No field has a default: the configured structure (``structure_from_config``) is the one source of the values,
    and a structure built in code names every one of them.
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
        """Cross-section A = b h (m^2)."""
        return self.width * self.thickness

    @property
    def second_moment(self) -> float:
        """I = b h^3 / 12 (m^4)."""
        return self.width * self.thickness**3 / 12.0

    @property
    def bending_stiffness(self) -> float:
        """EI (N m^2)."""
        return self.youngs_modulus * self.second_moment

    @property
    def mass_per_length(self) -> float:
        """rho A (kg/m)."""
        return self.density * self.area

    @property
    def axial_stiffness(self) -> float:
        """k_b = E A / L (N/m), Section 2."""
        return self.youngs_modulus * self.area / self.length

    def with_contact(self, k_t: float, k_n: float) -> "StructureParameters":
        """The same structure with other contact stiffnesses (N/m)."""
        return replace(self, k_t=float(k_t), k_n=float(k_n))

    def replace(self, **changes) -> "StructureParameters":
        """The same structure with the named fields changed."""
        return replace(self, **changes)


def structure_from_config(cfg: Mapping, k_t: float, k_n: float, n_elements: int | None = None) -> StructureParameters:
    """Build :class:`StructureParameters` from the ``structure`` block of the config.

    ``cfg`` is the ``structure`` mapping (validated by the schema, which fills its defaults);
    ``k_t``, ``k_n`` the contact stiffnesses (N/m); ``n_elements`` overrides
    the mesh size (the rig uses a finer mesh).
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


def identified_structure(cfg: Mapping, linear_modes) -> StructureParameters:
    """The linear structure the chain identified: the config's ``structure`` block (``cfg``) with the contact
    stiffnesses k_t, k_n of ``linear_modes`` (linear_modes.nc, or any mapping with those keys) and, where it has one,
    its ``stiffness_scale``: Young's modulus times the scale the stiffness fit found (``stiction.stiffness_scale_sd``;
    1 where the fit kept the model's E)."""
    p = structure_from_config(cfg, float(linear_modes["k_t"]), float(linear_modes["k_n"]))
    scale = float(linear_modes["stiffness_scale"]) if "stiffness_scale" in linear_modes else 1.0
    return p if scale == 1.0 else p.replace(youngs_modulus=scale * p.youngs_modulus)
