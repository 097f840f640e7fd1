"""Contact laws of the rig and of the identified model (Section 5).

The rig's linear contact springs are the small-amplitude limits of these laws:
k_t is the Valanis law's stiction stiffness e_0 at the static preload (Eq. 22)
and k_n the normal law's tangent stiffness at the preload.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ValanisParameters:
    """Modified Valanis law, Eqs. 21-22: e_f (N/m), k_c (1/m), e_t (N/m), kappa (-), mu (-)."""

    e_f: float
    k_c: float
    e_t: float
    kappa: float
    mu: float

    @classmethod
    def from_config(cls, c) -> "ValanisParameters":
        """Read the law from a config mapping (keys ``e_f_n_per_m``, ``k_c_per_m``, ``e_t_n_per_m``, ``kappa``,
        ``mu``)."""
        return cls(
            float(c["e_f_n_per_m"]), float(c["k_c_per_m"]), float(c["e_t_n_per_m"]), float(c["kappa"]), float(c["mu"])
        )


def stiction_shear_stiffness(normal_force, e_f: float, k_c: float):
    """Contact shear stiffness at stiction e_0 = e_f (1 - exp(-k_c N / e_f)) (N/m), Eq. 22.

    normal_force: total normal force N (N), compression positive.
    """
    from .friction import initial_stiffness  # the one implementation of Eq. 22 (compiled; the kernels call it)

    n = np.asarray(normal_force, dtype=float)
    return (
        initial_stiffness(float(n), float(e_f), float(k_c))
        if n.ndim == 0
        else initial_stiffness(n, float(e_f), float(k_c))
    )


@dataclass(frozen=True)
class NormalLaw:
    """Hardening normal contact law around the preload (compression positive):

        N(eta) = N0 * ((delta0 - eta) / delta0)^p  for eta < delta0, 0 otherwise,

    with delta0 = p N0 / k_n the static approach, so that dN/d(-eta) = k_n at eta = 0.
    eta (m) is positive when the contact opens (Eq. 8).
    """

    preload: float
    stiffness_at_preload: float
    exponent: float

    @property
    def static_approach(self) -> float:
        """delta0 = p N0 / k_n (m)."""
        return self.exponent * self.preload / self.stiffness_at_preload

    def normal_force(self, eta):
        """Total normal force N (N) at normal gap change eta (m); zero once the contact opens."""
        d0 = self.static_approach
        c = np.clip((d0 - np.asarray(eta)) / d0, 0.0, None)
        return self.preload * c**self.exponent
