"""The rig's structure: the configured structure with the contact springs taken
from the rig's true contact laws (their small-amplitude limits)."""

from __future__ import annotations

from typing import Mapping

from ..contact_laws import NormalLaw, ValanisParameters, stiction_shear_stiffness
from ..parameters import StructureParameters, structure_from_config


def rig_contact_stiffness(structure_cfg: Mapping, rig_cfg: Mapping) -> tuple[float, float]:
    """True (k_t, k_n) in N/m: e_0 of Eq. 22 at the preload, and the normal law's tangent."""
    truth = rig_cfg["truth"]
    fr = ValanisParameters.from_config(truth["friction"])
    n0 = float(structure_cfg["preload_n"])
    k_t = float(stiction_shear_stiffness(n0, fr.e_f, fr.k_c))
    k_n = NormalLaw(n0, float(truth["normal"]["stiffness_at_preload_n_per_m"]),
                    float(truth["normal"]["exponent"])).stiffness_at_preload
    return k_t, float(k_n)


def rig_structure(structure_cfg: Mapping, rig_cfg: Mapping) -> StructureParameters:
    """StructureParameters of the rig (finer mesh, true contact stiffnesses)."""
    k_t, k_n = rig_contact_stiffness(structure_cfg, rig_cfg)
    return structure_from_config(structure_cfg, k_t, k_n, n_elements=int(rig_cfg.get("fe_elements", 96)))
